"""Figures of a study: lines (one swept field), heat maps (two), histograms and scatter (samples),
and the family of optimal pressure curves (optimize)."""

import math

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ..output import save_figure
from ..plotting import flat_value, scene_title, ticks_at
from ..scene.schema import PARTS
from .folder import CALIBRATION, read_complete

# The results drawn per task (at most four: a 2 x 2 panel figure).
PLOTTED = {
    "simulate": ("engagement_time_s", "lockup_torque_jump_Nm", "peak_torque_Nm", "dissipated_energy_J"),
    "optimize": ("engagement_time_s", "jerk_integral", "peak_torque_Nm", "dissipated_energy_J"),
}
SUFFIX_UNITS = (("_rad_s3", "rad/s^3"), ("_Nm", "N m"), ("_J", "J"), ("_Pa", "Pa"), ("_s", "s"))


NAMED_UNITS = {"jerk_integral": "rad^2/s^5", "objective": "-", "energy_balance_rel_error": "-"}


def result_label(column):
    """``"peak_torque_Nm"`` -> ``"peak torque [N m]"``."""
    if column in NAMED_UNITS:
        return f"{column.replace('_', ' ')} [{NAMED_UNITS[column]}]"
    for suffix, unit in SUFFIX_UNITS:
        if column.endswith(suffix):
            return f"{column[: -len(suffix)].replace('_', ' ')} [{unit}]"
    return column.replace("_", " ")


DISPLAY_UNITS = {"Pa": ("MPa", 1e-6)}      # SI unit -> (unit drawn on an axis, factor)


def field_axis(scene, name):
    """Axis label and scale of a scene field: ``"load.torque"`` -> ``("load.torque [N m]", 1.0)``,
    ``"actuation.pressure"`` -> ``("actuation.pressure [MPa]", 1e-6)`` (values times the scale)."""
    part, _, key = name.partition(".")
    spec = PARTS[part].allowed_fields(scene.variant(part)).get(key) if part in PARTS else None
    unit = getattr(spec, "dim", "1") if spec is not None and getattr(spec, "kind", "") == "quantity" else "1"
    unit, scale = DISPLAY_UNITS.get(unit, (unit, 1.0))
    return (f"{name} [{unit}]" if unit != "1" else name), scale


def _figure(rows, cols, width=4.2, height=3.2, layout="constrained", share=False):
    fig = Figure(figsize=(width * cols, height * rows), layout=layout)
    FigureCanvasAgg(fig)
    axes = fig.subplots(rows, cols, squeeze=False, sharex=share, sharey=share)
    return fig, axes.ravel()


def _values(rows, column):
    return np.array([r[column] if isinstance(r.get(column), float) and r["status"] == "ok" else np.nan
                     for r in rows], float)


def _title(scene, task, rows):
    n_failed = sum(r["status"] != "ok" for r in rows)
    failed = f", {n_failed} failed (marked x)" if n_failed else ""
    return scene_title(scene.name, f"{task.kind} sweep, {len(rows)} points{failed}", task.base_overrides)


def _failed(rows):
    """True where a point failed (its row has a reason and no results)."""
    return np.array([r["status"] != "ok" for r in rows])


def _constant_note(ax, values, column):
    """State on ``ax`` that a result is the same at every point to round-off; True if it is."""
    value = flat_value(values)
    if value is None:
        return False
    finite = values[np.isfinite(values)]
    ax.text(0.5, 0.5, f"{result_label(column)}\nthe same at every point: {value:.8g}\n(spread "
                      f"{finite.max() - finite.min():.2g}: round-off)", transform=ax.transAxes, ha="center",
            va="center", fontsize=8, bbox={"boxstyle": "round", "fc": "white", "ec": "0.7"})
    return True


def draw_study(out, scene, task, fields, rows, sampled):
    """Draw the study's figures into ``out``; returns the paths written."""
    plotted = [c for c in PLOTTED[task.kind] if np.isfinite(_values(rows, c)).any()]
    files = []
    if not rows or not plotted:
        return files
    numeric = [f for f in fields if all(isinstance(r[f], float) for r in rows)]
    if sampled:
        files.append(_histograms(out, scene, task, rows, plotted))
        if numeric:
            files.append(_scatter(out, scene, task, rows, plotted, numeric))
    elif len(fields) == 1 and numeric:
        files.append(_lines(out, scene, task, rows, plotted, fields[0]))
    elif len(fields) == 2 and len(numeric) == 2:
        files.append(_maps(out, scene, task, rows, plotted, fields))
    if task.kind == "optimize":
        path = _curves(out, scene, task, rows, fields)
        if path is not None:
            files.append(path)
    return files


