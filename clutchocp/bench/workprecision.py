"""Work-precision of the engagement simulation: error against run time for every integrator.

Every method integrates the same CasADi-generated equations of a scene
(:func:`clutchocp.engagement.run.simulate_engagement`): ``"idas"`` (the default engine: IDAS for
modes with algebraic variables, CasADi's CVODES with BDF for the others, which all engagement
modes are; ``SimulationOptions.ode_integrator``),
``"idas-native"`` (IDAS with the equations compiled to machine code), ``"cvodes"`` (CasADi's
CVODES on the same normalised-time ODE; the engagement modes have no algebraic variables) and
scipy's ``"Radau"``, ``"BDF"``, ``"LSODA"`` (the reduced ODE with the exact CasADi Jacobian).

Error of a run against a reference (all relative, see :func:`trajectory_errors`): speeds on the
output grid (to the largest reference speed), film thicknesses on the grid (to the local
thickness, at least the roughness), lock-up time, lock-up torque jump; the run's error is the
largest of the four. The reference is IDAS at ``REFERENCE_RTOL``, confirmed by scipy Radau at
``CONFIRM_RTOL`` (the confirmation's own error against it is reported). The engine locates events
to ``event_value_tol`` (1e-6 of the scaled event function) by default; so that the lock time
measures the integrator and not that setting, the engine methods get event tolerances that
follow the integration tolerance (:func:`event_options`), while scipy locates its events to
machine precision on its dense output.

Wall times are of the whole ``simulate_engagement`` call (integration, event location, outputs,
summary) with the model built and its integrators cached by an untimed warm-up run; the best of
``repeats`` runs counts. An IDAS row also gets the time of its run's summary work (the outputs its
summary reads, evaluated afresh, and the summary: :mod:`clutchocp.bench.summary_work`), which
every whole run pays whatever integrates it, and of its event work (its modes' event functions on
the samples it keeps: :mod:`clutchocp.bench.event_work`), which the floor, knowing its events,
skips, of its summary's arithmetic alone (its outputs evaluated beforehand), and of the calls its run
makes into compiled code replayed back to back (:mod:`clutchocp.bench.call_replay`): the least an
engine in Python making the same calls costs. Times at matched error come from the Pareto front of
each method's (error, time) points, interpolated in log-log (:func:`time_at_error`).
"""

import itertools
import math
import time

import numpy as np

from ..engagement.model import EngagementModel
from ..engagement.run import simulate_engagement
from ..errors import ClutchocpError, ModelError
from ..output import new_figure, save_figure, write_csv
from .call_replay import run_replay_time
from .event_work import event_work_time
from .summary_work import summary_arithmetic_time, summary_time
from .turns import best_of_turns

METHODS = ("idas", "idas-native", "cvodes", "Radau", "BDF", "LSODA")
SCIPY = ("Radau", "BDF", "LSODA")
PEERS = ("cvodes", "Radau", "BDF", "LSODA")          # compared with idas at matched error
TOLERANCES = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10)
REFERENCE_RTOL = 1e-12
CONFIRM_METHOD, CONFIRM_RTOL = "Radau", 1e-10
ATOL_RATIO = 1e-2                                      # atol = rtol * ATOL_RATIO (scaled states)
ERROR_LEVELS = tuple(10.0 ** -k for k in np.arange(4.5, 10.01, 0.5))   # matched errors below 1e-4
ERROR_PARTS = ("speeds", "gaps", "lock_time", "torque_jump")


def event_options(rtol):
    """Engine event tolerances for integration tolerance ``rtol``: the default ones (1e-9 s,
    1e-6) at rtol >= 1e-6, tighter with tighter rtol, so the event location error stays below
    the integration error."""
    return {"event_value_tol": min(1e-6, rtol), "event_time_tol": min(1e-9, 1e-3 * rtol)}


