"""What every figure of clutchocp shares, so that an engineer can read it without guessing.

:func:`finish` is applied to every figure when it is saved (:func:`clutchocp.output.save_figure`) or
handed to the user (``result.plot()``):

- tick labels are plain numbers, never an offset ("1e-8 - 5.3077484e1" above the axis), and on log
  axes "0.5", "20" rather than "5 x 10^-1", "2 x 10^1";
- a series constant to round-off is drawn as a flat line with its value stated, not as a signal
  (:data:`FLAT_REL`);
- a legend inside the axes is moved to their right, outside the data, and the figure is widened by
  the legend's width so the data area keeps its size;
- titles are wrapped to the width they have (no title cut at the figure's edge).

The helpers below are for the figure modules: :func:`scene_title` names a scene with the
``--set`` overrides its run was made with (:func:`overrides_of`), :func:`clip_spike` scales an axis
to the signal around a short spike and annotates the spike's size.
"""

import math
import textwrap

import numpy as np

from .scene.loader import read_toml

# A series whose values all lie within FLAT_REL of their magnitude is constant to round-off. IDAS
# keeps each step's local error within rtol (1e-8 by default) of the states; a result read from a
# whole run therefore moves by up to ~1e-7 of its value between runs that should be equal (the
# engagement time of repeated identical engagements: 3e-9 s of 0.2847 s). Nothing a clutch engineer
# reads is resolved finer than that.
FLAT_REL = 1e-7
LEGEND_WRAP = 34          # characters per legend line


def _plain_log_formatter(**kw):
    """A log-axis tick formatter that writes plain numbers ("0.5", "20", "1e-05"), not "5 x 10^-1"."""
    from matplotlib.ticker import LogFormatter

    class PlainLogFormatter(LogFormatter):
        def _num_to_string(self, x, vmin, vmax):
            return f"{x:.4g}"

    return PlainLogFormatter(**kw)


def plain_numbers(ax):
    """Plain tick labels on both axes of ``ax``: no offset and no "x 1e5" multiplier on linear axes;
    on log axes numbers instead of powers of ten, with the 2, 3, 4, 6 ticks labelled when the axis
    spans less than two decades (matplotlib's default formatters only; a formatter set by hand stays)."""
    from matplotlib.ticker import LogFormatterMathtext, LogFormatterSciNotation, ScalarFormatter

    for axis in (ax.xaxis, ax.yaxis):
        formatter = axis.get_major_formatter()
        if isinstance(formatter, ScalarFormatter):
            formatter.set_useOffset(False)
        elif type(formatter) in (LogFormatterSciNotation, LogFormatterMathtext):
            axis.set_major_formatter(_plain_log_formatter(labelOnlyBase=False))
            if type(axis.get_minor_formatter()) in (LogFormatterSciNotation, LogFormatterMathtext):
                axis.set_minor_formatter(_plain_log_formatter(labelOnlyBase=False, minor_thresholds=(2, 0.5)))


def flat_value(values, rel=FLAT_REL):
    """The value a series is constant at to round-off, or None if it varies.

    Parameters
    ----------
    values : array_like
        The series (non-finite entries are ignored).
    rel : float
        Largest spread, relative to the largest magnitude, counted as round-off.

    Returns
    -------
    float or None
        The mean of the finite values when max - min <= rel * max |value| (and they are not all
        exactly equal, which needs no help); else None.
    """
    v = np.asarray(values, float)
    v = v[np.isfinite(v)]
    if v.size < 2:
        return None
    spread, scale = float(v.max() - v.min()), float(np.max(np.abs(v)))
    if spread == 0.0 or spread > rel * scale:
        return None
    return float(v.mean())


def _flatten_round_off(ax):
    """Draw an axis whose data lines are constant to round-off as a flat line with the value stated."""
    from matplotlib.collections import QuadMesh
    from matplotlib.image import AxesImage

    if ax.get_yscale() != "linear" or any(isinstance(c, (QuadMesh, AxesImage)) for c in ax.get_children()):
        return
    lines = [line for line in ax.get_lines() if line.get_transform() == ax.transData]
    if not lines:
        return
    y = np.concatenate([np.asarray(line.get_ydata(), float).ravel() for line in lines])
    value = flat_value(y)
    if value is None:
        return
    finite = y[np.isfinite(y)]
    half = 0.05 * abs(value) or 1.0
    ax.set_ylim(value - half, value + half)
    ax.text(0.5, 0.55, f"constant: {value:.8g}\n(spread {finite.max() - finite.min():.2g}, "
                       f"{(finite.max() - finite.min()) / abs(value):.0e} of the value: round-off)",
            transform=ax.transAxes, ha="center", va="bottom", fontsize=8,
            bbox={"boxstyle": "round", "fc": "white", "ec": "0.7"})


def _legend_outside(ax, renderer):
    """Move a legend placed inside ``ax`` to its right; returns the width it takes [inches] (0 if none moved)."""
    legend = ax.get_legend()
    if legend is None or getattr(legend, "_bbox_to_anchor", None) is not None:
        return 0.0
    handles = list(getattr(legend, "legend_handles", None) or getattr(legend, "legendHandles", []))
    labels = [textwrap.fill(t.get_text(), LEGEND_WRAP) for t in legend.get_texts()]
    size = legend.get_texts()[0].get_fontsize() if labels else 8
    title = legend.get_title().get_text()
    legend.remove()
    moved = ax.legend(handles, labels, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0,
                      fontsize=size, title=title or None, title_fontsize=size)
    return moved.get_window_extent(renderer).width / ax.figure.dpi + 0.1


