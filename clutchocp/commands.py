"""The commands of ``clutchocp``: each takes the parsed arguments and returns the exit code.

:mod:`clutchocp.cli` parses the command line and runs the function named as the command here
(``clutchocp scenes`` excepted, which needs the scene files alone); it imports this module only
when such a command runs, so that ``--help``, ``scenes`` and a mistyped option answer without
loading the models, the integrators and the optimiser.
"""

import math
import sys
from pathlib import Path

import numpy as np
from tqdm import tqdm

from .analyses import run_validation
from .bench import format_summary as format_bench
from .bench import run_bench
from .engagement.cycles import format_cycles, run_cycles, write_cycles
from .engagement.report import format_summary as format_engagement
from .engagement.report import write_engagement
from .engagement.run import simulate_engagement
from .errors import OptionError
from .optimal.problem import check_weights
from .optimal.report import run_optimize
from .output import output_folder
from .scene import default_scene, load_scene, parse_override
from .study import run_sweep

MAX_SWEEP_POINTS = 50     # engagement-time limits in one sweep (each is a full IPOPT solve)


def parse_time_list(text, option):
    """``"0.2,0.3,0.4"`` or ``"0.2:0.5:7"`` (start:stop:count) -> sorted distinct positive times [s].

    Raises OptionError naming ``option`` for anything else (NaN, zero or negative times, a count
    below 2 or above :data:`MAX_SWEEP_POINTS`, an empty list).
    """
    usage = f"{option} {text}: give positive times in seconds, '0.2,0.3,0.4' or start:stop:count like '0.2:0.5:7'"
    try:
        if ":" in text:
            start, stop, n = text.split(":")
            start, stop, n = float(start), float(stop), int(n)
        else:
            values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise OptionError(usage) from None
    if ":" in text:
        if not 2 <= n <= MAX_SWEEP_POINTS:
            raise OptionError(f"{option} {text}: the count (after the second colon) must be from 2 to "
                              f"{MAX_SWEEP_POINTS}")
        values = np.linspace(start, stop, n)
    if not len(values) or not all(math.isfinite(v) and v > 0 for v in values):
        raise OptionError(usage)
    values = sorted({float(v) for v in values})
    if len(values) > MAX_SWEEP_POINTS:
        raise OptionError(f"{option} {text}: at most {MAX_SWEEP_POINTS} times (each is a full solve)")
    return values


def parse_weights(text, option="--weights"):
    """``"jerk=1,energy=0.1"`` -> {"jerk": 1.0, "energy": 0.1} (names and values checked by the solver)."""
    usage = f"{option} {text!r}: write name=number pairs separated by commas, e.g. jerk=1,energy=0.1"
    weights = {}
    for item in (part.strip() for part in text.split(",")):
        name, eq, value = item.partition("=")
        try:
            number = float(value)
        except ValueError:
            raise OptionError(usage) from None
        if not eq or not name.strip():
            raise OptionError(usage)
        if name.strip() in weights:
            raise OptionError(f"{option} {text!r}: '{name.strip()}' is given twice")
        weights[name.strip()] = number
    if not weights:
        raise OptionError(usage)
    return weights


def validate(args):
    """``clutchocp validate``: the static analyses against the seed papers."""
    run_validation(args.out)
    return 0


def simulate(args):
    """``clutchocp simulate SCENE``: one engagement with IDAS; summary printed, files written."""
    overrides = dict(parse_override(text) for text in args.set)
    scene = load_scene(args.scene, overrides=overrides)
    with output_folder(args.out) as folder:
        run = simulate_engagement(scene, rtol=args.rtol, atol=args.atol, method=args.method, native=args.native)
        print(format_engagement(run.summary))
        files = write_engagement(run, folder.path)
    print(f"wrote {len(files)} files to {args.out}: {', '.join(f.name for f in files)}")
    return 0


