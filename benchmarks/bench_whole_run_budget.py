"""Benchmark (not a test): the time a whole IDAS engagement run may take for `clutchocp bench`'s
``whole / floor >= 0.6``, against where its time goes, per engagement scene and tolerance.

    PYTHONPATH=. python benchmarks/bench_whole_run_budget.py                      # the three scenes below 0.6
    PYTHONPATH=. python benchmarks/bench_whole_run_budget.py --scenes bao2020 --rtols 1e-7

``whole / floor`` (:func:`clutchocp.bench.run.whole_over_floor`) is IDAS's whole-run speed-up over
Radau divided by its floor's: ``(T_floor / T_whole) x (R_whole / R_floor)`` for IDAS times ``T`` and
Radau times ``R``. At one tolerance, ``whole / floor >= TARGET`` allows an IDAS run at most
``T_floor x R_whole / (TARGET x R_floor)``: the *budget* (the bench takes the ratios at matched
error, averaged over error levels; here they are taken at equal rtol, one tolerance at a time).

At each tolerance the times a ratio divides are taken side by side: Radau's whole run and floor
pass, and per engine IDAS's plain run, floor pass and a run with timers take turns, one timed call
each per round (Radau in the first third of the ``--repeats`` rounds, at least 3), after one untimed
call each; the best of each counts (:func:`clutchocp.bench.turns.best_of_turns`). The timed run's
time (wall clock) is split with timers around:

* ``integrator_calls``: the IDAS/CVODES calls (``IdasPath._run``); ``integrator_excess_ms`` is their
  time beyond the floor's (the calls start and stop where the run finds its events);
* ``grid_evaluations``: functions evaluated on two or more samples (outputs and event functions on
  the output grid, ``ColumnFunction``), in the hybrid loop and in the summary;
* ``summary``: :func:`clutchocp.engagement.measures.summarize` without its evaluations;
* ``hybrid_loop``: the rest of the hybrid loop (``_Run.loop``: call planning, event scan and location
  logic, mode switches and resets, one-sample evaluations);
* ``setup_and_assembly``: the rest of the run, outside the loop and the summary (the engagement
  wrapper, the model's inputs and first state, the result built from the samples).

``whole_over_floor_without_loop`` is the ratio a run would reach if its loop, setup and assembly cost
nothing: its integrator calls as they are (results unchanged), its grid evaluations and summary.
``whole_over_floor_without_hybrid_loop`` is the ratio a run would reach if the hybrid loop alone cost
nothing (compiled, say) and everything else stayed as it is: the most a faster hybrid loop gives.

``summary_work_ms`` is the work every whole run does after its integration, IDAS's and Radau's alike:
the outputs the summary reads, evaluated afresh on the run's samples, and the summary itself
(:mod:`clutchocp.bench.summary_work`). ``whole_over_floor_ideal`` is the ratio of an IDAS run that cost its floor plus
that work and nothing else (no event detection or location, no call beyond the floor's, no loop):
what no change to the IDAS path can beat while the summary costs what it does. ``path_overhead_ms``
is what the run spends beyond floor and summary work (calls beyond the floor, event functions on the
grid, the loop), ``path_allowance_ms`` what the target leaves for it (``budget - floor - summary work``).
``whole_over_floor_calls_and_summary`` is the ratio of a run made of its integrator calls as they are
and the summary work alone: the most any hybrid loop reaches without changing where the calls start
and stop (which moves IDAS's steps, so its results). ``event_work_ms`` is the event detection no
loop can skip while the grid detects the events: the event functions on every sample a run keeps
(:mod:`clutchocp.bench.event_work`, the bench's ``event_work_s``); ``whole_over_floor_calls_summary_events``
the ratio of a run made of its calls, the summary work and that event work.

``whole_over_floor_calls_replayed`` is the ratio of a run made of its own calls into compiled code,
recorded on one run (:class:`clutchocp.bench.call_replay.CallRecorder`: the integrator calls and
their statistics, the column functions on the grid or at one sample, other CasADi functions such as
the consistent-initialisation Newton solve) and issued back to back from Python with nothing between
them (``replayed_calls_ms``), plus the summary's own arithmetic (``parts_ms["summary"]``): what a
Python engine that makes the same calls, so gives the same results, reaches with its hybrid loop,
setup and assembly costing nothing (the bench's ``whole_over_floor_replay_bound_vs_radau``).

The Radau run pays the same grid evaluations and summary after its integration. ``engine``: ``vm``
(CasADi's virtual machine and numpy, the default) and ``native`` (the equations, outputs and event
functions compiled to C, ``simulate_engagement(native=True)``; its floor integrates the compiled
equations). Results go to ``bench_whole_run_budget.json`` in ``--out`` and a table to stdout.
"""

