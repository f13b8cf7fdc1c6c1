"""Convergence of the optimal engagement pressure (direct collocation) with the mesh, against solve time.

On the default scene (the ``clutchocp optimize`` problem, engagement time limited to the
baseline's lock-up time), :class:`clutchocp.optimal.EngagementOCP` is solved cold from the
scene's IDAS run for growing numbers of intervals (degree 3) and growing degree (fixed
intervals), and once on a fine mesh as the reference. Each optimum is replayed with IDAS
(:func:`clutchocp.optimal.verify`). Reported against the solve time (IPOPT, both stages; and
with the transcription build):

* objective: |J - J_ref| / |J_ref|;
* lock time: the IDAS replay's lock-up time against the reference's replay (relative);
* torque jump: the replay's lock-up torque jump against the reference's, relative to the
  torque carried after lock-up;
* the collocation prediction against its own replay (lock time), i.e. the verification gap.
"""

import math
import time

import numpy as np

from .. import optimal
from ..engagement.run import simulate_engagement
from ..errors import ClutchocpError
from ..output import new_figure, save_figure, write_csv
from ..scene.loader import default_scene

FULL = {"meshes": [(25, 3), (50, 3), (100, 3), (200, 3), (50, 2), (50, 4), (50, 5)], "reference": (200, 4)}
QUICK = {"meshes": [(25, 3), (50, 3), (100, 3), (50, 2), (50, 4)], "reference": (200, 4)}


def _optimal():
    """The optimisation package, or None with the reason it cannot be used."""
    try:
        for name in ("EngagementOCP", "verify"):
            getattr(optimal, name)
        return optimal, None
    except AttributeError as exc:
        return None, f"clutchocp.optimal is not available ({exc})"


def plan(quick=False):
    """The meshes to solve (None if the optimisation package is not there)."""
    optimal, _ = _optimal()
    return (QUICK if quick else FULL) if optimal is not None else None


def unavailable(reason=None):
    """Summary entry when the optimisation part cannot run."""
    return {"available": False, "reason": reason or _optimal()[1]}


def _solve(optimal, scene, baseline, t_max, intervals, degree):
    start = time.perf_counter()
    ocp = optimal.EngagementOCP(scene, intervals=intervals, degree=degree, baseline=baseline)
    built = time.perf_counter()
    opt = ocp.solve(t_max=t_max)
    solved = time.perf_counter()
    check, _ = optimal.verify(ocp, opt)
    return {"intervals": intervals, "degree": degree, "status": "ok",
            "build_time_s": built - start, "solve_time_s": solved - built,
            "ipopt_time_s": opt.stats["wall_time_s"], "iterations": opt.stats["iterations"],
            "objective": opt.objective, "engagement_time_s": opt.terms["engagement_time_s"],
            "lockup_torque_jump_Nm": opt.terms["lockup_torque_jump_Nm"],
            "idas_engagement_time_s": check["idas"]["engagement_time_s"],
            "idas_lockup_torque_jump_Nm": check["idas"]["lockup_torque_jump_Nm"],
            "idas_locked_torque_Nm": check["idas"]["locked_torque_Nm"],
            "verification_lock_time_rel_diff": check["lock_time_rel_diff"]}


def _errors(row, ref):
    def rel(a, b, scale=None):
        if a is None or b is None:
            return math.inf
        return abs(a - b) / abs(scale if scale is not None else b)
    row["objective_rel_error"] = rel(row["objective"], ref["objective"])
    row["lock_time_rel_error"] = rel(row["idas_engagement_time_s"], ref["idas_engagement_time_s"])
    row["torque_jump_rel_error"] = rel(row["idas_lockup_torque_jump_Nm"], ref["idas_lockup_torque_jump_Nm"],
                                       ref["idas_locked_torque_Nm"])
    return row


