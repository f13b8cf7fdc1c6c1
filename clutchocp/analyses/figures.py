"""The figures of ``clutchocp validate``: each analysis's numbers (:class:`AnalysisResult.figure_data`) drawn."""

from pathlib import Path

import numpy as np

from clutchocp.analyses.chen2021 import FIG7_SPLINE_COF, TABLE3_TORQUE, reference_values
from clutchocp.analyses.cui2019 import TABLE1_COF, TABLE1_PRESSURE
from clutchocp.analyses.liao2021 import MM, SWEEP_LABELS
from clutchocp.output import new_figure, save_figure
from clutchocp.physics.friction import mu_cui2019


def draw(result, out_dir):
    """The PNG files of one analysis's result, written into ``out_dir``; returns their paths."""
    return FIGURES[result.name](Path(out_dir), **result.figure_data)


def chen2021_figures(out_dir, res, bench):
    """Pressure attenuation (Fig. 7 analogue), pack torque against Tables 2-3 and Fig. 8 analogue."""
    p, cofs = res["pressures"], res["spline_cofs"]
    files = []
    fig, (ax,) = new_figure()
    fp = res["fig_pressures"]
    idx = np.arange(1, fp.shape[0] + 1)
    for j, p0 in enumerate(p):
        ax.plot(np.r_[0, idx], np.r_[p0, fp[:, j]] / 1e6, "o-", ms=3, label=f"p0 = {p0 / 1e6:g} MPa")
    ax.set_xlabel("friction pair (interface) number (0 = piston)")
    ax.set_ylabel("contact pressure [MPa]")
    ax.set_title(f"Pressure attenuation, spline COF {FIG7_SPLINE_COF} (Chen 2021 Fig. 7 analogue)")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    files.append(save_figure(fig, out_dir / "chen2021_attenuation.png"))

    fig, (ax1, ax2) = new_figure(2, width=5.2)
    for k, mu_s in enumerate(cofs):
        line, = ax1.plot(p / 1e6, res["torque"][k], "o-", label=f"clutchocp, mu_fs = {mu_s:g}")
        ref = reference_values(TABLE3_TORQUE, p, mu_s)
        if np.isfinite(ref).any():
            ax1.plot(p / 1e6, ref, "x", color=line.get_color(), ms=9, label=f"Chen Table 3, mu_fs = {mu_s:g}")
    ax1.plot(p / 1e6, bench, "ks", mfc="none", label="bench T6* (Table 2)")
    ax1.set_xlabel("applied pressure [MPa]")
    ax1.set_ylabel("six-pair torque [N m]")
    ax1.set_title("Pack torque vs Chen 2021 Tables 2-3")
    ax1.legend(fontsize=8)
    ax1.grid(alpha=0.3)
    for j, p0 in enumerate(p):
        line, = ax2.plot(idx, res["fig_torque"][:, j], "-", label=f"{p0 / 1e6:g} MPa")
        ax2.plot(idx, res["fig_torque_none"][:, j], "--", color=line.get_color())
    ax2.set_xlabel("number of friction pairs")
    ax2.set_ylabel("torque [N m]")
    ax2.set_title("Spline friction (solid) / none (dashed), Fig. 8 analogue")
    ax2.legend(fontsize=8)
    ax2.grid(alpha=0.3)
    files.append(save_figure(fig, out_dir / "chen2021_torque.png"))
    return files


