"""The ``clutchocp`` command: a thin layer over the Python API.

Every user mistake ends in one line on stderr naming the field and what is allowed, exit code 2.
Ctrl-C stops the run (also inside IDAS and IPOPT) with one line and exit code 130; no output folder
is left that looks complete (results are written through :func:`clutchocp.output.output_folder`).

Helpers for the commands' options (:func:`positive_float`, :func:`tolerance`, :func:`count`) are
argparse ``type=`` functions: a bad value ends in one line naming the option and what is allowed.
The commands are the functions of :mod:`clutchocp.commands` named like them; ``scenes`` is here.
"""

import argparse
import math
import os
import sys
import warnings

from . import interrupt
from .errors import ClutchocpError
from .scene import list_scenes, load_scene
from .scene.uncertainty import Uncertainty

# Integration tolerances a user may ask for: tighter than 1e-14 is below double precision noise on
# the scaled states; looser ones give results that only look like answers (bao2020 at rtol = atol:
# 1e-2 -> energy balance off by 1.1 %, lock-up 1.2 % late; 10 -> 6.8 % and 4.7 %). Above
# LOOSE_TOLERANCE the run goes on with a warning.
TOLERANCE_RANGE = (1e-14, 1e-2)
LOOSE_TOLERANCE = 1e-4
MAX_INTERVALS = 2000      # collocation intervals: 2000 x degree 3 is ~10^5 NLP variables (minutes, GBs)


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (exit code 2) instead of the usage block."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message} (see '{self.prog} --help')\n")


def positive_float(text, *, upper=None, what="a positive number"):
    """A finite number > 0 (and <= ``upper``); an argparse ``type=``."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a number; {what} is allowed") from None
    if not (math.isfinite(value) and value > 0) or (upper is not None and value > upper):
        limit = f" up to {upper:g}" if upper is not None else ""
        raise argparse.ArgumentTypeError(f"{text}: {what}{limit} is allowed")
    return value


def tolerance(text):
    """An integration tolerance in :data:`TOLERANCE_RANGE`; an argparse ``type=``."""
    low, high = TOLERANCE_RANGE
    allowed = "a tolerance from 1e-14 to 1e-2"
    value = positive_float(text, what=allowed)
    if not low <= value <= high:
        raise argparse.ArgumentTypeError(f"{text}: {allowed} is allowed (looser tolerances give errors of "
                                         "percents without a warning)")
    if value > LOOSE_TOLERANCE:
        warnings.warn(f"tolerance {text} is loose: expect errors of about that size in the results "
                      f"(at 1e-2 bao2020's energy balance was off by 1.1 %); {LOOSE_TOLERANCE:g} or tighter is "
                      "advised", stacklevel=2)
    return value


def count(low, high, what):
    """An argparse ``type=`` for an integer from ``low`` to ``high``."""
    def parse(text):
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"'{text}' is not an integer; {what} from {low} to {high}") from None
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(f"{text}: {what} from {low} to {high} is allowed")
        return value
    return parse


def time_limit(text):
    """A positive, finite time [s]; an argparse ``type=``."""
    return positive_float(text, what="a positive time in seconds")


def nonnegative_time(text):
    """A finite time >= 0 [s]; an argparse ``type=``."""
    return 0.0 if text.strip() in ("0", "0.0") else positive_float(text, what="a time >= 0 in seconds")


def temperature(text):
    """A finite temperature above absolute zero [degC]; an argparse ``type=``."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a number; a temperature in degC is allowed") from None
    if not (math.isfinite(value) and value > -273.15):
        raise argparse.ArgumentTypeError(f"{text}: a temperature in degC above -273.15 is allowed")
    return value


STRATEGY_NAMES = ("baseline", "nominal_optimum", "robust_feedforward", "closed_loop")


def strategy_list(text):
    """A comma-separated subset of the robust command's strategies; an argparse ``type=``."""
    names = [part.strip() for part in text.split(",") if part.strip()]
    unknown = [n for n in names if n not in STRATEGY_NAMES]
    if unknown or not names:
        raise argparse.ArgumentTypeError(f"'{text}': a comma-separated subset of {', '.join(STRATEGY_NAMES)} is allowed")
    return tuple(dict.fromkeys(names))


def _command(name):
    """The command ``name`` of :mod:`clutchocp.commands`, imported when it runs."""
    def run(args):
        # imported here: --help, scenes and a mistyped option answer without loading the models
        from . import commands
        return getattr(commands, name)(args)
    return run


def _cmd_scenes(args):
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