def run_method(scene, model, method, rtol, **solver_options):
    """One engagement run with ``method`` at ``rtol`` (atol = rtol * ATOL_RATIO)."""
    native = method == "idas-native"
    engine = method in ("idas", "idas-native", "cvodes")
    options = {**(event_options(rtol) if engine else {}), **solver_options}
    return simulate_engagement(scene, model=model, method="idas" if native else method, rtol=rtol,
                               atol=rtol * ATOL_RATIO, native=native, solver_options=options)


def timed_run(scene, model, method, rtol, repeats=1, **solver_options):
    """Best wall time [s], best CPU time [s] of ``repeats`` runs, and the run with the best wall time."""
    best_wall, best_cpu, best_run = math.inf, math.inf, None
    for _ in range(max(1, repeats)):
        wall, cpu = time.perf_counter(), time.process_time()
        run = run_method(scene, model, method, rtol, **solver_options)
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
        if wall < best_wall:
            best_wall, best_run = wall, run
        best_cpu = min(best_cpu, cpu)
    return best_wall, best_cpu, best_run


def grid_values(run, name):
    """Values of ``name`` on the scene's output grid (of the samples repeating a time at an
    event, the one after it)."""
    scene = run.model.scene
    grid = np.linspace(0.0, scene.value("simulation.t_end"), scene.value("simulation.output_points"))
    t, values = run.result.t, run.result[name]
    index = np.searchsorted(t, grid, side="right") - 1
    return values[index]


def _relative(value, reference, floor=0.0):
    if value is None and reference is None:
        return 0.0
    if value is None or reference is None:
        return math.inf
    return abs(value - reference) / max(abs(reference), floor) if max(abs(reference), floor) > 0 else abs(value)


def trajectory_errors(run, reference):
    """Relative errors of ``run`` against ``reference`` (same scene and grid).

    Returns
    -------
    dict
        ``speeds``: max over the grid of |w - w_ref| / max |w_ref| (input and output);
        ``gaps``: max over the grid and the films of |h - h_ref| / max(h_ref, sigma);
        ``lock_time``: |t - t_ref| / t_ref (inf if only one of them locks);
        ``torque_jump``: |jump - jump_ref| / |jump_ref|;
        ``max``: the largest of these.
    """
    model = reference.model
    errors = {}
    speed_errors = []
    for name in ("w_in_rad_s", "w_out_rad_s"):
        ref = grid_values(reference, name)
        scale = np.max(np.abs(ref))
        if scale > 0:
            speed_errors.append(np.max(np.abs(grid_values(run, name) - ref)) / scale)
    errors["speeds"] = float(max(speed_errors, default=0.0))
    gap_errors = []
    for i in range(model.n):
        ref = grid_values(reference, f"h_{i + 1}_m")
        gap_errors.append(np.max(np.abs(grid_values(run, f"h_{i + 1}_m") - ref) / np.maximum(ref, model.sigma)))
    errors["gaps"] = float(max(gap_errors))
    errors["lock_time"] = _relative(run.summary["engagement_time_s"], reference.summary["engagement_time_s"])
    errors["torque_jump"] = _relative(run.summary["lockup_torque_jump_Nm"], reference.summary["lockup_torque_jump_Nm"],
                                      floor=1e-9 * reference.summary["peak_torque_Nm"])
    errors["max"] = max(errors[k] for k in ERROR_PARTS)
    return errors


def reference_runs(scene, model):
    """The reference run (IDAS, REFERENCE_RTOL) and its confirmation (CONFIRM_METHOD, CONFIRM_RTOL).

    Returns
    -------
    reference : EngagementResult
    confirmation : dict
        ``method``, ``rtol`` and the confirmation's errors against the reference (None if the
        confirming method failed, with ``failure``).
    """
    reference = run_method(scene, model, "idas", REFERENCE_RTOL)
    confirmation = {"method": CONFIRM_METHOD, "rtol": CONFIRM_RTOL}
    try:
        other = run_method(scene, model, CONFIRM_METHOD, CONFIRM_RTOL)
        confirmation["errors"] = trajectory_errors(other, reference)
    except ClutchocpError as err:
        confirmation.update(errors=None, failure=str(err)[:300])
    return reference, confirmation


