"""Run time of one engagement against the number of plate pairs, with the fitted growth exponent.

The scene is rebuilt with ``plates.n_interfaces = n`` (and, for a pack of masses, n copies of
the first plate mass; with a [thermal] part, the pack's plate heat capacities, which are totals
over the interfaces, in proportion to n); everything else stays. More pairs carry more torque, so the engagement
itself changes (it locks sooner); the report gives the IDAS steps beside the time, so the
cost per step can be told apart from the physics. The exponent p of ``time ~ n^p`` is the slope
of a least-squares line through (log n, log time).
"""

import math
import time

import numpy as np

from ..engagement.model import EngagementModel
from ..engagement.run import simulate_engagement
from ..output import new_figure, save_figure

PAIRS = (1, 2, 4, 8, 16)


THERMAL_TOTALS = ("thermal.separator_heat_capacity", "thermal.friction_plate_heat_capacity")   # [J/K], whole pack


def with_pairs(scene, n):
    """``scene`` with ``n`` friction interfaces (plate masses repeated for a pack of masses; the
    pack's heat capacities, totals over the interfaces, scaled by ``n`` over the scene's count, so
    each interface keeps its plates)."""
    overrides = {"plates.n_interfaces": int(n)}
    if scene.variant("pack") == "masses":
        overrides["pack.plate_masses"] = [float(scene.value("pack.plate_masses")[0])] * int(n)
    if scene.has("thermal"):
        ratio = int(n) / scene.value("plates.n_interfaces")
        overrides.update({key: scene.value(key) * ratio for key in THERMAL_TOTALS})
    return scene.with_overrides(overrides)


def growth_exponent(sizes, times):
    """Slope p of the least-squares fit log t = p log n + c."""
    return float(np.polyfit(np.log(np.asarray(sizes, float)), np.log(np.asarray(times, float)), 1)[0])


def plate_pair_scaling(scene, pairs=PAIRS, repeats=3, progress=None):
    """Warm wall time of one IDAS engagement for each number of plate pairs.

    Parameters
    ----------
    scene : clutchocp.scene.Scene
    pairs : sequence of int
    repeats : int
        Timed runs per size after an untimed warm-up (the best counts).
    progress : clutchocp.bench.progress.Progress, optional

    Returns
    -------
    dict
        ``pairs``, ``wall_time_s``, ``n_steps``, ``n_states``, ``engagement_time_s``,
        ``build_time_s`` (model assembly and first run), ``exponent`` (of the wall time) and
        ``exponent_per_step`` (of the wall time per IDAS step).
    """
    out = {key: [] for key in ("pairs", "wall_time_s", "n_steps", "n_states", "engagement_time_s", "build_time_s")}
    for n in pairs:
        variant = with_pairs(scene, n)
        start = time.perf_counter()
        model = EngagementModel(variant)
        run = simulate_engagement(variant, model=model)
        build = time.perf_counter() - start
        best = math.inf
        for _ in range(max(1, repeats)):
            start = time.perf_counter()
            run = simulate_engagement(variant, model=model)
            best = min(best, time.perf_counter() - start)
        out["pairs"].append(int(n))
        out["wall_time_s"].append(best)
        out["n_steps"].append(int(run.summary["solver"]["statistics"]["n_steps"]))
        out["n_states"].append(int(model.n_states))
        out["engagement_time_s"].append(run.summary["engagement_time_s"])
        out["build_time_s"].append(build)
        if progress:
            progress.step(f"{scene.name}: {n:2d} plate pairs, {best * 1e3:7.1f} ms, {out['n_steps'][-1]} steps")
    out["exponent"] = growth_exponent(out["pairs"], out["wall_time_s"])
    per_step = [w / s for w, s in zip(out["wall_time_s"], out["n_steps"])]
    out["exponent_per_step"] = growth_exponent(out["pairs"], per_step)
    return out


def plot_scaling(results, path):
    """Wall time against plate pairs (log-log) per scene, with the fitted power law."""
    fig, (ax,) = new_figure(width=6.0, height=4.4)
    for name, res in results.items():
        n, t = np.array(res["pairs"], float), np.array(res["wall_time_s"]) * 1e3
        line = ax.loglog(n, t, "o", label=f"{name}: exponent {res['exponent']:.2f}")[0]
        c = np.polyfit(np.log(n), np.log(t), 1)
        ax.loglog(n, np.exp(np.polyval(c, np.log(n))), "-", color=line.get_color(), lw=1)
    ax.set(xlabel="plate pairs (friction interfaces)", ylabel="wall time of one engagement [ms]",
           title="Run time against pack size (IDAS, scene tolerance)")
    ax.legend(fontsize=8)
    return save_figure(fig, path)
