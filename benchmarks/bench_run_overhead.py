"""Benchmark (not a test): the share of a sweep point's time spent outside the integrator calls, per
engagement scene, for this source tree and, side by side in the same run, for another one.

    PYTHONPATH=. python benchmarks/bench_run_overhead.py                         # this tree
    git archive <commit> | tar -x -C /tmp/base                                   # a tree to compare with
    PYTHONPATH=. python benchmarks/bench_run_overhead.py --against /tmp/base     # both, interleaved

A point runs as a sweep runs it (:func:`clutchocp.study.tasks.simulate_point`: the scene with the
point's oil viscosity (a Walther oil's density, :func:`swept_key`), one parametric model per
process, on CasADi's virtual machine or as compiled C). Its share is
``1 - integration_time_s / run_time_s`` of its row (the definition of
``benchmarks/bench_sweep.py``), the median over ``--points`` points after ``--warm-up`` points
(the first builds the model and integrators that later points reuse). Also reported: points per
second on one core (the inverse of the mean point time), and where a point's time goes (a second
pass over points between those, with timers around the parts: scene with the overrides,
integrator look-up and construction, event location, event functions on samples, outputs on the
grid, where the tree has it the grid's events evaluated with its outputs in one compiled call, and
the summary; the parts overlap: event location includes its event functions and integrator calls).
``cpu_share`` is the same share in CPU time of the process's thread (``time.thread_time``, around
each point and around each ``IdasPath._run``), ``cpu_point_ms`` a point's CPU time: on a machine
shared with other jobs the wall times move with their load, the CPU times much less, and
``fastest_point_ms`` (the fastest point of all rounds, wall time) estimates a point's cost without
the other jobs. ``floor_share`` is the share a point cannot go below without changing its
results (:func:`point_floor`: its many-sample evaluations replayed at their fastest and the IDAS
integrators its new output patterns need, against its time in IDAS).

Every (scene, engine, tree) measurement is a fresh process; the trees alternate within each scene
and each pair repeats ``--rounds`` times, so a change of the machine's load hits both alike. The
load (``os.getloadavg``) is recorded before and after. Numbers go to ``bench_run_overhead.json``
in ``--out`` and to stdout.
"""

import argparse
import functools
import json
import math
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

SCENES = ("zhang2021", "bao2020", "default_driveline")
TARGET = 0.15


def _timers(acc):
    """Wrap the parts of a point with timers adding into ``acc`` (seconds by label)."""
    import clutchocp.engagement.run as run
    import clutchocp.simulation.driver as driver
    import clutchocp.simulation.idas_path as idas_path
    import clutchocp.study.tasks as tasks

    def wrap(owner, name, label):
        inner = getattr(owner, name)

        @functools.wraps(inner)
        def timed(*args, **kwargs):
            start = time.perf_counter()
            try:
                return inner(*args, **kwargs)
            finally:
                acc[label] = acc.get(label, 0.0) + time.perf_counter() - start
        setattr(owner, name, timed)

    wrap(tasks, "point_scene", "scene with overrides")
    wrap(idas_path.IdasPath, "_integrator", "integrator look-up and construction")
    wrap(idas_path.IdasPath, "_locate", "event location (integrator calls included)")
    wrap(idas_path.IdasPath, "_events", "event functions on samples")
    wrap(driver._Run, "segments", "outputs on the grid")
    wrap(run, "summarize", "summary")
    from clutchocp.simulation.compiled import CompiledMode as compiled
    if hasattr(compiled, "native_events_outputs"):      # trees that evaluate a grid's events with its outputs
        inner_merged = compiled.native_events_outputs

        def merged(self):
            function = inner_merged(self)
            if function is None:
                return None

            def timed(*args):
                start = time.perf_counter()
                try:
                    return function(*args)
                finally:
                    label = "events with outputs on the grid (one compiled call)"
                    acc[label] = acc.get(label, 0.0) + time.perf_counter() - start
            return timed
        compiled.native_events_outputs = merged


def swept_key(scene):
    """The scene key a scene's points sweep: ``oil.viscosity`` [Pa s] for a constant oil,
    ``oil.density`` [kg/m^3] for a Walther oil. A Walther oil's dynamic viscosity is derived
    (density times the kinematic viscosity of Walther's law, whose coefficients are fitted from
    the datasheet viscosities as numbers), so neither it nor the datasheet viscosities can be a
    parameter of one model for all points; the density scales the dynamic viscosity alike."""
    return "oil.density" if scene.get("oil.model") == "walther" else "oil.viscosity"


