"""The integrator floor: the best speed-up over scipy any event handling and output scheme could give.

A whole engagement run pays for more than the integrator: event detection and location,
restarts after events, outputs on the grid, the summary. Here the event times and the states
after every switch are taken from the reference run, and each mode piece (reference event to
reference event) is integrated in one call from the reference state at its start, with one
output at its end and no event functions:

* ``"idas"``: one call per piece of the engine's integrator of that mode (IDAS, or CVODES for a
  mode without algebraic variables), the same cached integrators, options and consistent
  initialisation as the engine (:class:`~clutchocp.simulation.idas_path.IdasPath`);
* ``"Radau"``, ``"LSODA"``: one ``solve_ivp`` per piece on the same reduced right-hand side and
  exact CasADi Jacobian as the engine's scipy path (:class:`~clutchocp.simulation.scipy_path.ScipyPath`).

The time of a method at a tolerance is the sum over the pieces (best of ``repeats``); its error
is the one the method's whole run reached at that tolerance in the work-precision sweep (same
pieces, same tolerances), so floor times compare at the sweep's matched errors. The largest
relative error of the scaled end states, ``|xs - xs_ref| / max(1, |xs_ref|)``, is reported as
a check (``piece_end_error``). The ratio of the scipy time to the IDAS time at matched error
bounds what whole runs can reach: these add grid work to both sides, restarts to IDAS.
"""

import functools
import math
import time

import numpy as np
from scipy.integrate import solve_ivp

from ..errors import ClutchocpError
from ..simulation.idas_path import IdasPath, _IdasFailure
from ..simulation.options import SimulationOptions
from ..simulation.scipy_path import ScipyPath
from . import workprecision
from .turns import best_of_turns

METHODS = ("idas", "Radau", "LSODA")
COLUMNS = ("scene", "method", "rtol", "status", "time_s", "error", "piece_end_error")
PEERS = ("Radau", "LSODA")


def pieces(reference):
    """The mode pieces of a reference run: ``(mode, t0, xs0, zs0, t1, xs1)``, scaled states at
    the start (just after the switch) and at the end (just before the next switch, or the end)."""
    compiled = reference.model.hybrid.compiled()
    out = []
    for seg in reference.result.segments:
        if seg.t.size < 2 or seg.t[-1] <= seg.t[0]:
            continue
        cm = compiled[seg.mode]
        xs = np.array([seg.x[n] for n in cm.x_names]) / cm.x_nominal[:, None]
        zs0 = np.array([seg.z[n][0] for n in cm.z_names]) / cm.z_nominal if cm.nz else np.zeros(0)
        out.append((cm, float(seg.t[0]), xs[:, 0], zs0, float(seg.t[-1]), xs[:, -1]))
    return out


def _idas_piece(path, cm, t0, xs0, zs0, pu, t1):
    try:
        xs, _ = path._integrate_to(cm, t0, xs0, zs0, pu, t1)
    except _IdasFailure as fail:
        raise ClutchocpError(f"IDAS failed in mode '{cm.name}' between t = {t0:.9g} and {t1:.9g} s: {fail}") from None
    return xs


def _scipy_piece(path, method, cm, t0, xs0, pu, t1, rtol, atol):
    _, rhs, jac = path._functions(cm, pu)
    with np.errstate(all="ignore"):
        sol = solve_ivp(rhs, (t0, t1), xs0, method=method, rtol=rtol, atol=atol, jac=jac)
    if sol.status != 0:
        raise ClutchocpError(f"scipy {method} failed in mode '{cm.name}' after t = {sol.t[-1]:.9g} s: {sol.message}")
    return sol.y[:, -1]


def floor_run(model, parts, method, rtol, repeats=3, native=False):
    """Integrate every piece once per repeat with ``method`` at ``rtol`` (atol = rtol x
    :data:`~clutchocp.bench.workprecision.ATOL_RATIO`); ``native``: the engine's integrators on the
    equations compiled to machine code (``SimulationOptions.native``, the floor of ``"idas-native"``).

    Returns
    -------
    time_s : float
        Best total time over the repeats [s].
    error : float
        Largest relative error of the scaled end states (see the module docstring).
    """
    path = floor_path(model, method, rtol, native)
    best, error = math.inf, 0.0
    for attempt in range(max(1, repeats) + 1):       # the first pass builds and caches the integrators
        total, error = floor_pass(model, parts, method, rtol, path)
        if attempt > 0:
            best = min(best, total)
    return best, error


