"""Every number the documentation quotes, measured by running the tool, and written into the docs.

Run from the repository root (the items run two at a time; 10 minutes of CPU in all, so about
6-10 minutes on two idle cores; 35 minutes measured with the machine's load average at 8-10)::

    python benchmarks/docs_numbers.py                  # measure every item, update the JSON, rewrite the docs
    python benchmarks/docs_numbers.py --only optimize_default,readme_example
    python benchmarks/docs_numbers.py --skip bench,robust
    python benchmarks/docs_numbers.py --render         # no measuring: rewrite the docs from the committed JSON
    python benchmarks/docs_numbers.py --check          # exit 1 if a doc differs from what --render would write

What it writes:

- ``benchmarks/docs_numbers.json``: the measured values of each item (``ITEMS``), with the date and
  the command that measured them; an item not run keeps its previous values;
- every block ``<!-- generated: NAME -->`` ... ``<!-- end generated -->`` in README.md and
  docs/**/*.md, rendered by ``RENDERERS[NAME]`` from that JSON;
- ``docs/scene-keys.md``, generated from :mod:`clutchocp.scene.schema` (every part and key with its
  unit, allowed range, default and meaning).

The tests (``pytest -k "docs or readme"``) check that every generated block equals what this script
renders from the committed JSON, that the cheap numbers re-computed live agree with it, and that
every summary.json key and CSV column the commands wrote here (``keys`` of each item) is documented
on the command's page. After a change that moves results, run this script and commit the JSON and
the docs together.

Adding a number to a page: write an item (a function of a scratch folder that runs the command or
script and returns the values, JSON-ready; add it to ``ITEMS``, ``ORDER`` and, if it writes a
command's folder, its ``keys`` to ``KEYS_OF``), a renderer of those values (add it to
``RENDERERS``), and put ``<!-- generated: NAME -->`` / ``<!-- end generated -->`` where the page
shows it. A benchmark that writes its own JSON (e.g. ``--json FILE``) becomes an item that runs it
and reads that file. Run the item with ``--only NAME``.
"""

import argparse
import csv
import datetime
import hashlib
import heapq
import itertools
import json
import os
import re
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
JSON_PATH = ROOT / "benchmarks" / "docs_numbers.json"
SCENE_KEYS = ROOT / "docs" / "scene-keys.md"
BLOCK = re.compile(r"(<!-- generated: ([\w-]+) -->\n)(.*?)(<!-- end generated -->)", re.S)
EXAMPLE = re.compile(r"<!-- example: ([\w-]+) -->\n```python\n(.*?)```", re.S)
COMMAND_PAGES = ROOT / "docs" / "commands"


# -- running the tool -----------------------------------------------------------------------------
COMMAND_TIMEOUT_S = 3 * 3600          # one command; the slowest (robust, 200 samples) takes ~10-35 min


class Slots:
    """At most ``n`` commands at once; a free slot goes to the waiting request of the highest priority
    (lowest number), then the earliest. An item waits for a slot per command, never while holding one."""

    def __init__(self, n):
        self.free = n
        self.waiting = []
        self.tickets = itertools.count()
        self.cond = threading.Condition()

    def acquire(self, priority):
        with self.cond:
            ticket = (priority, next(self.tickets))
            heapq.heappush(self.waiting, ticket)
            while not (self.free and self.waiting[0] == ticket):
                self.cond.wait()
            heapq.heappop(self.waiting)
            self.free -= 1
            self.cond.notify_all()

    def release(self):
        with self.cond:
            self.free += 1
            self.cond.notify_all()


@dataclass
class Run:
    """One finished command: its folder (``--out``), what it printed and how long it took [s]."""

    folder: Path
    stdout: str
    stderr: str
    returncode: int
    seconds: float


class Runner:
    """One measuring session: a scratch folder, the command slots, and every command run so far.

    Each command runs once per session in a fresh interpreter on the checkout's own package, into a
    folder of its own (``NNN_<label>`` under the scratch folder); an item asking for a command another
    item has run (or is running) gets that run (e.g. ``clutchocp simulate zhang2021`` serves the scene
    table and the physics page, ``clutchocp optimize`` the README and the scene table).
    """

    def __init__(self, root, jobs):
        self.root = Path(root)
        self.slots = Slots(jobs)
        self.lock = threading.Lock()
        self.count = itertools.count(1)
        self.runs = {}                   # command -> (threading.Event, [Run or exception])
        self.env = {**os.environ, "MPLBACKEND": "Agg",
                    "PYTHONPATH": os.pathsep.join([str(ROOT), *filter(None, [os.environ.get("PYTHONPATH")])])}

    def folder(self, label):
        """A new folder name under the scratch folder, unique in the session (not created)."""
        with self.lock:
            number = next(self.count)
        return self.root / f"{number:03d}_{re.sub(r'[^A-Za-z0-9_.=-]+', '_', label)[:80]}"

    def _execute(self, argv, folder, cwd, timeout, priority):
        self.slots.acquire(priority)
        try:
            start = time.perf_counter()
            proc = subprocess.run(argv, capture_output=True, text=True, cwd=cwd, env=self.env, timeout=timeout)
            seconds = time.perf_counter() - start
        finally:
            self.slots.release()
        return Run(folder, proc.stdout, proc.stderr, proc.returncode, seconds)

    def clutchocp(self, *args, priority=0, check=True, timeout=COMMAND_TIMEOUT_S):
        """``clutchocp ARGS --out FOLDER``, run once per session; returns its :class:`Run`.

        With ``check`` a non-zero exit raises (with the end of stderr); without, the failed run is returned."""
        with self.lock:
            entry = self.runs.get(args)
            owner = entry is None
            if owner:
                entry = self.runs[args] = (threading.Event(), [])
        done, box = entry
        if owner:
            try:
                folder = self.folder("_".join(args))
                folder.parent.mkdir(parents=True, exist_ok=True)
                box.append(self._execute([sys.executable, "-m", "clutchocp.cli", *args, "--out", str(folder)],
                                         folder, self.root, timeout, priority))
            except BaseException as exc:      # noqa: BLE001 - handed to every item that waits for this run
                box.append(exc)
                raise
            finally:
                done.set()
        done.wait()
        result = box[0]
        if isinstance(result, BaseException):
            raise RuntimeError(f"clutchocp {' '.join(args)} failed: {result}")
        if check and result.returncode != 0:
            raise RuntimeError(f"clutchocp {' '.join(args)} exited {result.returncode}: "
                               f"{result.stderr.strip()[-2000:]}")
        return result

    def python(self, code, label, priority=0, timeout=COMMAND_TIMEOUT_S):
        """``python -c CODE`` in a folder of its own (its working directory); returns its :class:`Run`."""
        folder = self.folder(label)
        folder.mkdir(parents=True)
        run = self._execute([sys.executable, "-c", code], folder, folder, timeout, priority)
        if run.returncode != 0:
            raise RuntimeError(f"{label} exited {run.returncode}: {run.stderr.strip()[-2000:]}")
        return run


def flat_keys(value, path=()):
    """The key paths of a JSON value as lists of segments; a list adds ``[]`` to its key, an empty
    list or dict ends in ``*`` (anything may stand below it)."""
    if isinstance(value, dict):
        if not value and path:
            yield [*path, "*"]
        for key, item in value.items():
            yield from flat_keys(item, (*path, key))
    elif isinstance(value, list):
        listed = (*path[:-1], f"{path[-1]}[]") if path else ("[]",)
        if not value:
            yield [*listed, "*"]
        for item in value:
            yield from flat_keys(item, listed)
    else:
        yield list(path)


def folder_keys(folder):
    """What a command wrote into ``folder``: summary.json key paths, CSV headers, file names."""
    folder = Path(folder)
    out = {"summary": [], "csv": {}, "files": sorted(p.name for p in folder.iterdir() if not p.name.startswith("."))}
    summary = folder / "summary.json"
    if summary.is_file():
        seen = set()
        for key in flat_keys(json.loads(summary.read_text())):
            if tuple(key) not in seen:
                seen.add(tuple(key))
                out["summary"].append(key)
    for table in sorted(folder.glob("*.csv")):
        with table.open(newline="", encoding="utf-8") as handle:
            out["csv"][table.name] = next(csv.reader(handle), [])
    return out


def merge_keys(*found):
    """Union of several :func:`folder_keys` results (keys in first-seen order)."""
    out = {"summary": [], "csv": {}, "files": []}
    seen = set()
    for item in found:
        for key in item["summary"]:
            if tuple(key) not in seen:
                seen.add(tuple(key))
                out["summary"].append(key)
        for name, columns in item["csv"].items():
            have = out["csv"].setdefault(name, [])
            have += [c for c in columns if c not in have]
        out["files"] = sorted(set(out["files"]) | set(item["files"]))
    return out


def summary_of(folder):
    return json.loads((Path(folder) / "summary.json").read_text())


def pick(mapping, *names):
    return {name: mapping.get(name) for name in names}


# -- the items: each measures what some docs quote -------------------------------------------------
class Item:
    """What one item measures with: the session's :class:`Runner` at the item's priority, and the
    commands it used (their seconds, a run shared with another item counted for both)."""

    def __init__(self, runner, name, priority):
        self.runner, self.name, self.priority = runner, name, priority
        self.seconds = []
        self.lock = threading.Lock()

    def _count(self, run):
        with self.lock:
            self.seconds.append(run.seconds)
        return run

    def clutchocp(self, *args, check=True):
        """``clutchocp ARGS --out FOLDER`` (once per session, see :meth:`Runner.clutchocp`)."""
        return self._count(self.runner.clutchocp(*args, priority=self.priority, check=check))

    def many(self, commands, check=True):
        """Several ``clutchocp`` commands at once (as slots free up); their runs in the order given."""
        box = [None] * len(commands)

        def one(k):
            try:
                box[k] = self.clutchocp(*commands[k], check=check)
            except Exception as exc:      # noqa: BLE001 - raised below, in the item's thread
                box[k] = exc
        threads = [threading.Thread(target=one, args=(k,), daemon=True) for k in range(len(commands))]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
        for result in box:
            if isinstance(result, Exception):
                raise result
        return box

    def python(self, code, label):
        """``python -c CODE`` in a folder of its own; returns its :class:`Run`."""
        return self._count(self.runner.python(code, label, priority=self.priority))


