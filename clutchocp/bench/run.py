"""``clutchocp bench``: work-precision, stiffness, pack-size scaling and optimisation convergence.

:func:`run_bench` runs everything for every built-in engagement scene and writes into a folder:

* ``engagement_work_precision.csv`` / ``.png`` -- every integrator over the tolerance sweep;
* ``engagement_speedup.csv`` -- time ratio of each peer to IDAS at matched error levels;
* ``stiffness_<scene>.csv`` / ``.png`` -- Jacobian eigenvalue spread and fastest time constant
  along the reference trajectory;
* ``scaling.csv`` / ``scaling.png`` -- run time against the number of plate pairs;
* ``optimization_convergence.csv`` / ``.png`` -- collocation errors against solve time;
* ``summary.json`` -- per scene ``speedup_vs_radau``, ``speedup_vs_bdf``, ``speedup_vs_lsoda``,
  ``speedup_vs_cvodes`` (geometric mean over the matched error levels below 1e-4 that both
  sweeps reach; ``*_min`` the smallest), ``scaling_exponent_pairs`` and the stiffness extremes;
  the same ratios of the time spent inside the integrator calls alone (``*_integration``: IDAS
  or ``solve_ivp``, without the event checks on the output grid, the outputs and the summary);
  the integrator floor (``floor_speedup_vs_radau``, ``floor_speedup_vs_lsoda``: the integrators
  alone with the event times known, :mod:`clutchocp.bench.floor`) and the share of it whole runs
  keep (``whole_over_floor_vs_radau``, ``whole_over_floor_vs_lsoda``: ``speedup_vs_<peer>`` /
  ``floor_speedup_vs_<peer>``; 1 when a whole run costs over the floor what the peer's does), and
  the most a whole run could keep with its integrator calls as they are, spending no time outside
  them (``whole_over_floor_bound_vs_radau``, ``whole_over_floor_bound_vs_lsoda``,
  :func:`whole_over_floor_bound`), spending no time outside them and the summary work every
  whole run does (``whole_over_floor_summary_bound_vs_radau``, ``..._vs_lsoda``), and outside them,
  the summary work and the event checks on the samples the run keeps
  (``whole_over_floor_events_bound_vs_radau``, ``..._vs_lsoda``), and made of the run's own calls
  into compiled code replayed back to back and the summary's arithmetic
  (``whole_over_floor_replay_bound_vs_radau``, ``..._vs_lsoda``: an engine in Python making the same
  calls, with nothing around them);
  ``idas_slower``: every scene, peer and matched error level at which a peer was faster than IDAS
  (a measured fact, not a target); ``single_run_s``: one warm bao2020 engagement at its settings;
* ``engagement_integrator_floor.csv`` -- the floor of every method and tolerance (also drawn,
  dashed, on the work-precision figure).

``quick=True`` leaves out IDAS with native code, times single runs (nine for the engine methods,
three for the floor's peers) and solves coarser optimisation meshes (about ten minutes on two cores).
In both modes every engine run and IDAS floor pass is timed at least ``engine_repeats`` (9) times:
they take 5-25 ms, and with three IDAS's best at one point moved by up to 1.45x against Radau's
between two quick benches, whole / floor by up to 0.18; with nine, two quick benches' whole /
floor agreed within 0.02 on every scene.
"""

import math
import time
from pathlib import Path

from ..engagement.model import EngagementModel
from ..engagement.run import simulate_engagement
from ..engagement.stiffness import stiffness_profile, write_stiffness
from ..output import shown, write_csv, write_summary, writes_folder
from ..scene.loader import list_scenes
from ..simulation.native import compiler
from . import floor, optimization, scaling, workprecision
from .progress import Progress

FULL = {"tolerances": workprecision.TOLERANCES, "methods": workprecision.METHODS, "repeats": 3,
        "scaling_repeats": 3, "floor_repeats": 3, "engine_repeats": 9}
# quick: single timings, but three of every run whole / floor is made of (the floor's peers' whole
# runs and every floor point): a single timing of one of them moved it by up to 0.07 between runs;
# nine of the engine's runs and floor passes (5-25 ms each): with three, IDAS's best at one point
# moved by up to 1.45x against Radau's between two runs, and whole / floor by up to 0.18
QUICK = {"tolerances": workprecision.TOLERANCES, "methods": ("idas", "cvodes", "Radau", "BDF", "LSODA"),
         "repeats": 1, "scaling_repeats": 1, "floor_repeats": 3, "engine_repeats": 9}
