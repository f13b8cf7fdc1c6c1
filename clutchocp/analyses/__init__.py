"""Static analyses against the seed papers (``clutchocp validate``).

Each analysis builds no DAE: it evaluates the physics components on a built-in scene and
compares the numbers with the tables of its paper.

* :mod:`~clutchocp.analyses.chen2021` — spline friction, pack torque vs Chen Tables 2-3;
* :mod:`~clutchocp.analyses.cui2019` — mixed-friction torques vs film ratio, Eq. 18 vs Table 1;
* :mod:`~clutchocp.analyses.liao2021` — film distribution of an HVC pack vs Liao Table 3;
* :mod:`~clutchocp.analyses.figures` — the figures of all three, drawn from their results.
"""

from pathlib import Path

from clutchocp.analyses import chen2021, cui2019, liao2021
from clutchocp.analyses.figures import draw
from clutchocp.analyses.report import format_table
from clutchocp.output import nest, shown, write_summary, writes_folder

__all__ = ["run_validation", "ANALYSES"]

#: The analyses run by :func:`run_validation`, in order.
ANALYSES = (chen2021, cui2019, liao2021)


@writes_folder
def run_validation(out_dir, *, quiet=False):
    """Run every static analysis on its built-in scene and write the results.

    Parameters
    ----------
    out_dir : str or pathlib.Path
        Output folder (created if needed). Receives ``summary.json``, CSV files and PNG figures.
    quiet : bool
        If True, do not print the table.

    Returns
    -------
    dict
        The summary, flat keys ``"<analysis>.<quantity>[_unit]"``, e.g.
        ``"chen2021.table3_max_rel_deviation"`` and ``"chen2021.bench_max_rel_error"`` (fractions);
        ``summary.json`` holds it nested by analysis (``{"chen2021": {"table3_max_rel_deviation": ...}}``).
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    results = [analysis.run(out_dir) for analysis in ANALYSES]
    for res in results:
        res.files.extend(draw(res, out_dir))
    summary = {}
    for res in results:
        summary.update(res.summary)
    path = write_summary(out_dir / "summary.json", nest(summary))
    if not quiet:
        print(format_table(results))
        files = [f.name for res in results for f in res.files] + [path.name]
        print(f"wrote {len(files)} files to {shown(out_dir)}: {', '.join(files)}")
    return summary
