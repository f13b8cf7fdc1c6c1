"""Work-precision benchmark of the engagement simulation: IDAS against CVODES and scipy Radau, BDF, LSODA.

A thin caller of :mod:`clutchocp.bench.workprecision` (the same sweep ``clutchocp bench`` runs on
every engagement scene; see that module for the error measure, the confirmed reference and the
matched-error ratios). This script runs the sweep on the scenes given, prints the time ratio of
each peer to IDAS at matched error levels (wall and CPU time), the integrator floor
(:mod:`clutchocp.bench.floor`: the integrators alone, event times known), and the time of one
bao2020 engagement at the scene's tolerance, warm and cold.

Usage::

    python benchmarks/bench_engagement.py [--out DIR] [--scenes bao2020 zhang2021] [--repeats 3] [--quick]

Writes ``engagement_work_precision.csv`` and ``engagement_work_precision.png`` into DIR.
"""

import argparse
import sys
import time
from pathlib import Path

from clutchocp.bench import floor
from clutchocp.bench import workprecision as wp
from clutchocp.bench.progress import Progress
from clutchocp.engagement.model import EngagementModel
from clutchocp.engagement.run import simulate_engagement
from clutchocp.scene.loader import load_scene

LEVELS = (1e-5, 1e-6, 1e-7, 1e-8)


def single_run(method, repeats=20):
    """Warm wall and CPU time, cold time [s] and IDAS steps of one bao2020 engagement at its tolerance."""
    scene = load_scene("bao2020")
    start = time.perf_counter()
    model = EngagementModel(scene)
    run = simulate_engagement(scene, model=model, native=method == "idas-native")
    cold = time.perf_counter() - start
    warm, warm_cpu, _ = wp.timed_run(scene, model, method, scene.value("simulation.rtol"), repeats)
    return warm, warm_cpu, cold, run.summary["solver"]["statistics"]["n_steps"]


def _ms(seconds):
    return f"{seconds * 1e3:7.2f} ms" if seconds is not None else "      -"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default="bench_engagement_out", help="output directory")
    parser.add_argument("--scenes", nargs="+", default=["bao2020", "zhang2021"])
    parser.add_argument("--repeats", type=int, default=3, help="timed runs per point (the best counts)")
    parser.add_argument("--quick", action="store_true", help="no native-code IDAS, tolerances 1e-4 ... 1e-10 by 100x")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    methods = tuple(m for m in wp.METHODS if not (args.quick and m == "idas-native"))
    tolerances = (1e-4, 1e-6, 1e-8, 1e-10) if args.quick else wp.TOLERANCES

    progress = Progress(len(args.scenes) * (2 + len(methods) * len(tolerances)) + 2)
    results, floors = [], {}
    for name in args.scenes:
        res = wp.sweep(load_scene(name), methods=methods, tolerances=tolerances, repeats=args.repeats,
                       progress=progress)
        floors[name] = floor.integrator_floor(res.pop("reference_run"), res["rows"], repeats=args.repeats,
                                              progress=progress)
        progress.step(f"{name}: integrator floor")
        results.append(res)
    single = {}
    for method in ("idas", "idas-native"):
        single[method] = single_run(method)
        progress.step(f"single bao2020 run, {method}")

    csv_path = wp.write_rows(out / "engagement_work_precision.csv", [r for res in results for r in res["rows"]])
    png_path = wp.plot_work_precision(results, out / "engagement_work_precision.png",
                                      {name: low["rows"] for name, low in floors.items()})

    print("\nTime ratio of each method to IDAS at matched error (Pareto front of each sweep, log-log; "
          "'-': level outside a sweep); wall time, CPU time in brackets:")
    for res in results:
        conf = res["confirmation"]
        print(f"  {res['scene']}: reference IDAS rtol {wp.REFERENCE_RTOL:g}; {conf['method']} rtol {conf['rtol']:g} "
              f"agrees within {conf['errors']['max']:.1e}" if conf.get("errors") else f"  {res['scene']}: unconfirmed")
        wall, cpu = wp.speedups(res["rows"], levels=LEVELS), wp.speedups(res["rows"], levels=LEVELS, key="cpu_time_s")
        for level in LEVELS:
            idas = wp.time_at_error(wp.points_of(res["rows"], "idas"), level)
            cells = []
            for peer in wp.PEERS:
                ratio, ratio_cpu = wall[peer][level], cpu[peer][level]
                cells.append(f"{peer} " + (f"{ratio:5.1f}x ({ratio_cpu:5.1f}x)" if ratio is not None else "-"))
            print(f"    error {level:.0e}: IDAS {_ms(idas)} | " + " | ".join(cells))
        low = floors[res["scene"]]
        print("    integrator floor (event times known, one call per mode piece), mean over matched errors: "
              + ", ".join(f"{peer} {low[f'floor_speedup_vs_{peer.lower()}']:.1f}x" for peer in floor.PEERS
                          if low.get(f"floor_speedup_vs_{peer.lower()}") is not None))
    print()
    for method, (warm, warm_cpu, cold, steps) in single.items():
        print(f"One bao2020 engagement at rtol 1e-8 (scene tolerance), {method}: warm {warm * 1e3:.1f} ms wall, "
              f"{warm_cpu * 1e3:.1f} ms CPU; cold {cold * 1e3:.0f} ms "
              f"(model assembly, compilation, first run); {steps} IDAS steps")
    print(f"\nwrote {csv_path} and {png_path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
