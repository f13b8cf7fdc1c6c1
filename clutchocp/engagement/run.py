"""Simulate an engagement scene and reduce the run to the numbers a clutch engineer reads."""

import time
from dataclasses import dataclass

import numpy as np

from ..errors import SolverError
from ..simulation import SimulationOptions, simulate
from .model import ENERGY_TERMS, EngagementModel


@dataclass
class EngagementResult:
    """An engagement run: the model, the raw hybrid result and its summary (``summary`` is JSON-ready)."""

    model: EngagementModel
    result: object
    summary: dict

    def series(self):
        """Time series on the output grid and at both sides of each event: {column: array}."""
        res = self.result
        columns = {"time_s": res.t, "mode": res.mode}
        for name in self.model.state_names:
            if not name.startswith("E_"):
                columns[name] = res[name]
        for name in res.names():
            if name.endswith(("_m", "_Pa", "_rad_s", "_Nm", "_N", "_rad_s2", "_rad_s3", "_W", "_J")):
                columns[name] = res[name]
        return columns


def simulate_engagement(scene, *, rtol=None, atol=None, method="idas", t_end=None, output_points=None,
                        model=None, native=False, solver_options=None, parameters=None):
    """Simulate an engagement scene through impact, slip and lock-up.

    Parameters
    ----------
    scene : clutchocp.scene.Scene
        An engagement scene.
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
        IDAS: evaluate the equations and outputs as compiled machine code
        (:class:`~clutchocp.simulation.SimulationOptions` ``native``; same results, ~30 % faster
        runs, ~0.3 s of compilation per mode the first time).
    solver_options : dict, optional
        Further :class:`~clutchocp.simulation.SimulationOptions` fields, e.g.
        ``{"max_wall_time": 10.0}`` (a wall-time cap [s]) or ``{"event_value_tol": 1e-10}``.
    parameters : dict, optional
        Values of the free parameters of ``model.hybrid`` (a model built with scene values as
        CasADi symbols, :mod:`clutchocp.study.parametric`), SI.

    Returns
    -------
    EngagementResult
    """
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


def _first_crossing(t, y, level):
    """First time y reaches ``level`` (linear interpolation), or None."""
    above = np.nonzero(y >= level)[0]
    if above.size == 0:
        return None
    k = above[0]
    if k == 0:
        return float(t[0])
    return float(t[k - 1] + (level - y[k - 1]) * (t[k] - t[k - 1]) / (y[k] - y[k - 1]))


def response_times(model, result):
    """Zhang 2021's response times [s].

    Pressure response: from 10 % to 90 % of the set pressure. Torque response: from 50 % of
    the set pressure to 90 % of the transmitted torque, taken as the largest slipping torque.
    """
    t, p = result.t, result["pressure_Pa"]
    p_set = model.scene.value("actuation.pressure")
    p0 = model.scene.value("actuation.initial_pressure")
    rise = lambda frac: _first_crossing(t, (p - p0) / (p_set - p0), frac) if p_set != p0 else None  # noqa: E731
    t10, t50, t90 = rise(0.1), rise(0.5), rise(0.9)
    pressure_time = t90 - t10 if t10 is not None and t90 is not None else None
    slipping = np.concatenate([np.full(seg.t.size, not str(seg.mode).endswith("locked")) for seg in result.segments])
    torque = np.abs(result["total_torque_Nm"])
    torque_time = None
    if t50 is not None and slipping.any():
        t90_torque = _first_crossing(t[slipping], torque[slipping], 0.9 * torque[slipping].max())
        if t90_torque is not None:
            torque_time = t90_torque - t50
    return pressure_time, torque_time


def energy_balance(model, result):
    """Energy bookkeeping of the run [J] and its relative error.

    work in (source + hydraulic - load + spring released) = kinetic energy change + contact
    (elastic) storage + dissipation (slip, film, seal, splines, shaft damping, impact); the spring
    energy includes the twist of a compliant shaft.
    """
    E = {name: result.final(name) if name in model.energy_terms else 0.0 for name in ENERGY_TERMS}
    ke = result["kinetic_energy_J"]
    spring = result["spring_energy_J"]
    work_in = E["E_source"] + E["E_hydraulic"] - E["E_load"] + (spring[0] - spring[-1])
    dissipated = E["E_slip"] + E["E_film"] + E["E_seal"] + E["E_spline"] + E["E_shaft"] + E["E_impact"]
    stored = (ke[-1] - ke[0]) + E["E_contact"]
    scale = max(abs(work_in), abs(ke[-1] - ke[0]), abs(dissipated), 1e-12)
    return {
        "work_in_J": work_in,
        "kinetic_energy_change_J": ke[-1] - ke[0],
        "contact_storage_J": E["E_contact"],
        "dissipated_J": dissipated,
        "rel_error": abs(work_in - stored - dissipated) / scale,
    }


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
    pressure_time, torque_time = response_times(model, result)
    jerk = result["output_jerk_rad_s3"]
    return {
        "scene": model.scene.name,
        "engagement_time_s": t_lock,
        "lockup_torque_jump_Nm": jump,
        "peak_torque_Nm": float(np.max(np.abs(result["total_torque_Nm"]))),
        "peak_jerk_rad_s3": float(np.max(np.abs(jerk[np.isfinite(jerk)]))),
        "dissipated_energy_J": energy["dissipated_J"],
        "energy_balance_rel_error": energy["rel_error"],
        "energy": energy,
        "torque_response_time_s": torque_time,
        "pressure_response_time_s": pressure_time,
        "events": [{"name": e.name, "time_s": float(e.t), "from": e.source, "to": e.target} for e in result.events],
        "final_mode": str(result.final_mode),
        "wall_time_s": wall_time,
        "n_states": model.n_states,
        "solver": {"method": method, **{k: v for k, v in options.as_dict().items() if k != "idas_options"},
                   "statistics": result.stats},
    }
