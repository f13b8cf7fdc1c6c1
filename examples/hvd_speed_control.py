"""Speed regulation of a hydro-viscous drive: static map, exact linearisation, LQI and PI, closed loop.

Runs the chain of ``clutchocp control`` step by step on the built-in HVD scenes (Liao 2021, Cui 2019)
with both built-in controller specs, and prints the figures the issue asks for::

    python examples/hvd_speed_control.py [--out out/examples/hvd] [--scene liao2021_hvd] [--controller pi]
"""

import argparse
from pathlib import Path

from clutchocp.hvd import HvdModel, linearize, operating_point, run_control, static_map
from clutchocp.hvd.linearize import describe
from clutchocp.scene import load_scene


def show_plant(scene_name):
    """The API underneath run_control: static map, an operating point, its linear model."""
    model = HvdModel(load_scene(scene_name))
    data = static_map(model)
    inside = data["within_valve_range"] > 0
    print(f"{scene_name}: output speed {data['speed_rad_s'][inside].min():.1f}-{data['speed_rad_s'][inside].max():.1f}"
          f" rad/s within the valve range {model.p_min / 1e6:g}-{model.p_max / 1e6:g} MPa")
    for fraction in (0.4, 0.6, 0.9):
        op = operating_point(model, fraction * model.rated_speed, map_data=data)
        info = describe(linearize(model, op))
        poles = ", ".join(f"{re:.3g}{im:+.2g}j" if im else f"{re:.3g}" for re, im in info["poles"])
        print(f"  {fraction:.0%} rated: p = {op.pressure / 1e6:.4f} MPa, film {op.films[0] * 1e6:.1f} um, "
              f"dw/dp = {info['dc_gain']['w_out_rad_s/p_cmd']:.3g} rad/s/Pa, poles {poles} 1/s")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out/examples/hvd", help="output folder")
    parser.add_argument("--scene", action="append", help="scene name (repeatable; default: both HVD scenes)")
    parser.add_argument("--controller", action="append", help="controller spec (default: lqi and pi)")
    args = parser.parse_args(argv)
    scenes = args.scene or ["liao2021_hvd", "cui2019_hvd"]
    controllers = args.controller or ["lqi", "pi"]
    rows = []
    for scene in scenes:
        show_plant(scene)
        for controller in controllers:
            summary = run_control(scene, controller, out_dir=Path(args.out) / f"{scene}_{controller}")
            rows.append((scene, controller, summary))
            print()
    print(f"{'scene':<14}{'ctrl':<6}{'GM dB':>8}{'PM deg':>8}{'OS %':>7}{'t_s 2% s':>10}{'sse %':>8}{'load %':>8}"
          f"{'sat s':>7}  limit cycle")
    for scene, controller, s in rows:
        m, c = s["margins"], s["closed_loop"]
        gm = "inf" if m["gain_margin_dB"] is None else f"{m['gain_margin_dB']:.1f}"
        print(f"{scene:<14}{controller:<6}{gm:>8}{m['phase_margin_deg']:>8.1f}{c['overshoot_pct']:>7.2f}"
              f"{c['settling_time_s']:>10.2f}{100 * c['steady_state_error_rel']:>8.3f}"
              f"{100 * c['load_peak_deviation_rel']:>8.2f}{c['time_in_saturation_s']:>7.2f}  "
              f"{'yes' if c['limit_cycle'] else 'no'}")


if __name__ == "__main__":
    main()