def build_parser():
    """The argument parser of the ``clutchocp`` command."""
    parser = _Parser(
        prog="clutchocp",
        description="Wet-clutch and hydro-viscous-drive simulation, optimal engagement pressure and control.",
    )
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    _add_scene_commands(sub)
    _add_optimize(sub)
    _add_control_commands(sub)
    _add_sweep(sub)
    return parser


def _add_scene_commands(sub):
    """scenes, validate, simulate, cycles."""
    p = sub.add_parser("scenes", help="list the built-in scenes, one line each; or check the scenes named")
    p.add_argument("scene", nargs="*", help="scene name or TOML file to check and describe")
    p.set_defaults(run=_cmd_scenes)
    p = sub.add_parser("validate", help="static analyses against the seed papers' tables (Chen, Cui, Liao)")
    p.add_argument("--out", default="out/validate", help="output folder (default: out/validate)")
    p.set_defaults(run=_command("validate"))
    p = sub.add_parser("simulate", help="simulate an engagement scene through impact and lock-up (IDAS)")
    p.add_argument("scene", help="scene name (see 'clutchocp scenes') or TOML file")
    p.add_argument("--out", default="out/simulate", help="output folder (default: out/simulate); written when complete")
    p.add_argument("--set", action="append", default=[], metavar="PART.KEY=VALUE",
                   help="override a scene value, e.g. --set oil.viscosity='0.04 Pa s' (repeatable)")
    p.add_argument("--rtol", type=tolerance, default=None,
                   help="relative tolerance, 1e-14 ... 1e-2 (default: the scene's simulation.rtol)")
    p.add_argument("--atol", type=tolerance, default=None,
                   help="absolute tolerance on the states scaled by their nominal values, 1e-14 ... 1e-2")
    p.add_argument("--method", default="idas", choices=("idas", "Radau", "BDF", "LSODA"),
                   help="integrator (default: idas)")
    p.add_argument("--native", action="store_true",
                   help="compile the equations to C with the system compiler first (faster repeated runs)")
    p.set_defaults(run=_command("simulate"))
    p = sub.add_parser("cycles", help="repeated engagements with cooling between: temperature and engagement-time "
                                      "drift per cycle, until a limit (scene needs a [thermal] part)")
    p.add_argument("scene", help="engagement scene with a [thermal] part (e.g. default_driveline_thermal) or TOML file")
    p.add_argument("--cycles", type=count(1, 10000, "engagements"), default=10, help="largest number of engagements (default: 10)")
    p.add_argument("--cooling-time", type=nonnegative_time, default=10.0, metavar="S",
                   help="open-clutch cooling interval after each engagement run [s] (default: 10)")
    p.add_argument("--max-temperature", type=temperature, default=None, metavar="DEGC",
                   help="stop after the cycle whose peak interface temperature reaches this [degC]")
    p.add_argument("--set", action="append", default=[], metavar="PART.KEY=VALUE",
                   help="override a scene value (repeatable)")
    p.add_argument("--out", default="out/cycles", help="output folder (default: out/cycles)")

    p.set_defaults(run=_command("cycles"))


def _add_optimize(sub):
    """optimize."""
    p = sub.add_parser("optimize", help="optimal engagement pressure by direct collocation (the main job)")
    p.add_argument("scene", nargs="?", default=None, help="engagement scene (default: the default scene)")
    p.add_argument("--out", default="out/optimize", help="output folder (default: out/optimize)")
    p.add_argument("--set", action="append", default=[], metavar="PART.KEY=VALUE",
                   help="override a scene value, e.g. --set actuation.max_pressure='1.2 MPa' (repeatable)")
    p.add_argument("--t-max", type=time_limit, default=None,
                   help="largest engagement time [s] (default: the scene's actuation.engagement_time_limit, else "
                        "the lock-up time of its own profile)")
    p.add_argument("--weights", default=None, metavar="NAME=W,...",
                   help="objective weights, e.g. jerk=1,energy=10. Objective: jerk x (int jerk^2 dt)/J_ref "
                        "+ energy x E/E_ref + time x t_f/t_ref + jump x (torque jump/locked torque)^2 + smooth "
                        "x int (dp/dt)^2 dt t_ref/p_max^2 (+ fill_time x t_fill/t_ref + kiss_speed x "
                        "(piston speed at the kiss point/v_ref)^2 on a scene with a fill phase), where t_ref "
                        "and E_ref are the lock time and energy of the scene's own profile and J_ref the "
                        "kinematic jerk bound at t_ref. Defaults: jerk=1, energy=0, time=0, jump=0, smooth=0.1 "
                        "x jerk (a penalty on the command's rate that keeps it smooth; 0 when jerk=0), "
                        "fill_time=0, kiss_speed=0. Names not given keep their default")
    p.add_argument("--intervals", type=count(2, MAX_INTERVALS, "collocation intervals"), default=100,
                   help=f"collocation intervals, 2 ... {MAX_INTERVALS} (default: 100)")
    p.add_argument("--degree", type=count(1, 9, "collocation points per interval"), default=3,
                   help="collocation points per interval, 1 ... 9 (default: 3)")
    p.add_argument("--sweep-t-max", default=None, metavar="LIST|START:STOP:COUNT",
                   help="solve for several engagement-time limits and draw the jerk/time trade-off")
    p.add_argument("--max-temperature", type=temperature, default=None, metavar="DEGC",
                   help="largest interface temperature [degC] while slipping (scene needs a [thermal] part)")
    p.add_argument("--max-specific-power", type=positive_float, default=None, metavar="W_MM2",
                   help="largest interface heat power per friction area [W/mm^2] while slipping")
    p.add_argument("--clamp-margin", type=positive_float, default=None, metavar="RATIO",
                   help="after lock-up, ramp to the clamp pressure whose static torque capacity is RATIO x "
                        "the locked torque (>= 1, default: 1.3, or the most the pack holds if less)")

    p.set_defaults(run=_command("optimize"))


