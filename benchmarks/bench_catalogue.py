"""``clutchocp optimize`` on every catalogue clutch and shipped engagement scene: verified, refused or failed.

Each clutch runs as its own ``clutchocp optimize SCENE --out OUT/NAME`` process (the command a user
types, with its defaults: 100 intervals, default weights, t_max = the scene's own lock-up), with a
time limit. The outcome of a run is

* **verified**: exit code 0 and ``summary.json`` says ``verification.passed`` (the IDAS replay locks
  within 1 % of the collocation's lock-up with |jump| <= 2 % of its reference);
* **refused**: exit code 2 with a single line on stderr (``clutchocp optimize: error: ...``) that
  names a physical limit: the message contains one of :data:`LIMIT_MARKERS` (the clutch does not
  lock even at the pressure limit, t_max below the fastest lock-up, a capacity, a kiss point, the
  contact, a temperature or power limit) and none of :data:`SOLVER_MARKERS` (a solver's status);
  these are the ``ModelError`` refusals of ``clutchocp.optimal.problem`` (see ``clutchocp/errors.py``:
  the command line prints every ``ClutchocpError`` as one line with exit code 2);
* **failed**: anything else: an optimum that IDAS does not confirm, a raw solver message (IPOPT's
  status, also ``Infeasible_Problem_Detected``, which is IPOPT's local verdict and not a proof), a
  refusal that names no physical limit, an internal error (exit code 1), a crash (a signal), more
  than one line on stderr (a traceback) or the time limit.

Writes ``catalogue_bench.csv`` and ``catalogue_bench.md`` (clutch, outcome, the one-line message,
IDAS lock-up time [s], |jump| in % of its reference (the locked torque, or the peak slipping torque
for a lock that carries none), wall time [s]; then the counts and the median wall time per clutch)
into ``--out``, each clutch's result folder below it. Run from the repository root:

    python benchmarks/bench_catalogue.py [--out out/bench_catalogue] [--workers 1] [--timeout 1800]
        [--only NAME ...] [--no-shipped] [--docs docs/benchmarks.md]

``--docs PAGE`` also writes the table into PAGE between the lines ``<!-- catalogue-bench:start -->``
and ``<!-- catalogue-bench:end -->`` (added at the end of the page if it has none), so the numbers the
documentation quotes are this script's.
"""

import argparse
import csv
import json
import os
import re
import shutil
import signal
import statistics
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor, as_completed
from pathlib import Path

from tqdm import tqdm

from clutchocp.scene import list_scenes

ROOT = Path(__file__).resolve().parent.parent
CATALOGUE = ROOT / "models" / "catalogue"

# Phrases of a refusal that names a physical limit (case-insensitive).
LIMIT_MARKERS = ("does not lock up", "below the fastest lock-up", "capacity", "kiss point", "never reaches",
                 "contact cannot", "temperature limit", "power limit", "pressure limit")
# Phrases of a solver's own verdict: a message with one of them is a failure, whatever else it says.
SOLVER_MARKERS = ("ipopt", "idas", "cvodes", "casadi", "infeasible_problem_detected", "maximum_iterations",
                  "restoration", "internal error", "traceback")
COLUMNS = ("clutch", "source", "outcome", "message", "lock_time_s", "jump_pct", "wall_time_s", "exit_code")


def clutchocp_command():
    """The ``clutchocp`` console script of this interpreter's environment."""
    here = Path(sys.executable).with_name("clutchocp")
    found = str(here) if here.exists() else shutil.which("clutchocp")
    if found is None:
        sys.exit("bench_catalogue: the clutchocp command is not installed (pip install -e .)")
    return found


def clutches(only=None, shipped=True):
    """(name, scene argument, source) of every catalogue file and shipped engagement scene."""
    out = [(p.stem, str(p), "catalogue") for p in sorted(CATALOGUE.glob("*.toml"))]
    if shipped:
        out += [(sc.name, sc.name, "shipped") for sc in list_scenes() if sc.kind == "engagement"]
    if only:
        missing = set(only) - {name for name, _, _ in out}
        if missing:
            sys.exit(f"bench_catalogue: --only: no clutch named {', '.join(sorted(missing))}")
        out = [c for c in out if c[0] in only]
    return out


