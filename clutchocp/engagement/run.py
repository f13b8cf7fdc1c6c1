"""Simulate an engagement scene: the run, its result (time series, table, figure) and the explanation of a
failed run; the numbers a clutch engineer reads are :mod:`clutchocp.engagement.measures`."""

import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import ModelEdgeError, ModelError, SolverError
from ..simulation.result import Table, unit_of
from ..simulation import SimulationOptions, simulate
from ..scene import load_scene
from ..scene.loader import check_value
from ..scene.schema import PARTS
from ..output import save_figure
from .edges import check_contact_capacity, contact_capacity
from .measures import summarize   # also imported from here by the optimal, shift-control and study floors
from .model import EngagementModel


def check_run_settings(**settings):
    """Check rtol, atol, t_end and output_points given to a run as the scene's [simulation] values are.

    None means "the scene's value". Raises a PhysicalRangeError naming the argument.
    """
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
        # Figures import results, never the reverse: the figure module (and matplotlib, ~0.3 s to
        # import) is loaded only when a run is drawn, never by the runs of a sweep.
        from .figures import overview_figure
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
        res.load(res.names())                  # every output: one call per segment
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
        plate temperatures ``T_interface`` .. ``T_core`` [degC] of a repeated engagement).
    parameters : dict, optional
        Values of the free parameters of ``model.hybrid`` (a model built with scene values as
        CasADi symbols, :mod:`clutchocp.study.parametric`), SI.

    Returns
    -------
    EngagementResult

    Raises
    ------
    PhysicalRangeError
        Before the run: the pack pressure exceeds what the asperity contact carries at zero gap
        (:func:`~clutchocp.engagement.edges.check_contact_capacity`).
    ModelEdgeError
        During the run: a film gap reached zero (the contact could not carry the load); one line naming
        the film, the time, its load and the contact's capacity.
    """
    if isinstance(scene, (str, Path)):
        scene = load_scene(scene)
    check_run_settings(rtol=rtol, atol=atol, t_end=t_end, output_points=output_points)
    check_contact_capacity(scene)
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
    grid = np.linspace(0.0, t_end, n_out)
    breaks = [b for b in model.actuation.breakpoints() if b < t_end]
    if breaks:                          # the profile's kinks join the grid (np.unique: sorted, once each)
        grid = np.unique(np.concatenate([grid, breaks]))
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
    except ModelEdgeError as err:
        raise explain_edge(model, err) from None
    except SolverError as err:
        raise explain_failure(model, err) from None
    wall = time.perf_counter() - start
    summary = summarize(model, result, wall, options, method)
    return EngagementResult(model, result, summary)


def explain_edge(model, err):
    """The edge event ``err`` (a film gap reached zero) in the engagement's terms: the film, the time, the
    load the film was pressed with and what the asperity contact carries at zero gap (or that there is
    none), and what to change. Other edges are returned unchanged."""
    if getattr(err, "event", None) != "film_closed":
        return err
    film, outputs = model.film, err.outputs
    i = int(err.edge.split()[1])
    contact = float(film.contact_force(0.0))
    load = float(outputs[f"film_{i}_fluid_force_N"]) + contact
    pressed = (f"film load {load / 1e3:.4g} kN = {load / film.area / 1e6:.3g} MPa over its {film.area * 1e6:.0f} "
               f"mm^2, pack force {float(outputs['pack_force_N']) / 1e3:.4g} kN")
    capacity = contact_capacity(model.scene)
    if capacity is None:
        causes = ["there is no asperity contact to carry the load (contact.model = 'none')"]
        if film.permeability > 0:
            causes.append(f"the oil drains through the permeable lining (plates.lining_permeability = "
                          f"{film.permeability:.3g} m^2)")
        why = "; ".join(causes) + f" ({pressed})"
        change = ("give a contact law with roughness (contact.model = 'greenwood_tripp', roughness.sigma of a few "
                  "um), or plates.lining_permeability = 0, or a lower actuation.pressure")
    else:
        why = (f"the contact could not carry the load ({pressed}; {capacity.law} carries at most "
               f"{contact / 1e3:.4g} kN = {capacity.pressure_Pa / 1e6:.3g} MPa at zero gap, {capacity.data})")
        change = ("lower actuation.pressure (or the inertia pressing the film), or raise roughness.sigma_* / "
                  "contact.E_equiv / roughness.asperity_density")
    new = ModelEdgeError(f"film {i} closed at t = {err.t:.6g} s in mode '{err.mode}': {why}; the model has no "
                         f"result beyond a closed film. Change: {change}.")
    for attr in ("t", "mode", "event", "edge", "flag", "states", "outputs"):
        setattr(new, attr, getattr(err, attr))
    return new


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