def convergence(out_dir, quick=False, progress=None):
    """Solve the meshes and the reference; write the CSV and PNG.

    Returns
    -------
    dict
        ``available``, ``scene``, ``t_max_s``, ``reference`` (its numbers), ``rows`` and ``files``.
    """
    optimal, reason = _optimal()
    if optimal is None:
        return unavailable(reason)
    settings = QUICK if quick else FULL
    scene = default_scene()
    baseline = simulate_engagement(scene)
    t_max = baseline.summary["engagement_time_s"]
    try:
        ref = _solve(optimal, scene, baseline, t_max, *settings["reference"])
    except ClutchocpError as exc:
        return unavailable(f"the fine-mesh reference {settings['reference']} failed: {exc}")
    if progress:
        progress.step(f"optimisation reference N = {ref['intervals']}, degree {ref['degree']}: "
                      f"objective {ref['objective']:.8g}, {ref['solve_time_s']:.1f} s")
    rows = []
    for intervals, degree in settings["meshes"]:
        try:
            row = _errors(_solve(optimal, scene, baseline, t_max, intervals, degree), ref)
        except ClutchocpError as exc:
            row = {"intervals": intervals, "degree": degree, "status": f"failed: {str(exc)[:200]}"}
        rows.append(row)
        if progress:
            text = (f"objective error {row['objective_rel_error']:.1e}, {row['solve_time_s']:.2f} s"
                    if row["status"] == "ok" else row["status"][:80])
            progress.step(f"optimisation N = {intervals:3d}, degree {degree}: {text}")
    files = [_write(rows, out_dir), _plot(rows, ref, out_dir)]
    return {"available": True, "scene": scene.name, "t_max_s": t_max,
            "reference": {k: ref[k] for k in ("intervals", "degree", "objective", "solve_time_s", "iterations",
                                              "idas_engagement_time_s", "idas_lockup_torque_jump_Nm")},
            "rows": rows, "files": files}


COLUMNS = ("intervals", "degree", "status", "build_time_s", "solve_time_s", "ipopt_time_s", "iterations",
           "objective", "objective_rel_error", "lock_time_rel_error", "torque_jump_rel_error",
           "verification_lock_time_rel_diff", "engagement_time_s", "idas_engagement_time_s",
           "idas_lockup_torque_jump_Nm")


def _write(rows, out_dir):
    def cell(row, col):
        value = row.get(col)
        if value is None:
            return ""
        return "inf" if isinstance(value, float) and not math.isfinite(value) else value
    return write_csv(f"{out_dir}/optimization_convergence.csv", {c: [cell(r, c) for r in rows] for c in COLUMNS})


def _plot(rows, ref, out_dir):
    ok = [r for r in rows if r["status"] == "ok"]
    fig, axes = new_figure(3, width=4.4, height=3.8)
    for ax, key, label in zip(axes, ("objective_rel_error", "lock_time_rel_error", "torque_jump_rel_error"),
                              ("objective", "lock time (IDAS replay)", "torque jump (IDAS replay)")):
        for degree in sorted({r["degree"] for r in ok}):
            pts = sorted((r["solve_time_s"], max(r[key], 1e-16), r["intervals"]) for r in ok if r["degree"] == degree)
            if pts:
                t, e, _ = zip(*pts)
                ax.loglog(t, e, "o-", ms=4, label=f"degree {degree}")
                for ti, ei, ni in pts:
                    ax.annotate(f"N={ni}", (ti, ei), fontsize=6, xytext=(3, 3), textcoords="offset points")
        ax.set(xlabel="solve time [s]", ylabel=f"{label} error [relative]",
               title=f"vs N = {ref['intervals']}, degree {ref['degree']}")
        ax.legend(fontsize=7)
    return save_figure(fig, f"{out_dir}/optimization_convergence.png")


def finite_or_none(value):
    """``value`` if it is a finite number, else None (for summary.json)."""
    return value if isinstance(value, (int, float)) and np.isfinite(value) else None