def classify(code, stderr, summary):
    """Outcome and one-line message of a finished run (see the module docstring).

    Parameters
    ----------
    code : int or None
        Exit code (None: the time limit stopped it; negative: killed by that signal).
    stderr : str
        The run's standard error.
    summary : dict or None
        Its summary.json (exit code 0 only).

    Returns
    -------
    (str, str)
        ``"verified"``, ``"refused"`` or ``"failed"``, and the message.
    """
    lines = [ln for ln in stderr.splitlines() if ln.strip() and ": warning:" not in ln]
    if code is None:
        return "failed", "time limit reached"
    if code == 0:
        if summary is None:
            return "failed", "exit code 0 without summary.json"
        ver = summary["verification"]
        idas = ver["idas"]["engagement_time_s"]
        text = (f"IDAS lock-up {_fmt(idas, '.4g')} s, rel. diff {_fmt(ver['lock_time_rel_diff'], '.2e')}, "
                f"|jump| {_fmt(_jump_pct(ver), '.3g')} % of {_fmt(ver['jump_reference_Nm'], '.4g')} N m")
        return ("verified", text) if ver["passed"] else ("failed", "optimum not confirmed by IDAS: " + text)
    if code < 0:
        return "failed", f"killed by signal {signal.Signals(-code).name}"
    message = " ".join(lines[-1].split()) if lines else f"exit code {code}, nothing on stderr"
    message = re.sub(r"^clutchocp optimize: (error: )?", "", message)
    if code == 2 and len(lines) == 1:
        lower = message.lower()
        if any(m in lower for m in LIMIT_MARKERS) and not any(m in lower for m in SOLVER_MARKERS):
            return "refused", message
    return "failed", message if len(lines) <= 1 else f"{len(lines)} lines on stderr, last: {message}"


def _jump_pct(ver):
    jump, ref = ver.get("torque_jump_Nm"), ver.get("jump_reference_Nm")
    return None if jump is None or not ref else 100.0 * abs(jump) / ref


def _fmt(value, spec):
    return "none" if value is None else format(value, spec)


def run_one(command, name, scene, source, out_dir, timeout):
    """Run ``clutchocp optimize`` on one clutch in its own process group; a row of the table."""
    folder = out_dir / name
    cmd = [command, "optimize", scene, "--out", str(folder)]
    start = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        stdout, stderr = proc.communicate(timeout=timeout)
        code = proc.returncode
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)             # this run's own process group only
        stdout, stderr = proc.communicate()
        code = None
    wall = time.perf_counter() - start
    (out_dir / "logs").mkdir(exist_ok=True)
    (out_dir / "logs" / f"{name}.log").write_text(f"$ {' '.join(cmd)}\n--- stdout\n{stdout}\n--- stderr\n{stderr}",
                                                   encoding="utf-8")
    summary = None
    if code == 0 and (folder / "summary.json").is_file():
        summary = json.loads((folder / "summary.json").read_text(encoding="utf-8"))
    outcome, message = classify(code, stderr, summary)
    ver = summary["verification"] if summary else {}
    return {"clutch": name, "source": source, "outcome": outcome, "message": message,
            "lock_time_s": (ver.get("idas") or {}).get("engagement_time_s"), "jump_pct": _jump_pct(ver) if ver else None,
            "wall_time_s": wall, "exit_code": "timeout" if code is None else code}