MEASURES = ("engagement_time_s", "lockup_torque_jump_Nm", "jerk_integral", "peak_jerk_rad_s3", "peak_torque_Nm",
            "dissipated_energy_J")


def default_scene():
    """The name of the default engagement scene (``clutchocp optimize`` without a scene)."""
    sys.path.insert(0, str(ROOT))
    from clutchocp.scene import list_scenes

    return next(s.name for s in list_scenes() if s.value("scene.default"))


def engagement_scenes():
    sys.path.insert(0, str(ROOT))
    from clutchocp.scene import list_scenes

    return [s.name for s in list_scenes() if s.kind == "engagement"]


def optimize_command(name):
    """The command that optimises scene ``name``: plain ``optimize`` for the default scene, so that the
    README's command and the scene table share one run."""
    return ("optimize",) if name == default_scene() else ("optimize", name)


def optimize_default(item):
    """``clutchocp optimize --out DIR``: the first command of the README, on the default scene."""
    run = item.clutchocp("optimize")
    stdout, s = run.stdout, summary_of(run.folder)
    table = stdout[stdout.index(f"scene {s['scene']}: optimal"):].rstrip() if "optimal engagement" in stdout \
        else stdout.rstrip()
    return {
        "command": "clutchocp optimize --out out/optimize",
        "scene": s["scene"],
        "optimal": pick(s["optimal"], *MEASURES),
        "baseline": {**pick(s["baseline"], *MEASURES), "profile": s["baseline"]["profile"]},
        "verification": {**pick(s["verification"], "passed", "lock_time_rel_diff", "torque_jump_Nm", "torque_jump_rel"),
                         "idas_lock_time_s": s["verification"]["idas"]["engagement_time_s"]},
        "solver": pick(s["solver"], "status", "iterations", "wall_time_s", "n_variables", "intervals"),
        "clamp": pick(s["clamp"], "clamp_pressure_Pa", "locked_torque_Nm", "ramp_start_s", "ramp_end_s",
                      "capacity_margin_at_end", "lock_held"),
        "jerk_lower_bound_ratio": s["jerk_lower_bound_ratio"],
        "peak_interface_temperature_C": (s.get("heat") or {}).get("idas", {}).get("peak_interface_temperature_C"),
        "t_max_s": s["limits"]["t_max_s"],
        "printed": table,
        "keys": folder_keys(run.folder),
    }


WEIGHT_VARIANTS = ("jerk=1,energy=10", "jerk=0,time=1", "jerk=1,energy=0.1")


def optimize_weights(item):
    """``clutchocp optimize --weights ...`` on the default scene: what each objective weight trades."""
    runs = item.many([("optimize", "--weights", weights) for weights in WEIGHT_VARIANTS])
    rows = {}
    for weights, run in zip(WEIGHT_VARIANTS, runs):
        s = summary_of(run.folder)
        rows[weights] = {**pick(s["optimal"], *MEASURES), "passed": s["verification"]["passed"]}
    return {"command": "clutchocp optimize --weights W --out DIR", "rows": rows}


SIMULATE_NUMBERS = ("engagement_time_s", "lockup_torque_jump_Nm", "peak_torque_Nm", "peak_jerk_rad_s3",
                    "dissipated_energy_J", "energy_balance_rel_error", "torque_response_time_stable_s",
                    "stable_torque_Nm", "torque_response_time_s", "pressure_response_time_s", "specific_energy_J_mm2",
                    "peak_specific_power_W_mm2", "peak_interface_temperature_C", "wall_time_s")


def simulate_scenes(item):
    """``clutchocp simulate SCENE`` for every built-in engagement scene."""
    names = engagement_scenes()
    runs = item.many([("simulate", name) for name in names])
    rows = {name: pick(summary_of(run.folder), *SIMULATE_NUMBERS) for name, run in zip(names, runs)}
    return {"command": "clutchocp simulate SCENE --out DIR", "rows": rows,
            "keys": merge_keys(*(folder_keys(run.folder) for run in runs))}


CYCLE_RUNS = (("default_driveline_thermal", 0.5), ("default_driveline_thermal", 5.0), ("default_driveline", 0.5))


def cycles(item):
    """``clutchocp cycles SCENE --cycles 10 --cooling-time S --max-temperature 110``."""
    runs = item.many([("cycles", name, "--cycles", "10", "--cooling-time", f"{cooling:g}", "--max-temperature", "110")
                      for name, cooling in CYCLE_RUNS])
    out = []
    for (name, cooling), run in zip(CYCLE_RUNS, runs):
        s = summary_of(run.folder)
        out.append({"scene": name, "cooling_time_s": cooling, "stop_reason": s["stop_reason"],
                    "drift_s": s["engagement_time_drift_s"],
                    "cycles": [pick(c, "cycle", "start_interface_temperature_C", "peak_interface_temperature_C",
                                    "engagement_time_s") for c in s["cycles"]]})
    return {"command": "clutchocp cycles SCENE --cycles 10 --cooling-time S --max-temperature 110 --out DIR",
            "runs": out, "keys": merge_keys(*(folder_keys(run.folder) for run in runs))}


def validate(item):
    """``clutchocp validate``: the static analyses against the seed papers."""
    run = item.clutchocp("validate")
    return {"command": "clutchocp validate --out DIR", "summary": summary_of(run.folder),
            "keys": folder_keys(run.folder)}


CONTROL_RUNS = (("liao2021_hvd", "lqi"), ("cui2019_hvd", "pi"))


def control(item):
    """``clutchocp control SCENE --controller SPEC`` on both hydro-viscous drive scenes."""
    runs = item.many([("control", name, "--controller", spec) for name, spec in CONTROL_RUNS])
    rows = {}
    for (name, spec), run in zip(CONTROL_RUNS, runs):
        s = summary_of(run.folder)
        rows[f"{name} {spec}"] = {**pick(s["margins"], "gain_margin_dB", "phase_margin_deg", "all_points_stable"),
                                  **pick(s["closed_loop"], "overshoot_pct", "settling_time_s", "steady_state_error_rel",
                                         "time_in_saturation_s")}
    return {"command": "clutchocp control SCENE --controller SPEC --out DIR", "rows": rows,
            "keys": merge_keys(*(folder_keys(run.folder) for run in runs))}


SWEEPS = (
    ("simulate grid", ("zhang2021", "--grid", "actuation.pressure=0.3 MPa:0.6 MPa:3", "--grid",
                       "oil.viscosity=0.05:0.08:3")),
    ("simulate samples", ("default_driveline", "--samples", "12", "--seed", "1")),
    ("optimize grid", ("default_driveline", "--task", "optimize", "--grid", "load.torque=90:130:2", "--grid",
                       "oil.viscosity=0.06:0.08:2", "--intervals", "20")),
)


def sweep(item):
    """``clutchocp sweep``: a simulate grid, Monte Carlo samples and an optimize grid (what they write);
    one worker each, as the slots run the commands side by side."""
    runs = item.many([("sweep", *args, "--workers", "1") for _, args in SWEEPS])
    rows = {}
    for (label, args), run in zip(SWEEPS, runs):
        rows[label] = {"command": "clutchocp sweep " + " ".join(f"'{a}'" if " " in a else a for a in args),
                       **pick(summary_of(run.folder), "points", "points_ok", "points_failed")}
    return {"rows": rows, "keys": merge_keys(*(folder_keys(run.folder) for run in runs))}


def optimize_scenes(item):
    """``clutchocp optimize SCENE`` for every engagement scene: solve, IDAS check, time."""
    names = engagement_scenes()
    runs = item.many([optimize_command(name) for name in names])
    rows = {}
    for name, run in zip(names, runs):
        s = summary_of(run.folder)
        solves = s.get("mesh", {}).get("solves", [])
        rows[name] = {
            "phases": " + ".join(p["name"] for p in s["phases"]),
            "n_variables": s["solver"]["n_variables"],
            "stages": ", ".join(x["stage"] for x in solves),
            "iterations": sum(x["iterations"] or 0 for x in solves) or s["solver"]["iterations"],
            "ipopt_s": sum(x["wall_time_s"] or 0.0 for x in solves) or s["solver"]["wall_time_s"],
            "command_s": run.seconds,
            "t_f_s": s["optimal"]["engagement_time_s"],
            "lock_time_rel_diff": s["verification"]["lock_time_rel_diff"],
            "torque_jump_rel": s["verification"]["torque_jump_rel"],
            "passed": s["verification"]["passed"],
            "min_film_pressure_Pa": (s["verification"].get("idas") or {}).get("min_film_pressure_Pa"),
            "fill_comparison": {k: pick(v, "engagement_time_s", "peak_jerk_rad_s3", "lockup_torque_jump_Nm",
                                        "kiss_speed_m_s", "dissipated_energy_J")
                                for k, v in s["fill_comparison"].items() if k in ("optimal", "baseline")}
            if "fill_comparison" in s else None,
        }
    return {"command": "clutchocp optimize SCENE --out DIR", "rows": rows,
            "keys": merge_keys(*(folder_keys(run.folder) for run in runs))}


def robust(item):
    """``clutchocp robust --samples 200 --seed 0``: the four shift-control strategies over the default box."""
    run = item.clutchocp("robust", "--samples", "200", "--seed", "0", "--workers", "1")
    s = summary_of(run.folder)
    stats = {name: {**pick(v, "lock_share", "lock_within_t_max_share"),
                    "jump_pct": v.get("jump_pct"), "jerk_integral_median": (v.get("jerk_integral") or {}).get("median")}
             for name, v in s["statistics"].items()}
    return {"command": "clutchocp robust --samples 200 --seed 0 --out DIR", "t_max_s": s["t_max_s"],
            "strategies": s["strategies"], "statistics": stats,
            "acceptance": {k: v.get("passed") for k, v in s["acceptance"].items()},
            "samples_per_s": s["timing"]["samples_per_s"], "keys": folder_keys(run.folder)}