import argparse
import functools
import json
import sys
import time
from pathlib import Path

import numpy as np

from clutchocp.bench.call_replay import Patches, recorded_calls

SCENES = ("zhang2021", "default_driveline", "default_driveline_thermal")
TARGET = 0.6


def budget(t_floor, r_whole, r_floor, target=TARGET):
    """Largest IDAS whole-run time [s] with ``whole / floor >= target``, from the IDAS floor time and
    the Radau whole-run and floor times [s] at the same tolerance."""
    return t_floor * r_whole / (target * r_floor)


def whole_over_floor(t_whole, t_floor, r_whole, r_floor):
    """``whole / floor`` at one tolerance from IDAS and Radau times [s]: the bench's own ratio
    (:func:`clutchocp.bench.run.whole_over_floor`) of these speed-ups."""
    from clutchocp.bench.run import whole_over_floor as ratio

    entry = {"speedup_vs_radau": r_whole / t_whole, "floor_speedup_vs_radau": r_floor / t_floor}
    return ratio(entry, peers=("Radau",))["whole_over_floor_vs_radau"]


class PartTimers(Patches):
    """Wall-clock timers around the parts of an engagement run (see the module docstring), installed
    on the classes until :meth:`remove`; only the outermost of nested grid evaluations counts."""

    def __init__(self):
        import clutchocp.engagement.run as run
        import clutchocp.simulation.compiled as compiled
        import clutchocp.simulation.driver as driver
        import clutchocp.simulation.idas_path as idas_path

        super().__init__()
        self.parts, self._depth, self._in_summary, self._in_loop = {}, 0, False, False
        self._wrap(idas_path.IdasPath, "_run", self._timed("integrator_calls"))
        for name in ("__call__", "on_numpy"):
            self._wrap(compiled.ColumnFunction, name, self._evaluation)
        self._wrap(run, "summarize", self._within("_in_summary", "summary_total"))
        self._wrap(driver._Run, "loop", self._within("_in_loop", "loop_total"))

    def _add(self, label, seconds):
        self.parts[label] = self.parts.get(label, 0.0) + seconds

    def _timed(self, label):
        def make(inner):
            def timed(*args, **kwargs):
                start = time.perf_counter()
                try:
                    return inner(*args, **kwargs)
                finally:
                    seconds = time.perf_counter() - start
                    self._add(label, seconds)
                    if self._in_loop:
                        self._add(f"loop_{label}", seconds)
            return timed
        return make

    def _evaluation(self, inner):
        def timed(column, xs, zs, pu, t, *rest):
            many = np.size(t) >= 2 and self._depth == 0
            self._depth += 1
            start = time.perf_counter()
            try:
                return inner(column, xs, zs, pu, t, *rest)
            finally:
                self._depth -= 1
                if many:
                    seconds = time.perf_counter() - start
                    self._add("grid_evaluations", seconds)
                    if self._in_summary:
                        self._add("summary_evaluations", seconds)
                    if self._in_loop:
                        self._add("loop_grid_evaluations", seconds)
        return timed

    def _within(self, flag, label):
        """A wrapper that times its calls as ``label`` with the attribute ``flag`` true while they run
        (the calls and evaluations made inside are then also counted as inside)."""
        def make(inner):
            def timed(*args, **kwargs):
                setattr(self, flag, True)
                start = time.perf_counter()
                try:
                    return inner(*args, **kwargs)
                finally:
                    setattr(self, flag, False)
                    self._add(label, time.perf_counter() - start)
            return timed
        return make


def summary_and_event_work(scene, model, method, rtol, repeats):
    """Best times [s] of the summary work (:func:`clutchocp.bench.summary_work.summary_time`) and of the
    event work (:func:`clutchocp.bench.event_work.event_work_time`) of one run, its samples taken
    before its summary reads the outputs (a native run reads them all)."""
    import clutchocp.engagement.run as run_module
    from clutchocp.bench.event_work import event_work_time
    from clutchocp.bench.summary_work import evaluators, summary_time
    from clutchocp.bench.workprecision import run_method

    kept, inner = [], run_module.summarize

    def taking(model, result, *rest):
        kept.append(evaluators(result))
        return inner(model, result, *rest)

    run_module.summarize = taking
    try:
        run = run_method(scene, model, method, rtol)
    finally:
        run_module.summarize = inner
    return summary_time(run, repeats, kept=kept[0])[0], event_work_time(run, repeats, kept=kept[0])