def point_floor(task, values, key="oil.viscosity", repeats=5):
    """What a point cannot spend less on outside IDAS without changing its results, per value of
    the oil viscosity ``key`` (:func:`swept_key`) in ``values``:

    * evaluating the functions its result needs on many samples at once (outputs on the output
      grid, event functions on its samples, merged where the tree merges them): every such call is
      recorded (arguments copied) and replayed ``repeats`` times, keeping each call's fastest
      replay; calls on one sample (guards, resets, located events) are left out (a lower bound);
    * building the IDAS integrators the point needs for output patterns this process has not met
      (the locked phase's count follows the lock-up time; an integrator of another count changes
      the outputs, see README-engine): the time of each ``casadi.integrator`` construction.

    Returns
    -------
    list of dict
        Per value: ``evaluations_s``, ``construction_s``, ``integrators_built``, ``integration_s``.
    """
    import casadi

    from clutchocp.simulation.compiled import ColumnFunction
    from clutchocp.study.tasks import simulate_point

    inner, build = ColumnFunction.__call__, casadi.integrator
    recorded, built = [], []

    def recording(self, xs, zs, pu, t):
        if np.atleast_1d(np.asarray(t, float)).size >= 2:
            recorded.append((self, *(np.array(a, float, copy=True) for a in (xs, zs, pu, t))))
        return inner(self, xs, zs, pu, t)

    def timed_build(*args):
        start = time.perf_counter()
        try:
            return build(*args)
        finally:
            built.append(time.perf_counter() - start)

    out = []
    for v in values:
        recorded.clear()
        built.clear()
        ColumnFunction.__call__, casadi.integrator = recording, timed_build
        try:
            row = simulate_point(task, {key: v})[0]
        finally:
            ColumnFunction.__call__, casadi.integrator = inner, build
        evaluations = 0.0
        for function, *args in recorded:
            best = math.inf
            for _ in range(repeats):
                start = time.perf_counter()
                inner(function, *args)
                best = min(best, time.perf_counter() - start)
            evaluations += best
        out.append({"evaluations_s": evaluations, "construction_s": sum(built), "integrators_built": len(built),
                    "integration_s": row["integration_time_s"]})
    return out


def worker(scene, native, points, warm_up):
    """One measurement in this process (this tree): JSON-ready dict."""
    from clutchocp.scene import load_scene
    from clutchocp.study.tasks import Task, simulate_point

    import clutchocp.simulation.idas_path as idas_path

    cpu = {"integrator": 0.0}                 # CPU time of this thread inside IdasPath._run (both trees have it)
    inner = idas_path.IdasPath._run

    def counted(self, *args):
        start = time.thread_time()
        try:
            return inner(self, *args)
        finally:
            cpu["integrator"] += time.thread_time() - start
    idas_path.IdasPath._run = counted

    key = swept_key(load_scene(scene))
    nominal = load_scene(scene).value(key)
    task = Task(scene, "simulate", options={"native": "auto" if native else False})
    n = warm_up + points
    values = [nominal * (0.95 + 0.1 * k / (n - 1)) for k in range(n)]
    rows, cpu_shares, cpu_points = [], [], []
    for k, v in enumerate(values):
        cpu["integrator"], start = 0.0, time.thread_time()
        rows.append(simulate_point(task, {key: v})[0])
        if k >= warm_up:
            cpu_points.append(time.thread_time() - start)
            cpu_shares.append(1 - cpu["integrator"] / cpu_points[-1])
    bad = [r for r in rows if r["status"] != "ok" or not r["model_reused"]]
    if bad:
        raise RuntimeError(f"{scene}: {len(bad)} points failed or did not reuse the model: {bad[0]}")
    timed = rows[warm_up:]
    run = [r["run_time_s"] for r in timed]
    integ = [r["integration_time_s"] for r in timed]
    acc = {}
    _timers(acc)
    start = time.perf_counter()
    for a, b in zip(values[warm_up - 1:], values[warm_up:]):  # new values: nothing cached from the first pass
        simulate_point(task, {key: 0.5 * (a + b)})
    second = time.perf_counter() - start
    # values met by neither pass (their output patterns are new to this process, as a new sweep point's are)
    floors = point_floor(task, [(2 * a + b) / 3 for a, b in zip(values[warm_up - 1:], values[warm_up:])], key)
    floor = [f["evaluations_s"] + f["construction_s"] for f in floors]
    return {"floor_evaluations_ms": 1e3 * statistics.median(f["evaluations_s"] for f in floors),
            "floor_construction_ms": 1e3 * statistics.median(f["construction_s"] for f in floors),
            "floor_integrators_built": statistics.median(f["integrators_built"] for f in floors),
            "floor_share": statistics.median(c / (c + f["integration_s"]) for c, f in zip(floor, floors)),
            "floor_evaluations_share": statistics.median(f["evaluations_s"] / (f["evaluations_s"] + f["integration_s"])
                                                         for f in floors),
            "share": statistics.median(1 - i / r for i, r in zip(integ, run)),
            "cpu_share": statistics.median(cpu_shares), "cpu_point_ms": 1e3 * statistics.median(cpu_points),
            "cpu_point_min_ms": 1e3 * min(cpu_points), "point_min_ms": 1e3 * min(run),
            "point_ms": 1e3 * statistics.median(run), "integration_ms": 1e3 * statistics.median(integ),
            "points_per_second": len(run) / sum(run), "native_used": bool(timed[0]["native_code"]),
            "n_steps": timed[0]["n_steps"],
            "breakdown_ms": {"point (timed pass)": 1e3 * second / points,
                             **{k: 1e3 * v / points for k, v in acc.items()}}}