TCU_UNCERTAIN = ("actuation.time_constant=uniform 20 %", "driveline.input_torque=uniform 5 %")


def tcu_acceptance(item, samples=100):
    """The TCU loop's acceptance run: ``slip_lqr_tcu`` closed loop, 100 draws of the box plus the valve lag
    and the engine torque the TCU is not told."""
    args = ["robust", "--controller", "slip_lqr_tcu", "--strategies", "closed_loop", "--samples", str(samples),
            "--seed", "11", "--workers", "2"]
    for field in TCU_UNCERTAIN:
        args += ["--uncertain", field]
    run = item.clutchocp(*args)
    s = summary_of(run.folder)
    written = sorted(p.name for p in run.folder.iterdir() if p.suffix in (".c", ".h", ".csv", ".json"))
    return {"command": "clutchocp " + " ".join(f'"{a}"' if " " in a else a for a in args) + " --out DIR",
            "t_max_s": s["t_max_s"], "acceptance": s["acceptance"]["closed_loop"],
            "statistics": s["statistics"]["closed_loop"], "timing": s["timing"], "written": written}


def tcu_thousand(item):
    """The acceptance run's command on 1000 draws: the closed loop's throughput and its statistics."""
    return tcu_acceptance(item, samples=1000)


def tcu_heldout(item):
    """``benchmarks/bench_tcu_heldout.py``: the old loop and the TCU loop on conditions they were not designed for."""
    code = ("import runpy, sys; sys.argv = ['bench_tcu_heldout.py', '--samples', '20', '--seed', '5', "
            f"'--workers', '2', '--out', '.']; runpy.run_path({str(ROOT / 'benchmarks' / 'bench_tcu_heldout.py')!r}, "
            "run_name='__main__')")
    run = item.python(code, "tcu_heldout")
    data = json.loads((run.folder / "heldout.json").read_text())
    return {"command": "python benchmarks/bench_tcu_heldout.py --samples 20 --seed 5 --workers 2",
            "conditions": list(data["results"]), **data}


REFUSALS = (("optimize", "models/catalogue/infeasible_dct_overload_launch.toml"),
            ("optimize", "default_driveline_thermal", "--max-temperature", "45"),
            ("optimize", "--set", "plates.r_inner=75 mm", "--set", "plates.r_outer=98 mm", "--set",
             "plates.n_interfaces=6", "--t-max", "0.05"))


def optimize_refusals(item):
    """Three clutches ``clutchocp optimize`` refuses before solving, and the line each prints."""
    rows = []
    for args in REFUSALS:
        run = item.clutchocp(*(str(ROOT / a) if a.startswith("models/") else a for a in args), check=False)
        line = next((x for x in run.stderr.splitlines() if x.startswith("clutchocp optimize: error:")), None)
        if run.returncode != 2 or line is None:
            raise RuntimeError(f"clutchocp {' '.join(args)}: expected a one-line refusal (exit 2), got exit "
                               f"{run.returncode}: {run.stderr.strip()[-500:]}")
        rows.append({"command": "clutchocp " + " ".join(f'"{a}"' if " " in a else a for a in args), "printed": line})
    return {"rows": rows}


def first_call_stop(item):
    """``benchmarks/bench_first_call_stop.py``: what a first call that stopped at its event would save,
    and CasADi's own event stop."""
    code = ("import runpy, sys; sys.argv = ['bench_first_call_stop.py', '--out', '.']; "
            f"runpy.run_path({str(ROOT / 'benchmarks' / 'bench_first_call_stop.py')!r}, run_name='__main__')")
    run = item.python(code, "first_call_stop")
    data = json.loads((run.folder / "bench_first_call_stop.json").read_text())
    return {"command": "PYTHONPATH=. python benchmarks/bench_first_call_stop.py", **data}


def bench(item):
    """``clutchocp bench --quick``: IDAS against scipy's integrators at matched error."""
    run = item.clutchocp("bench", "--quick")
    return {"command": "clutchocp bench --quick --out DIR", "summary": summary_of(run.folder),
            "keys": folder_keys(run.folder)}


def readme_example(item):
    """The Python example of the README, run as a user would, and what it prints."""
    code = examples()["readme"]
    run = item.python(code, "readme_example")
    return {"code_sha256": code_hash(code), "stdout": run.stdout}


# The physics page: its closed forms (docs/scripts/physics_numbers.py) and the runs it quotes.
PHYSICS_SCRIPT = ROOT / "docs" / "scripts" / "physics_numbers.py"
THERMAL_CELLS = (1, 2, 3, 4, 6, 20)
PHYSICS_NUMBERS = ("engagement_time_s", "peak_torque_Nm", "specific_energy_J_mm2", "peak_specific_power_W_mm2",
                   "energy_balance_rel_error", "min_film_pressure_Pa", "peak_interface_temperature_C",
                   "peak_friction_plate_temperature_C", "peak_core_temperature_C")
# `clutchocp simulate default_driveline --set ...`: what the plausibility and capacity checks answer
EDGE_EXAMPLES = ("plates.r_outer=85", "oil.viscosity=40", "roughness.sigma_1=8", "driveline.input_speed=1e6",
                 "actuation.pressure=8", "driveline.output_inertia=1e6")
CAPACITY_EXAMPLE = "roughness.sigma_1=6 um"


def physics_runs():
    """{label: clutchocp arguments} of the simulations docs/physics.md quotes."""
    sys.path.insert(0, str(ROOT))
    from clutchocp.scene import load_scene

    zhang = load_scene("zhang2021")
    half = (zhang.value("roughness.sigma_1") ** 2 + zhang.value("roughness.sigma_2") ** 2) ** 0.5 / 2 ** 0.5
    runs = {"zhang2021": ("simulate", "zhang2021"),
            "zhang2021_equal_split": ("simulate", "zhang2021", "--set", f"roughness.sigma_1={half!r}",
                                      "--set", f"roughness.sigma_2={half!r}"),
            "zhang2021_1000rpm": ("simulate", "zhang2021", "--set", "driveline.input_speed=1000 rpm"),
            "default_driveline": ("simulate", "default_driveline"),
            "bao2020": ("simulate", "bao2020")}
    for cells in THERMAL_CELLS:        # the scene's own cell count is the plain run (shared with the scene table)
        own = load_scene("default_driveline_thermal").value("thermal.lining_cells") == cells
        runs[f"thermal_cells_{cells}"] = ("simulate", "default_driveline_thermal") if own else \
            ("simulate", "default_driveline_thermal", "--set", f"thermal.lining_cells={cells}")
    return runs


def last_row(folder, column):
    """The last value of ``column`` in a run's timeseries.csv."""
    with (Path(folder) / "timeseries.csv").open(newline="", encoding="utf-8") as handle:
        rows = list(csv.DictReader(handle))
    return float(rows[-1][column])


def physics(item):
    """docs/physics.md: the closed forms of ``docs/scripts/physics_numbers.py``, the simulations it quotes
    and what the plausibility and contact-capacity checks print."""
    labels, commands = zip(*physics_runs().items())
    checks = (*EDGE_EXAMPLES, CAPACITY_EXAMPLE)
    runs = item.many([*commands, *(("simulate", "default_driveline", "--set", s) for s in checks)], check=False)
    sims, answers = dict(zip(labels, runs[:len(labels)])), dict(zip(checks, runs[len(labels):]))
    for label, run in sims.items():
        if run.returncode != 0:
            raise RuntimeError(f"physics: {label} exited {run.returncode}: {run.stderr.strip()[-2000:]}")
    gaps = {name: last_row(sims[name].folder, "h_1_m") for name in ("zhang2021", "default_driveline")}
    code = (f"import json, runpy; m = runpy.run_path({str(PHYSICS_SCRIPT)!r}); "
            f"print(json.dumps({{'formulas': m['formulas'](), 'settled_contact': "
            f"{{n: m['contact_data'](n, g) for n, g in {gaps!r}.items()}}}}))")
    closed = json.loads(item.python(code, "physics_formulas").stdout)
    message = {s: next((line.split(": ", 1)[1] for line in run.stderr.splitlines()
                        if line.startswith("clutchocp simulate: ")), run.stderr.strip()[-300:])
               for s, run in answers.items()}
    return {"command": "clutchocp simulate SCENE [--set ...] --out DIR; docs/scripts/physics_numbers.py",
            **closed, "runs": {label: pick(summary_of(run.folder), *PHYSICS_NUMBERS) for label, run in sims.items()},
            "settled_gap_m": gaps,
            "checks": {s: {"exit": answers[s].returncode, "message": message[s]} for s in checks}}


ITEMS = {
    "optimize_default": optimize_default,
    "readme_example": readme_example,
    "optimize_weights": optimize_weights,
    "simulate_scenes": simulate_scenes,
    "physics": physics,
    "cycles": cycles,
    "validate": validate,
    "control": control,
    "sweep": sweep,
    "optimize_scenes": optimize_scenes,
    "robust": robust,
    "optimize_refusals": optimize_refusals,
    "tcu_acceptance": tcu_acceptance,
    "tcu_heldout": tcu_heldout,
    "tcu_thousand": tcu_thousand,
    "bench": bench,
    "first_call_stop": first_call_stop,
}
# Priority of an item's commands when two wait for a slot: the longest first, so that the two slots
# finish together (robust ~35 %, bench and optimize_scenes ~25 % each of the commands' time).
ORDER = ("tcu_thousand", "robust", "optimize_scenes", "bench", "tcu_heldout", "tcu_acceptance", "optimize_refusals", "optimize_weights", "sweep", "control", "optimize_default",
         "simulate_scenes", "physics", "cycles", "readme_example", "first_call_stop", "validate")
