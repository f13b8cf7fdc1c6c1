"""Writing results: summary.json, CSV tables and PNG figures (shared by every command).

Figures are drawn with matplotlib's object API on an Agg canvas, so no GUI backend is touched.
Nothing non-finite is ever written: a NaN or infinity in a result raises ModelError naming the key.
"""

import csv
import json
import math
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from .errors import ModelError


def write_csv(path, columns):
    """Write equal-length columns to a CSV file (header = column names, with units).

    Parameters
    ----------
    path : str or pathlib.Path
        File to write.
    columns : dict
        ``{"name [unit]": sequence}``; all sequences of the same length. Numbers must be finite.

    Returns
    -------
    pathlib.Path of the file.
    """
    path = Path(path)
    names = list(columns)
    data = [list(columns[n]) for n in names]
    lengths = {len(d) for d in data}
    if len(lengths) != 1:
        raise ModelError(f"{path.name}: columns of unequal length {sorted(lengths)}")
    for name, values in zip(names, data):
        for v in values:
            if isinstance(v, (float, np.floating)) and not math.isfinite(v):
                raise ModelError(f"{path.name}: non-finite value in column '{name}'")
    with path.open("w", newline="", encoding="utf-8") as fh:
        writer = csv.writer(fh)
        writer.writerow(names)
        for row in zip(*data):
            writer.writerow([_fmt_csv(v) for v in row])
    return path


def _fmt_csv(v):
    if isinstance(v, (float, np.floating)):
        return f"{float(v):.10g}"
    if isinstance(v, (np.integer,)):
        return str(int(v))
    return v


def new_figure(n_panels=1, width=6.4, height=4.2):
    """A matplotlib Figure on an Agg canvas with ``n_panels`` axes side by side.

    Returns
    -------
    fig, axes : Figure and a list of Axes.
    """
    fig = Figure(figsize=(width * n_panels if n_panels > 1 else width, height), layout="constrained")
    FigureCanvasAgg(fig)
    axes = [fig.add_subplot(1, n_panels, k + 1) for k in range(n_panels)]
    return fig, axes


def save_figure(fig, path):
    """Save a figure as PNG (100 dpi) and return its path."""
    path = Path(path)
    fig.savefig(path, dpi=100)
    return path


def to_json_number(value, key):
    """A finite Python float/int/str/bool for summary.json; non-finite numbers raise ModelError."""
    if isinstance(value, (bool, str)):
        return value
    if isinstance(value, (int, np.integer)):
        return int(value)
    value = float(value)
    if not math.isfinite(value):
        raise ModelError(f"summary key '{key}' is not a finite number ({value})")
    return value


def _clean(value, key):
    """A JSON-ready copy of ``value``: dicts and lists recursively, None kept, numbers finite."""
    if value is None:
        return None
    if isinstance(value, dict):
        return {str(k): _clean(v, f"{key}.{k}" if key else str(k)) for k, v in value.items()}
    if isinstance(value, (list, tuple, np.ndarray)):
        return [_clean(v, f"{key}[{i}]") for i, v in enumerate(value)]
    return to_json_number(value, key)


def nest(flat):
    """``{"a.b": 1}`` -> ``{"a": {"b": 1}}`` (split at the first dot)."""
    nested = {}
    for key, value in flat.items():
        head, dot, rest = key.partition(".")
        if dot:
            nested.setdefault(head, {})[rest] = value
        else:
            nested[key] = value
    return nested


def write_summary(path, summary):
    """Write ``summary.json`` (nested dicts; units in the key names; None becomes null).

    Returns
    -------
    pathlib.Path of the file.
    """
    path = Path(path)
    path.write_text(json.dumps(_clean(summary, ""), indent=2, sort_keys=True) + "\n", encoding="utf-8")
    return path
