"""Optimal engagement pressure of the default driveline, verified with IDAS.

The same as ``clutchocp optimize --sweep-t-max ...``, then the lower-level API: the problem object,
a solve with an energy limit warm-started from the first optimum, its IDAS check and the kinematic
bound. Run from anywhere:

    python examples/optimal_pressure.py [OUT_DIR]        (default: out/optimal_pressure)
"""

import sys

from clutchocp.optimal import EngagementOCP, jerk_lower_bound, run_optimize, verify
from clutchocp.scene import default_scene


def main(out_dir="out/optimal_pressure"):
    # 1. The command: optimum, baselines, IDAS check, files and figures, a jerk / time trade-off.
    summary = run_optimize(out_dir=out_dir, sweep_t_max=[0.16, 0.18, 0.21, 0.25, 0.3])
    print(f"files: {', '.join(summary['files'])}\n")

    # 2. The API: optimise again with 2 % less dissipated energy allowed, from the first optimum.
    scene = default_scene()
    ocp = EngagementOCP(scene, intervals=100, degree=3)
    first = ocp.solve()
    limited = ocp.solve(e_max=0.98 * first.terms["dissipated_energy_J"], guess=first)
    check, _ = verify(ocp.exact, limited)
    w_rel0, rate0 = ocp.initial_slip()
    bound = jerk_lower_bound(w_rel0, rate0, limited.t_f)
    print(f"energy-limited optimum: {limited.terms['dissipated_energy_J']:.0f} J "
          f"(was {first.terms['dissipated_energy_J']:.0f} J), jerk integral {limited.terms['jerk_integral']:.4g} "
          f"rad^2/s^5 (was {first.terms['jerk_integral']:.4g}); {limited.stats['iterations']} warm iterations")
    print(f"IDAS: lock-up at {check['idas']['engagement_time_s']:.4f} s (collocation {limited.t_f:.4f} s), "
          f"jump {check['torque_jump_Nm']:.3f} N m; slip jerk / kinematic bound = "
          f"{limited.terms['slip_jerk_integral'] / bound:.3f}")


if __name__ == "__main__":
    main(*sys.argv[1:2])