KEYS_OF = {"optimize": ("optimize_default", "optimize_scenes"), "simulate": ("simulate_scenes",),
           "cycles": ("cycles",), "validate": ("validate",), "control": ("control",), "sweep": ("sweep",),
           "robust": ("robust", "tcu_acceptance", "tcu_thousand"), "bench": ("bench",)}


# -- examples in the docs --------------------------------------------------------------------------
def doc_files():
    """README.md and every Markdown page under docs/."""
    return [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]


def examples():
    """The named examples: ``<!-- example: NAME -->`` followed by a python block, in any doc."""
    found = {}
    for path in doc_files():
        for name, code in EXAMPLE.findall(path.read_text(encoding="utf-8")):
            found[name] = code
    return found


def code_hash(code):
    return hashlib.sha256(code.encode()).hexdigest()[:16]


# -- rendering -------------------------------------------------------------------------------------
def fmt(value, digits=4, unit=""):
    """A number as the docs write it: 4 significant digits, '-' for none."""
    if value is None:
        return "-"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int):
        return f"{value}{' ' + unit if unit else ''}"
    text = f"{value:.{digits}g}"
    if "e" in text:
        mantissa, exponent = text.split("e")
        text = f"{mantissa}e{int(exponent)}"
    return f"{text}{' ' + unit if unit else ''}"


def pct(value, digits=3):
    return "-" if value is None else f"{100 * value:.{digits}g} %"


def table(header, rows):
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines) + "\n"


def measured(numbers, item):
    entry = numbers.get(item) or {}
    return f"measured {entry.get('measured', 'never')}"


def r_optimize_default_table(n):
    d = n["optimize_default"]
    o, b = d["optimal"], d["baseline"]
    rows = [("engagement (lock-up) time [s]", fmt(o["engagement_time_s"]), fmt(b["engagement_time_s"])),
            ("lock-up torque jump [N m]", fmt(o["lockup_torque_jump_Nm"], 3), fmt(b["lockup_torque_jump_Nm"])),
            ("int jerk^2 dt [rad^2/s^5]", fmt(o["jerk_integral"]), fmt(b["jerk_integral"])),
            ("peak jerk [rad/s^3]", fmt(o["peak_jerk_rad_s3"]), fmt(b["peak_jerk_rad_s3"])),
            ("dissipated energy [J]", fmt(o["dissipated_energy_J"]), fmt(b["dissipated_energy_J"]))]
    v = d["verification"]
    return (table(("`clutchocp optimize`, default scene", "optimal", f"baseline ({b['profile']})"), rows)
            + f"\nIDAS replay of the optimum: lock-up {fmt(v['idas_lock_time_s'])} s "
              f"({fmt(v['lock_time_rel_diff'], 2)} from the collocation), jump {fmt(v['torque_jump_Nm'], 3)} N m: "
              f"check {'passed' if v['passed'] else 'failed'}. IPOPT: {d['solver']['iterations']} iterations "
              f"({d['solver']['n_variables']} variables). After lock-up the command ramps to the clamp pressure "
              f"{fmt(d['clamp']['clamp_pressure_Pa'] / 1e6)} MPa by {fmt(d['clamp']['ramp_end_s'])} s. "
              f"({measured(n, 'optimize_default')} with `{d['command']}`.)\n")


def r_optimize_default_printed(n):
    d = n["optimize_default"]
    return f"```text\n$ {d['command']}\n...\n{d['printed']}\n```\n({measured(n, 'optimize_default')}.)\n"


def r_readme_example_output(n):
    return f"```text\n{n['readme_example']['stdout'].rstrip()}\n```\n"


def r_optimize_weights(n):
    d, base = n["optimize_weights"], n["optimize_default"]["optimal"]
    rows = [("`jerk=1` (default)", fmt(base["engagement_time_s"]), fmt(base["dissipated_energy_J"]),
             fmt(base["jerk_integral"]), fmt(base["peak_jerk_rad_s3"]), "yes")]
    for weights, r in d["rows"].items():
        rows.append((f"`{weights}`", fmt(r["engagement_time_s"]), fmt(r["dissipated_energy_J"]),
                     fmt(r["jerk_integral"]), fmt(r["peak_jerk_rad_s3"]), fmt(r["passed"])))
    return (table(("`--weights`", "lock-up [s]", "dissipated energy [J]", "int jerk^2 dt [rad^2/s^5]",
                   "peak jerk [rad/s^3]", "IDAS check passed"), rows)
            + f"\n(Default scene, 100 intervals, t_max = the baseline's lock-up; {measured(n, 'optimize_weights')}.)\n")


def r_simulate_scenes(n):
    d = n["simulate_scenes"]
    rows = [(f"`{name}`", fmt(r["engagement_time_s"]), fmt(r["lockup_torque_jump_Nm"]), fmt(r["peak_torque_Nm"]),
             fmt(r["dissipated_energy_J"]), fmt(r["energy_balance_rel_error"], 2),
             fmt(None if r["torque_response_time_stable_s"] is None else 1e3 * r["torque_response_time_stable_s"], 3),
             fmt(r["wall_time_s"], 2))
            for name, r in d["rows"].items()]
    return (table(("scene", "lock-up [s]", "lock-up jump [N m]", "peak torque [N m]", "dissipated [J]",
                   "energy balance error", "Zhang torque response [ms]", "wall time [s]"), rows)
            + f"\n(`{d['command']}`; {measured(n, 'simulate_scenes')}; wall times on a shared machine.)\n")


def r_simulate_thermal(n):
    d = n["simulate_scenes"]["rows"]
    rows = [(f"`{name}`", fmt(r["engagement_time_s"]), fmt(r["specific_energy_J_mm2"], 3),
             fmt(r["peak_specific_power_W_mm2"], 3), fmt(r["peak_interface_temperature_C"], 3))
            for name, r in d.items() if name.startswith("default_driveline")]
    return (table(("scene", "lock-up [s]", "specific energy [J/mm^2]", "peak specific power [W/mm^2]",
                   "peak interface temperature [degC]"), rows) + f"\n({measured(n, 'simulate_scenes')}.)\n")


def r_cycles(n):
    d = n["cycles"]
    rows = []
    for run in d["runs"]:
        c = run["cycles"]
        rows.append((f"`{run['scene']}`, {run['cooling_time_s']:g} s", f"{len(c)} ({run['stop_reason']})",
                     " / ".join(fmt(x["start_interface_temperature_C"], 3) for x in c),
                     " / ".join(fmt(x["peak_interface_temperature_C"], 4) for x in c),
                     " / ".join(fmt(x["engagement_time_s"]) for x in c),
                     fmt(run["drift_s"], 3)))
    return (table(("scene, `--cooling-time`", "cycles (stopped by)", "start [degC]", "peak [degC]", "lock-up [s]",
                   "drift first to last [s]"), rows)
            + f"\n(`{d['command']}`; {measured(n, 'cycles')}.)\n")


VALIDATE_ROWS = (
    ("chen2021", "table3_max_rel_deviation", "Chen 2021 Table 3 torques: largest relative deviation"),
    ("chen2021", "bench_max_rel_error", "Chen 2021 bench torques (Table 2): largest relative error"),
    ("cui2019", "eq18_table1_max_rel_deviation", "Cui 2019 Eq. 18 against its Table 1: largest relative deviation"),
    ("cui2019", "patir_gap_max_rel_deviation", "Cui 2019 gap (Patir-Cheng) : largest relative deviation"),
    ("liao2021", "table3_alpha_max_rel_deviation", "Liao 2021 Table 3 film coefficients: largest relative deviation"),
    ("liao2021", "table3_new_torque_max_rel_deviation", "Liao 2021 Table 3 torques (new formula): largest deviation"),
    ("liao2021", "table3_new_torque_max_rel_error_vs_test", "Liao 2021 Table 3 torques against the test: largest error"),
)


def r_validate(n):
    s = n["validate"]["summary"]
    rows = [(text, f"`{paper}.{key}`", pct(s.get(paper, {}).get(key))) for paper, key, text in VALIDATE_ROWS]
    return table(("check", "summary.json key", "value"), rows) + f"\n({measured(n, 'validate')}.)\n"


def r_control(n):
    d = n["control"]
    rows = [(f"`{name}`", fmt(r["gain_margin_dB"], 3), fmt(r["phase_margin_deg"], 3), fmt(r["overshoot_pct"], 3),
             fmt(r["settling_time_s"], 3), fmt(r["steady_state_error_rel"], 2), fmt(r["time_in_saturation_s"], 3))
            for name, r in d["rows"].items()]
    return (table(("scene, controller", "worst gain margin [dB]", "worst phase margin [deg]", "overshoot [%]",
                   "2 % settling [s]", "steady-state error [-]", "time in saturation [s]"), rows)
            + f"\n(`{d['command']}`; {measured(n, 'control')}.)\n")


def r_optimize_scenes(n):
    d = n["optimize_scenes"]
    rows = [(f"`{name}`", r["phases"], r["n_variables"], r["stages"], f"{r['iterations']}", fmt(r["ipopt_s"], 3),
             fmt(r["command_s"], 3), fmt(r["t_f_s"]), pct(r["lock_time_rel_diff"], 2), pct(r["torque_jump_rel"], 2),
             fmt(r["passed"]))
            for name, r in d["rows"].items()]
    return (table(("scene", "phases", "NLP variables", "solves", "IPOPT iterations", "IPOPT [s]", "whole command [s]",
                   "lock-up [s]", "IDAS lock-up difference", "IDAS \\|jump\\| / reference", "passed"), rows)
            + f"\n(`{d['command']}`, 100 intervals, default weights and t_max; {measured(n, 'optimize_scenes')}; "
              "times on a shared 2-core machine.)\n")