def measure(tree, scene, native, points, warm_up):
    """:func:`worker` in a fresh process on source tree ``tree``."""
    env = dict(os.environ, PYTHONPATH=str(tree))
    cmd = [sys.executable, str(Path(__file__).resolve()), "--worker", scene, "--native" if native else "--vm",
           "--points", str(points), "--warm-up", str(warm_up)]
    done = subprocess.run(cmd, env=env, capture_output=True, text=True, check=False, cwd=str(tree))
    if done.returncode != 0:
        raise RuntimeError(f"{tree} {scene}: {done.stderr.strip().splitlines()[-1:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def load():
    return [round(v, 2) for v in os.getloadavg()]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", default="out/bench_run_overhead")
    parser.add_argument("--against", help="another source tree (e.g. an exported earlier commit) to run side by side")
    parser.add_argument("--points", type=int, default=12, help="timed points per measurement (default 12)")
    parser.add_argument("--warm-up", type=int, default=3, help="points run first, not timed (default 3)")
    parser.add_argument("--rounds", type=int, default=2, help="repeats of each measurement (default 2; median)")
    parser.add_argument("--scenes", default=",".join(SCENES))
    parser.add_argument("--engines", default="vm,native", help="vm, native or both (native: compiled C)")
    parser.add_argument("--worker", help=argparse.SUPPRESS)
    parser.add_argument("--native", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--vm", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        print(json.dumps(worker(args.worker, args.native, args.points, args.warm_up)))
        return 0
    here = Path(__file__).resolve().parents[1]
    trees = {"this": here} | ({"against": Path(args.against).resolve()} if args.against else {})
    result = {"target_share": TARGET, "points": args.points, "warm_up": args.warm_up, "rounds": args.rounds,
              "trees": {k: str(v) for k, v in trees.items()}, "load_before": load(), "scenes": {}}
    for scene in args.scenes.split(","):
        for engine in args.engines.split(","):
            runs = {label: [] for label in trees}
            for _ in range(args.rounds):
                for label, tree in trees.items():
                    runs[label].append(measure(tree, scene, engine == "native", args.points, args.warm_up))
            entry = {}
            for label, got in runs.items():
                best = sorted(got, key=lambda m: m["share"])[len(got) // 2]     # the median round
                entry[label] = {**best, "share_rounds": [m["share"] for m in got],
                                "cpu_share_rounds": [m["cpu_share"] for m in got]}
            if "against" in entry:
                entry["point_time_this_over_against"] = entry["this"]["point_ms"] / entry["against"]["point_ms"]
                entry["cpu_point_time_this_over_against"] = (entry["this"]["cpu_point_ms"]
                                                             / entry["against"]["cpu_point_ms"])
                fastest = {label: min(m["point_min_ms"] for m in got) for label, got in runs.items()}
                entry["fastest_point_ms"] = fastest
                entry["fastest_point_this_over_against"] = fastest["this"] / fastest["against"]
            result["scenes"][f"{scene}/{engine}"] = entry
            print(scene, engine, {k: (round(entry[k]["share"], 3), round(entry[k]["cpu_share"], 3)) for k in trees},
                  file=sys.stderr)
    result["load_after"] = load()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "bench_run_overhead.json").write_text(json.dumps(result, indent=2) + "\n")
    print(json.dumps(result, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
