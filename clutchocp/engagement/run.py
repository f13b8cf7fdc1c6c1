"""Simulate an engagement scene and reduce the run to the numbers a clutch engineer reads."""

import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import ModelError, SolverError
from ..simulation.result import Table, unit_of
from ..simulation import SimulationOptions, simulate
from ..simulation.locate import crossing_time, peak
from ..scene import load_scene
from ..scene.loader import check_value
from .model import ENERGY_TERMS, EngagementModel


def check_run_settings(**settings):
    """Check rtol, atol, t_end and output_points given to a run as the scene's [simulation] values are.

    None means "the scene's value". Raises a PhysicalRangeError naming the argument.
    """
    from ..scene.schema import PARTS
    fields = PARTS["simulation"].fields
    for name, value in settings.items():
        if value is not None:
            check_value(name, value, fields[name])


@dataclass(repr=False)
class EngagementResult:
    """An engagement run: the model, the raw hybrid result and its summary (``summary`` is JSON-ready).

    ``table()`` gives the time series with units, ``plot()`` an overview figure.
    """

    model: EngagementModel
    result: object
    summary: dict

    def __repr__(self):
        s = self.summary
        lock = "never locks" if s["engagement_time_s"] is None else f"lock-up {s['engagement_time_s']:.4g} s"
        return (f"EngagementResult(scene={s['scene']!r}, {lock}, peak torque {s['peak_torque_Nm']:.4g} N m, "
                f"dissipated {s['dissipated_energy_J']:.4g} J, {self.result.t.size} samples)")

    def table(self):
        """The time series as a :class:`~clutchocp.simulation.result.Table`: every column named with its
        unit (those of timeseries.csv without the unit-less state copies), samples on the output grid
        and at both sides of each event."""
        return Table({name: values for name, values in self.series().items() if name == "mode" or unit_of(name)})

    def plot(self, path=None):
        """Overview figure: films, speeds, torque and pressure against time; PNG if ``path`` is given.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from .report import overview_figure
        from ..output import save_figure
        fig = overview_figure(self)
        if path is not None:
            save_figure(fig, path)
        return fig

    def series(self):
        """Time series on the output grid and at both sides of each event: {column: array}.

        Besides the states and outputs, the energy accumulators E_x of the run are columns
        ``x_energy_J`` (work or energy since t = 0 [J]): with ``kinetic_energy_J`` and
        ``spring_energy_J`` they close the energy balance from the table alone (a transient of
        microseconds, bao2020's plate impact, is not resolved by any output grid).
        """
        res = self.result
        columns = {"time_s": res.t, "mode": res.mode}
        for name in self.model.state_names:
            if not name.startswith("E_"):
                columns[name] = res[name]
        for name in self.model.energy_terms:
            columns[f"{name[2:]}_energy_J"] = res[name]
        for name in res.names():
            if name.endswith(("_m", "_m_s", "_Pa", "_rad_s", "_Nm", "_N", "_rad_s2", "_rad_s3", "_W", "_J", "_C")):
                columns[name] = res[name]
        columns["specific_power_W_mm2"] = res["interface_heat_power_W"] / self.summary["friction_area_mm2"]
        return columns


def simulate_engagement(scene, *, rtol=None, atol=None, method="idas", t_end=None, output_points=None,
                        model=None, native=False, solver_options=None, initial_state=None, parameters=None):
    """Simulate an engagement scene through impact, slip and lock-up.

    Parameters
    ----------
    scene : clutchocp.scene.Scene, str or pathlib.Path
        An engagement scene, or a built-in scene name or a scene file.
    rtol, atol : float, optional
        Integration tolerances (default: the scene's [simulation] values); ``atol`` applies to
        states scaled by their nominal values.
    method : str
        ``"idas"`` (default), ``"cvodes"`` (CasADi CVODES on the same equations; scenes whose
        modes have no algebraic variables) or a scipy method (``"Radau"``, ``"BDF"``,
        ``"LSODA"``) on the same CasADi-generated right-hand side and Jacobian.
    t_end : float, optional
        End time [s] (default: simulation.t_end).
    output_points : int, optional
        Number of output times (default: simulation.output_points).
    model : EngagementModel, optional
        A model already built for this scene (saves the symbolic assembly; a second run of the
        same model also reuses its compiled functions and IDAS integrators).
    native : bool
        IDAS: evaluate the equations, the outputs and the event functions that call tables as
        compiled machine code
        (:class:`~clutchocp.simulation.SimulationOptions` ``native``; same results, ~30 % faster
        runs, ~0.3 s of compilation per mode the first time).
    solver_options : dict, optional
        Further :class:`~clutchocp.simulation.SimulationOptions` fields, e.g.
        ``{"max_wall_time": 10.0}`` (a wall-time cap [s]) or ``{"event_value_tol": 1e-10}``.
    initial_state : dict, optional
        ``{state name: value}`` replacing the scene's initial values (e.g. the plate temperatures
        ``T_friction``, ``T_separator`` [degC] of a repeated engagement).
    parameters : dict, optional
        Values of the free parameters of ``model.hybrid`` (a model built with scene values as
        CasADi symbols, :mod:`clutchocp.study.parametric`), SI.

    Returns
    -------
    EngagementResult
    """
    if isinstance(scene, (str, Path)):
        scene = load_scene(scene)
    check_run_settings(rtol=rtol, atol=atol, t_end=t_end, output_points=output_points)
    model = model or EngagementModel(scene)
    t_end = t_end or scene.value("simulation.t_end")
    n_out = output_points or scene.value("simulation.output_points")
    # IDAS calls end just past the predicted next event (simulation/idas_path.py): the free piston
    # of the approach phase is not integrated past its impact (bao2020: 2 000 steps in all; fixed
    # chunks of 32 intervals took 3 600, one call per piece 72 000).
    settings = {"rtol": rtol or scene.value("simulation.rtol"), "atol": atol or scene.value("simulation.atol"),
                "native": native}
    settings.update(solver_options or {})
    options = SimulationOptions(**settings)
    grid = np.unique(np.concatenate([np.linspace(0.0, t_end, n_out),
                                     [b for b in model.actuation.breakpoints() if b < t_end]]))
    x0 = dict(zip(model.state_names, model.initial_state))
    for name, value in (initial_state or {}).items():
        if name not in x0:
            raise ModelError(f"initial_state: '{name}' is not a state of scene '{scene.name}' "
                             f"(states: {', '.join(model.state_names)})")
        x0[name] = float(value)
    start = time.perf_counter()
    try:
        result = simulate(model.hybrid, x0, grid, mode=model.initial_mode(), p=parameters, options=options,
                          method=method)
    except SolverError as err:
        raise explain_failure(model, err) from None
    wall = time.perf_counter() - start
    summary = summarize(model, result, wall, options, method)
    return EngagementResult(model, result, summary)


def explain_failure(model, err):
    """The solver error ``err`` with the engagement behind it, where it can be told from the state.

    A film that has closed to (almost) zero thickness is the usual cause: with no asperity contact
    to carry the load (contact.model = 'none', or roughness far smaller than the gap scale) the
    squeeze film thins without bound, and through a permeable lining it drains completely in
    finite time; the viscous torque ~ 1/h then overflows. Other errors are returned unchanged.
    """
    states = getattr(err, "states", None) or {}
    gaps = {name: value for name, value in states.items() if name.startswith("h_")}
    if not gaps:
        return err
    name, h = min(gaps.items(), key=lambda item: item[1])
    sigma = model.film.sigma
    if not (h <= 1e-3 * model.sigma):
        return err
    causes = []
    if model.film.contact_model == "none":
        causes.append("there is no asperity contact to carry the load (contact.model = 'none')")
    elif sigma > 0 and sigma < 1e-3 * model.H0:
        causes.append(f"the roughness roughness.sigma = {sigma:.3g} m is tiny against the gap "
                      f"pack.initial_gap = {model.H0:.3g} m, so contact only begins at a vanishing film")
    if model.film.permeability > 0:
        causes.append(f"oil drains through the permeable lining (plates.lining_permeability = "
                      f"{model.film.permeability:.3g} m^2) even when the film has closed")
    why = "; ".join(causes) or "the film load could not stop the plates"
    text = (f"{err} Extreme case: film {name} had closed to {h:.3g} m at t = {getattr(err, 't', float('nan')):.6g} s "
            f"because {why}. Change: give a contact law with roughness (contact.model = 'greenwood_tripp', "
            f"roughness.sigma of a few um), or plates.lining_permeability = 0, or a lower actuation.pressure.")
    new = SolverError(text)
    for attr in ("t", "mode", "flag", "states"):
        if hasattr(err, attr):
            setattr(new, attr, getattr(err, attr))
    return new


def pieces(result):
    """Label of each sample: the index of its segment (one mode between two events)."""
    return np.concatenate([np.full(seg.t.size, i) for i, seg in enumerate(result.segments)])


def _first_crossing(t, y, level, piece=None):
    """First time y reaches ``level``, located on the local cubic of the samples (or None)."""
    return crossing_time(t, y, level, piece=piece)


def pressure_rise_time(model, result, fraction):
    """First time [s] the pressure has risen by ``fraction`` of the way to the set pressure (located on
    the local cubic of the samples), or None (also when the set pressure is not above the initial one)."""
    return pressure_rise_times(model, result, (fraction,))[fraction]


def pressure_rise_times(model, result, fractions, piece=None):
    """:func:`pressure_rise_time` of each of ``fractions`` (a dict ``{fraction: time [s] or None}``),
    the pressure samples read once; ``piece``: :func:`pieces` of ``result`` if already at hand."""
    p_set = model.scene.value("actuation.pressure")
    p0 = model.scene.value("actuation.initial_pressure")
    if p_set <= p0:       # no rise (a release: spring-applied clutch): Zhang's response times do not apply
        return dict.fromkeys(fractions)
    rise = (result["pressure_Pa"] - p0) / (p_set - p0)
    piece = pieces(result) if piece is None else piece
    return {fraction: _first_crossing(result.t, rise, fraction, piece) for fraction in fractions}


def _slipping(result):
    """Boolean mask of the output samples taken while the clutch slips."""
    return np.concatenate([np.full(seg.t.size, not str(seg.mode).endswith("locked")) for seg in result.segments])


def response_times(model, result, *, rise=None, piece=None, slipping=None):
    """Zhang 2021's response times [s], with the torque response measured to the largest slipping torque.

    Pressure response: from 10 % to 90 % of the set pressure. Torque response (peak-based): from
    50 % of the set pressure to 90 % of the largest slipping torque (viscous + asperity). Zhang's
    own definition, to the stable torque, is :func:`stable_torque_response`. ``rise``
    (:func:`pressure_rise_times` of 0.1, 0.5 and 0.9), ``piece`` (:func:`pieces`) and ``slipping``
    save reading them again when the caller has them.
    """
    t = result.t
    piece = pieces(result) if piece is None else piece
    rise = pressure_rise_times(model, result, (0.1, 0.5, 0.9), piece) if rise is None else rise
    t10, t50, t90 = rise[0.1], rise[0.5], rise[0.9]
    pressure_time = t90 - t10 if t10 is not None and t90 is not None else None
    slipping = _slipping(result) if slipping is None else slipping
    torque_time = None
    if t50 is not None and slipping.any():
        t_slip, piece_slip = t[slipping], piece[slipping]
        torque = np.abs(result["total_torque_Nm"][slipping])
        t90_torque = _first_crossing(t_slip, torque, 0.9 * peak(t_slip, torque, piece_slip)[0], piece_slip)
        if t90_torque is not None:
            torque_time = t90_torque - t50
    return pressure_time, torque_time


def stable_torque_response(model, result, *, t50=False, piece=None, slipping=None):
    """Zhang 2021's torque response to the stable transmitted torque (Zhang Section 3, Fig. 2).

    Zhang defines the torque response time as the time from 50 % of the set pressure to the
    torque reaching 90 % of its *stable* value. Once the film has drained (Zhang Section 2,
    'mechanical contact stage') the transmitted torque is the asperity friction torque alone, so
    the stable torque is the asperity torque at the end of the slip (the last slipping sample:
    just before lock-up, or at the end of the run), which for a massless pack at the set
    pressure P_o is f_c P_o A_n r_eff per film; the response is the first time the asperity
    torque reaches 90 % of it. The total torque is not used: its viscous part can exceed the
    stable torque from the start of the squeeze (zhang2021 at 1000 rad/s: 43 N m on the open gap
    against 53 N m stable), which would make the time negative and blind to the contact.
    ``t50`` (the 50 % pressure time, None if never), ``piece`` and ``slipping`` save reading them
    again when the caller has them.

    Returns
    -------
    (stable_torque, response_time) : [N m], [s]; each None if it does not exist (no slip, no
    asperity torque, or the pressure never reaches 50 %).
    """
    slipping = _slipping(result) if slipping is None else slipping
    if not slipping.any():
        return None, None
    t, contact_torque = result.t[slipping], np.abs(result["contact_torque_Nm"][slipping])
    stable = float(contact_torque[-1])
    piece = pieces(result) if piece is None else piece
    t50 = pressure_rise_times(model, result, (0.5,), piece)[0.5] if t50 is False else t50
    if stable <= 0 or t50 is None:
        return (stable if stable > 0 else None), None
    t90 = _first_crossing(t, contact_torque, 0.9 * stable, piece[slipping])
    return stable, (t90 - t50 if t90 is not None else None)


def energy_balance(model, result):
    """Energy bookkeeping of the run [J] and its relative error.

    work in (source + hydraulic - load + spring released) = kinetic energy change + contact
    (elastic) storage + dissipation (slip, film, seal, splines, shaft damping, impact); the spring
    energy includes the twist of a compliant shaft. With a [thermal] part the slip and film
    dissipation is closed through the plates instead: it must equal the heat stored in them plus
    the heat convected to the oil (so the balance checks the temperature states too).
    """
    E = {name: result.final(name) if name in model.energy_terms else 0.0 for name in ENERGY_TERMS}
    ke = result["kinetic_energy_J"]
    spring = result["spring_energy_J"]
    work_in = E["E_source"] + E["E_hydraulic"] - E["E_load"] + (spring[0] - spring[-1])
    interfaces = E["E_slip"] + E["E_film"]
    dissipated = interfaces + E["E_seal"] + E["E_spline"] + E["E_shaft"] + E["E_impact"]
    stored = (ke[-1] - ke[0]) + E["E_contact"]
    out = {"work_in_J": work_in, "kinetic_energy_change_J": ke[-1] - ke[0], "contact_storage_J": E["E_contact"],
           "dissipated_J": dissipated}
    closure = dissipated
    if model.thermal.present:
        out["heat_stored_J"] = float(result["stored_heat_J"][-1] - result["stored_heat_J"][0])
        out["heat_to_oil_J"] = E["E_convection"]
        closure = dissipated - interfaces + out["heat_stored_J"] + out["heat_to_oil_J"]
    scale = max(abs(work_in), abs(ke[-1] - ke[0]), abs(dissipated), 1e-12)
    out["rel_error"] = abs(work_in - stored - closure) / scale
    return out


def summarize(model, result, wall_time, options, method):
    """The numbers of an engagement (JSON-ready; units in the key names)."""
    locks = [e for e in result.events if e.name == "lockup" and e.target.endswith("locked")]
    locked_at_end = str(result.final_mode).endswith("locked")
    lock = locks[-1] if locks and locked_at_end else None
    jump = None
    t_lock = float(lock.t) if lock is not None else None
    if lock is not None:
        jump = float(lock.outputs_after["total_torque_Nm"] - lock.outputs_before["total_torque_Nm"])
    elif all(str(seg.mode).endswith("locked") for seg in result.segments):
        t_lock = float(result.t[0])          # locked from the start (equal speeds held): no slip, no jump
    energy = energy_balance(model, result)
    piece, slipping = pieces(result), _slipping(result)
    rise = pressure_rise_times(model, result, (0.1, 0.5, 0.9), piece)
    pressure_time, torque_time = response_times(model, result, rise=rise, piece=piece, slipping=slipping)
    stable_torque, stable_torque_time = stable_torque_response(model, result, t50=rise[0.5], piece=piece,
                                                               slipping=slipping)
    jerk = result["output_jerk_rad_s3"]
    summary = {
        "scene": model.scene.name,
        "engagement_time_s": t_lock,
        "lockup_torque_jump_Nm": jump,
        "peak_torque_Nm": peak(result.t, np.abs(result["total_torque_Nm"]), piece)[0],
        "peak_jerk_rad_s3": float(np.max(np.abs(jerk[np.isfinite(jerk)]))),
        "dissipated_energy_J": energy["dissipated_J"],
        "energy_balance_rel_error": energy["rel_error"],
        "energy": energy,
        "torque_response_time_s": torque_time,
        "stable_torque_Nm": stable_torque,
        "torque_response_time_stable_s": stable_torque_time,
        "pressure_response_time_s": pressure_time,
        "events": [{"name": e.name, "time_s": float(e.t), "from": e.source, "to": e.target} for e in result.events],
        "final_mode": str(result.final_mode),
        "wall_time_s": wall_time,
        "n_states": model.n_states,
        "solver": {"method": method, **{k: v for k, v in options.as_dict().items() if k != "idas_options"},
                   "statistics": result.stats},
    }
    summary.update(thermal_summary(model, result))
    return summary


def thermal_summary(model, result):
    """Heat numbers a clutch is sized by (JSON-ready; units in the key names).

    The friction area is the nominal area of all interfaces, n_interfaces x pi (r2^2 - r1^2);
    the interface heat is the slip and squeeze-film dissipation. The temperatures need a
    [thermal] part.
    """
    area_mm2 = model.n * model.film.area * 1e6
    heat = result["interface_heat_power_W"]
    out = {"friction_area_mm2": area_mm2,
           "interface_heat_J": float(result.final("E_slip") + result.final("E_film")),
           "peak_specific_power_W_mm2": float(np.max(heat)) / area_mm2}
    out["specific_energy_J_mm2"] = out["interface_heat_J"] / area_mm2
    if model.thermal.present:
        temperature = result["interface_temperature_C"]
        k = int(np.argmax(temperature))
        out.update({"peak_interface_temperature_C": float(temperature[k]),
                    "peak_interface_temperature_time_s": float(result.t[k]),
                    "final_interface_temperature_C": float(temperature[-1]),
                    "final_friction_plate_temperature_C": float(result.final("T_friction")),
                    "final_separator_temperature_C": float(result.final("T_separator"))})
    return out