def r_fill_comparison(n):
    r = n["optimize_scenes"]["rows"].get("default_fill") or {}
    f = r.get("fill_comparison")
    if not f:
        return "(not measured)\n"
    o, b = f["optimal"], f["baseline"]
    rows = [("engagement (lock-up) time [s]", fmt(o["engagement_time_s"]), fmt(b["engagement_time_s"])),
            ("peak jerk, kiss included [rad/s^3]", fmt(o["peak_jerk_rad_s3"]), fmt(b["peak_jerk_rad_s3"])),
            ("piston speed at the kiss point [m/s]", fmt(o["kiss_speed_m_s"], 3), fmt(b["kiss_speed_m_s"], 3)),
            ("lock-up torque jump [N m]", fmt(o["lockup_torque_jump_Nm"], 3), fmt(b["lockup_torque_jump_Nm"], 3)),
            ("dissipated energy [J]", fmt(o["dissipated_energy_J"]), fmt(b["dissipated_energy_J"]))]
    return (table(("IDAS numbers, `clutchocp optimize default_fill`", "minimum-time optimum",
                   "tuned fill pulse, hold, ramp"), rows) + f"\n({measured(n, 'optimize_scenes')}.)\n")


STRATEGY_NAMES = {"baseline": "baseline", "nominal_optimum": "nominal optimum + clamp",
                  "robust_feedforward": "robust feedforward + clamp", "closed_loop": "slip feedback (`slip_lqr`)"}


def r_robust(n):
    d = n["robust"]
    rows = []
    order = [n for n in STRATEGY_NAMES if n in d["statistics"]] + [n for n in d["statistics"] if n not in STRATEGY_NAMES]
    for name in order:
        v = d["statistics"][name]
        jump = v.get("jump_pct") or {}
        rows.append((STRATEGY_NAMES.get(name, name), pct(v["lock_share"]), pct(v["lock_within_t_max_share"]),
                     " / ".join(fmt(jump.get(k), 3) for k in ("median", "p95", "worst")),
                     fmt(v["jerk_integral_median"], 3)))
    accept = ", ".join(f"{k}: {'met' if v else 'not met'}" for k, v in d["acceptance"].items())
    return (table(("strategy", "locks", "within t_max", "\\|jump\\| median / p95 / worst [% of locked torque]",
                   "jerk integral median [rad^2/s^5]"), rows)
            + f"\nt_max = {fmt(d['t_max_s'])} s; acceptance: {accept}. (`{d['command']}`; {measured(n, 'robust')}.)\n")


def r_tcu_acceptance(n):
    d = n["tcu_acceptance"]
    a, st, tm = d["acceptance"], d["statistics"], d["timing"]
    lim = a["limits"]
    jump = st["jump_pct"]
    rows = [("every draw locks by this x t_max", fmt(lim["lock_by_t_max"], 3),
             f"{pct(a['lock_by_limit_share'])} of the draws (the latest at {fmt(a['latest_lock_over_t_max'], 4)})"),
            ("\\|jump\\| p95 [% of locked torque]", fmt(lim["jump_p95_pct"], 3), fmt(a["jump_p95_pct"], 3)),
            ("\\|jump\\| worst [% of locked torque]", fmt(lim["jump_worst_pct"], 3), fmt(a["jump_worst_pct"], 3)),
            ("nominal jerk integral / the nominal optimum's", fmt(lim["nominal_jerk_over_nominal_optimum"], 3),
             fmt(a["nominal_jerk_over_nominal_optimum"], 3))]
    return (table(("target", "limit", "measured"), rows)
            + f"\nt_max = {fmt(d['t_max_s'])} s; {pct(st['lock_within_t_max_share'])} of the draws lock within t_max; "
              f"\\|jump\\| median {fmt(jump['median'], 3)} %; targets met: {fmt(bool(a['passed']))}. "
              f"{fmt(tm['monte_carlo_s'], 3)} s of Monte Carlo ({fmt(tm['samples_per_s'], 3)} samples/s on "
              f"{tm['workers']} processes) after {fmt(tm['setup_s'], 3)} s of set-up. The folder holds "
              f"{', '.join('`' + f + '`' for f in d['written'])}. (`{d['command']}`; {measured(n, 'tcu_acceptance')}.)\n")


def r_tcu_thousand(n):
    d = n["tcu_thousand"]
    a, st, tm = d["acceptance"], d["statistics"], d["timing"]
    jump = st["jump_pct"]
    rows = [("draws", fmt(st["samples"])),
            ("Monte Carlo time [s]", fmt(tm["monte_carlo_s"], 3)),
            ("samples/s", f"{fmt(tm['samples_per_s'], 3)} on {tm['workers']} processes"),
            ("set-up (designs, feedforwards) [s]", fmt(tm["setup_s"], 3)),
            ("lock within t_max / by 1.03 t_max", f"{pct(st['lock_within_t_max_share'])} / "
                                                  f"{pct(a['lock_by_limit_share'])} (the latest at "
                                                  f"{fmt(a['latest_lock_over_t_max'], 4)} t_max)"),
            ("\\|jump\\| median / p95 / worst [% of locked torque]",
             f"{fmt(jump['median'], 3)} / {fmt(jump['p95'], 3)} / {fmt(jump['worst'], 3)}")]
    return table(("quantity", "value"), rows) + f"\n(`{d['command']}`; {measured(n, 'tcu_thousand')}.)\n"


def r_tcu_heldout(n):
    d = n["tcu_heldout"]

    def cells(s):
        if s is None:
            return ["-", "- (exact readings only)"]
        return [pct(s["within_t_max"]), " / ".join(fmt(s[k], 3) for k in ("jump_median_pct", "jump_p95_pct",
                                                                          "jump_worst_pct"))]
    order = d.get("conditions") or list(d["results"])          # the script's order (the JSON sorts keys)
    rows = [(label, *cells(d["results"][label].get("old")), *cells(d["results"][label].get("tcu"))) for label in order]
    return (table(("condition", "old loop: within t_max", "old: \\|jump\\| % median / p95 / worst",
                   "TCU loop: within t_max", "TCU: \\|jump\\| % median / p95 / worst"), rows)
            + f"\n({d['samples']} draws per condition; `{d['command']}`; {measured(n, 'tcu_heldout')}.)\n")


def r_optimize_refusals(n):
    d = n["optimize_refusals"]
    lines = "\n".join(f"$ {r['command']}\n{r['printed']}" for r in d["rows"])
    return f"```text\n{lines}\n```\n({measured(n, 'optimize_refusals')}.)\n"


def r_bench(n):
    s = n["bench"]["summary"]
    scenes = s.get("scenes") or {k: v for k, v in s.items() if isinstance(v, dict) and "speedup_vs_radau" in v}
    rows = [(f"`{name}`", fmt(v.get("speedup_vs_radau"), 3), fmt(v.get("speedup_vs_bdf"), 3),
             fmt(v.get("speedup_vs_lsoda"), 3), fmt(v.get("floor_speedup_vs_radau"), 3),
             fmt(v.get("whole_over_floor_vs_radau"), 2), fmt(v.get("whole_over_floor_bound_vs_radau"), 2),
             fmt(v.get("whole_over_floor_summary_bound_vs_radau"), 2),
             fmt(v.get("whole_over_floor_events_bound_vs_radau"), 2), fmt(v.get("whole_over_floor_replay_bound_vs_radau"), 2),
             fmt(v.get("scaling_exponent_pairs"), 3))
            for name, v in scenes.items()]
    return (table(("scene", "IDAS speed-up vs Radau", "vs BDF", "vs LSODA", "integrator floor vs Radau",
                   "whole / floor", "bound (no time outside the integrator)", "bound (no time outside the integrator "
                   "and the summary work)", "bound (... and the event checks)", "bound (the run's own calls replayed, and the "
                   "summary's arithmetic)", "run time ~ pairs^k: k"), rows)
            + "\n(speed-ups at matched error, the geometric mean over the error levels both reach; whole / floor: the "
              "whole run's speed-up over Radau divided by the floor's, below 1 where the run spends time outside "
              "the integrator: output grid, event location, summary; bound: the whole / floor a run would reach "
              "with its integrator calls as they are and no time outside them (they start and stop where the run "
              "finds its events, the floor's at the known event times); bound with the summary work: the same with "
              "the work every whole run does after its integration, Radau's too (the outputs its summary reads and "
              "the summary), added to IDAS's calls; bound with the event checks: the same with the event functions "
              "on the samples the run keeps added too, the detection a run that finds its events on its output "
              "grid cannot skip: what a hybrid loop costing nothing else would reach; bound with the calls replayed: "
              "every call the run makes into compiled code (integrators, outputs and event functions on the grid or "
              "at one sample) made again back to back from Python, plus the summary's own arithmetic: what an "
              "engine in Python making the same calls, so giving the same results, reaches when the Python around "
              "them costs nothing; "
              f"`{n['bench']['command']}`; {measured(n, 'bench')}.)\n")


def r_first_call_stop(n):
    d = n["first_call_stop"]
    rows = [(f"`{r['scene']}`", f"{r['event_t_s']:.4g} / {r['piece_end_s']:g}",
             f"{r['full_ms']:.2f} ({r['full_steps']})", f"{r['past']}", f"{r['ended_ms']:.2f} ({r['ended_steps']})",
             fmt(r["ended_change"], 2), f"{r['casadi_zero_ms']:.2f} ({r['casadi_zero_steps']})",
             fmt(r["zero_change"], 2), f"{r['whole_ms']:.2f}", f"{100 * r['ended_saving_share']:.1f} %",
             f"{1 / (1 - r['ended_saving_share']):.2f}")
            for r in d["rows"]]
    rtols = sorted({r["rtol"] for r in d["rows"]})
    return (table(("scene", "event / piece end [s]", "first call to the piece end: ms (steps)",
                   "ended past the event: grid intervals", "ended: ms (steps)", "ended: samples changed",
                   "CasADi zero events: ms (steps)", "zero events: samples changed", "whole run [ms]",
                   "ended call saves", "whole / floor factor"), rows)
            + f"\n(rtol {', '.join(f'{r:g}' for r in rtols)}; the first integrator call of the slipping piece; the "
              "three calls and the whole runs (the engine's and those of the next table) take turns, one timed call each "
              "per round, best of 15 each, so a run "
              "is timed after the CasADi call and reads slower than one of a series of runs; samples changed: the "
              "largest change of the scaled states before the event against the call to the piece end; whole / floor factor: 1 / (1 - saving), what an ended first call would "
              f"raise whole / floor by with every other time unchanged (the call's own steps only); `{d['command']}`; "
              f"{measured(n, 'first_call_stop')}.)\n")


