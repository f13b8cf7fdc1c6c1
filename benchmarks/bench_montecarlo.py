"""Monte Carlo throughput of ``clutchocp robust``: samples per second, per strategy and in parallel.

On the default scene (its [uncertainty]: mu +-10 %, viscosity +-30 %, load torque +-20 %, uniform) it
builds the strategies once (nominal optimum, slip feedback; the robust feedforward when installed)
and then reports, side by side in one run:

* per strategy, the wall time of one sample on one process (median over ``--samples`` draws) [s];
* the whole Monte Carlo sample (every strategy) on 1 process and on ``--workers`` processes:
  samples per second and the parallel speed-up.

Run from the repository root:

    python benchmarks/bench_montecarlo.py [--samples 6] [--workers 2] [--json FILE]
"""

import argparse
import json
import statistics
import time

from clutchocp.scene import default_scene
from clutchocp.shiftcontrol.montecarlo import parallel_map, run_sample
from clutchocp.shiftcontrol.workflow import build_strategies
from clutchocp.shiftcontrol.spec import load_slip_spec
from clutchocp.scene.uncertainty import Uncertainty


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=6)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--json", help="also write the numbers to this JSON file")
    args = parser.parse_args()

    scene = default_scene()
    uncertainty = Uncertainty.from_scene(scene)
    nominal = scene.without_uncertainty()
    start = time.perf_counter()
    strategies, facts = build_strategies(nominal, uncertainty, load_slip_spec(), say=lambda *a: None)
    setup = time.perf_counter() - start
    t_max = facts["t_max_s"]
    draws = uncertainty.samples(args.samples, seed=args.seed)

    def tasks(chosen):
        return [{"scene_raw": nominal.raw, "scene_path": nominal.path, "overrides": d, "index": i,
                 "strategies": chosen, "t_max": t_max, "t_end": 1.5 * t_max + 0.05} for i, d in enumerate(draws)]

    per_strategy = {}
    for strategy in strategies:
        times = []
        for task in tasks([strategy]):
            t0 = time.perf_counter()
            run_sample(task)
            times.append(time.perf_counter() - t0)
        per_strategy[strategy.name] = statistics.median(times)
    t0 = time.perf_counter()
    parallel_map(run_sample, tasks(strategies), workers=1)
    serial = time.perf_counter() - t0
    t0 = time.perf_counter()
    parallel_map(run_sample, tasks(strategies), workers=args.workers)
    parallel = time.perf_counter() - t0
    out = {"setup_s": setup, "samples": args.samples, "strategies": [s.name for s in strategies],
           "seconds_per_sample_by_strategy": per_strategy,
           "samples_per_s_1_process": args.samples / serial,
           f"samples_per_s_{args.workers}_processes": args.samples / parallel,
           "parallel_speedup": serial / parallel}
    print(f"set-up (optimum, feedback design): {setup:.1f} s")
    for name, sec in per_strategy.items():
        print(f"  {name:<20} {sec:.2f} s per sample (1 process, model build included)")
    print(f"all strategies: {out['samples_per_s_1_process']:.3f} samples/s on 1 process, "
          f"{args.samples / parallel:.3f} on {args.workers} (speed-up {serial / parallel:.2f})")
    if args.json:
        with open(args.json, "w", encoding="utf-8") as fh:
            json.dump(out, fh, indent=2)


if __name__ == "__main__":
    main()
