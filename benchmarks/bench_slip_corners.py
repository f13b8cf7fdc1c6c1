"""The closed loop on the hardest clutches: slip feedback run on the corners of the uncertainty box.

A development check of the slip feedback that takes about a minute instead of the Monte Carlo's
ten: on the default scene it solves the nominal optimum, designs the slip feedback of a spec as ``clutchocp
robust`` does (the feedforward with the spec's time margin, scheduled on the spec's field), and runs the closed
loop through IDAS on the nominal clutch and on the 2^3 corners of the scene's [uncertainty] box
(mu +-10 %, viscosity +-30 %, load torque +-20 %), or on ``--samples`` random draws instead. Per
clutch it prints the lock-up time (and whether it is within t_max, with the 1 % lock-time tolerance
of the Monte Carlo), |torque jump| in % of the locked torque, the jerk integral over the nominal
optimum's (at t_max), and the largest feedback correction [kPa].

Run from the repository root:

    python benchmarks/bench_slip_corners.py [--controller slip_lqr] [--samples N]
"""

import argparse
import os
import time

import numpy as np

from clutchocp.optimal.problem import EngagementOCP
from clutchocp.optimal.verify import LOCK_TIME_TOLERANCE, run_numbers
from clutchocp.scene import default_scene
from clutchocp.shiftcontrol.closed_loop import run_closed_loop
from clutchocp.shiftcontrol.schedule import design_schedule
from clutchocp.shiftcontrol.spec import load_slip_spec
from clutchocp.scene.uncertainty import Uncertainty


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--controller", default="slip_lqr", help="slip-feedback spec name or TOML file")
    parser.add_argument("--samples", type=int, default=0, help="random draws (seed --seed) instead of the corners")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--intervals", type=int, default=60)
    args = parser.parse_args()

    scene = default_scene()
    uncertainty = Uncertainty.from_scene(scene)
    nominal = scene.without_uncertainty()
    spec = load_slip_spec(args.controller)
    ocp = EngagementOCP(nominal, intervals=args.intervals)
    t_max = ocp.default_t_max()
    start = time.perf_counter()
    opt = ocp.solve(t_max=t_max)

    def feedforward_for(design_scene):      # as clutchocp robust: the design scene's optimum at the spec's margin
        found = EngagementOCP(design_scene, intervals=args.intervals).solve(t_max=spec.t_max_fraction * t_max)
        return found.command_times, found.command

    schedule = design_schedule(nominal, spec, uncertainty, feedforward_for, say=lambda *a: None)
    print(f"t_max {t_max:.4f} s; feedforwards lock at {', '.join(f'{t:.4f}' for t in schedule.lock_times)} s "
          f"({spec.t_max_fraction:g} x t_max, {len(schedule.feedbacks)} design(s) on "
          f"{schedule.field or 'the nominal scene'}); set-up {time.perf_counter() - start:.1f} s; "
          f"load {os.getloadavg()[0]:.1f}")
    if args.samples:
        cases = [(f"s{i}", d) for i, d in enumerate(uncertainty.samples(args.samples, seed=args.seed))]
    else:
        cases = [(f"c{i}", d) for i, d in enumerate(uncertainty.corners())]
    cases = [("nominal", uncertainty.centre())] + cases
    t_end = 1.5 * t_max + 0.05
    jerk_ref = opt.terms["jerk_integral"]
    jumps, within = [], []
    print(f"{'clutch':8} {'mu':>5} {'visc':>5} {'load':>5} {'lock [s]':>9} {'in t_max':>8} {'|jump| %':>8} "
          f"{'jerk/opt':>8} {'max du [kPa]':>12}")
    for name, overrides in cases:
        clutch = nominal.with_overrides(overrides)
        feedback, design = schedule.select(clutch)
        run, tcu = run_closed_loop(clutch, feedback, t_end, nominal_scene=nominal.with_overrides(design))
        n = run_numbers(run)
        t_lock = n["engagement_time_s"]
        ok = t_lock is not None and t_lock <= t_max * (1 + LOCK_TIME_TOLERANCE)
        jump = 100 * abs(n["lockup_torque_jump_Nm"]) / abs(n["locked_torque_Nm"]) if t_lock is not None else np.nan
        rel = [overrides[k] / nominal.value(k) for k in ("friction.mu", "oil.viscosity", "load.torque")]
        print(f"{name:8} {rel[0]:5.2f} {rel[1]:5.2f} {rel[2]:5.2f} {t_lock or np.nan:9.4f} {'yes' if ok else 'NO':>8} "
              f"{jump:8.2f} {n['jerk_integral'] / jerk_ref:8.3f} {np.max(np.abs(tcu['correction_Pa'])) / 1e3:12.0f}")
        if name != "nominal":
            jumps.append(jump)
            within.append(ok)
    print(f"{len(jumps)} clutches: within t_max {100 * np.mean(within):.0f} %, |jump| median {np.nanmedian(jumps):.2f} %, "
          f"worst {np.nanmax(jumps):.2f} %; load {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