ENGINE_METHODS = ("idas", "idas-native", "cvodes")
SINGLE_RUN_SCENE = "bao2020"     # the scene of the single-run timing


def engagement_scenes():
    """The built-in engagement scenes, by name."""
    return [s for s in list_scenes() if s.kind == "engagement"]


def _steps(settings, n_scenes, opt_steps):
    per_scene = 1 + len(settings["methods"]) * len(settings["tolerances"]) + 2 + len(scaling.PAIRS)
    return n_scenes * per_scene + opt_steps


@writes_folder
def run_bench(out_dir, quick=False, progress=True, scenes=None):
    """Run the benchmark and write its files.

    Parameters
    ----------
    out_dir : str or pathlib.Path
        Output folder (created).
    quick : bool
        No native-code IDAS, single timed runs (nine for the engine methods), coarser
        optimisation meshes.
    progress : bool
        A progress bar and one line per step on stderr.
    scenes : sequence of Scene, optional
        Default: every built-in engagement scene.

    Returns
    -------
    dict
        The summary also written to ``summary.json``.
    """
    start = time.perf_counter()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    settings = QUICK if quick else FULL
    scenes = list(scenes) if scenes is not None else engagement_scenes()
    opt_plan = optimization.plan(quick)
    bar = Progress(_steps(settings, len(scenes), len(opt_plan["meshes"]) + 1 if opt_plan else 0), enabled=progress)
    files, results, per_scene, scaling_results, speed_rows, floors = [], [], {}, {}, [], {}

    for scene in scenes:
        model = EngagementModel(scene)
        res = workprecision.sweep(scene, methods=settings["methods"], tolerances=settings["tolerances"],
                                  repeats=settings["repeats"], progress=bar, model=model,
                                  least_repeats={**{peer: settings["floor_repeats"] for peer in floor.PEERS},
                                                 **dict.fromkeys(ENGINE_METHODS, settings["engine_repeats"])})
        results.append(res)
        low = floor.integrator_floor(res["reference_run"], res["rows"], repeats=settings["floor_repeats"], progress=bar,
                                     least_repeats={"idas": settings["engine_repeats"]})
        floors[scene.name] = low.pop("rows")
        bar.step(f"{scene.name}: integrator floor {low['floor_speedup_vs_radau'] or math.nan:.1f}x over Radau, "
                 f"{low['floor_speedup_vs_lsoda'] or math.nan:.1f}x over LSODA")
        profile = stiffness_profile(res.pop("reference_run"))
        files += write_stiffness(profile, out)
        bar.step(f"{scene.name}: stiffness ratio up to {profile.summary()['max_stiffness_ratio']:.3g}")
        scaling_results[scene.name] = scaling.plate_pair_scaling(scene, pairs=scaling.PAIRS,
                                                                 repeats=settings["scaling_repeats"], progress=bar)
        per_scene[scene.name] = {**_scene_summary(res, profile, scaling_results[scene.name], speed_rows), **low}
        per_scene[scene.name].update(whole_over_floor(per_scene[scene.name]))
        for bound in BOUNDS:
            per_scene[scene.name].update(whole_over_floor_bound(res["rows"], per_scene[scene.name], bound=bound))

    files.append(workprecision.write_rows(out / "engagement_work_precision.csv", [r for res in results for r in res["rows"]]))
    files.append(workprecision.write_rows(out / "engagement_integrator_floor.csv", [r for rows in floors.values() for r in rows],
                                          floor.COLUMNS))
    files.append(workprecision.plot_work_precision(results, out / "engagement_work_precision.png", floors))
    files.append(write_csv(out / "engagement_speedup.csv", {
        key: [row[key] for row in speed_rows] for key in ("scene", "peer", "error_level", "time_ratio_to_idas")}))
    files.append(_write_scaling(scaling_results, out / "scaling.csv"))
    files.append(scaling.plot_scaling(scaling_results, out / "scaling.png"))

    single = single_run_times(scenes, native=not quick)
    bar.note(f"{SINGLE_RUN_SCENE}: one warm engagement " + ", ".join(f"{k} {v * 1e3:.1f} ms" for k, v in single.items()))
    opt_summary = optimization.convergence(out, quick=quick, progress=bar) if opt_plan else optimization.unavailable()
    files += [Path(p) for p in opt_summary.pop("files", [])]

    summary = {"quick": quick, "scenes": per_scene, "optimization": opt_summary,
               "settings": {"tolerances": list(settings["tolerances"]), "methods": list(settings["methods"]),
                            "repeats": settings["repeats"], "floor_repeats": settings["floor_repeats"],
                            "engine_repeats": settings["engine_repeats"],
                            "reference_rtol": workprecision.REFERENCE_RTOL,
                            "atol_over_rtol": workprecision.ATOL_RATIO,
                            "matched_error_levels": list(workprecision.ERROR_LEVELS)},
               "single_run_s": single, "idas_slower": idas_slower(per_scene), "wall_time_s": time.perf_counter() - start}
    files.append(write_summary(out / "summary.json", json_ready(summary)))
    summary["files"] = [shown(f) for f in files]
    bar.note(f"done in {summary['wall_time_s']:.0f} s; wrote {len(files)} files to {shown(out)}")
    bar.close()
    return summary