def _lines(out, scene, task, rows, plotted, field):
    label, scale = field_axis(scene, field)
    x = np.array([r[field] for r in rows], float) * scale
    order = np.argsort(x)
    failed = _failed(rows)
    n = len(plotted)
    fig, axes = _figure(math.ceil(n / 2), min(n, 2))
    for ax, column in zip(axes, plotted):
        y = _values(rows, column)
        ax.plot(x[order], y[order], "o-", color="C0")
        # points without a value sit on the lower edge: x failed, o no value (e.g. no lock-up in t_end)
        missing = ~np.isfinite(y)
        for mask, marker, text in ((failed, "x", "failed point"), (missing & ~failed, "o", "no value")):
            if mask.any():
                ax.plot(x[mask], np.zeros(mask.sum()), marker, color="C3", mfc="none", ms=8, clip_on=False,
                        transform=ax.get_xaxis_transform(), label=text)
        if missing.any():
            ax.legend(fontsize=7)
        ticks_at(ax.xaxis, x[np.isfinite(x)])
        ax.set_xlabel(label)
        ax.set_ylabel(result_label(column))
        ax.grid(True, alpha=0.3)
    for ax in axes[n:]:
        ax.set_visible(False)
    fig.suptitle(_title(scene, task, rows))
    return save_figure(fig, out / "sweep_lines.png")


def _maps(out, scene, task, rows, plotted, fields):
    xs = np.unique([r[fields[1]] for r in rows])
    ys = np.unique([r[fields[0]] for r in rows])
    (x_label, x_scale), (y_label, y_scale) = field_axis(scene, fields[1]), field_axis(scene, fields[0])
    failed = _failed(rows)
    n = len(plotted)
    cols = min(n, 2)
    # Fixed margins, not the constrained layout: it measured every tick label twice and took 60 % of
    # the time of a sweep's figures (the drawing is serial time at the end of every sweep). Every
    # map is on the same grid, so the panels share their axes: tick labels and field names on the
    # outer edges only (less to read, and a fifth less to draw).
    fig, axes = _figure(math.ceil(n / 2), cols, width=4.8, height=3.6, layout=None, share=True)
    rows_of_axes = math.ceil(n / 2)
    fig.subplots_adjust(left=0.12, right=0.94, bottom=0.16 / rows_of_axes, top=1 - 0.3 / rows_of_axes,
                        wspace=0.35, hspace=0.3)
    cell = [(np.searchsorted(ys, r[fields[0]]), np.searchsorted(xs, r[fields[1]])) for r in rows]
    for k, (ax, column) in enumerate(zip(axes, plotted)):
        values = _values(rows, column)
        grid = np.full((ys.size, xs.size), np.nan)
        for (i, j), v in zip(cell, values):
            grid[i, j] = v
        constant = flat_value(values) is not None
        # a result constant to round-off is one colour with its value stated, not a map of noise
        shown = np.where(np.isfinite(grid), np.nanmean(values), np.nan) if constant else grid
        mesh = ax.pcolormesh(_edges(xs) * x_scale, _edges(ys) * y_scale, np.ma.masked_invalid(shown),
                             shading="flat", cmap="viridis")
        if constant:
            _constant_note(ax, values, column)
        else:
            fig.colorbar(mesh, ax=ax)             # the panel's title names the result and its unit
        for (i, j), v, bad in zip(cell, values, failed):
            if bad or not np.isfinite(v):
                ax.text(xs[j] * x_scale, ys[i] * y_scale, "x" if bad else "-", ha="center", va="center",
                        color="C3", fontsize=11, fontweight="bold")
        ax.set_title(result_label(column), fontsize=10)
        ticks_at(ax.xaxis, xs, x_scale)
        ticks_at(ax.yaxis, ys, y_scale)
        bottom, left = k + cols >= n, k % cols == 0     # no panel drawn below it / first column
        ax.tick_params(labelbottom=bottom, labelleft=left)
        if bottom:
            ax.set_xlabel(x_label)
        if left:
            ax.set_ylabel(y_label)
    for ax in axes[n:]:
        ax.set_visible(False)
    fig.suptitle(_title(scene, task, rows) + "\nticks at the sampled values; x: failed point, "
                 "-: no value (e.g. no lock-up within t_end)", fontsize=11)
    return save_figure(fig, out / "sweep_maps.png")


