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
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
JSON_PATH = ROOT / "benchmarks" / "docs_numbers.json"
SCENE_KEYS = ROOT / "docs" / "scene-keys.md"
BLOCK = re.compile(r"(<!-- generated: ([\w-]+) -->\n)(.*?)(<!-- end generated -->)", re.S)
EXAMPLE = re.compile(r"<!-- example: ([\w-]+) -->\n```python\n(.*?)```", re.S)
COMMAND_PAGES = ROOT / "docs" / "commands"


# -- running the tool -----------------------------------------------------------------------------
def clutchocp(*args, cwd=None, timeout=3600):
    """Run ``clutchocp ARGS`` in a fresh interpreter; returns its stdout (raises with stderr on failure)."""
    env = {**os.environ, "MPLBACKEND": "Agg"}
    proc = subprocess.run([sys.executable, "-m", "clutchocp.cli", *args], capture_output=True, text=True,
                          cwd=cwd, env=env, timeout=timeout)
    if proc.returncode != 0:
        raise RuntimeError(f"clutchocp {' '.join(args)} exited {proc.returncode}: {proc.stderr.strip()[-2000:]}")
    return proc.stdout


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
MEASURES = ("engagement_time_s", "lockup_torque_jump_Nm", "jerk_integral", "peak_jerk_rad_s3", "peak_torque_Nm",
            "dissipated_energy_J")


def optimize_default(work):
    """``clutchocp optimize --out DIR``: the first command of the README, on the default scene."""
    out = work / "optimize"
    stdout = clutchocp("optimize", "--out", str(out))
    s = summary_of(out)
    table = stdout[stdout.index("scene default_driveline: optimal"):].rstrip() if "optimal engagement" in stdout \
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
        "keys": folder_keys(out),
    }


WEIGHT_VARIANTS = ("jerk=1,energy=10", "jerk=0,time=1", "jerk=1,energy=0.1")


def optimize_weights(work):
    """``clutchocp optimize --weights ...`` on the default scene: what each objective weight trades."""
    rows = {}
    for weights in WEIGHT_VARIANTS:
        out = work / f"weights_{len(rows)}"
        clutchocp("optimize", "--weights", weights, "--out", str(out))
        s = summary_of(out)
        rows[weights] = {**pick(s["optimal"], *MEASURES), "passed": s["verification"]["passed"]}
    return {"command": "clutchocp optimize --weights W --out DIR", "rows": rows}


def engagement_scenes():
    sys.path.insert(0, str(ROOT))
    from clutchocp.scene import list_scenes

    return [s.name for s in list_scenes() if s.kind == "engagement"]


SIMULATE_NUMBERS = ("engagement_time_s", "lockup_torque_jump_Nm", "peak_torque_Nm", "peak_jerk_rad_s3",
                    "dissipated_energy_J", "energy_balance_rel_error", "torque_response_time_stable_s",
                    "stable_torque_Nm", "torque_response_time_s", "pressure_response_time_s", "specific_energy_J_mm2",
                    "peak_specific_power_W_mm2", "peak_interface_temperature_C", "wall_time_s")


def simulate_scenes(work):
    """``clutchocp simulate SCENE`` for every built-in engagement scene."""
    rows, keys = {}, []
    for name in engagement_scenes():
        out = work / f"simulate_{name}"
        clutchocp("simulate", name, "--out", str(out))
        rows[name] = pick(summary_of(out), *SIMULATE_NUMBERS)
        keys.append(folder_keys(out))
    return {"command": "clutchocp simulate SCENE --out DIR", "rows": rows, "keys": merge_keys(*keys)}


CYCLE_RUNS = (("default_driveline_thermal", 0.5), ("default_driveline_thermal", 5.0), ("default_driveline", 0.5))


def cycles(work):
    """``clutchocp cycles SCENE --cycles 10 --cooling-time S --max-temperature 110``."""
    runs, keys = [], []
    for name, cooling in CYCLE_RUNS:
        out = work / f"cycles_{name}_{cooling:g}"
        clutchocp("cycles", name, "--cycles", "10", "--cooling-time", f"{cooling:g}", "--max-temperature", "110",
                  "--out", str(out))
        s = summary_of(out)
        runs.append({"scene": name, "cooling_time_s": cooling, "stop_reason": s["stop_reason"],
                     "drift_s": s["engagement_time_drift_s"],
                     "cycles": [pick(c, "cycle", "start_interface_temperature_C", "peak_interface_temperature_C",
                                     "engagement_time_s") for c in s["cycles"]]})
        keys.append(folder_keys(out))
    return {"command": "clutchocp cycles SCENE --cycles 10 --cooling-time S --max-temperature 110 --out DIR",
            "runs": runs, "keys": merge_keys(*keys)}


def validate(work):
    """``clutchocp validate``: the static analyses against the seed papers."""
    out = work / "validate"
    clutchocp("validate", "--out", str(out))
    return {"command": "clutchocp validate --out DIR", "summary": summary_of(out), "keys": folder_keys(out)}


CONTROL_RUNS = (("liao2021_hvd", "lqi"), ("cui2019_hvd", "pi"))