def cui2019_figures(out_dir, r):
    """Eq. 18 against Table 1, film and contact (Figs 12-13), torques (Figs 14-16) analogues."""
    files = []
    lam = r["film_ratio"]
    fig, (a1, a2, a3) = new_figure(3, width=4.2)
    p = np.linspace(0, 1.1e6, 200)
    a1.plot(TABLE1_PRESSURE / 1e6, TABLE1_COF, "ks", mfc="none", label="Cui Table 1")
    a1.plot(p / 1e6, mu_cui2019(p), "-", label="Cui Eq. 18")
    a1.set_xlabel("contact pressure [MPa]")
    a1.set_ylabel("contact friction coefficient [-]")
    a1.set_title("Eq. 18 vs Table 1 (Fig. 8 analogue)")
    a1.legend(fontsize=8)
    a2.plot(lam, r["h"] * 1e6, "k--", label="nominal h")
    a2.plot(lam, r["h_T"] * 1e6, "-", label="h_T exact (Gaussian)")
    a2.plot(lam, r["h_T_patir"] * 1e6, ":", label="h_T Cui Eq. 1")
    a2.set_xlabel("film thickness ratio lambda [-]")
    a2.set_ylabel("film thickness [um]")
    a2.set_title("Fig. 12 analogue")
    a2.legend(fontsize=8)
    a3.plot(lam, r["area_ratio"], "-")
    a3.set_xlabel("film thickness ratio lambda [-]")
    a3.set_ylabel("contact area ratio k_a [-]")
    a3.set_title("Fig. 13 analogue (Greenwood-Tripp)")
    for ax in (a1, a2, a3):
        ax.grid(alpha=0.3)
    files.append(save_figure(fig, out_dir / "cui2019_film_contact.png"))

    fig, (b1, b2, b3) = new_figure(3, width=4.2)
    b1.plot(lam, r["fluid_torque"], "-")
    b1.set_title("Fluid torque (Fig. 14 analogue)")
    b2.plot(lam, r["asperity_torque"], "-", color="C1")
    b2.set_title("Asperity friction torque (Fig. 15 analogue)")
    b3.plot(lam, r["fluid_torque"], "-", label="fluid")
    b3.plot(lam, r["asperity_torque"], "-", label="asperity")
    b3.plot(lam, r["total_torque"], "k-", lw=2, label="total")
    b3.set_title("Total torque (Fig. 16a analogue)")
    b3.legend(fontsize=8)
    for ax in (b1, b2, b3):
        ax.set_xlabel("film thickness ratio lambda [-]")
        ax.set_ylabel("torque [N m]")
        ax.grid(alpha=0.3)
    files.append(save_figure(fig, out_dir / "cui2019_torque.png"))
    return files


def liao2021_figures(out_dir, cases, t3, n_films):
    """Films and torques per film over the three sweeps (Figs 4-9 analogues) and Table 3."""
    files = []
    idx = np.arange(1, n_films + 1)
    titles = {"groove_depth": "Figs 4/5", "angle_ratio": "Figs 6/7", "k3_over_k1": "Figs 8/9"}
    for what, ylabel, fname, scale in (("films", "film thickness [mm]", "liao2021_films.png", 1 / MM),
                                       ("torques", "viscous torque per film [N m]", "liao2021_torque.png", 1.0)):
        fig, axes = new_figure(3, width=4.2)
        for ax, (name, cs) in zip(axes, cases.items()):
            label, lscale, unit = SWEEP_LABELS[name]
            for c in cs:
                ax.plot(idx, np.asarray(c[what]) * scale, "o-", label=f"{label} = {c['value'] * lscale:g} {unit}")
            ax.set_xlabel("film number (1 = piston side)")
            ax.set_ylabel(ylabel)
            ax.set_title(f"Liao 2021 {titles[name]} analogue")
            ax.legend(fontsize=8)
            ax.grid(alpha=0.3)
        files.append(save_figure(fig, out_dir / fname))
    if t3:
        fig, (ax1, ax2) = new_figure(2, width=4.8)
        ours = np.concatenate([r["alpha"] for r in t3])
        paper = np.concatenate([r["alpha_paper"] for r in t3])
        ax1.plot(paper, ours, "o", ms=4)
        lim = [0, 1.1 * max(ours.max(), paper.max())]
        ax1.plot(lim, lim, "k--", lw=0.8)
        ax1.set_xlabel("alpha_i, Liao Table 3")
        ax1.set_ylabel("alpha_i, clutchocp (first film from Table 3)")
        ax1.set_title("Modified coefficients")
        ax1.grid(alpha=0.3)
        k = np.arange(1, len(t3) + 1)
        ax2.plot(k, [r["torque_test"] for r in t3], "ks", mfc="none", label="test")
        ax2.plot(k, [r["torque_original_paper"] for r in t3], "v", label="original formula (paper)")
        ax2.plot(k, [r["torque_new_paper"] for r in t3], "x", ms=8, label="new formula (paper)")
        ax2.plot(k, [r["torque_new"] for r in t3], "o", mfc="none", label="Eq. 14, clutchocp")
        ax2.set_xlabel("Table 3 row")
        ax2.set_ylabel("overall viscous torque [N m]")
        ax2.set_title("Liao 2021 Table 3")
        ax2.legend(fontsize=8)
        ax2.grid(alpha=0.3)
        files.append(save_figure(fig, out_dir / "liao2021_table3.png"))
    return files


FIGURES = {"chen2021": chen2021_figures, "cui2019": cui2019_figures, "liao2021": liao2021_figures}
