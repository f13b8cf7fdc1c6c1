"""The ``clutchocp`` command: a thin layer over the Python API.

Every user mistake ends in one line on stderr naming the field and what is allowed, exit code 2.
"""

import argparse
import sys
from pathlib import Path

import numpy as np

from .errors import ClutchocpError, ModelError


def _cmd_scenes(args):
    from .scene import list_scenes, load_scene

    if args.scene:
        for name in args.scene:
            _describe(load_scene(name))
        return 0
    scenes = list_scenes()
    width = max(len(s.name) for s in scenes)
    for scene in scenes:
        mark = " (default)" if scene.value("scene.default") else ""
        print(f"{scene.name:<{width}}  {scene.kind:<10}  {scene.title}{mark}")
    return 0


def _describe(scene):
    """Print a checked scene: its parts, their chosen variants and its uncertain fields."""
    from .uncertainty import Uncertainty

    uncertainty = Uncertainty.from_scene(scene)
    print(f"{scene.name}: {scene.kind} scene, valid")
    print(f"  source: {scene.source}")
    for part in scene.parts:
        if part != "scene":
            variant = scene.variant(part)
            print(f"  [{part}]" + (f" model = {variant}" if variant else ""))
    if uncertainty:
        print("  [uncertainty]")
        for line in uncertainty.describe():
            print(f"    {line}")


def _cmd_validate(args):
    from .analyses import run_validation

    run_validation(Path(args.out))
    return 0


def _cmd_simulate(args):
    from .engagement.report import format_summary, write_engagement
    from .engagement.run import simulate_engagement
    from .scene import load_scene, parse_override

    overrides = dict(parse_override(text) for text in args.set)
    scene = load_scene(args.scene, overrides=overrides)
    run = simulate_engagement(scene, rtol=args.rtol, atol=args.atol, method=args.method, native=args.native)
    print(format_summary(run.summary))
    files = write_engagement(run, args.out)
    print(f"wrote {len(files)} files to {args.out}: {', '.join(f.name for f in files)}")
    return 0


def _cmd_control(args):
    from .hvd.report import run_control

    run_control(args.scene, args.controller, out_dir=args.out)
    return 0


def _parse_weights(text):
    """``"jerk=1,energy=0.1"`` -> {"jerk": 1.0, "energy": 0.1}."""
    weights = {}
    for item in filter(None, (part.strip() for part in text.split(","))):
        name, eq, value = item.partition("=")
        try:
            weights[name.strip()] = float(value)
        except ValueError:
            eq = ""
        if not eq:
            raise ModelError(f"--weights {text}: write name=number pairs separated by commas, e.g. jerk=1,energy=0.1")
    return weights