def _add_control_commands(sub):
    """bench, control, robust."""
    p = sub.add_parser("bench", help="error against run time, stiffness and scaling (work-precision report)")
    p.add_argument("--quick", action="store_true", help="fewer tolerances, repeats and sizes, no native code (a few minutes)")
    p.add_argument("--out", default="out/bench", help="output folder (default: out/bench)")
    p.set_defaults(run=_command("bench"))
    p = sub.add_parser("control", help="hydro-viscous drive: operating points, linearisation, speed controller, closed loop")
    p.add_argument("scene", help="an hvd scene (e.g. liao2021_hvd, cui2019_hvd) or TOML file")
    p.add_argument("--controller", default=None, help="controller spec name (lqi, pi) or TOML file (default: lqi)")
    p.add_argument("--out", default="out/control", help="output folder (default: out/control)")
    p.set_defaults(run=_command("control"))
    p = sub.add_parser("robust", help="Monte Carlo of shift-control strategies over the scene's uncertainty "
                                      "(baseline, nominal optimum, robust feedforward, slip feedback)")
    p.add_argument("scene", nargs="?", default=None, help="engagement scene (default: the default scene)")
    p.add_argument("--out", default="out/robust", help="output folder (default: out/robust)")
    p.add_argument("--samples", type=count(1, 1_000_000, "samples"), default=200,
                   help="draws of the uncertainty (default: 200)")
    p.add_argument("--seed", type=count(0, 2**32 - 1, "seed"), default=0, help="seed of the draws (default: 0)")
    p.add_argument("--uncertain", action="append", default=[], metavar="PART.KEY=SPEC",
                   help="add or replace an uncertain field, e.g. --uncertain 'friction.mu=uniform 10 %%' (repeatable)")
    p.add_argument("--t-max", type=time_limit, default=None,
                   help="engagement-time limit [s] (default: the scene's actuation.engagement_time_limit, else the "
                        "lock-up time of its own profile)")
    p.add_argument("--controller", default="slip_lqr", help="slip-feedback spec name or TOML file (default: slip_lqr)")
    p.add_argument("--workers", type=count(1, 1024, "parallel processes"), default=None,
                   help="parallel processes (default: the local cores)")
    p.add_argument("--intervals", type=count(2, MAX_INTERVALS, "collocation intervals"), default=60, help="collocation intervals of the optimisations (default: 60)")
    p.add_argument("--strategies", type=strategy_list, default=None, metavar="NAMES",
                   help="comma-separated subset of baseline, nominal_optimum, robust_feedforward, closed_loop "
                        "(default: all)")
    p.set_defaults(run=_command("robust"))