def r_first_call_restart(n):
    d = n["first_call_stop"]
    parts = [r["parts"] for r in d["rows"][0]["restarts"]] if d["rows"] else []
    rows = []
    for r in (r for r in d["rows"] if r["restarts"]):
        fastest = next(x for x in r["restarts"] if x["parts"] == r["restart_best_parts"])
        rows.append((f"`{r['scene']}`", f"{r['whole_ms']:.2f} ({r['whole_steps']})", fmt(r["whole_error"], 2),
                     *(f"{x['whole_ms']:.2f} ({x['steps']}){'' if x['ends_past_event'] else ' *'}" for x in r["restarts"]),
                     f"1/{r['restart_best_parts']}", fmt(fastest["error"], 2),
                     f"{100 * r['restart_best_saving_share']:.1f} %", f"{1 / (1 - r['restart_best_saving_share']):.2f}"))
    rtols = sorted({r["rtol"] for r in d["rows"]})
    ended = [r for r in d["rows"] if r["restarts"]]
    fastest_past = [r["scene"] for r in ended
                    if next(x for x in r["restarts"] if x["parts"] == r["restart_best_parts"])["ends_past_event"]]
    short_slower = [f"1/{x['parts']} on {r['scene']}" for r in ended for x in r["restarts"]
                    if not x["ends_past_event"] and x["whole_ms"] > r["whole_ms"]]
    verdict = ("On every scene the fastest guess is one whose first call ends past the event, so that finds it "
               "with no restart at all" if len(fastest_past) == len(ended) else
               "The fastest guess ends past the event, with no restart, on " + (", ".join(fastest_past) or "no scene"))
    verdict += (("; guesses that fall short of the event and restart are slower than the engine's own run: "
                 + ", ".join(short_slower)) if short_slower else "") + ".\n\n"
    return (verdict + table(("scene", "whole run: ms (steps)", "its error",
                   *(f"first call ended at 1/{k} of the piece: ms (steps)" for k in parts),
                   "fastest", "its error", "saves", "whole / floor factor"), rows)
            + f"\n(rtol {', '.join(f'{r:g}' for r in rtols)}; whole runs, the engine's and those whose first call of the "
              "slipping piece ends after 1/k of the piece, then restarts, taking turns with the calls of the table "
              "above, best of 15 each; *: the first call ends before the event and restarts; error: the largest relative error against IDAS at rtol 1e-12 (speeds, film "
              "gaps, lock-up time and torque jump, as in the work-precision sweep); whole / floor factor: "
              f"1 / (1 - saving); `{d['command']}`; {measured(n, 'first_call_stop')}.)\n")


# -- docs/physics.md ---------------------------------------------------------------------------------
def _phys(n):
    return n["physics"]


def _run(n, label):
    return _phys(n)["runs"][label]


def r_physics_wall(n):
    rows = [(f"{w['eps']:g}", f"{w['smooth_drag']:.3f}", f"{w['rough_viscous']:.3f}", f"{w['form_drag']:.3f}")
            for w in _phys(n)["formulas"]["one_dimensional_wall"]]
    return table(("eps", "smooth-wall drag", "rough-wall viscous shear", "form drag"), rows) + \
        f"\n(`python docs/scripts/physics_numbers.py`; {measured(n, 'physics')}.)\n"


def r_physics_shear_factors(n):
    rows = [(f"{r['H']:g}", f"{r['phi_f']:.3f}", f"{r['Phi_fs']:.3f}", f"{r['rough_viscous']:.3f}",
             f"{r['patir_cheng']:.3f}", f"{r['table']:.3f}", f"{r['h_T_over_h']:.3f}")
            for r in _phys(n)["formulas"]["shear_factors"]]
    return table(("H", "phi_f", "Phi_fs", "rough wall's viscous phi_f - Phi_fs", "transmitted phi_f + Phi_fs",
                  "transmitted, deterministic flow (`\"table\"`)", "h_T / h"), rows) + \
        f"\n(`clutchocp.physics.shear`, one rough wall over the nominal film h; {measured(n, 'physics')}.)\n"


def r_physics_shear_effect(n):
    z, e, d = _run(n, "zhang2021"), _run(n, "zhang2021_equal_split"), _run(n, "default_driveline")
    return (f"Effect on the built-in scenes (`clutchocp simulate SCENE`): zhang2021 (lining rough, separator "
            f"smooth) locks at {fmt(z['engagement_time_s'])} s with a {fmt(z['peak_torque_Nm'])} N m peak (the "
            f"roughness split equally: {fmt(e['engagement_time_s'])} s and {fmt(e['peak_torque_Nm'])} N m); "
            f"default_driveline locks at {fmt(d['engagement_time_s'])} s. ({measured(n, 'physics')}; CHANGELOG.md "
            "has the values before the correction.)\n")


def r_physics_zhang_printed(n):
    z, low = _phys(n)["formulas"]["zhang_as_printed"], _run(n, "zhang2021_1000rpm")
    return (f"Table 1's {fmt(z['speed_rad_s'])} rad/s is {z['speed_rpm']:.0f} rpm, {z['rim_speed_m_s']:.0f} m/s at "
            f"the outer radius (high for a vehicle clutch). One stop puts {z['energy_J'] / 1e3:.0f} kJ on one "
            f"{z['area_mm2']:.0f} mm^2 friction face, {fmt(z['specific_energy_J_mm2'], 3)} J/mm^2: some twenty times "
            f"what a paper lining survives in one engagement (about 1-2 J/mm^2); kept in a 2 mm steel separator and "
            f"a plate of like heat capacity ({z['steel_plate_J_K']:.0f} J/K each) it would heat them by "
            f"{z['two_steel_plates_rise_K']:.0f} K. At {z['low_speed']} "
            f"(`--set \"driveline.input_speed='{z['low_speed']}'\"`, the plausible alternative) it is "
            f"{fmt(low['specific_energy_J_mm2'], 3)} J/mm^2 and the lock-up comes at "
            f"{fmt(low['engagement_time_s'], 3)} s. ({measured(n, 'physics')}.)\n")


def r_physics_contact_data(n):
    c = _phys(n)["settled_contact"]
    z, d = c["zhang2021"], c["default_driveline"]
    return (f"Zhang's asperity data give n beta sigma = {fmt(z['n_beta_sigma'], 3)}, about ten times "
            f"Greenwood-Williamson's usual 0.03-0.05: his real-area ratio pi n beta sigma F_1(H) is "
            f"{fmt(z['area_ratio'], 3)} at zhang2021's settled film (H = {fmt(z['settled_H'], 3)}); the "
            f"Greenwood-Tripp ratio of default_driveline with the same data is {fmt(d['area_ratio'], 3)} at its "
            f"settled film (H = {fmt(d['settled_H'], 3)}) and reaches the cap of {pct(d['cap'])} at "
            f"H = {fmt(d['cap_H'], 2)}. ({measured(n, 'physics')}.)\n")


def r_physics_cavitation_offset(n):
    c = _phys(n)["formulas"]["cavitation"]
    return (f"With the corner width w = {c['width']:g} |L| the squeeze load is off by at most "
            f"{fmt(c['offset'], 2)} |L| ({fmt(c['offset_Pa_at_1_bar'] / 1e3, 2)} kPa of mean pressure at -1 bar); "
            f"the residual slope is eps = {c['residual_slope']:g}.\n")


def r_physics_film_pressures(n):
    d, b = _run(n, "default_driveline"), _run(n, "bao2020")
    return (f"The shipped scenes' own runs never pull their films: the lowest mean film pressure is "
            f"{fmt(d['min_film_pressure_Pa'], 2)} Pa on default_driveline and {fmt(b['min_film_pressure_Pa'], 2)} Pa "
            f"on bao2020 (the centrifugal suction after lock-up); their energy balances close to "
            f"{fmt(d['energy_balance_rel_error'], 2)} and {fmt(b['energy_balance_rel_error'], 2)}. "
            f"({measured(n, 'physics')}.)\n")


def r_physics_optimum_film_pressure(n):
    rows = n["optimize_scenes"]["rows"]
    z, b = (None if rows[name]["min_film_pressure_Pa"] is None else rows[name]["min_film_pressure_Pa"] / 1e5
            for name in ("zhang2021", "bao2020"))
    return (f"Lowest mean film pressure of the IDAS replay (`verification.idas.min_film_pressure_Pa`): "
            f"{fmt(z, 3)} bar for zhang2021's optimum, {fmt(b, 3)} bar for bao2020's "
            f"(`clutchocp optimize SCENE`; {measured(n, 'optimize_scenes')}).\n")


def r_physics_capacity(n):
    c = _phys(n)["formulas"]["capacity_examples"]
    return (f"which scales as sigma^2.5 E': {fmt(c['greenwood_tripp'] / 1e6, 3)} MPa for Zhang 2021's asperities at "
            f"sigma = 8.41 um (default_driveline), {fmt(c['greenwood_tripp_6um'] / 1e6, 3)} MPa at 6 um. Zhang's "
            f"variant (`contact.model = \"zhang_gw\"`, load E delta^2 with delta = pi n_a beta sigma F_1(H)) carries "
            f"E (pi n_a beta sigma phi(0))^2 ({fmt(c['zhang_gw'] / 1e6, 3)} MPa for zhang2021). "
            f"({measured(n, 'physics')}.)\n")


