"""The figures of ``clutchocp robust``: jump against the uncertain fields, distributions, envelopes."""

import textwrap

import numpy as np

from ..output import new_figure, save_figure
from .montecarlo import HISTORY_STEP

COLOURS = {"baseline": "tab:gray", "nominal_optimum": "tab:blue", "robust_feedforward": "tab:green",
           "closed_loop": "tab:red"}


def _label(key):
    return {"friction.mu": "friction coefficient [-]", "oil.viscosity": "oil viscosity [Pa s]",
            "load.torque": "load torque [N m]"}.get(key, key)


def plot_jump_vs_fields(out, rows, uncertainty, strategies, target=None):
    """|jump| at lock-up against each numeric uncertain field, one panel per field; no-lock samples on top
    (dashed: the closed loop's 95th-percentile target ``target`` [%], default 3 %)."""
    target = 3.0 if target is None else target
    numeric = [s.key for s in uncertainty.spreads if s.kind != "values"]
    if not numeric:
        return []
    fig, axes = new_figure(len(numeric), width=4.6, height=4.3)
    values = [r["jump_pct"] for r in rows if r["jump_pct"] is not None]
    floor = max(min(values + [2.0]) * 0.5, 1e-3)
    top = max(values + [1.0]) * 2.0
    for ax, key in zip(axes, numeric):
        for s in strategies:
            mine = [r for r in rows if r["strategy"] == s.name]
            x = [r[key] for r in mine if r["jump_pct"] is not None]
            y = [max(r["jump_pct"], floor) for r in mine if r["jump_pct"] is not None]
            ax.scatter(x, y, s=9, alpha=0.6, color=COLOURS.get(s.name), label=s.label)
            miss = [r[key] for r in mine if r["jump_pct"] is None]
            if miss:
                ax.scatter(miss, [top] * len(miss), marker="x", s=18, color=COLOURS.get(s.name))
        ax.axhline(target, color="k", lw=0.8, ls="--")
        ax.set_xlabel(_label(key))
        ax.set_ylabel("|torque jump at lock-up| [% of locked torque]")
        ax.set_yscale("log")
        ax.set_ylim(floor, top * 1.5)
        ax.grid(alpha=0.3, which="both")
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower center", ncol=len(strategies), fontsize=8)
    fig.suptitle(f"Torque jump at lock-up over {len({r['sample'] for r in rows})} samples "
                 f"(x at the top: no lock-up; dashed: {target:g} %)", fontsize=10)
    return [save_figure(fig, out / "jump_vs_fields.png")]


def plot_distributions(out, rows, strategies, t_max, target=None):
    """Box plots per strategy: |jump| [% of locked torque] and engagement time [s] (with t_max); dashed: the
    closed loop's 95th-percentile target ``target`` [%] (default 3 %)."""
    target = 3.0 if target is None else target
    fig, (ax1, ax2) = new_figure(2, width=5.6, height=4.6)
    names = [s.name for s in strategies]
    share = {n: 100 * np.mean([r["locked_within_t_max"] for r in rows if r["strategy"] == n]) for n in names}
    labels = [textwrap.fill(s.label, 22) + f"\nlocked in t_max: {share[s.name]:.0f} %" for s in strategies]
    for ax, key, title in ((ax1, "jump_pct", "|torque jump at lock-up| [% of locked torque]"),
                           (ax2, "engagement_time_s", "lock-up time [s]")):
        data = [[max(r[key], 1e-3) for r in rows if r["strategy"] == n and r[key] is not None] or [np.nan]
                for n in names]
        box = ax.boxplot(data, whis=(5, 95), showfliers=True, patch_artist=True)
        for patch, n in zip(box["boxes"], names):
            patch.set_facecolor(COLOURS.get(n, "white"))
            patch.set_alpha(0.5)
        ax.set_xticks(range(1, len(names) + 1), labels, fontsize=7)
        ax.set_ylabel(title)
        ax.grid(alpha=0.3, axis="y")
    ax1.axhline(target, color="k", lw=0.8, ls="--", label=f"{target:g} %")
    ax1.set_yscale("log")
    ax1.set_ylim(bottom=min(ax1.get_ylim()[0], 1.0))
    ax1.legend(fontsize=7)
    ax2.axhline(t_max, color="k", lw=0.8, ls="--", label=f"t_max = {t_max:.3f} s")
    ax2.legend(fontsize=7)
    fig.suptitle("Distributions per strategy (box: quartiles, whiskers: 5-95 %; share locked within t_max "
                 "under each name)", fontsize=10)
    return save_figure(fig, out / "distributions.png")


def plot_envelopes(out, rows, centre, strategies, t_max):
    """Envelopes (min-max and 5-95 %) of slip, clutch torque and pressure over time, per strategy."""
    signals = (("w_rel_rad_s", "slip speed [rad/s]", 1.0), ("total_torque_Nm", "clutch torque [N m]", 1.0),
               ("pressure_Pa", "clutch pressure [MPa]", 1e-6))
    fig, axes = new_figure(len(strategies), width=3.6, height=7.5)
    fig.clear()
    grid = fig.add_gridspec(len(signals), len(strategies))
    for j, s in enumerate(strategies):
        mine = [r for r in rows if r["strategy"] == s.name]
        nominal = next((r for r in centre if r["strategy"] == s.name), None)
        for i, (key, label, scale) in enumerate(signals):
            ax = fig.add_subplot(grid[i, j])
            data = np.array([r["history"][key] for r in mine]) * scale
            t = np.arange(data.shape[1]) * HISTORY_STEP
            colour = COLOURS.get(s.name, "tab:blue")
            ax.fill_between(t, data.min(0), data.max(0), color=colour, alpha=0.2, lw=0, label="min-max")
            ax.fill_between(t, np.percentile(data, 5, 0), np.percentile(data, 95, 0), color=colour, alpha=0.45,
                            lw=0, label="5-95 %")
            if nominal is not None:
                ax.plot(t, nominal["history"][key] * scale, color="k", lw=0.9, label="nominal clutch")
            ax.axvline(t_max, color="k", lw=0.6, ls="--")
            ax.grid(alpha=0.3)
            if i == 0:
                ax.set_title(textwrap.fill(s.label, 48), fontsize=8)
            if j == 0:
                ax.set_ylabel(label)
            if i == len(signals) - 1:
                ax.set_xlabel("time [s]")
            if i == 0 and j == 0:
                ax.legend(fontsize=6)
    fig.suptitle(f"Time histories over {len({r['sample'] for r in rows})} samples (dashed: t_max)", fontsize=10)
    return save_figure(fig, out / "envelopes.png")