def control(work):
    """``clutchocp control SCENE --controller SPEC`` on both hydro-viscous drive scenes."""
    rows, keys = {}, []
    for name, spec in CONTROL_RUNS:
        out = work / f"control_{name}"
        clutchocp("control", name, "--controller", spec, "--out", str(out))
        s = summary_of(out)
        rows[f"{name} {spec}"] = {**pick(s["margins"], "gain_margin_dB", "phase_margin_deg", "all_points_stable"),
                                  **pick(s["closed_loop"], "overshoot_pct", "settling_time_s", "steady_state_error_rel",
                                         "time_in_saturation_s")}
        keys.append(folder_keys(out))
    return {"command": "clutchocp control SCENE --controller SPEC --out DIR", "rows": rows, "keys": merge_keys(*keys)}


SWEEPS = (
    ("simulate grid", ("zhang2021", "--grid", "actuation.pressure=0.3 MPa:0.6 MPa:3", "--grid",
                       "oil.viscosity=0.05:0.08:3")),
    ("simulate samples", ("default_driveline", "--samples", "12", "--seed", "1")),
    ("optimize grid", ("default_driveline", "--task", "optimize", "--grid", "load.torque=90:130:2", "--grid",
                       "oil.viscosity=0.06:0.08:2", "--intervals", "20")),
)


def sweep(work):
    """``clutchocp sweep``: a simulate grid, Monte Carlo samples and an optimize grid (what they write)."""
    rows, keys = {}, []
    for label, args in SWEEPS:
        out = work / f"sweep_{len(rows)}"
        clutchocp("sweep", *args, "--workers", "1", "--out", str(out))
        s = summary_of(out)
        rows[label] = {"command": "clutchocp sweep " + " ".join(f"'{a}'" if " " in a else a for a in args),
                       **pick(s, "points", "points_ok", "points_failed")}
        keys.append(folder_keys(out))
    return {"rows": rows, "keys": merge_keys(*keys)}


def optimize_scenes(work):
    """``clutchocp optimize SCENE`` for every engagement scene: solve, IDAS check, time."""
    rows, keys = {}, []
    for name in engagement_scenes():
        out = work / f"optimize_{name}"
        start = time.perf_counter()
        clutchocp("optimize", name, "--out", str(out))
        wall = time.perf_counter() - start
        s = summary_of(out)
        solves = s.get("mesh", {}).get("solves", [])
        rows[name] = {
            "phases": " + ".join(p["name"] for p in s["phases"]),
            "n_variables": s["solver"]["n_variables"],
            "stages": ", ".join(x["stage"] for x in solves),
            "iterations": sum(x["iterations"] or 0 for x in solves) or s["solver"]["iterations"],
            "ipopt_s": sum(x["wall_time_s"] or 0.0 for x in solves) or s["solver"]["wall_time_s"],
            "command_s": wall,
            "t_f_s": s["optimal"]["engagement_time_s"],
            "lock_time_rel_diff": s["verification"]["lock_time_rel_diff"],
            "torque_jump_rel": s["verification"]["torque_jump_rel"],
            "passed": s["verification"]["passed"],
            "fill_comparison": {k: pick(v, "engagement_time_s", "peak_jerk_rad_s3", "lockup_torque_jump_Nm",
                                        "kiss_speed_m_s", "dissipated_energy_J")
                                for k, v in s["fill_comparison"].items() if k in ("optimal", "baseline")}
            if "fill_comparison" in s else None,
        }
        keys.append(folder_keys(out))
    return {"command": "clutchocp optimize SCENE --out DIR", "rows": rows, "keys": merge_keys(*keys)}


def robust(work):
    """``clutchocp robust --samples 200 --seed 0``: the four shift-control strategies over the default box."""
    out = work / "robust"
    clutchocp("robust", "--samples", "200", "--seed", "0", "--workers", "1", "--out", str(out))
    s = summary_of(out)
    stats = {name: {**pick(v, "lock_share", "lock_within_t_max_share"),
                    "jump_pct": v.get("jump_pct"), "jerk_integral_median": (v.get("jerk_integral") or {}).get("median")}
             for name, v in s["statistics"].items()}
    return {"command": "clutchocp robust --samples 200 --seed 0 --out DIR", "t_max_s": s["t_max_s"],
            "strategies": s["strategies"], "statistics": stats,
            "acceptance": {k: v.get("passed") for k, v in s["acceptance"].items()},
            "samples_per_s": s["timing"]["samples_per_s"], "keys": folder_keys(out)}


def bench(work):
    """``clutchocp bench --quick``: IDAS against scipy's integrators at matched error."""
    out = work / "bench"
    clutchocp("bench", "--quick", "--out", str(out))
    s = summary_of(out)
    return {"command": "clutchocp bench --quick --out DIR", "summary": s, "keys": folder_keys(out)}


def readme_example(work):
    """The Python example of the README, run as a user would, and what it prints."""
    code = examples()["readme"]
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=work, timeout=1800,
                          env={**os.environ, "MPLBACKEND": "Agg"})
    if proc.returncode != 0:
        raise RuntimeError(f"the README example failed: {proc.stderr.strip()[-2000:]}")
    return {"code_sha256": code_hash(code), "stdout": proc.stdout}