def _answer(n, setting):
    a = _phys(n)["checks"][setting]
    return f"$ clutchocp simulate default_driveline --set \"{setting}\"\n{a['message']}"


def r_physics_plausible(n):
    return "```text\n" + "\n".join(_answer(n, s) for s in EDGE_EXAMPLES) + \
        f"\n```\n({measured(n, 'physics')}; exit code 2 for an error, 0 with a warning.)\n"


def r_physics_capacity_example(n):
    return f"```text\n{_answer(n, CAPACITY_EXAMPLE)}\n```\n"


def r_physics_capacity_ratios(n):
    rows = [(f"`{name}`", r["law"], fmt(r["capacity_Pa"] / 1e6, 3), fmt(r["run_ratio"], 2),
             fmt(r["max_pressure_ratio"], 2))
            for name, r in _phys(n)["formulas"]["contact_capacity"].items()]
    return table(("scene", "contact law", "capacity at zero gap [MPa]", "largest pack pressure / capacity, its run",
                  "up to `actuation.max_pressure`"), rows) + f"\n({measured(n, 'physics')}.)\n"


def r_physics_conduction(n):
    c = _phys(n)["formulas"]["conduction"]
    rows = [(cells, *(pct(e, 2) for e in errors)) for cells, errors in c["errors"].items()]
    return table(("cells", *(f"{t:g} s" for t in c["times_s"])), rows) + f"\n({measured(n, 'physics')}.)\n"


def r_physics_thermal(n):
    t = _run(n, "thermal_cells_6")
    q = t["peak_specific_power_W_mm2"] * 1e6          # W/m^2
    steel_k, half = 50.0, 1e-3                         # W/(m K), m: the separator's steel, half-thickness
    cells = ", ".join(f"{c} cell{'s' if c > 1 else ''} {fmt(_run(n, f'thermal_cells_{c}')['peak_interface_temperature_C'], 3)}"
                      for c in THERMAL_CELLS)
    return (f"On default_driveline_thermal (`clutchocp simulate default_driveline_thermal`) the interface (the "
            f"lining's surface) peaks at {fmt(t['peak_interface_temperature_C'], 3)} degC, the friction plates' bulk "
            f"at {fmt(t['peak_friction_plate_temperature_C'], 3)} degC, their core at "
            f"{fmt(t['peak_core_temperature_C'], 3)} degC; the energy balance, counting the heat stored in every "
            f"node, closes to {fmt(t['energy_balance_rel_error'], 2)}. Left out is the gradient across the "
            f"separator's steel itself, about q L / (3 k) under a flux q on a half-thickness L: "
            f"{fmt(q * half / (3 * steel_k), 2)} K at this engagement's peak {fmt(t['peak_specific_power_W_mm2'], 3)} "
            f"W/mm^2 (L = 1 mm, k = 50 W/(m K)). Peak interface temperature against the cell count "
            f"(`--set thermal.lining_cells=N`): {cells} degC. ({measured(n, 'physics')}.)\n")


RENDERERS = {
    "optimize-default-table": r_optimize_default_table,
    "optimize-default-printed": r_optimize_default_printed,
    "readme-example-output": r_readme_example_output,
    "optimize-weights": r_optimize_weights,
    "simulate-scenes": r_simulate_scenes,
    "simulate-thermal": r_simulate_thermal,
    "cycles": r_cycles,
    "validate": r_validate,
    "control": r_control,
    "optimize-scenes": r_optimize_scenes,
    "fill-comparison": r_fill_comparison,
    "robust": r_robust,
    "optimize-refusals": r_optimize_refusals,
    "tcu-acceptance": r_tcu_acceptance,
    "tcu-heldout": r_tcu_heldout,
    "tcu-thousand": r_tcu_thousand,
    "bench": r_bench,
    "first-call-stop": r_first_call_stop,
    "first-call-restart": r_first_call_restart,
    "physics-wall": r_physics_wall,
    "physics-shear-factors": r_physics_shear_factors,
    "physics-shear-effect": r_physics_shear_effect,
    "physics-zhang-printed": r_physics_zhang_printed,
    "physics-contact-data": r_physics_contact_data,
    "physics-cavitation-offset": r_physics_cavitation_offset,
    "physics-film-pressures": r_physics_film_pressures,
    "physics-optimum-film-pressure": r_physics_optimum_film_pressure,
    "physics-capacity": r_physics_capacity,
    "physics-plausible": r_physics_plausible,
    "physics-capacity-example": r_physics_capacity_example,
    "physics-capacity-ratios": r_physics_capacity_ratios,
    "physics-conduction": r_physics_conduction,
    "physics-thermal": r_physics_thermal,
}


def render_text(text, numbers):
    """``text`` with every generated block rendered from ``numbers`` (unknown names raise KeyError)."""
    def block(match):
        name = match.group(2)
        try:
            body = RENDERERS[name](numbers)
        except KeyError as missing:       # an item never measured: say so in the page
            if name not in RENDERERS:
                raise
            body = f"(not measured yet: `python benchmarks/docs_numbers.py` has no {missing} numbers)\n"
        return match.group(1) + body + match.group(4)
    return BLOCK.sub(block, text)


def blocks(text):
    """The generated blocks of a text: [(name, content)]."""
    return [(m.group(2), m.group(3)) for m in BLOCK.finditer(text)]


# -- the scene-key reference -----------------------------------------------------------------------
def _unit(field):
    kinds = {"int": "integer", "bool": "true/false", "str": "text", "str_list": "list of text", "choice": "text"}
    if field.kind in kinds:
        return kinds[field.kind]
    unit = "-" if field.dim == "1" else field.dim
    return f"list, {unit}" if field.kind == "quantity_list" else unit


def _allowed(field):
    from clutchocp.scene.schema import CHECKS

    if field.kind == "choice":
        return ", ".join(f'`"{c}"`' for c in field.choices)
    if field.kind in ("str", "str_list", "bool"):
        return ""
    return CHECKS[field.check][1] if field.check != "any" else "any value"


def _default(field):
    if field.required and field.default is None:
        return "**required**"
    if field.default is None or field.default == ():
        return "absent"
    if field.kind == "choice" or isinstance(field.default, str):
        return f'`"{field.default}"`'
    if isinstance(field.default, bool):
        return f"`{str(field.default).lower()}`"
    unit = "" if field.dim in ("1", "") or field.kind != "quantity" else f" {field.dim}"
    return f"{field.default:g}{unit}"


def _plausible(field):
    """The key's plausibility spans (:class:`clutchocp.scene.schema.Span`), or "" for a key without."""
    if field.span is None:
        return ""
    return field.span.describe(field.dim)


def _field_rows(fields):
    return [(f"`{key}`", _unit(f), _allowed(f), _plausible(f), _default(f), f.doc) for key, f in fields.items()]


def scene_keys_page():
    """docs/scene-keys.md: every part and key of a scene file, from :mod:`clutchocp.scene.schema`."""
    sys.path.insert(0, str(ROOT))
    from clutchocp.scene import list_scenes
    from clutchocp.scene.schema import PARTS, REQUIRED_PARTS, RETIRED

    scenes = list_scenes()
    lines = ["# Scene keys", "",
             "<!-- GENERATED from clutchocp/scene/schema.py by `python benchmarks/docs_numbers.py --render`; "
             "do not edit by hand. -->", "",
             "Every part (TOML table) a scene file may declare, and every key of each part: its unit, the values "
             "allowed, its default and what it means. How to write a scene for your own clutch: "
             "[own-clutch.md](own-clutch.md). `clutchocp scenes FILE` checks a file against this list.", "",
             "- A quantity is a plain number in SI units or a string with its unit: `\"8.4 um\"`, `\"6000 rpm\"`, "
             "`\"46 cSt\"`, `\"6 bar\"`, `\"80 degC\"` (see [own-clutch.md](own-clutch.md#units)).",
             "- *absent*: the key may be left out and then has no value (the model does without it or says what "
             "it needs); **required**: the scene must give it.",
             "- A part with variants chooses one with `model = \"...\"`; the keys of the other variants are not "
             "allowed then. A part a scene does not declare adds no states and no equations.",
             "- *allowed*: a value outside is refused in one line naming the key. *plausible*: the values a wet "
             "clutch has (*typical*) and those any wet clutch stays within; a value outside the typical span is "
             "a warning on stderr and in `summary.json` (`warnings`) and the run goes on, one outside the limits "
             "is refused with the unit it was probably written in (e.g. `plates.r_outer = 85` read as 85 m: "
             "\"did you mean 85 mm\"). A key whose 0 means none (*0 = none*) accepts 0 whatever its spans.", "",
             "Parts each kind of scene must declare:", ""]
    lines += [f"- `{kind}`: " + ", ".join(f"`[{p}]`" for p in parts) for kind, parts in REQUIRED_PARTS.items()]
    lines += ["", "Contents: " + ", ".join(f"[`[{p}]`](#{p})" for p in PARTS) + ", [`[uncertainty]`](#uncertainty)"
              + (", [keys that no longer exist](#keys-that-no-longer-exist)" if RETIRED else ""),
              ""]
    header = ("key", "unit", "allowed", "plausible", "default", "meaning")
    for name, part in PARTS.items():
        used = [s.name for s in scenes if name in s.raw]
        lines += [f"## {name}", "", f"`[{name}]`: {part.doc}.", ""]
        lines += [f"Built-in scenes with this part: {', '.join(f'`{u}`' for u in used)}." if used
                  else "No built-in scene has this part.", ""]
        if part.variants:
            choices = ", ".join(f'`"{v}"`' for v in part.variants)
            default = f' (default `"{part.default_variant}"`)' if part.default_variant else ""
            lines += [f"`model` = {choices}{default}.", ""]
        if part.fields:
            lines += [("Keys of every variant:" if part.variants else "Keys:"), "", table(header, _field_rows(part.fields))]
        for variant, fields in part.variants.items():
            if fields:
                lines += [f'`model = "{variant}"` adds:', "", table(header, _field_rows(fields))]
            else:
                lines += [f'`model = "{variant}"` has no keys of its own.', ""]
    lines += ["## uncertainty", "",
              "`[uncertainty]`: the spread of the clutches a scene stands for (robust optimisation, sweeps with "
              "`--samples`, `clutchocp robust`). Each key is a scene field written `\"part.key\"`, each value a law:",
              "", table(("value", "meaning"), [
                  ('`"uniform 10 %"`', "nominal +- 10 %, uniform"),
                  ('`"normal 5 %"`', "sigma = 5 % of the nominal, truncated at +- 3 sigma (corners at +- 2 sigma)"),
                  ('`"uniform 20 N m"`', "a half-width (or sigma) with a unit; a plain number is SI"),
                  ('`["patir_cheng", "none"]`', "a list of values (numbers with units, or the choices of a choice "
                                                 "field), drawn with equal weight")]),
              "The nominal is the scene's own value. On the command line: `--uncertain \"friction.mu=uniform 10 %\"` "
              "(repeatable). A spread that leaves a field's allowed range is refused with the field named.", ""]
    if RETIRED:
        lines += ["## Keys that no longer exist", "",
                  "A scene that still has one is refused in one line saying what took its place:", "",
                  table(("key", "what to do"), [(f"`{key}`", why) for key, why in RETIRED.items()])]
    return "\n".join(lines).rstrip() + "\n"