def cycles(args):
    """``clutchocp cycles SCENE``: repeated engagements with cooling between, a bar per engagement on stderr."""
    scene = load_scene(args.scene, overrides=dict(parse_override(text) for text in args.set))
    with tqdm(total=args.cycles, desc="engagements", unit="cycle", file=sys.stderr) as bar:
        def step(row):
            bar.update(1)
            bar.set_postfix_str(f"peak {row['peak_interface_temperature_C']:.1f} degC")
        result = run_cycles(scene, cycles=args.cycles, cooling_time=args.cooling_time,
                            max_temperature_C=args.max_temperature, progress=step)
    print(format_cycles(result))
    files = write_cycles(result, args.out)
    print(f"wrote {len(files)} files to {args.out}: {', '.join(f.name for f in files)}")
    return 0


def control(args):
    """``clutchocp control SCENE``: HVD speed controller designed and checked."""
    # imported here: python-control takes 0.4 s to import; control and robust alone need it
    from .hvd.report import run_control

    run_control(args.scene, args.controller, out_dir=args.out)
    return 0


def optimize(args):
    """``clutchocp optimize [SCENE]``: optimal engagement pressure beside the baselines."""
    overrides = dict(parse_override(text) for text in args.set)
    if args.scene is None:
        scene = default_scene().with_overrides(overrides) if overrides else default_scene()
    else:
        scene = load_scene(args.scene, overrides=overrides)
    weights = parse_weights(args.weights) if args.weights is not None else None
    if weights is not None:
        check_weights(weights)             # before any solving
    sweep = parse_time_list(args.sweep_t_max, "--sweep-t-max") if args.sweep_t_max is not None else None
    run_optimize(scene, out_dir=args.out, t_max=args.t_max, weights=weights,
                 intervals=args.intervals, degree=args.degree, sweep_t_max=sweep,
                 max_temperature_C=args.max_temperature, max_specific_power_W_mm2=args.max_specific_power,
                 clamp_margin=args.clamp_margin)
    return 0


def robust(args):
    """``clutchocp robust [SCENE]``: Monte Carlo of the shift-control strategies."""
    # imported here: python-control takes 0.4 s to import (see control)
    from .shiftcontrol.report import run_robust

    run_robust(args.scene, out_dir=args.out, samples=args.samples, seed=args.seed, uncertain=args.uncertain,
               t_max=args.t_max, controller=args.controller, workers=args.workers, intervals=args.intervals,
               **({"strategies": args.strategies} if args.strategies else {}))
    return 0


def bench(args):
    """``clutchocp bench``: work-precision, stiffness, scaling and optimisation convergence."""
    summary = run_bench(args.out, quick=args.quick, progress=True)
    print(format_bench(summary))
    return 0


def sweep(args):
    """``clutchocp sweep SCENE``: a grid or Monte Carlo study on local processes or Dask."""
    if args.scheduler and args.engine not in (None, "dask"):
        raise OptionError(f"--scheduler {args.scheduler}: needs --engine dask (or no --engine)")
    engine = args.engine or ("dask" if args.scheduler else "local")
    options = {}
    if args.task == "simulate":
        options.update(native={"auto": "auto", "on": True, "off": False}[args.native],
                       output_points=args.output_points, reuse_model=not args.model_per_point)
    else:
        options.update(intervals=args.intervals, degree=args.degree, t_max=args.t_max,
                       weights=parse_weights(args.weights) if args.weights is not None else None,
                       warm_start=not args.cold, verify=not args.no_verify, reuse_problem=not args.model_per_point)
    summary = run_sweep(args.scene, args.out, task=args.task, grid=args.grid, samples=args.samples,
                        seed=args.seed, uncertain=args.uncertain,
                        overrides=dict(parse_override(text) for text in args.set), options=options,
                        engine=engine, workers=args.workers, scheduler=args.scheduler, progress=True)
    rate = summary["points_per_second"]
    print(f"{summary['scene']} {summary['task']} sweep: {summary['points']} points, {summary['points_ok']} ok, "
          f"{summary['points_failed']} failed, {summary['points_resumed']} resumed; "
          f"{summary['wall_time_s']:.1f} s" + (f" ({rate:.2f} points/s)" if rate else ""))
    print(f"wrote {args.out}: " + ", ".join(Path(f).name for f in summary["files"]) + ", results.csv")
    return 0