def _parse_sweep(text):
    """``"0.2,0.3,0.4"`` or ``"0.2:0.5:7"`` (start:stop:count) -> list of engagement-time limits [s]."""
    try:
        if ":" in text:
            start, stop, count = text.split(":")
            return [float(v) for v in np.linspace(float(start), float(stop), int(count))]
        return [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise ModelError(f"--sweep-t-max {text}: give limits in seconds, '0.2,0.3,0.4' or start:stop:count "
                         "like '0.2:0.5:7'") from None


def _cmd_optimize(args):
    from .optimal.report import run_optimize

    run_optimize(args.scene, out_dir=args.out, t_max=args.t_max,
                 weights=_parse_weights(args.weights) if args.weights else None,
                 intervals=args.intervals, degree=args.degree,
                 sweep_t_max=_parse_sweep(args.sweep_t_max) if args.sweep_t_max else None,
                 clamp_margin=args.clamp_margin)
    return 0


def _cmd_bench(args):
    from .bench import format_summary, run_bench

    summary = run_bench(Path(args.out), quick=args.quick, progress=True)
    print(format_summary(summary))
    return 0


def build_parser():
    """The argument parser of the ``clutchocp`` command."""
    parser = argparse.ArgumentParser(
        prog="clutchocp",
        description="Wet-clutch and hydro-viscous-drive simulation, optimal engagement pressure and control.",
    )
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    p = sub.add_parser("scenes", help="list the built-in scenes, one line each; or check the scenes named")
    p.add_argument("scene", nargs="*", help="scene name or TOML file to check and describe")
    p.set_defaults(run=_cmd_scenes)
    p = sub.add_parser("validate", help="static analyses against the seed papers' tables (Chen, Cui, Liao)")
    p.add_argument("--out", default="out/validate", help="output folder (default: out/validate)")
    p.set_defaults(run=_cmd_validate)
    p = sub.add_parser("simulate", help="simulate an engagement scene through impact and lock-up (IDAS)")
    p.add_argument("scene", help="scene name (see 'clutchocp scenes') or TOML file")
    p.add_argument("--out", default="out/simulate", help="output folder (default: out/simulate)")
    p.add_argument("--set", action="append", default=[], metavar="PART.KEY=VALUE",
                   help="override a scene value, e.g. --set oil.viscosity='0.04 Pa s' (repeatable)")
    p.add_argument("--rtol", type=float, default=None, help="relative tolerance (default: the scene's)")
    p.add_argument("--atol", type=float, default=None, help="absolute tolerance on scaled states")
    p.add_argument("--method", default="idas", choices=("idas", "Radau", "BDF", "LSODA"),
                   help="integrator (default: idas)")
    p.add_argument("--native", action="store_true",
                   help="compile the equations to C with the system compiler first (faster repeated runs)")
    p.set_defaults(run=_cmd_simulate)
    p = sub.add_parser("optimize", help="optimal engagement pressure by direct collocation (the main job)")
    p.add_argument("scene", nargs="?", default=None, help="engagement scene (default: the default scene)")
    p.add_argument("--out", default="out/optimize", help="output folder (default: out/optimize)")
    p.add_argument("--t-max", type=float, default=None, help="largest engagement time [s]")
    p.add_argument("--weights", default=None, metavar="NAME=W,...",
                   help="objective weights, e.g. jerk=1,energy=0.1,time=0,jump=1")
    p.add_argument("--intervals", type=int, default=100, help="collocation intervals (default: 100)")
    p.add_argument("--degree", type=int, default=3, help="collocation points per interval (default: 3)")
    p.add_argument("--sweep-t-max", default=None, metavar="LIST|START:STOP:COUNT",
                   help="solve for several engagement-time limits and draw the jerk/time trade-off")
    p.add_argument("--clamp-margin", type=float, default=1.3, metavar="RATIO",
                   help="after lock-up, ramp to the clamp pressure whose static torque capacity is RATIO x "
                        "the locked torque (>= 1, default: 1.3)")
    p.set_defaults(run=_cmd_optimize)
    p = sub.add_parser("bench", help="error against run time, stiffness and scaling (work-precision report)")
    p.add_argument("--quick", action="store_true", help="fewer tolerances and sizes (under 3 minutes)")
    p.add_argument("--out", default="out/bench", help="output folder (default: out/bench)")
    p.set_defaults(run=_cmd_bench)
    p = sub.add_parser("control", help="hydro-viscous drive: operating points, linearisation, speed controller, closed loop")
    p.add_argument("scene", help="an hvd scene (e.g. liao2021_hvd, cui2019_hvd) or TOML file")
    p.add_argument("--controller", default=None, help="controller spec name (lqi, pi) or TOML file (default: lqi)")
    p.add_argument("--out", default="out/control", help="output folder (default: out/control)")
    p.set_defaults(run=_cmd_control)
    return parser


def main(argv=None):
    """Entry point; returns the process exit code."""
    args = build_parser().parse_args(argv)
    try:
        return args.run(args)
    except ClutchocpError as exc:
        print(f"clutchocp {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("clutchocp: interrupted", file=sys.stderr)
        return 130



def run():
    """Console-script entry point: exit with :func:`main`'s code."""
    sys.exit(main())


if __name__ == "__main__":
    run()