ITEMS = {
    "optimize_default": optimize_default,
    "readme_example": readme_example,
    "optimize_weights": optimize_weights,
    "simulate_scenes": simulate_scenes,
    "cycles": cycles,
    "validate": validate,
    "control": control,
    "sweep": sweep,
    "optimize_scenes": optimize_scenes,
    "robust": robust,
    "bench": bench,
}
# The longest first, so that two at a time finish together.
ORDER = ("robust", "bench", "optimize_scenes", "sweep", "optimize_weights", "cycles", "control", "simulate_scenes",
         "optimize_default", "readme_example", "validate")
KEYS_OF = {"optimize": ("optimize_default", "optimize_scenes"), "simulate": ("simulate_scenes",),
           "cycles": ("cycles",), "validate": ("validate",), "control": ("control",), "sweep": ("sweep",),
           "robust": ("robust",), "bench": ("bench",)}


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


def r_bench(n):
    s = n["bench"]["summary"]
    scenes = s.get("scenes") or {k: v for k, v in s.items() if isinstance(v, dict) and "speedup_vs_radau" in v}
    rows = [(f"`{name}`", fmt(v.get("speedup_vs_radau"), 3), fmt(v.get("speedup_vs_bdf"), 3),
             fmt(v.get("speedup_vs_lsoda"), 3), fmt(v.get("floor_speedup_vs_radau"), 3),
             fmt(v.get("scaling_exponent_pairs"), 3))
            for name, v in scenes.items()]
    return (table(("scene", "IDAS speed-up vs Radau", "vs BDF", "vs LSODA", "integrator floor vs Radau",
                   "run time ~ pairs^k: k"), rows)
            + f"\n(speed-ups at matched error; `{n['bench']['command']}`; {measured(n, 'bench')}.)\n")


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
    "bench": r_bench,
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


def documented_patterns(page):
    """The key patterns a page documents: every code span, braces expanded, split into segments."""
    patterns = []
    for span in SPAN.findall(Path(page).read_text(encoding="utf-8")):
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
    spans = set(SPAN.findall(Path(page).read_text(encoding="utf-8")))
    columns = [re.compile("".join(".+" if p.startswith("<") else re.escape(p)
                                  for p in re.split(r"(<[^<>]+>)", s))) for span in spans for s in _expand(span)]
    missing = [".".join(k) for k in keys["summary"] if not any(_matches(k, p) for p in patterns)]
    for name, header in keys["csv"].items():
        missing += [f"{name}: {c}" for c in header if not any(r.fullmatch(c) for r in columns)]
    missing += [f"file {f}" for f in keys["files"] if not any(r.fullmatch(f) for r in columns)]
    return missing


def undocumented_all(numbers):
    """{command: [what its page does not document]} over every item's recorded keys."""
    out = {}
    for command, items in KEYS_OF.items():
        keys = [numbers[i]["keys"] for i in items if i in numbers and "keys" in numbers[i]]
        if keys:
            missing = undocumented(merge_keys(*keys), COMMAND_PAGES / f"{command}.md")
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
    """Run the items ``names`` (two at a time by default); returns {name: values} of those that worked."""
    today = datetime.date.today().isoformat()
    results, failures = {}, {}

    def run(name):
        start = time.perf_counter()
        with tempfile.TemporaryDirectory(prefix=f"docs_{name}_") as work:
            values = ITEMS[name](Path(work))
        values["measured"] = today
        values["item_wall_time_s"] = round(time.perf_counter() - start, 1)
        print(f"  {name}: {values['item_wall_time_s']:.0f} s", flush=True)
        return values

    order = [n for n in ORDER if n in names]
    with ThreadPoolExecutor(max_workers=jobs) as pool:
        futures = {name: pool.submit(run, name) for name in order}
        for name, future in futures.items():
            try:
                results[name] = future.result()
            except Exception as exc:     # noqa: BLE001 - one failed item keeps the others' numbers
                failures[name] = str(exc)
                print(f"  {name}: FAILED: {exc}", file=sys.stderr, flush=True)
    return results, failures


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", default=None, help="comma-separated items to measure (default: all)")
    parser.add_argument("--skip", default="", help="comma-separated items not to measure")
    parser.add_argument("--render", action="store_true", help="no measuring: rewrite the docs from the JSON")
    parser.add_argument("--check", action="store_true", help="exit 1 if a doc differs from what --render writes")
    parser.add_argument("--jobs", type=int, default=2, help="items measured at once (default: 2)")
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
        start = time.perf_counter()
        print(f"measuring {', '.join(names)} ({args.jobs} at a time)", flush=True)
        results, failures = measure(names, args.jobs)
        numbers.update(results)
        JSON_PATH.write_text(json.dumps(numbers, indent=1, sort_keys=True) + "\n")
        numbers = load_numbers()          # render what is stored (sorted keys), as the tests do
        print(f"measured in {time.perf_counter() - start:.0f} s; wrote {JSON_PATH.relative_to(ROOT)}")
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