def timed_runs(method, repeats, least_repeats=None):
    """Timed runs per sweep point of ``method``: ``repeats``, three times as many for the engine
    methods (short, noisy runs), at least ``least_repeats[method]`` where given."""
    count = repeats * (3 if method in ("idas", "idas-native", "cvodes") else 1)
    return max(count, (least_repeats or {}).get(method, 1))


def sweep(scene, *, methods=METHODS, tolerances=TOLERANCES, repeats=3, progress=None, model=None, least_repeats=None):
    """Every method over the tolerance sweep on one scene, against the reference.

    After one warm-up run of each method, the methods take turns at each tolerance (all of them at
    the loosest, then at the next), one timed run each per round: the times a speed-up divides are
    taken side by side, so a machine that slows down for a while slows them alike, and the best
    run of each comes from its fastest stretch. The rows come out by method, then tolerance.

    Parameters
    ----------
    scene : clutchocp.scene.Scene
    methods, tolerances : sequences
    repeats : int
        Timed runs per point (the best counts); the engine methods, whose runs are short and
        noisy, get three times as many.
    least_repeats : dict, optional
        ``{method: n}``: at least ``n`` timed runs per point for these methods (e.g. the peers a
        ratio of the bench divides by, whose single timings move it by several per cent).
    progress : clutchocp.bench.progress.Progress, optional
    model : EngagementModel, optional

    Returns
    -------
    dict
        ``scene``, ``reference`` (summary numbers, solver statistics), ``confirmation`` and
        ``rows`` (one per method and tolerance: wall and CPU time, errors, counts, status).
    """
    model = model or EngagementModel(scene)
    reference, confirmation = reference_runs(scene, model)
    ref_stats = reference.summary["solver"]["statistics"]
    if progress:
        err = confirmation["errors"]["max"] if confirmation.get("errors") else math.nan
        progress.step(f"{scene.name}: reference IDAS rtol {REFERENCE_RTOL:g} ({ref_stats['n_steps']} steps), "
                      f"{CONFIRM_METHOD} rtol {CONFIRM_RTOL:g} within {err:.1e}")
    rows, ready = [], []
    for method in methods:
        try:
            run_method(scene, model, method, tolerances[0])                   # warm-up: builds, caches
        except ModelError as exc:                                            # e.g. cvodes on a DAE mode
            rows += [{"scene": scene.name, "method": method, "rtol": r, "status": f"n/a: {exc}"} for r in tolerances]
            if progress:
                progress.step(f"{scene.name} {method}: not applicable ({str(exc)[:80]})")
            continue
        except ClutchocpError:
            pass
        ready.append(method)
    for rtol in tolerances:
        rows += _points(scene, model, reference, ready, rtol, repeats, least_repeats, progress)
    order = {method: i for i, method in enumerate(methods)}
    rows.sort(key=lambda row: (order[row["method"]], tolerances.index(row["rtol"])))
    return {"scene": scene.name,
            "reference": {"method": "idas", "rtol": REFERENCE_RTOL, "atol": REFERENCE_RTOL * ATOL_RATIO,
                          "engagement_time_s": reference.summary["engagement_time_s"],
                          "lockup_torque_jump_Nm": reference.summary["lockup_torque_jump_Nm"],
                          "n_steps": ref_stats.get("n_steps"), "wall_time_s": reference.summary["wall_time_s"]},
            "confirmation": confirmation, "rows": rows, "reference_run": reference}


