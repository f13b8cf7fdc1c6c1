"""What a static analysis hands to the report, and the printed table (files: :mod:`clutchocp.output`)."""

from dataclasses import dataclass, field


@dataclass
class AnalysisResult:
    """What one static analysis hands to the report.

    Attributes
    ----------
    name : str
        Analysis name, the prefix of its summary keys (e.g. ``"chen2021"``).
    title : str
        One line for the printed table.
    summary : dict
        ``{"chen2021.key_with_unit": number or str}`` entries for summary.json.
    rows : list of tuple
        Printed table rows ``(quantity, clutchocp value, reference value, deviation)`` as strings.
    files : list of pathlib.Path
        CSV and PNG files written.
    figure_data : dict
        What its figures draw (keyword arguments of its function in :mod:`clutchocp.analyses.figures`).
    """

    name: str
    title: str
    summary: dict = field(default_factory=dict)
    rows: list = field(default_factory=list)
    files: list = field(default_factory=list)
    figure_data: dict = field(default_factory=dict)


def format_table(results):
    """The human summary: one block per analysis, columns quantity | clutchocp | paper | deviation."""
    headers = ("quantity", "clutchocp", "paper", "deviation")
    rows = [r for res in results for r in res.rows]
    widths = [max(len(h), *(len(str(r[k])) for r in rows)) if rows else len(h)
              for k, h in enumerate(headers)]
    line = "  ".join(f"{h:<{w}}" for h, w in zip(headers, widths))
    out = []
    for res in results:
        out.append(f"== {res.title}")
        out.append(line)
        out.append("  ".join("-" * w for w in widths))
        for r in res.rows:
            out.append("  ".join(f"{str(c):<{w}}" for c, w in zip(r, widths)))
        out.append("")
    return "\n".join(out).rstrip() + "\n"


def pct(fraction):
    """A fraction as a signed percentage string with two decimals."""
    return f"{100 * fraction:+.2f} %"