def _add_sweep(sub):
    """sweep."""
    p = sub.add_parser("sweep", help="many runs of a scene: a grid of operating points or Monte Carlo samples, "
                                     "on local processes or a Dask cluster")
    p.add_argument("scene", help="engagement scene name or TOML file")
    p.add_argument("--task", default="simulate", choices=("simulate", "optimize"),
                   help="what to do at each point (default: simulate)")
    p.add_argument("--grid", action="append", default=[], metavar="PART.KEY=START:STOP:COUNT",
                   help="a swept field (SI numbers or quantities, e.g. load.torque=50:150:5); repeat for a full grid")
    p.add_argument("--samples", type=count(1, 1_000_000, "samples"), default=None, metavar="N",
                   help="N samples of the scene's [uncertainty] (and --uncertain fields)")
    p.add_argument("--seed", type=count(0, 2**32 - 1, "seed"), default=0, help="seed of the samples (default: 0)")
    p.add_argument("--uncertain", action="append", default=[], metavar="PART.KEY=DIST",
                   help="an uncertain field, e.g. 'friction.mu=uniform 10 %%' (repeatable)")
    p.add_argument("--set", action="append", default=[], metavar="PART.KEY=VALUE",
                   help="override a scene value at every point (repeatable)")
    p.add_argument("--out", default="out/sweep", help="output folder (default: out/sweep); a folder holding the "
                                                      "same sweep is resumed")
    p.add_argument("--engine", default=None, choices=("local", "dask", "serial"),
                   help="local worker processes (default), dask (a LocalCluster, or --scheduler) or serial")
    p.add_argument("--workers", type=count(1, 1024, "workers"), default=None,
                   help="local or LocalCluster workers (default: all cores)")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="address of a running Dask scheduler, e.g. tcp://10.0.0.5:8786 (implies --engine dask)")
    p.add_argument("--output-points", type=count(2, 200_000, "output times per run"), default=None,
                   help="simulate: output times per run (default: the scene's simulation.output_points)")
    p.add_argument("--model-per-point", action="store_true",
                   help="build a new model (simulate: the single-run results bit for bit) or collocation problem "
                        "(optimize) at every point (default: one per worker with the swept fields as parameters, "
                        "where possible)")
    p.add_argument("--native", default="auto", choices=("auto", "on", "off"),
                   help="simulate: compiled C code: auto (default) for a model reused over the points, where "
                        "a C compiler exists; on: also for one model per point (1-4 s each); off: never")
    p.add_argument("--t-max", type=time_limit, default=None,
                   help="optimize: largest engagement time [s] (default: the scene's "
                        "actuation.engagement_time_limit, else each point's own baseline lock-up time)")
    p.add_argument("--weights", default=None, metavar="NAME=W,...", help="optimize: objective weights")
    p.add_argument("--intervals", type=count(2, MAX_INTERVALS, "collocation intervals"), default=40,
                   help="optimize: collocation intervals (default: 40)")
    p.add_argument("--degree", type=count(1, 9, "collocation points per interval"), default=3,
                   help="optimize: collocation points per interval (default: 3)")
    p.add_argument("--cold", action="store_true", help="optimize: no warm start from the neighbouring point")
    p.add_argument("--no-verify", action="store_true", help="optimize: skip the IDAS replay of each optimum")
    p.set_defaults(run=_command("sweep"))


def main(argv=None):
    """Entry point; returns the process exit code.

    0: done; 2: a user mistake or a solver failure (one line on stderr naming the field and what
    is allowed, or when, where and why the solver stopped);
    130: interrupted by Ctrl-C (one line; no output folder was put in place); 1: a system failure
    or an unexpected error (one line; ``CLUTCHOCP_DEBUG=1`` shows the traceback).
    """
    name = "clutchocp"
    try:
        with interrupt.catch_interrupts(), warnings.catch_warnings():
            warnings.showwarning = lambda message, *rest, **kw: print(
                f"{name}: warning: {' '.join(str(message).split())}", file=sys.stderr)
            args = build_parser().parse_args(argv)
            name = f"clutchocp {args.command}"
            try:
                code = args.run(args)
            except ClutchocpError:
                interrupt.check()          # a solver failure that a Ctrl-C caused is an interrupt
                raise
            interrupt.check()
            return code
    except SystemExit as exc:            # argparse: --help (0) or a bad option (2, already printed)
        return exc.code if isinstance(exc.code, int) else 2
    except KeyboardInterrupt as exc:
        if getattr(exc, "keeps_results", False):      # a study: the points finished so far stay written
            print(f"{name}: {exc}", file=sys.stderr)
            return 130
        where = str(exc) if isinstance(exc, interrupt.UserInterrupt) and str(exc) else "interrupted by the user"
        print(f"{name}: {where}; stopped, no results written", file=sys.stderr)
        return 130
    except ClutchocpError as exc:
        print(f"{name}: error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:
        print(f"{name}: error: {exc.strerror or exc}{': ' + str(exc.filename) if exc.filename else ''}",
              file=sys.stderr)
        return 1
    except Exception as exc:  # noqa: BLE001 - a bug: one line unless debugging
        if os.environ.get("CLUTCHOCP_DEBUG"):
            raise
        text = " ".join(str(exc).split())[:300]
        print(f"{name}: internal error ({type(exc).__name__}: {text}); please report it "
              "(CLUTCHOCP_DEBUG=1 shows the traceback)", file=sys.stderr)
        return 1


def run():
    """Console-script entry point: exit with :func:`main`'s code."""
    sys.exit(main())


if __name__ == "__main__":
    run()