def _points(scene, model, reference, methods, rtol, repeats, least_repeats, progress):
    """The rows of :func:`sweep` at ``rtol``: the methods take turns, one timed run each per round,
    until each has had its :func:`timed_runs` (the best wall time, and its run, counts; the best CPU
    time apart), then each row gets its errors against ``reference``."""
    counts = {method: timed_runs(method, repeats, least_repeats) for method in methods}
    failed, best_cpu = {}, dict.fromkeys(methods, math.inf)

    def task(method):
        def timed():
            if method in failed:                 # out of the remaining rounds
                return math.inf, None
            start = time.perf_counter()
            try:
                wall, cpu, run = timed_run(scene, model, method, rtol)
            except ClutchocpError as exc:       # e.g. scipy BDF's step size collapsing at the impact
                failed[method] = (exc, time.perf_counter() - start)
                return math.inf, None
            best_cpu[method] = min(best_cpu[method], cpu)
            return wall, run
        return timed

    best = best_of_turns({method: task(method) for method in methods}, counts, warm_up=False)
    rows = []
    for method in methods:
        row = {"scene": scene.name, "method": method, "rtol": rtol, "atol": rtol * ATOL_RATIO}
        if method in failed:
            exc, elapsed = failed[method]
            row.update(status=f"failed: {str(exc)[:200]}", wall_time_s=elapsed)
            if progress:
                progress.step(f"{scene.name} {method:11s} rtol {rtol:.0e}: FAILED ({str(exc)[:70]}...)")
            rows.append(row)
            continue
        (wall, run), cpu = best[method], best_cpu[method]
        stats = run.summary["solver"]["statistics"]
        if method == "idas":        # before the errors read more outputs
            row["summary_work_s"] = summary_time(run, counts[method])[0]
            row["event_work_s"] = event_work_time(run, counts[method])
            row["summary_arithmetic_s"] = summary_arithmetic_time(run, counts[method])
            row["replayed_calls_s"] = run_replay_time(scene, model, method, rtol, counts[method])
        errors = trajectory_errors(run, reference)
        row.update(status="ok", wall_time_s=wall, cpu_time_s=cpu, error=errors["max"],
                   integration_time_s=stats.get("integration_time_s"),
                   **{f"error_{k}": errors[k] for k in ERROR_PARTS},
                   engagement_time_s=run.summary["engagement_time_s"],
                   n_steps=stats.get("n_steps"), n_rhs_evals=stats.get("n_rhs_evals", 0),
                   n_jacobian_evals=stats.get("n_jacobian_evals", 0))
        rows.append(row)
        if progress:
            progress.step(f"{scene.name} {method:11s} rtol {rtol:.0e}: {wall * 1e3:8.1f} ms, error {errors['max']:.1e}")
    return rows


def pareto_front(points):
    """The (error, time) points no other point beats in both, sorted by error."""
    front = []
    for e, w in sorted((e, w) for e, w in points if math.isfinite(e) and e > 0 and math.isfinite(w)):
        if not front or w < front[-1][1]:
            front.append((e, w))
    return front


def time_at_error(points, level):
    """Time to reach error ``level``: the cheapest run at least that accurate, interpolated in log-log
    along the Pareto front of (error, time) points.

    None outside the errors the runs reached (below the most accurate run's, above the least
    accurate run's). Between the front's least accurate point and a less accurate run that was not
    cheaper (off the front: e.g. a single timing of a loose run stretched by a busy machine) the
    cheapest run at least that accurate is the front's last point, and its time is returned.
    """
    front = pareto_front(points)
    if not front:
        return None
    reached = max(e for e, w in points if math.isfinite(e) and e > 0 and math.isfinite(w))
    if not front[0][0] <= level <= reached:
        return None
    if level >= front[-1][0]:
        return front[-1][1]
    for (e0, w0), (e1, w1) in itertools.pairwise(front):
        if e0 <= level <= e1:
            s = (math.log(level) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(w0) + s * (math.log(w1) - math.log(w0)))
    return None


def points_of(rows, method, key="wall_time_s"):
    """(error, time) of the successful rows of ``method``."""
    return [(r["error"], r[key]) for r in rows if r["method"] == method and r.get("status") == "ok"]