def parts_task(scene, model, method, rtol):
    """A task (:func:`clutchocp.bench.turns.best_of_turns`) of one run with :class:`PartTimers` installed
    around it alone: its wall time [s] and its parts [s] (``integrator_calls``, ``grid_evaluations``,
    ``summary``, ``hybrid_loop``, ``setup_and_assembly``)."""
    from clutchocp.bench.workprecision import run_method

    def task():
        timers = PartTimers()
        try:
            start = time.perf_counter()
            run_method(scene, model, method, rtol)
            whole = time.perf_counter() - start
        finally:
            timers.remove()
        parts = timers.parts
        summary = parts.get("summary_total", 0.0) - parts.get("summary_evaluations", 0.0)
        named = {"integrator_calls": parts.get("integrator_calls", 0.0),
                 "grid_evaluations": parts.get("grid_evaluations", 0.0), "summary": summary,
                 "hybrid_loop": parts.get("loop_total", 0.0) - parts.get("loop_integrator_calls", 0.0)
                 - parts.get("loop_grid_evaluations", 0.0)}
        named["setup_and_assembly"] = whole - sum(named.values())
        return whole, named

    return task


def measure(name, rtols, repeats, engines):
    """One scene: JSON-ready rows, one per (engine, rtol).

    At each tolerance the runs and floor passes take turns (:func:`clutchocp.bench.turns.best_of_turns`):
    one timed call of each per round, Radau's whole run and floor in the first third of the rounds
    (at least 3), each IDAS engine's plain run, floor pass and run split by timers in all of them;
    the best of each counts. The summary and event work are timed afterwards on one run."""
    from clutchocp.bench import floor
    from clutchocp.bench.turns import best_of_turns, wall
    from clutchocp.bench.workprecision import REFERENCE_RTOL, run_method
    from clutchocp.engagement.model import EngagementModel
    from clutchocp.scene import load_scene

    scene = load_scene(name)
    model = EngagementModel(scene)
    parts = floor.pieces(run_method(scene, model, "idas", REFERENCE_RTOL))
    rows = []
    for rtol in rtols:
        radau_path = floor.floor_path(model, "Radau", rtol)
        tasks = {"radau_whole": wall(functools.partial(run_method, scene, model, "Radau", rtol)),
                 "radau_floor": functools.partial(floor.floor_pass, model, parts, "Radau", rtol, radau_path)}
        counts = {"radau_whole": max(3, repeats // 3), "radau_floor": max(3, repeats // 3)}
        recorders = {}
        for engine in engines:
            method = "idas-native" if engine == "native" else "idas"
            path = floor.floor_path(model, "idas", rtol, native=engine == "native")
            run_method(scene, model, method, rtol)                # builds what a run builds before its calls are recorded
            recorders[engine] = recorded_calls(scene, model, method, rtol)
            tasks.update({f"{engine}_whole": wall(functools.partial(run_method, scene, model, method, rtol)),
                          f"{engine}_floor": functools.partial(floor.floor_pass, model, parts, "idas", rtol, path),
                          f"{engine}_parts": parts_task(scene, model, method, rtol),
                          f"{engine}_replay": wall(recorders[engine].replay)})
            counts.update(dict.fromkeys((f"{engine}_whole", f"{engine}_floor", f"{engine}_parts", f"{engine}_replay"),
                                        repeats))
        best = best_of_turns(tasks, counts)
        r_whole, r_floor = best["radau_whole"][0], best["radau_floor"][0]
        for engine in engines:
            method = "idas-native" if engine == "native" else "idas"
            t_whole, t_floor = best[f"{engine}_whole"][0], best[f"{engine}_floor"][0]
            timed_whole, split = best[f"{engine}_parts"]
            replayed = best[f"{engine}_replay"][0]
            allowed = budget(t_floor, r_whole, r_floor)
            work, events = summary_and_event_work(scene, model, method, rtol, repeats)
            rows.append({
                "scene": name, "engine": engine, "rtol": rtol,
                "whole_over_floor": whole_over_floor(t_whole, t_floor, r_whole, r_floor),
                "whole_over_floor_without_loop": whole_over_floor(
                    split["integrator_calls"] + split["grid_evaluations"] + split["summary"], t_floor, r_whole, r_floor),
                "whole_over_floor_without_hybrid_loop": whole_over_floor(
                    timed_whole - split["hybrid_loop"], t_floor, r_whole, r_floor),
                "idas_whole_ms": 1e3 * t_whole, "idas_floor_ms": 1e3 * t_floor,
                "radau_whole_ms": 1e3 * r_whole, "radau_floor_ms": 1e3 * r_floor,
                "budget_ms": 1e3 * allowed, "budget_beyond_floor_ms": 1e3 * (allowed - t_floor),
                "radau_beyond_floor_ms": 1e3 * (r_whole - r_floor),
                "timed_whole_ms": 1e3 * timed_whole,
                "parts_ms": {k: 1e3 * v for k, v in split.items()},
                "integrator_excess_ms": 1e3 * (split["integrator_calls"] - t_floor),
                "summary_work_ms": 1e3 * work,
                "whole_over_floor_ideal": whole_over_floor(t_floor + work, t_floor, r_whole, r_floor),
                "whole_over_floor_calls_and_summary": whole_over_floor(
                    split["integrator_calls"] + work, t_floor, r_whole, r_floor),
                "event_work_ms": 1e3 * events,
                "whole_over_floor_calls_summary_events": whole_over_floor(
                    split["integrator_calls"] + work + events, t_floor, r_whole, r_floor),
                "path_overhead_ms": 1e3 * (t_whole - t_floor - work),
                "path_allowance_ms": 1e3 * (allowed - t_floor - work),
                "after_integration_ms": 1e3 * (split["grid_evaluations"] + split["summary"]),
                "replayed_calls_ms": 1e3 * replayed, "replayed_calls": recorders[engine].counts(),
                "whole_over_floor_calls_replayed": whole_over_floor(replayed + split["summary"], t_floor, r_whole, r_floor),
            })
            print(_line(rows[-1]), file=sys.stderr, flush=True)
    return rows


def _line(row):
    p = row["parts_ms"]
    return (f"{row['scene']:<26} {row['engine']:<6} rtol {row['rtol']:.0e}: whole/floor {row['whole_over_floor']:.2f} "
            f"(without the hybrid loop {row['whole_over_floor_without_hybrid_loop']:.2f}, without it, setup and "
            f"assembly {row['whole_over_floor_without_loop']:.2f}); "
            f"IDAS whole {row['idas_whole_ms']:.2f} ms, budget {row['budget_ms']:.2f} ms (floor {row['idas_floor_ms']:.2f} "
            f"+ {row['budget_beyond_floor_ms']:.2f}); timed run {row['timed_whole_ms']:.2f} ms = integrator calls "
            f"{p['integrator_calls']:.2f} (floor + {row['integrator_excess_ms']:.2f}) + grid evaluations "
            f"{p['grid_evaluations']:.2f} + summary {p['summary']:.2f} + hybrid loop {p['hybrid_loop']:.2f} "
            f"+ setup and assembly {p['setup_and_assembly']:.2f}; "
            f"Radau beyond its floor {row['radau_beyond_floor_ms']:.2f} ms; summary work {row['summary_work_ms']:.2f} ms: "
            f"ideal whole/floor {row['whole_over_floor_ideal']:.2f}, with the calls as they are "
            f"{row['whole_over_floor_calls_and_summary']:.2f}, with the event functions on the samples too "
            f"({row['event_work_ms']:.2f} ms) {row['whole_over_floor_calls_summary_events']:.2f}, with the run's own "
            f"calls replayed back to back ({row['replayed_calls_ms']:.2f} ms) and the summary's arithmetic "
            f"{row['whole_over_floor_calls_replayed']:.2f}; IDAS path "
            f"{row['path_overhead_ms']:.2f} ms "
            f"against an allowance of {row['path_allowance_ms']:.2f} ms")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", default="out/bench_whole_run_budget")
    parser.add_argument("--scenes", default=",".join(SCENES))
    parser.add_argument("--rtols", default="1e-6,1e-7,1e-8", help="integration tolerances (default 1e-6,1e-7,1e-8)")
    parser.add_argument("--repeats", type=int, default=15, help="timed IDAS runs per point, best counts (Radau: a third, at least 3)")
    parser.add_argument("--engines", default="vm,native", help="vm, native or both (native needs a C compiler)")
    args = parser.parse_args(argv)
    rtols = [float(r) for r in args.rtols.split(",")]
    engines = args.engines.split(",")
    unknown = sorted(set(engines) - {"vm", "native"})
    if unknown:
        parser.error(f"--engines takes vm and native (got {', '.join(unknown)})")
    if args.repeats < 1:
        parser.error(f"--repeats must be >= 1 (got {args.repeats})")
    rows = [row for name in args.scenes.split(",") for row in measure(name, rtols, args.repeats, engines)]
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    result = {"target": TARGET, "repeats": args.repeats, "rows": rows}
    (out / "bench_whole_run_budget.json").write_text(json.dumps(result, indent=2) + "\n")
    for row in rows:
        print(_line(row))
    return 0


if __name__ == "__main__":
    sys.exit(main())