# -- which keys are documented ---------------------------------------------------------------------
SPAN = re.compile(r"`([^`\n]+)`")


def _expand(text):
    """``"{a,b}.c"`` -> ``["a.c", "b.c"]`` (one level of braces at a time, repeated)."""
    match = re.search(r"\{([^{}]*)\}", text)
    if not match:
        return [text]
    out = []
    for option in match.group(1).split(","):
        out += _expand(text[:match.start()] + option.strip() + text[match.end():])
    return out


def _segment_regex(segment):
    parts = re.split(r"(<[^<>]+>)", segment)
    return re.compile("".join(".+" if p.startswith("<") and p.endswith(">") else re.escape(p) for p in parts))


PLACEHOLDER = re.compile(r"<[^<>]+>")
SCENE_FIELD = re.compile(r"[A-Za-z_]\w*\.[A-Za-z_]\w*")


def key_spans(page):
    """The code spans of a page with a literal name in them; a span that is a placeholder alone (`<i>`,
    `<field>`) names no summary key, and only a scene field (``part.key``) as a column (see :func:`undocumented`)."""
    return {span for span in SPAN.findall(Path(page).read_text(encoding="utf-8"))
            if re.search(r"\w", PLACEHOLDER.sub("", span))}


def documented_patterns(page):
    """The key patterns a page documents: every key span, braces expanded, split into segments."""
    patterns = []
    for span in key_spans(page):
        for text in _expand(span.strip()):
            patterns.append([_segment_regex(s) for s in text.split(".")])
    return patterns


def _matches(key, pattern):
    if key and key[-1] == "*":           # an empty list or table: documented if something below it is
        head = key[:-1]
        return len(pattern) > len(head) - 1 and all(p.fullmatch(k) for p, k in zip(pattern, head[:-1])) \
            and (pattern[len(head) - 1].fullmatch(head[-1]) is not None)
    return len(key) == len(pattern) and all(p.fullmatch(k) for p, k in zip(pattern, key))


def undocumented(keys, page):
    """What of ``keys`` (a :func:`folder_keys` result) the page does not document:
    summary key paths (dotted) and ``file.csv: column`` entries."""
    patterns = documented_patterns(page)
    spans = key_spans(page)
    columns = [re.compile("".join(".+" if p.startswith("<") else re.escape(p)
                                  for p in re.split(r"(<[^<>]+>)", s))) for span in spans for s in _expand(span)]
    # `<field>` alone: a column per swept or drawn scene field (part.key)
    fields = any(PLACEHOLDER.fullmatch(span) for span in SPAN.findall(Path(page).read_text(encoding="utf-8")))
    missing = [".".join(k) for k in keys["summary"] if not any(_matches(k, p) for p in patterns)]
    for name, header in keys["csv"].items():
        missing += [f"{name}: {c}" for c in header
                    if not (any(r.fullmatch(c) for r in columns) or (fields and SCENE_FIELD.fullmatch(c)))]
    missing += [f"file {f}" for f in keys["files"] if not any(r.fullmatch(f) for r in columns)]
    return missing


# A file one command writes with the columns of another's, documented on that command's page
SHARED_FILES = {"optimize": {"timeseries.csv": "simulate"}}


def undocumented_all(numbers):
    """{command: [what its page does not document]} over every item's recorded keys."""
    out = {}
    for command, items in KEYS_OF.items():
        keys = [numbers[i]["keys"] for i in items if i in numbers and "keys" in numbers[i]]
        if keys:
            keys = merge_keys(*keys)
            missing = []
            for name, page in SHARED_FILES.get(command, {}).items():
                if name in keys["csv"]:
                    shared = {"summary": [], "csv": {name: keys["csv"][name]}, "files": []}
                    missing += undocumented(shared, COMMAND_PAGES / f"{page}.md")
                    keys = {**keys, "csv": {k: v for k, v in keys["csv"].items() if k != name}}
            missing += undocumented(keys, COMMAND_PAGES / f"{command}.md")
            if missing:
                out[command] = missing
    return out


# -- main --------------------------------------------------------------------------------------------
def load_numbers():
    return json.loads(JSON_PATH.read_text()) if JSON_PATH.is_file() else {}


def render_all(numbers, write=True):
    """Rewrite the generated blocks and docs/scene-keys.md; returns the files that changed."""
    changed = []
    for path in doc_files():
        text = path.read_text(encoding="utf-8")
        new = render_text(text, numbers)
        if new != text:
            changed.append(path)
            if write:
                path.write_text(new, encoding="utf-8")
    page = scene_keys_page()
    if not SCENE_KEYS.is_file() or SCENE_KEYS.read_text(encoding="utf-8") != page:
        changed.append(SCENE_KEYS)
        if write:
            SCENE_KEYS.write_text(page, encoding="utf-8")
    return changed


def measure(names, jobs):
    """Run the items ``names``, their commands ``jobs`` at a time; returns ({name: values} of those that
    worked, {name: error} of those that failed, the wall time [s])."""
    today = datetime.date.today().isoformat()
    results, failures = {}, {}
    start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="docs_numbers_") as scratch:
        runner = Runner(scratch, jobs)

        def run(name):
            item = Item(runner, name, ORDER.index(name))
            begin = time.perf_counter()
            try:
                values = ITEMS[name](item)
            except Exception as exc:     # noqa: BLE001 - one failed item keeps the others' numbers
                failures[name] = str(exc)
                print(f"  {name}: FAILED: {exc}", file=sys.stderr, flush=True)
                return
            values["measured"] = today
            values["item_wall_time_s"] = round(time.perf_counter() - begin, 1)
            values["item_command_s"] = round(sum(item.seconds), 1)
            results[name] = values
            print(f"  {name}: done after {values['item_wall_time_s']:.0f} s "
                  f"({len(item.seconds)} commands, {values['item_command_s']:.0f} s of command time)", flush=True)

        threads = [threading.Thread(target=run, args=(name,), daemon=True) for name in ORDER if name in names]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
        commands = sorted(((run[1][0].seconds, " ".join(args)) for args, run in runner.runs.items()
                           if run[1] and isinstance(run[1][0], Run)), reverse=True)
    for seconds, command in commands:
        print(f"    {seconds:7.1f} s  clutchocp {command}")
    return results, failures, time.perf_counter() - start


def positive_int(text):
    if not text.isdigit() or int(text) < 1:
        raise argparse.ArgumentTypeError(f"--jobs must be a whole number >= 1, got {text!r}")
    return int(text)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", default=None, help="comma-separated items to measure (default: all)")
    parser.add_argument("--skip", default="", help="comma-separated items not to measure")
    parser.add_argument("--render", action="store_true", help="no measuring: rewrite the docs from the JSON")
    parser.add_argument("--check", action="store_true", help="exit 1 if a doc differs from what --render writes")
    parser.add_argument("--jobs", type=positive_int, default=2,
                        help="commands run at once (default: 2; 1 on a machine others use)")
    args = parser.parse_args(argv)
    numbers = load_numbers()
    if args.check:
        changed = render_all(numbers, write=False)
        for path in changed:
            print(f"out of date: {path.relative_to(ROOT)}")
        return 1 if changed else 0
    failures = {}
    if not args.render:
        names = [n.strip() for n in args.only.split(",")] if args.only else list(ITEMS)
        unknown = [n for n in names + [s for s in args.skip.split(",") if s] if n not in ITEMS]
        if unknown:
            parser.error(f"unknown items {unknown}; the items are {', '.join(ITEMS)}")
        names = [n for n in names if n not in args.skip.split(",")]
        print(f"measuring {', '.join(names)} ({args.jobs} commands at a time)", flush=True)
        results, failures, wall = measure(names, args.jobs)
        numbers.update(results)
        JSON_PATH.write_text(json.dumps(numbers, indent=1, sort_keys=True) + "\n")
        numbers = load_numbers()          # render what is stored (sorted keys), as the tests do
        print(f"measured in {wall:.0f} s; wrote {JSON_PATH.relative_to(ROOT)}")
    for path in render_all(numbers):
        print(f"rewrote {path.relative_to(ROOT)}")
    for command, missing in undocumented_all(numbers).items():
        print(f"docs/commands/{command}.md does not document: {', '.join(missing[:20])}"
              + (f" (and {len(missing) - 20} more)" if len(missing) > 20 else ""), file=sys.stderr)
    if failures:
        print(f"failed items (their previous numbers kept): {', '.join(failures)}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
