"""Analogues of Bao et al. 2020 (Processes 8, 1474), Figs 9-14, from the bao2020 scene (or from
bao2020_as_published, Bao's Eqs. 19, 20 and 26 as printed: ``--scene bao2020_as_published``).

Fig. 9   film thicknesses h1(t), h2(t)
Fig. 10  viscous, asperity-contact and total friction torque
Fig. 11  spring preload:             output speed, friction torque, film thickness
Fig. 12  oil viscosity:              the same three
Fig. 13  collision velocity (free piston travel 0.5 mm, or none with the preload 0.5 mm shorter so
         that the spring force at first contact is the same): the same three
Fig. 14  friction-plate mass:        the same three

The model's trends are discussed in tests/test_engagement_trends.py (viscosity, plate mass and
collision velocity do not come out as in the paper; the reasons are given there).

Usage::

    python examples/bao2020_figures.py --out figures/bao2020
    python examples/bao2020_figures.py --scene bao2020_as_published --out figures/bao2020_as_published
"""

import argparse
import time
from pathlib import Path

import numpy as np

from clutchocp.engagement.run import simulate_engagement
from clutchocp.output import new_figure, save_figure
from clutchocp.scene.loader import load_scene

SWEEPS = {
    "fig11_spring_preload": ("spring compression", [("36 mm", {"piston.spring_preload": "0.036 m"}),
                                                    ("40 mm (Table 1)", {}),
                                                    ("44 mm", {"piston.spring_preload": "0.044 m"})]),
    "fig12_viscosity": ("oil viscosity", [("0.015 Pa s", {"oil.viscosity": "0.015 Pa s"}),
                                          ("0.020 Pa s (Table 1)", {}),
                                          ("0.025 Pa s", {"oil.viscosity": "0.025 Pa s"})]),
    "fig13_collision_velocity": ("collision", [("initial velocity included (0.5 mm free travel)", {}),
                                               ("not included (at the pack, preload 39.5 mm: same spring force)",
                                                {"piston.travel_to_pack": "0 m", "piston.spring_preload": "0.0395 m"})]),
    "fig14_friction_plate_mass": ("friction plate mass", [("0.2 kg", {"pack.plate_masses": ["0.367 kg", "0.2 kg"]}),
                                                          ("0.367 kg (Table 1)", {}),
                                                          ("0.6 kg", {"pack.plate_masses": ["0.367 kg", "0.6 kg"]})]),
}


# All cases lock up before 0.5 s on bao2020 and 0.9 s on bao2020_as_published: run to 1 s with 0.1 ms
# output spacing (the scenes: 3 s, 1.5 ms).
T_END, OUTPUT_POINTS = 1.0, 10001


def engage(scene):
    return simulate_engagement(scene, t_end=T_END, output_points=OUTPUT_POINTS)


def window(run, margin=1.15):
    """Samples up to a little after lock-up (the locked tail to t_end says nothing new)."""
    t_lock = run.summary["engagement_time_s"] or run.result.t[-1]
    return run.result.t <= margin * t_lock


def fig9(run, out):
    res, keep = run.result, window(run)
    fig, (ax,) = new_figure()
    for i in range(run.model.n):
        ax.plot(res.t[keep] * 1e3, res[f"h_{i + 1}_m"][keep] * 1e6, label=f"h{i + 1}(t)")
    ax.set(xlabel="time [ms]", ylabel="oil film thickness [um]", title=f"Fig. 9 analogue ({run.model.scene.name}): film thicknesses",
           xscale="symlog", yscale="log")
    ax.set_xscale("symlog", linthresh=0.1)
    ax.set_xlim(left=0)
    ax.legend()
    return save_figure(fig, out / "fig09_film_thickness.png")


def fig10(run, out):
    res, keep = run.result, window(run)
    fig, (ax,) = new_figure()
    ax.plot(res.t[keep], res["viscous_torque_Nm"][keep], label="viscous torque")
    ax.plot(res.t[keep], res["contact_torque_Nm"][keep], label="rough contact torque")
    ax.plot(res.t[keep], res["total_torque_Nm"][keep], "k", lw=1.5, label="total friction torque")
    ax.axvline(run.summary["engagement_time_s"], color="0.5", ls="--", lw=0.8, label="lock-up")
    ax.set(xlabel="time [s]", ylabel="torque [N m]", title=f"Fig. 10 analogue ({run.model.scene.name}): friction torque")
    ax.legend(fontsize=8)
    return save_figure(fig, out / "fig10_friction_torque.png")


def sweep_figure(name, label, runs, out):
    """Three panels: output speed, total friction torque, film thickness h1."""
    fig, axes = new_figure(3, width=4.6, height=3.8)
    for text, run in runs:
        res, keep = run.result, window(run, 1.3)
        t_lock = run.summary["engagement_time_s"]
        line, = axes[0].plot(res.t[keep], res["w_out_rad_s"][keep] * 30 / np.pi, label=f"{text}: {t_lock:.3f} s")
        axes[1].plot(res.t[keep], res["total_torque_Nm"][keep], color=line.get_color())
        axes[2].plot(res.t[keep] * 1e3, res["h_1_m"][keep] * 1e6, color=line.get_color())
    axes[0].set(xlabel="time [s]", ylabel="output speed [rpm]", title="(a) output speed")
    axes[1].set(xlabel="time [s]", ylabel="friction torque [N m]", title="(b) friction torque")
    axes[2].set(xlabel="time [ms]", ylabel="film thickness h1 [um]", title="(c) film thickness", yscale="log")
    axes[2].set_xscale("symlog", linthresh=0.1)
    axes[2].set_xlim(left=0)
    axes[0].legend(fontsize=7, title=f"{label}: engagement time", title_fontsize=7)
    fig.suptitle(f"Fig. {name[3:5]} analogue ({runs[0][1].model.scene.name}): effect of {label}")
    return save_figure(fig, out / f"{name}.png")


def main(argv=None):
    parser = argparse.ArgumentParser(description="Bao 2020 Figs 9-14 analogues from the bao2020 scene")
    parser.add_argument("--out", default="bao2020_figures", help="output directory for the PNG files")
    parser.add_argument("--scene", default="bao2020", choices=("bao2020", "bao2020_as_published"),
                        help="bao2020, or bao2020_as_published (Bao's Eqs. 19, 20 and 26 as printed)")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    scene = load_scene(args.scene)
    base = engage(scene)
    files = [fig9(base, out), fig10(base, out)]
    for name, (label, cases) in SWEEPS.items():
        runs = [(text, base if not overrides else engage(scene.with_overrides(overrides)))
                for text, overrides in cases]
        files.append(sweep_figure(name, label, runs, out))
        print(f"{name}: " + ", ".join(f"{text} -> {run.summary['engagement_time_s']:.4f} s, "
                                       f"lock-up jump {run.summary['lockup_torque_jump_Nm']:.0f} N m"
                                       for text, run in runs))
    print(f"wrote {len(files)} figures to {out} in {time.perf_counter() - start:.1f} s")
    return files


if __name__ == "__main__":
    main()