def floor_path(model, method, rtol, native=False):
    """The integrator path :func:`floor_pass` integrates with (its integrators cached on the model)."""
    if model.hybrid.p or model.hybrid.u:
        raise ClutchocpError("the integrator floor needs a model with its parameters built in (no free inputs)")
    options = SimulationOptions(rtol=rtol, atol=rtol * workprecision.ATOL_RATIO, native=native)
    return IdasPath(options) if method == "idas" else ScipyPath(method, options)


def floor_pass(model, parts, method, rtol, path):
    """One pass over the pieces: the time inside the integrations [s] and the largest relative error
    of the scaled end states."""
    pu = np.zeros(0)                                  # the engagement model's values are built in
    atol = rtol * workprecision.ATOL_RATIO
    total, worst = 0.0, 0.0
    for cm, t0, xs0, zs0, t1, xs_ref in parts:
        start = time.perf_counter()
        if method == "idas":
            xs = _idas_piece(path, cm, t0, xs0, zs0, pu, t1)
        else:
            xs = _scipy_piece(path, method, cm, t0, xs0, pu, t1, rtol, atol)
        total += time.perf_counter() - start
        worst = max(worst, float(np.max(np.abs(xs - xs_ref) / np.maximum(1.0, np.abs(xs_ref)))))
    return total, worst


def integrator_floor(reference, sweep_rows, methods=METHODS, repeats=3, progress=None, least_repeats=None):
    """The floor of every (method, rtol) point of a work-precision sweep on one scene.

    Each point keeps the error its whole run reached in the sweep (the floor integrates the same
    pieces at the same tolerances), so the floor times compare at the sweep's matched errors.

    Parameters
    ----------
    reference : EngagementResult
        The sweep's reference run (its event times, states and model).
    sweep_rows : list of dict
        The rows of :func:`~clutchocp.bench.workprecision.sweep` for this scene.
    methods : sequence of str
    repeats : int
        Timed passes per point (the best counts).
    least_repeats : dict, optional
        ``{method: n}``: at least ``n`` timed passes per point for these methods (e.g. IDAS, whose
        passes are short and noisy).
    progress : clutchocp.bench.progress.Progress, optional

    Returns
    -------
    dict
        ``rows`` (method, rtol, error of the whole run, time_s of the floor, piece_end_error,
        status), ``n_pieces``, and per peer ``floor_speedup_vs_<peer>`` (geometric mean over the
        matched error levels of :data:`~clutchocp.bench.workprecision.ERROR_LEVELS`), ``..._min``
        and ``..._levels``.
    """
    model = reference.model
    parts = pieces(reference)
    name = model.scene.name
    points = [r for r in sweep_rows if r["method"] in methods and r.get("status") == "ok"]
    rows = []
    # at each tolerance the methods take turns, one pass each, ``repeats`` rounds after one untimed pass
    # each (the methods of ``least_repeats`` take their extra rounds last): the floors a ratio divides are
    # timed side by side, so a machine that slows down for a while slows them alike, and the best pass
    # of each comes from its fastest stretch
    for rtol in sorted({r["rtol"] for r in points}, reverse=True):
        at = [{"scene": name, "method": r["method"], "rtol": rtol, "error": r["error"]} for r in points if r["rtol"] == rtol]
        paths = {}
        for row in at:
            try:
                paths[row["method"]] = floor_path(model, row["method"], rtol)
                row.update(status="ok", time_s=math.inf,
                           piece_end_error=floor_pass(model, parts, row["method"], rtol, paths[row["method"]])[1])
            except ClutchocpError as exc:
                row.update(status=f"failed: {str(exc)[:200]}")
        ok = [row for row in at if row["status"] == "ok"]
        best = best_of_turns({row["method"]: functools.partial(floor_pass, model, parts, row["method"], rtol,
                                                               paths[row["method"]]) for row in ok},
                             {row["method"]: max(repeats, (least_repeats or {}).get(row["method"], 1)) for row in ok},
                             warm_up=False)
        for row in ok:
            row["time_s"], row["piece_end_error"] = best[row["method"]]
        rows += at
    rows.sort(key=lambda r: (list(methods).index(r["method"]), -r["rtol"]))
    for method in methods:
        done = [r for r in rows if r["method"] == method and r["status"] == "ok"]
        if progress and done:
            progress.note(f"{name} integrator floor, {method}: " + ", ".join(
                f"{r['time_s'] * 1e3:.1f} ms at rtol {r['rtol']:.0e}" for r in done[::2]))
    summary = {"n_pieces": len(parts), "rows": rows}
    ratios = workprecision.speedups(rows, peers=PEERS, key="time_s")
    for peer, by_level in ratios.items():
        mean, low, count = workprecision.headline(by_level)
        key = f"floor_speedup_vs_{peer.lower()}"
        summary.update({key: mean, f"{key}_min": low, f"{key}_levels": count})
    return summary