def write_tables(rows, out_dir, args):
    """catalogue_bench.csv and catalogue_bench.md (no NaN: a missing number is an empty cell or '-')."""
    with open(out_dir / "catalogue_bench.csv", "w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, fieldnames=COLUMNS)
        writer.writeheader()
        for r in rows:
            writer.writerow({k: "" if r[k] is None else (f"{r[k]:.6g}" if isinstance(r[k], float) else r[k])
                             for k in COLUMNS})
    counts = {o: sum(r["outcome"] == o for r in rows) for o in ("verified", "refused", "failed")}
    median = statistics.median(r["wall_time_s"] for r in rows) if rows else 0.0
    lines = [f"# clutchocp optimize on the clutch catalogue", "",
             f"{len(rows)} clutches, `clutchocp optimize NAME` with its defaults, {args.workers} at a time, time "
             f"limit {args.timeout:g} s; load average at the end {os.getloadavg()[0]:.2f}.", "",
             "| clutch | source | outcome | message | IDAS lock-up [s] | \\|jump\\| / reference [%] | wall time [s] |",
             "|---|---|---|---|---|---|---|"]
    for r in rows:
        msg = r["message"].replace("|", "\\|")
        lines.append(f"| `{r['clutch']}` | {r['source']} | {r['outcome']} | {msg} | {_fmt(r['lock_time_s'], '.4g')} | "
                     f"{_fmt(r['jump_pct'], '.3g')} | {r['wall_time_s']:.1f} |")
    lines += ["", f"verified {counts['verified']}, refused {counts['refused']}, failed {counts['failed']}; "
                  f"median wall time per clutch {median:.1f} s, total {sum(r['wall_time_s'] for r in rows):.0f} s.", ""]
    (out_dir / "catalogue_bench.md").write_text("\n".join(lines), encoding="utf-8")
    return counts, median, lines


DOCS_START, DOCS_END = "<!-- catalogue-bench:start -->", "<!-- catalogue-bench:end -->"


def write_docs(page, lines):
    """The table (``lines`` of catalogue_bench.md, its title left out) into ``page`` between the markers."""
    page = Path(page)
    text = page.read_text(encoding="utf-8") if page.exists() else ""
    block = "\n".join([DOCS_START, "Generated by `python benchmarks/bench_catalogue.py --docs docs/benchmarks.md`; "
                       "do not edit by hand.", ""] + lines[2:] + [DOCS_END])
    if DOCS_START in text and DOCS_END in text:
        head, rest = text.split(DOCS_START, 1)
        text = head + block + rest.split(DOCS_END, 1)[1]
    else:
        text = text.rstrip("\n") + ("\n\n" if text else "") + block + "\n"
    page.parent.mkdir(parents=True, exist_ok=True)
    page.write_text(text, encoding="utf-8")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out/bench_catalogue", help="folder for the tables and each clutch's result")
    parser.add_argument("--workers", type=int, default=1, help="clutches run at the same time (each its own process)")
    parser.add_argument("--timeout", type=float, default=1800.0, help="time limit of one run [s]")
    parser.add_argument("--only", nargs="+", help="run these clutches only (file stems or shipped scene names)")
    parser.add_argument("--no-shipped", action="store_true", help="the catalogue only, not the shipped scenes")
    parser.add_argument("--docs", default=None, metavar="PAGE",
                        help="also write the table into this Markdown page between its catalogue-bench markers")
    args = parser.parse_args()
    if args.workers < 1 or not args.timeout > 0:
        parser.error("--workers must be >= 1 and --timeout > 0")
    out_dir = Path(args.out)
    out_dir.mkdir(parents=True, exist_ok=True)
    command = clutchocp_command()
    todo = clutches(args.only, not args.no_shipped)
    rows = []
    with ThreadPoolExecutor(max_workers=args.workers) as pool, tqdm(total=len(todo), unit="clutch") as bar:
        futures = {pool.submit(run_one, command, name, scene, source, out_dir, args.timeout): name
                   for name, scene, source in todo}
        for future in as_completed(futures):
            row = future.result()
            rows.append(row)
            bar.set_postfix_str(f"{row['clutch']}: {row['outcome']}")
            bar.update()
    order = {name: k for k, (name, _, _) in enumerate(todo)}
    rows.sort(key=lambda r: order[r["clutch"]])
    counts, median, lines = write_tables(rows, out_dir, args)
    if args.docs:
        write_docs(args.docs, lines)
    print(f"verified {counts['verified']}, refused {counts['refused']}, failed {counts['failed']}; median wall time "
          f"{median:.1f} s per clutch; tables in {out_dir}")


if __name__ == "__main__":
    main()
