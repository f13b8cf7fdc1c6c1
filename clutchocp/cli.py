"""The ``clutchocp`` command: a thin layer over the Python API.

Every user mistake ends in one line on stderr naming the field and what is allowed, exit code 2.
"""

import argparse
import sys
from pathlib import Path

from .errors import ClutchocpError


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
    """Print a checked scene: its parts and their chosen variants."""
    print(f"{scene.name}: {scene.kind} scene, valid")
    print(f"  source: {scene.source}")
    for part in scene.parts:
        if part != "scene":
            variant = scene.variant(part)
            print(f"  [{part}]" + (f" model = {variant}" if variant else ""))


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
