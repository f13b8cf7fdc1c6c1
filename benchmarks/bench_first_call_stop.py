"""Benchmark (not a test): what an integrator call that stopped at its event would save, and why
CasADi's own event stop is not used for it.

    PYTHONPATH=. python benchmarks/bench_first_call_stop.py
    PYTHONPATH=. python benchmarks/bench_first_call_stop.py --scenes zhang2021 --rtol 1e-8

The first call of a piece whose next crossing the quadratic prediction cannot see runs to the end
of the piece (the slipping piece of zhang2021, default_driveline and default_driveline_thermal: it
locks at 0.135-1.6 s of a 1.5-6 s run). Per scene, at one tolerance, this script takes that call as
a run makes it (its start, parameters, normalised time and output grid) and times, best of
``--repeats``:

* ``full``: the call as the engine makes it, to the end of the piece;
* ``ended``: the same problem (the same normalised time and first output, so the same steps) with
  its outputs ending ``past`` grid intervals after the located event: what a call that stopped at
  its event without a restart would cost at most. A call's last steps are shortened to land on its
  end, so the samples just before that end move; ``past`` starts at ``--past`` and doubles until
  the samples before the event equal the full call's (``ended_change``, the largest change of the
  scaled states, 0 unless the piece ran out);
* ``casadi_zero``: CasADi's ``zero`` events with ``max_events=0``. The zero functions are the mode's
  scaled event functions delayed by ``past`` grid intervals (``s - lag ds/dt``, the time
  derivative along the flow), so that the sample after the crossing, which the event location
  needs, is still written. The call stops with an error at the first crossing of a zero function
  and leaves the samples before it in the output buffer. ``zero_change`` is the largest change of
  the samples before the event (scaled states) against the full call's. CasADi warns that its
  event support is experimental.

``whole_ms`` is a whole run's best time (``--repeats`` runs), ``ended_saving_share`` the part of it
an ended first call would save (``(full - ended) / whole``): with every other time unchanged,
``whole / floor`` would rise by the factor ``1 / (1 - share)``.

An engine can only end that call early by guessing: a call that ends before the event and a
restart (IDAS or CVODES again at order 1 with a small first step; from there the quadratic
prediction sees the crossing). ``restarts`` times whole runs whose blind first call ends after
``1/k`` of the piece, ``k`` in ``--parts``, at the same tolerance, side by side with the run as it
is; their samples move (the steps do), so each gets its error against a reference run
(:func:`clutchocp.bench.workprecision.trajectory_errors`, IDAS at rtol 1e-12) next to the run's own
(``whole_error``), and where its first call ends (``first_call_end_s``, ``ends_past_event``: a call
ending past the event finds it without a restart). ``restart_best_saving_share`` is the part of the
whole run the best of them saves.

Results go to ``bench_first_call_stop.json`` in ``--out`` and a table to stdout. The three calls
and the whole runs take turns, one timed call each per round, after one untimed call each
(:func:`clutchocp.bench.turns.best_of_turns`): the times a saving divides are taken side by side.
"""

import argparse
import contextlib
import functools
import json
import sys
import time
from pathlib import Path

import numpy as np

SCENES = ("zhang2021", "default_driveline", "default_driveline_thermal")
PARTS = (2, 4, 8, 16)


def first_call(scene, model, rtol):
    """The first integrator call of a run (the IDAS path, its compiled mode, t0, scaled x0 and z0, the
    inputs, the output times) and the run itself."""
    import clutchocp.simulation.idas_path as idas_path
    from clutchocp.bench.workprecision import run_method

    seen = []
    inner = idas_path.IdasPath._integrate

    def spy(path, cm, t0, xs0, zs0, pu, times):
        if not seen:
            seen.append((path, cm, float(t0), np.array(xs0, float), np.array(zs0, float),
                         np.array(pu, float).ravel(), np.array(times, float)))
        return inner(path, cm, t0, xs0, zs0, pu, times)

    idas_path.IdasPath._integrate = spy
    try:
        run = run_method(scene, model, "idas", rtol)
    finally:
        idas_path.IdasPath._integrate = inner
    return seen[0], run