def speedups(rows, peers=PEERS, levels=ERROR_LEVELS, key="wall_time_s", idas_key=None):
    """Time ratio peer / IDAS at each matched error level (None where either sweep does not reach it).

    ``key`` is the row's time [s] both sides are read at; ``idas_key`` (default ``key``) the one
    IDAS's side is read at, e.g. ``"integration_time_s"`` against the peers' ``"wall_time_s"``.

    Returns
    -------
    dict
        ``{peer: {level: ratio or None}}``.
    """
    idas = points_of(rows, "idas", idas_key or key)
    out = {}
    for peer in peers:
        other = points_of(rows, peer, key)
        out[peer] = {}
        for level in levels:
            a, b = time_at_error(idas, level), time_at_error(other, level)
            out[peer][level] = b / a if a is not None and b is not None else None
    return out


def headline(ratios):
    """Geometric mean, minimum and count of the defined ratios of one peer (None if none)."""
    values = [v for v in ratios.values() if v is not None]
    if not values:
        return None, None, 0
    return float(np.exp(np.mean(np.log(values)))), float(min(values)), len(values)


SWEEP_COLUMNS = ("scene", "method", "rtol", "atol", "status", "wall_time_s", "cpu_time_s", "integration_time_s",
                 "summary_work_s", "event_work_s", "summary_arithmetic_s", "replayed_calls_s", "error",
                 *(f"error_{k}" for k in ERROR_PARTS), "engagement_time_s", "n_steps", "n_rhs_evals", "n_jacobian_evals")


def write_rows(path, rows, columns=SWEEP_COLUMNS):
    """A table of rows as CSV (the sweep: one row per scene, method and tolerance)."""

    def cell(row, col):
        value = row.get(col)
        if value is None:
            return ""
        if isinstance(value, float) and not math.isfinite(value):
            return "inf"
        return value

    return write_csv(path, {col: [cell(r, col) for r in rows] for col in columns})


def plot_work_precision(results, path, floors=None):
    """Error against wall time (log-log), one panel per scene (three to a row), one curve per method;
    with ``floors`` (``{scene: rows of clutchocp.bench.floor.integrator_floor}``) the integrator
    floor of each method as a dashed curve of the same colour. One legend for all panels."""
    cols = min(3, len(results))
    rows = -(-len(results) // cols)
    fig, _ = new_figure(cols, width=4.6, height=3.6 * rows)
    fig.clear()                      # new_figure lays its panels in one row; this one is a grid
    axes = [fig.add_subplot(rows, cols, k + 1) for k in range(len(results))]
    handles = {}
    for ax, res in zip(axes, results):
        methods = list(dict.fromkeys(r["method"] for r in res["rows"]))
        floor_rows = (floors or {}).get(res["scene"], [])
        for method in methods:
            pts = sorted(points_of(res["rows"], method))
            if pts:
                e, w = zip(*pts)
                line, = ax.loglog(e, np.array(w) * 1e3, "o-", ms=4, label=method)
                handles.setdefault(method, line)
                low = sorted(points_of(floor_rows, method, key="time_s"))
                if low:
                    e, w = zip(*low)
                    floor, = ax.loglog(e, np.array(w) * 1e3, "x--", ms=4, color=line.get_color(),
                                       label=f"{method} floor")
                    handles.setdefault(f"{method} floor", floor)
        ax.axvspan(min(ERROR_LEVELS), 1e-4, color="0.93", zorder=0)
        ax.set(xlabel="error [relative]", ylabel="wall time [ms]", title=res["scene"])
        ax.grid(alpha=0.3, which="both")
    fig.legend(list(handles.values()), list(handles), loc="outside right upper", fontsize=8)
    fig.suptitle("Work-precision: wall time against the error of speeds, gaps, lock time and torque jump "
                 "(grey: the matched error levels; dashed: the integrator floor)", fontsize=10)
    return save_figure(fig, path)