def json_ready(value):
    """``value`` with every non-finite float replaced by None (summary.json holds no NaN or inf)."""
    if isinstance(value, dict):
        return {k: json_ready(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [json_ready(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def _scene_summary(res, profile, scale, speed_rows):
    """The summary.json entry of one scene (and its rows of the speed-up table)."""
    entry = {"reference": res["reference"], "confirmation": res["confirmation"]}
    for metric, key in (("wall", "wall_time_s"), ("cpu", "cpu_time_s"), ("integration", "integration_time_s")):
        ratios = workprecision.speedups(res["rows"], key=key)
        for peer, by_level in ratios.items():
            mean, low, count = workprecision.headline(by_level)
            name = f"speedup_vs_{peer.lower()}" + ("" if metric == "wall" else f"_{metric}")
            entry[name] = mean
            entry[f"{name}_min"] = low
            entry[f"{name}_levels"] = count
            if metric == "wall":
                entry[f"{name}_by_error"] = {f"{lvl:.1e}": r for lvl, r in by_level.items() if r is not None}
                speed_rows += [{"scene": res["scene"], "peer": peer, "error_level": lvl, "time_ratio_to_idas": r}
                               for lvl, r in by_level.items() if r is not None]
    entry["scaling_exponent_pairs"] = scale["exponent"]
    entry["scaling_exponent_pairs_per_step"] = scale["exponent_per_step"]
    entry["scaling"] = {k: scale[k] for k in ("pairs", "wall_time_s", "n_steps", "n_states", "engagement_time_s")}
    entry["stiffness"] = profile.summary()
    return entry


def whole_over_floor(entry, peers=floor.PEERS):
    """``{whole_over_floor_vs_<peer>: speedup_vs_<peer> / floor_speedup_vs_<peer>}`` of one scene's
    summary entry (None where either is missing): how much of the integrator floor's lead whole
    runs keep."""
    out = {}
    for peer in (p.lower() for p in peers):
        whole, low = entry.get(f"speedup_vs_{peer}"), entry.get(f"floor_speedup_vs_{peer}")
        out[f"whole_over_floor_vs_{peer}"] = whole / low if whole is not None and low else None
    return out


BOUNDS = {"whole_over_floor_bound": ("integration_time_s",),
          "whole_over_floor_summary_bound": ("integration_time_s", "summary_work_s"),
          "whole_over_floor_events_bound": ("integration_time_s", "summary_work_s", "event_work_s"),
          "whole_over_floor_replay_bound": ("replayed_calls_s", "summary_arithmetic_s")}


def whole_over_floor_bound(rows, entry, peers=floor.PEERS, levels=workprecision.ERROR_LEVELS,
                           bound="whole_over_floor_bound"):
    """The whole / floor a run would reach if it spent no time outside the parts :data:`BOUNDS` names
    for ``bound``.

    Per peer: the peer's whole-run time over the sum of IDAS's parts (row keys [s]) at matched error,
    averaged over the error levels as ``speedup_vs_<peer>`` is
    (:func:`~clutchocp.bench.workprecision.headline`), divided by ``floor_speedup_vs_<peer>``.

    * ``whole_over_floor_bound``: the integrator calls alone (``integration_time_s``), what whole /
      floor could reach by cutting everything between them. The calls of a whole run start and stop
      where its events are found (it cannot know an event before integrating past it), so they cost
      more than the floor's one call per mode piece, and moving where they start and stop moves
      IDAS's steps, so its results.
    * ``whole_over_floor_summary_bound``: and the summary work (``summary_work_s``: the outputs the
      summary reads and the summary, :mod:`~clutchocp.bench.summary_work`), which the peers' whole
      runs pay as well.
    * ``whole_over_floor_events_bound``: and the event work (``event_work_s``: the event functions
      on the samples the run keeps, :mod:`~clutchocp.bench.event_work`), which any run that finds
      its events on its output grid pays: what a hybrid loop that cost nothing else (event location,
      restarts and bookkeeping) would reach with the calls as they are.
    * ``whole_over_floor_replay_bound``: every call the run makes into compiled code, integrators
      and evaluations alike, replayed back to back (``replayed_calls_s``,
      :mod:`~clutchocp.bench.call_replay`), and the summary's own arithmetic
      (``summary_arithmetic_s``): what an engine in Python that makes the same calls, so gives the
      same results, reaches when the Python around them (loop, setup, result assembly) costs nothing.

    Parameters
    ----------
    rows : list of dict
        The work-precision rows of one scene (``method``, ``status``, ``error``, ``wall_time_s``,
        ``integration_time_s``, for IDAS ``summary_work_s`` and ``event_work_s`` [s]).
    entry : dict
        The scene's summary entry, with ``floor_speedup_vs_<peer>``.
    peers : sequence of str
        The floor's peers.
    levels : sequence of float
        The matched error levels (those of ``speedup_vs_<peer>``).
    bound : str
        A key of :data:`BOUNDS`.

    Returns
    -------
    dict
        ``{<bound>_vs_<peer>: float or None}`` (None where a ratio is missing).
    """
    parts, idas_key = BOUNDS[bound], "calls_and_work_s"
    rows = [{**r, idas_key: sum(r[k] for k in parts)}
            if r["method"] == "idas" and r.get("status") == "ok" else r for r in rows]
    ratios = workprecision.speedups(rows, peers=peers, levels=levels, key="wall_time_s", idas_key=idas_key)
    out = {}
    for peer, by_level in ratios.items():
        ratio, low = workprecision.headline(by_level)[0], entry.get(f"floor_speedup_vs_{peer.lower()}")
        out[f"{bound}_vs_{peer.lower()}"] = ratio / low if ratio is not None and low else None
    return out


def idas_slower(per_scene):
    """Where a scipy method was faster than IDAS at matched error: [{scene, peer, error_level, time_ratio}].

    ``time_ratio`` is the peer's time over IDAS's (below 1: the peer was faster).
    """
    found = []
    for name, entry in per_scene.items():
        for peer in workprecision.SCIPY:
            for level, ratio in entry[f"speedup_vs_{peer.lower()}_by_error"].items():
                if ratio is not None and ratio < 1.0:
                    found.append({"scene": name, "peer": peer, "error_level": float(level), "time_ratio": ratio})
    return found


def single_run_times(scenes, repeats=5, native=True):
    """Best wall time [s] of ``repeats`` warm runs of the single-run scene (bao2020) at its own
    settings: ``{"idas": t}``, plus ``"idas-native"`` when ``native`` and a C compiler is there
    (empty if the scene is not among ``scenes``)."""
    scene = next((s for s in scenes if s.name == SINGLE_RUN_SCENE), None)
    if scene is None:
        return {}
    model = EngagementModel(scene)
    times = {}
    for method in ("idas", "idas-native") if native and compiler() else ("idas",):
        run = lambda: simulate_engagement(scene, model=model, native=method == "idas-native")  # noqa: E731
        run()                                                  # warm-up: builds and caches integrators
        best = math.inf
        for _ in range(repeats):
            start = time.perf_counter()
            run()
            best = min(best, time.perf_counter() - start)
        times[method] = best
    return times


def _write_scaling(results, path):
    rows = [(name, n, t, s, k) for name, res in results.items()
            for n, t, s, k in zip(res["pairs"], res["wall_time_s"], res["n_steps"], res["n_states"])]
    return write_csv(path, {"scene": [r[0] for r in rows], "plate_pairs": [r[1] for r in rows],
                            "wall_time_s": [r[2] for r in rows], "n_steps": [r[3] for r in rows],
                            "n_states": [r[4] for r in rows]})


def format_summary(summary):
    """A few lines for the terminal: measured speed-ups at matched error, the integrator floor, scaling, stiffness."""
    def num(value, fmt="{:.2f}"):
        return "-" if value is None else fmt.format(value)

    lines = [f"clutchocp bench ({'quick' if summary['quick'] else 'full'}): {summary['wall_time_s']:.0f} s"]
    for name, e in summary["scenes"].items():
        ratios = ", ".join(f"{peer} {num(e.get(f'speedup_vs_{peer}'))}x (min {num(e.get(f'speedup_vs_{peer}_min'))})"
                           for peer in ("radau", "bdf", "lsoda", "cvodes"))
        stiff = e["stiffness"]
        lines.append(f"  {name}: IDAS vs {ratios}")
        inside = ", ".join(f"{peer} {num(e.get(f'speedup_vs_{peer}_integration'))}x"
                           for peer in ("radau", "bdf", "lsoda", "cvodes"))
        lines.append(f"    inside the integrator calls only: IDAS vs {inside}")
        lines.append(f"    integrator floor (event times known, one call per mode piece): IDAS vs Radau "
                     f"{num(e.get('floor_speedup_vs_radau'))}x, LSODA {num(e.get('floor_speedup_vs_lsoda'))}x; "
                     f"whole / floor: Radau {num(e.get('whole_over_floor_vs_radau'))}, "
                     f"LSODA {num(e.get('whole_over_floor_vs_lsoda'))} (bound with no time outside the "
                     f"integrator calls: Radau {num(e.get('whole_over_floor_bound_vs_radau'))}, "
                     f"LSODA {num(e.get('whole_over_floor_bound_vs_lsoda'))}; with the summary work too: "
                     f"Radau {num(e.get('whole_over_floor_summary_bound_vs_radau'))}, "
                     f"LSODA {num(e.get('whole_over_floor_summary_bound_vs_lsoda'))}; and the event checks: "
                     f"Radau {num(e.get('whole_over_floor_events_bound_vs_radau'))}, "
                     f"LSODA {num(e.get('whole_over_floor_events_bound_vs_lsoda'))}; the run's own calls "
                     f"replayed back to back and the summary's arithmetic: "
                     f"Radau {num(e.get('whole_over_floor_replay_bound_vs_radau'))}, "
                     f"LSODA {num(e.get('whole_over_floor_replay_bound_vs_lsoda'))})")
        lines.append(f"    run time ~ pairs^{e['scaling_exponent_pairs']:.2f}; stiffness ratio up to "
                     f"{num(stiff['max_stiffness_ratio'], '{:.3g}')}, fastest time constant "
                     f"{num(stiff['min_time_constant_s'], '{:.3g}')} s")
    opt = summary["optimization"]
    if opt.get("available"):
        ref = opt["reference"]
        lines.append(f"  optimisation: reference N = {ref['intervals']}, degree {ref['degree']}; "
                     + ", ".join(f"N={r['intervals']}/d={r['degree']} objective error "
                                 f"{num(r.get('objective_rel_error'), '{:.1e}')} in {num(r.get('solve_time_s'))} s"
                                 for r in opt["rows"] if r.get("status") == "ok"))
    else:
        lines.append(f"  optimisation: not run ({opt.get('reason')})")
    if summary.get("single_run_s"):
        lines.append(f"  one warm {SINGLE_RUN_SCENE} engagement: "
                     + ", ".join(f"{k} {v * 1e3:.1f} ms" for k, v in summary["single_run_s"].items()))
    slower = summary["idas_slower"]
    lines.append("  a scipy method faster than IDAS at matched error: "
                 + ("nowhere" if not slower else "; ".join(f"{s['scene']} {s['peer']} at {s['error_level']:.0e} "
                                                           f"(time ratio {s['time_ratio']:.2f})" for s in slower)))
    return "\n".join(lines)