@contextlib.contextmanager
def blind_first_call_ended(parts):
    """The engine with the first call of a piece that predicts no crossing (it would run to the end
    of the piece) ended after ``1 / parts`` of the piece's outputs; the next call restarts and is
    planned as the engine plans it."""
    import clutchocp.simulation.idas_path as idas_path

    inner = idas_path.IdasPath._plan

    def plan(path, cm, left, pu, times, monitor, probes, horizon=None, first=False):
        n, t_probe, horizon = inner(path, cm, left, pu, times, monitor, probes, horizon, first)
        if first and t_probe is None and horizon is None and n == times.size:
            n = max(2, times.size // parts)
        return n, t_probe, horizon

    idas_path.IdasPath._plan = plan
    try:
        yield
    finally:
        idas_path.IdasPath._plan = inner


def run_ended(scene, model, rtol, parts):
    """A whole run (:func:`clutchocp.bench.workprecision.run_method`) with its blind first calls
    ended after ``1 / parts`` of the piece."""
    from clutchocp.bench.workprecision import run_method

    with blind_first_call_ended(parts):
        return run_method(scene, model, "idas", rtol)


def delayed_events(cm, lag_tau):
    """The scaled event functions of mode ``cm`` delayed by ``lag_tau`` (normalised time):
    ``s - lag_tau ds/dtau`` on the normalised-time DAE's variables."""
    import casadi as ca

    dae = cm.dae_tau
    tau, t0, span = dae["t"], dae["p"][-2], dae["p"][-1]
    s, slope, _ = cm.event_rates()
    return ca.substitute(s - lag_tau * span * slope, cm.t, t0 + tau * span)


def call_task(integrator, nx, nz, n, x0, z0, p):
    """A task (:func:`clutchocp.bench.turns.best_of_turns`) of one buffer call of ``integrator``: its time
    [s] and (the scaled states (nx, n), NaN where the call wrote none; its step count; its error
    message, '' if none)."""
    buffer, evaluate = integrator.buffer()
    dummy = np.zeros(1)

    def task():
        xf, zf = np.full((n, nx), np.nan), np.zeros((n, max(nz, 1)))
        for i, a in enumerate((x0, z0, p)):
            buffer.set_arg(i, memoryview(a if a.size else dummy))
        buffer.set_res(0, memoryview(xf))
        buffer.set_res(1, memoryview(zf if nz else dummy))
        message = ""
        start = time.perf_counter()
        try:
            evaluate()
        except RuntimeError as err:
            message = str(err).strip().splitlines()[-1]
        seconds = time.perf_counter() - start
        return seconds, (xf.T, int(buffer.stats().get("nsteps", 0)), message)

    return task


def measure(name, rtol, past, repeats, parts=PARTS):
    """One scene: a JSON-ready row."""
    import casadi as ca

    from clutchocp.bench.turns import best_of_turns, wall
    from clutchocp.bench.workprecision import REFERENCE_RTOL, run_method, trajectory_errors
    from clutchocp.engagement.model import EngagementModel
    from clutchocp.scene import load_scene

    scene = load_scene(name)
    model = EngagementModel(scene)
    (path, cm, t0, xs0, zs0, pu, times), run = first_call(scene, model, rtol)
    event = run.result.events[0]
    span, n = times[-1] - t0, times.size
    before = int(np.searchsorted(times, event.t))          # samples strictly before the event
    scheme = path.scheme_for(cm)
    plugin = "idas" if scheme == "idas" else "cvodes"
    options = path._idas_options(span, scheme)
    taus = np.arange(1, n + 1) / n
    p = np.concatenate([pu, [t0, span]])
    x0, z0 = np.ascontiguousarray(xs0).ravel(), np.ascontiguousarray(zs0).ravel()

    def task(dae, grid, extra=None):
        integrator = ca.integrator(f"{plugin}_{cm.name}", plugin, dae, 0.0, list(grid), {**options, **(extra or {})})
        return call_task(integrator, cm.nx, cm.nz, len(grid), x0, z0, p)

    full_x = task(cm.dae_tau, taus)()[1][0]
    while True:     # a call's last steps shorten to land on its end (its stop time): end far enough past the event
        ended_x = task(cm.dae_tau, taus[:min(n, before + past)])()[1][0]
        change = float(np.max(np.abs(ended_x[:, :before] - full_x[:, :before])))
        if change == 0.0 or before + past >= n:
            break
        past *= 2
    zero_dae = {**cm.dae_tau, "zero": delayed_events(cm, past / n)}
    # the three calls and the whole runs take turns, one timed call each per round
    best = best_of_turns({"full": task(cm.dae_tau, taus), "ended": task(cm.dae_tau, taus[:min(n, before + past)]),
                          "zero": task(zero_dae, taus, {"max_events": 0}),
                          "whole": wall(functools.partial(run_method, scene, model, "idas", rtol)),
                          **{f"restart_{k}": wall(functools.partial(run_ended, scene, model, rtol, k)) for k in parts}},
                         repeats)
    reference = run_method(scene, model, "idas", REFERENCE_RTOL)
    restarts = [{"parts": k, "whole_ms": 1e3 * best[f"restart_{k}"][0],
                 "first_call_end_s": float(times[max(2, n // k) - 1]),      # where the ended first call ends
                 "ends_past_event": bool(times[max(2, n // k) - 1] > event.t),
                 "steps": int(best[f"restart_{k}"][1].summary["solver"]["statistics"]["n_steps"]),
                 "error": trajectory_errors(best[f"restart_{k}"][1], reference)["max"]} for k in parts]
    fastest = min(restarts, key=lambda r: r["whole_ms"]) if restarts else None
    full_s, (full_x, full_steps, _) = best["full"]
    ended_s, (ended_x, ended_steps, _) = best["ended"]
    zero_s, (zero_x, zero_steps, zero_message) = best["zero"]
    whole = best["whole"][0]
    written = int(np.argmax(np.isnan(zero_x[0]))) if np.isnan(zero_x[0]).any() else n
    kept = min(before, written)
    return {
        "scene": name, "rtol": rtol, "mode": cm.name, "event_t_s": float(event.t), "piece_end_s": float(times[-1]),
        "outputs": n, "outputs_before_event": before, "past": past,
        "full_ms": 1e3 * full_s, "full_steps": full_steps,
        "ended_ms": 1e3 * ended_s, "ended_steps": ended_steps,
        "ended_change": change,
        "casadi_zero_ms": 1e3 * zero_s, "casadi_zero_steps": zero_steps, "casadi_zero_written": written,
        "casadi_zero_message": zero_message,
        "zero_change": float(np.max(np.abs(zero_x[:, :kept] - full_x[:, :kept]))) if kept else None,
        "whole_ms": 1e3 * whole, "ended_saving_share": (full_s - ended_s) / whole,
        "whole_steps": int(best["whole"][1].summary["solver"]["statistics"]["n_steps"]),
        "whole_error": trajectory_errors(best["whole"][1], reference)["max"],
        "restarts": restarts, "restart_best_parts": fastest["parts"] if fastest else None,
        "restart_best_saving_share": 1.0 - fastest["whole_ms"] / (1e3 * whole) if fastest else None,
    }


def _line(row):
    return (f"{row['scene']:<26} rtol {row['rtol']:.0e}: first call to {row['piece_end_s']:g} s {row['full_ms']:.2f} ms "
            f"({row['full_steps']} steps); ended {row['past']} grid intervals past the event at {row['event_t_s']:.4g} s: "
            f"{row['ended_ms']:.2f} ms ({row['ended_steps']} steps), samples changed {row['ended_change']:.1e}; "
            f"CasADi zero events: {row['casadi_zero_ms']:.2f} ms ({row['casadi_zero_steps']} steps, "
            f"{row['casadi_zero_written']} of {row['outputs']} samples written, {row['outputs_before_event']} before "
            f"the event), samples changed {row['zero_change']:.1e}; whole run {row['whole_ms']:.2f} ms "
            f"({row['whole_steps']} steps, error {row['whole_error']:.1e}), an ended first call would save "
            f"{100 * row['ended_saving_share']:.1f} % of it; first call ended by a restart at "
            + ", ".join(f"1/{r['parts']}: {r['whole_ms']:.2f} ms ({r['steps']} steps, error {r['error']:.1e})"
                        for r in row["restarts"]))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", default="out/bench_first_call_stop")
    parser.add_argument("--scenes", default=",".join(SCENES))
    parser.add_argument("--rtol", type=float, default=1e-7, help="integration tolerance (default 1e-7)")
    parser.add_argument("--past", type=int, default=5, help="grid intervals past the event an ended call keeps, first try (>= 1; doubled until its samples before the event are unchanged)")
    parser.add_argument("--repeats", type=int, default=15, help="timed calls and whole runs, the best counts")
    parser.add_argument("--parts", default=",".join(map(str, PARTS)),
                        help="whole runs whose blind first call ends after 1/k of the piece, k in this list (integers >= 2)")
    args = parser.parse_args(argv)
    if args.past < 1:
        parser.error(f"--past must be >= 1: the event location needs the sample after the crossing (got {args.past})")
    if args.repeats < 1:
        parser.error(f"--repeats must be >= 1 (got {args.repeats})")
    if not 0 < args.rtol < 1:
        parser.error(f"--rtol must lie in (0, 1) (got {args.rtol})")
    try:
        parts = tuple(int(k) for k in args.parts.split(",")) if args.parts else ()
    except ValueError:
        parts = (0,)
    if any(k < 2 for k in parts):
        parser.error(f"--parts must be a comma-separated list of integers >= 2 (got {args.parts!r})")
    rows = []
    for name in args.scenes.split(","):
        rows.append(measure(name, args.rtol, args.past, args.repeats, parts))
        print(_line(rows[-1]), file=sys.stderr, flush=True)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "bench_first_call_stop.json").write_text(json.dumps({"rows": rows}, indent=2) + "\n")
    for row in rows:
        print(_line(row))
    return 0


if __name__ == "__main__":
    sys.exit(main())