def _wrap(text_artist, width_px, renderer):
    """Wrap a title to ``width_px`` pixels (measured with the renderer)."""
    text = text_artist.get_text()
    if not text:
        return
    actual = text_artist.get_window_extent(renderer).width
    if actual <= width_px:
        return
    longest = max(len(line) for line in text.split("\n"))
    chars = max(20, int(longest * width_px / actual * 0.95))
    text_artist.set_text("\n".join(textwrap.fill(line, chars) for line in text.split("\n")))


def finish(fig):
    """Apply the shared conventions (module docstring) to ``fig``; returns it. Safe to call twice."""
    renderer = fig.canvas.get_renderer()
    widths = {}
    for ax in fig.axes:
        plain_numbers(ax)
        _flatten_round_off(ax)
        spec = ax.get_subplotspec()
        column = spec.colspan.stop if spec is not None else 0
        widths[column] = max(widths.get(column, 0.0), _legend_outside(ax, renderer))
    extra = sum(widths.values())
    if extra:
        fig.set_figwidth(fig.get_figwidth() + extra)
    for ax in fig.axes:
        _wrap(ax.title, 0.85 * ax.get_position().width * fig.get_figwidth() * fig.dpi, renderer)
    if getattr(fig, "_suptitle", None) is not None:
        _wrap(fig._suptitle, 0.95 * fig.get_figwidth() * fig.dpi, renderer)
    return fig


def overrides_of(scene):
    """The values of ``scene`` that differ from its file: ``{"part.key": value as written}``.

    A run keeps the scene it was made from (``run.model.scene``, ``result.scene``), and that scene
    keeps its raw tables and its file; comparing the two gives the overrides of the run (``--set``,
    ``overrides=``, a sweep's fixed values) without any bookkeeping. The ``[uncertainty]`` table is
    left out (robust runs and studies drop it on purpose). Empty for a scene made without a file.
    """
    if scene is None or getattr(scene, "path", None) is None or not scene.path.is_file():
        return {}
    try:
        _, original = read_toml(scene.path, "models", "scene")
    except Exception:      # noqa: BLE001 - the file changed or vanished since: no overrides to show
        return {}
    changed = {}
    for part in sorted(set(original) | set(scene.raw)):
        if part == "uncertainty":
            continue
        old, new = original.get(part, {}), scene.raw.get(part, {})
        if not isinstance(old, dict) or not isinstance(new, dict):
            continue
        for key in sorted(set(old) | set(new)):
            if old.get(key) != new.get(key):
                changed[f"{part}.{key}"] = new.get(key, "(removed)")
    return changed


def format_overrides(overrides):
    """``{"oil.viscosity": "80 cSt"}`` -> ``"--set oil.viscosity=80 cSt"`` ("" when there are none)."""
    return ", ".join(f"--set {k}={v}" for k, v in overrides.items())


def scene_title(scene, what, overrides=None):
    """``"zhang2021 (--set oil.viscosity=80 cSt): speeds"``: the scene, the overrides of its run, what is drawn.

    ``overrides`` default to :func:`overrides_of` the scene; ``scene`` may be a name (str) when no
    scene object is at hand (then only ``overrides`` given are shown).
    """
    name = scene if isinstance(scene, str) else scene.name
    if overrides is None:
        overrides = {} if isinstance(scene, str) else overrides_of(scene)
    text = format_overrides(overrides)
    return f"{name} ({text}): {what}" if text else f"{name}: {what}"


def clip_spike(ax, t, y, window, *, what="spike", unit=""):
    """Scale the y axis of ``ax`` to ``y`` outside the time window of a short spike and say how
    large the spike is.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    t, y : array_like
        The drawn series (several series may be clipped one after the other: the limits only grow).
    window : tuple of float
        (start, end) of the spike [s].
    what, unit : str
        Name of the spike and unit of ``y``, for the note.

    Returns
    -------
    float or None
        The largest |y| inside the window if it lies off the scale (and was annotated), else None.
    """
    t, y = np.asarray(t, float), np.asarray(y, float)
    inside = (t >= window[0]) & (t <= window[1])
    outside = ~inside & np.isfinite(y)
    if not inside.any() or not outside.any():
        return None
    lo, hi = float(y[outside].min()), float(y[outside].max())
    pad = 0.08 * (hi - lo or abs(hi) or 1.0)
    lo, hi = lo - pad, hi + pad
    if getattr(ax, "_clip_limits", None):
        lo, hi = min(lo, ax._clip_limits[0]), max(hi, ax._clip_limits[1])
    ax._clip_limits = (lo, hi)
    ax.set_ylim(lo, hi)
    k = np.flatnonzero(inside)[np.argmax(np.abs(y[inside]))]
    peak = float(y[k])
    if lo <= peak <= hi:
        return None
    edge = hi if peak > hi else lo
    ax.annotate(f"{what} at t = {t[k]:.3g} s: {peak:.3g} {unit} (off scale)".replace(" )", ")"),
                xy=(t[k], edge), xytext=(12, -14 if peak > hi else 14), textcoords="offset points",
                fontsize=8, ha="left", va="top" if peak > hi else "bottom",
                arrowprops={"arrowstyle": "->", "color": "0.3", "lw": 0.8})
    return abs(peak)


def ticks_at(axis, values, scale=1.0, most=9):
    """Put the ticks of ``axis`` (an x or y axis) at the sampled ``values`` times ``scale``
    (every k-th value when there are more than ``most``), labelled with their own digits."""
    values = np.unique(np.asarray(values, float)) * scale
    if not values.size:
        return
    step = max(1, math.ceil(values.size / most))
    shown = values[::step]
    axis.set_ticks(shown, [f"{v:.4g}" for v in shown])