def _edges(centres):
    """Cell edges around sorted cell centres (half a step beyond the ends)."""
    if centres.size == 1:
        half = 0.05 * abs(centres[0]) or 0.5
        return np.array([centres[0] - half, centres[0] + half])
    mid = 0.5 * (centres[1:] + centres[:-1])
    return np.concatenate([[2 * centres[0] - mid[0]], mid, [2 * centres[-1] - mid[-1]]])


def _histograms(out, scene, task, rows, plotted):
    n = len(plotted)
    fig, axes = _figure(math.ceil(n / 2), min(n, 2))
    for ax, column in zip(axes, plotted):
        y = _values(rows, column)
        y = y[np.isfinite(y)]
        ax.set_ylabel("points")
        if _constant_note(ax, y, column):
            ax.set_xticks([])
            continue
        ax.hist(y, bins=max(5, min(30, int(np.sqrt(y.size)) + 1)), color="C0", alpha=0.8)
        ax.axvline(np.mean(y), color="k", ls="--", lw=1, label=f"mean {np.mean(y):.4g}")
        ax.set_xlabel(result_label(column))
        ax.legend(fontsize=8)
    for ax in axes[n:]:
        ax.set_visible(False)
    fig.suptitle(_title(scene, task, rows).replace("sweep", "Monte Carlo"))
    return save_figure(fig, out / "sample_histograms.png")


def _scatter(out, scene, task, rows, plotted, fields):
    fig, axes = _figure(len(plotted), len(fields), width=3.4, height=2.6)
    axes = axes.reshape(len(plotted), len(fields))
    for i, column in enumerate(plotted):
        y = _values(rows, column)
        for j, field in enumerate(fields):
            ax = axes[i, j]
            label, scale = field_axis(scene, field)
            x = np.array([r[field] for r in rows], float) * scale
            ax.plot(x, y, ".", color="C0", ms=4)
            missing = ~np.isfinite(y)
            if missing.any():        # failed points and points without a value, on the lower edge
                ax.plot(x[missing], np.zeros(missing.sum()), "x", color="C3", ms=5, clip_on=False,
                        transform=ax.get_xaxis_transform())
            if i == len(plotted) - 1:
                ax.set_xlabel(label)
            if j == 0:
                ax.set_ylabel(result_label(column), fontsize=8)
            ax.grid(True, alpha=0.3)
    fig.suptitle(_title(scene, task, rows).replace("sweep", "Monte Carlo") + ": each result against each sampled "
                 "field (x on the lower edge: no value)")
    return save_figure(fig, out / "sample_scatter.png")


def _curves(out, scene, task, rows, fields):
    path = out / CALIBRATION
    if not path.is_file():
        return None
    with path.open(encoding="utf-8") as fh:
        header = fh.readline().strip().split(",")
    table = read_complete(path, header)
    if not table:
        return None
    by_point = {}
    for r in table:
        by_point.setdefault(r["point_id"], []).append(r)
    colour_field = fields[0] if fields and all(isinstance(r[fields[0]], float) for r in rows) else None
    colour_label, colour_scale = field_axis(scene, colour_field) if colour_field else ("", 1.0)
    values = [r[colour_field] * colour_scale for r in rows] if colour_field else [0.0]
    lo, hi = min(values), max(values)
    fig, axes = _figure(1, 1, width=7.0, height=4.4)
    ax = axes[0]
    from matplotlib import cm, colors

    norm = colors.Normalize(lo, hi if hi > lo else lo + 1)
    for r in rows:
        curve = by_point.get(r["point_id"])
        if not curve:
            continue
        colour = cm.viridis(norm(r[colour_field] * colour_scale)) if colour_field else "C0"
        ax.plot([c["time_s"] for c in curve], [c["pressure_Pa"] / 1e6 for c in curve], color=colour, lw=1.2)
    if colour_field:
        fig.colorbar(cm.ScalarMappable(norm=norm, cmap="viridis"), ax=ax, label=colour_label)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("optimal pressure command [MPa]")
    ax.grid(True, alpha=0.3)
    t_max = task.options.get("t_max") or scene.get("actuation.engagement_time_limit")
    limit = f"t_max = {t_max:g} s" if t_max else "t_max = each point's own baseline lock-up time"
    fig.suptitle(scene_title(scene.name, f"optimal engagement pressure, {len(by_point)} operating points",
                             task.base_overrides) + "\n"
                 f"each curve ends at its lock-up; {limit}", fontsize=10)
    return save_figure(fig, out / "optimal_curves.png")
