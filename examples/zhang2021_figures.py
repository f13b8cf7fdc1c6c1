"""Analogues of Zhang et al. 2021 (Shock and Vibration), Figs 3-7, from the zhang2021 scene.

Fig. 3  pressure hysteresis time t_s: applied pressure P_s(t), transmitted torque T(t), and the
        torque response time against the pressure response time
Fig. 4  lubricant viscosity           } torque response time against pressure response time,
Fig. 5  friction-lining permeability  } the pressure response time swept through
Fig. 6  equivalent elastic modulus    } t_s = 0.02, 0.04, 0.06, 0.08, 0.1 s (2.197 t_s, Zhang
Fig. 7  combined roughness RMS        } Section 3) for three values of each parameter

Response times as Zhang defines them (summary keys ``pressure_response_time_s`` and
``torque_response_time_stable_s``): pressure 10 % -> 90 % of P_o; torque from 50 % of P_o to 90 % of
the stable transmitted torque (the asperity torque once the film has drained, f_c P_o A r_eff). Which
of the paper's trends the model reproduces, and why not the others, is in
tests/test_engagement_trends.py.

Usage::

    python examples/zhang2021_figures.py --out figures/zhang2021
"""

import argparse
import time
from pathlib import Path

from clutchocp.engagement.run import simulate_engagement
from clutchocp.output import new_figure, save_figure
from clutchocp.scene.loader import load_scene

LAGS = (0.02, 0.04, 0.06, 0.08, 0.1)                 # t_s [s], Zhang Section 3
# The asperity torque settles within 0.2 s at t_s = 0.02 s and the pressure is within 5e-5 of P_o after
# 1 s at t_s = 0.1 s; the disc locks after ~5 s: 1 s at 0.5 ms spacing is enough for the response
# times (the scene: 6 s at 3 ms).
T_END, OUTPUT_POINTS = 1.0, 2001
SWEEPS = {
    "fig04_viscosity": ("lubricant viscosity", "oil.viscosity",
                        [("0.02 Pa s", "0.02 Pa s"), ("0.0681 Pa s (Table 1)", None), ("0.12 Pa s", "0.12 Pa s")]),
    "fig05_permeability": ("friction lining permeability", "plates.lining_permeability",
                           [("1e-12 m^2", "1e-12 m^2"), ("4e-12 m^2 (Table 1)", None), ("1e-11 m^2", "1e-11 m^2")]),
    "fig06_elastic_modulus": ("equivalent elastic modulus", "contact.E_equiv",
                              [("10 MPa", "1e7 Pa"), ("27 MPa (Table 1)", None), ("100 MPa", "1e8 Pa")]),
    "fig07_roughness": ("combined roughness RMS", "roughness.sigma",
                        [("6 um", "6e-6 m"), ("8.41 um (Table 1)", None), ("12 um", "1.2e-5 m")]),
}


def engage(scene, t_s):
    return simulate_engagement(scene.with_overrides({"actuation.time_constant": t_s}),
                               t_end=T_END, output_points=OUTPUT_POINTS)


def response_curve(scene):
    """(pressure response times, torque response times, runs) over the lag sweep."""
    runs = [engage(scene, t_s) for t_s in LAGS]
    return ([r.summary["pressure_response_time_s"] for r in runs],
            [r.summary["torque_response_time_stable_s"] for r in runs], runs)


def fig3(scene, out):
    dt_p, dt_t, runs = response_curve(scene)
    fig, axes = new_figure(3, width=4.6, height=3.8)
    for t_s, run in zip(LAGS, runs):
        res = run.result
        keep = res.t <= 0.5
        line, = axes[0].plot(res.t[keep], res["pressure_Pa"][keep] / 1e6, label=f"t_s = {t_s:g} s")
        axes[1].plot(res.t[keep], res["total_torque_Nm"][keep], color=line.get_color())
        axes[1].plot(res.t[keep], res["contact_torque_Nm"][keep], color=line.get_color(), ls="--")
    axes[2].plot(dt_p, dt_t, "o-")
    axes[0].set(xlabel="time [s]", ylabel="applied pressure P_s [MPa]", title="(a) applied pressure")
    axes[1].set(xlabel="time [s]", ylabel="transmitted torque [N m]",
                title="(b) total (solid), asperity (dashed)")
    axes[2].set(xlabel="pressure response time [s]", ylabel="torque response time [s]",
                title="(c) to 90 % of the stable torque")
    axes[0].legend(fontsize=7)
    fig.suptitle("Fig. 3 analogue: effect of the pressure hysteresis time")
    return save_figure(fig, out / "fig03_pressure_lag.png"), (dt_p, dt_t)


def sweep_figure(name, label, curves, out):
    fig, (ax,) = new_figure()
    for text, (dt_p, dt_t) in curves:
        ax.plot(dt_p, dt_t, "o-", label=text)
    ax.set(xlabel="pressure response time [s]", ylabel="torque response time (to 90 % of the stable torque) [s]",
           title=f"Fig. {int(name[3:5])} analogue: effect of {label}")
    ax.legend(fontsize=8)
    return save_figure(fig, out / f"{name}.png")


def main(argv=None):
    parser = argparse.ArgumentParser(description="Zhang 2021 Figs 3-7 analogues from the zhang2021 scene")
    parser.add_argument("--out", default="zhang2021_figures", help="output directory for the PNG files")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    scene = load_scene("zhang2021")
    path, base_curve = fig3(scene, out)
    files = [path]
    print("fig03: torque response " + ", ".join(f"{t:.4f}" for t in base_curve[1]) + " s for t_s = "
          + ", ".join(f"{t:g}" for t in LAGS) + " s")
    for name, (label, key, cases) in SWEEPS.items():
        curves = []
        for text, value in cases:
            dt_p, dt_t, _ = response_curve(scene.with_overrides({key: value})) if value else (*base_curve, None)
            curves.append((text, (dt_p, dt_t)))
            print(f"{name}: {text}: torque response " + ", ".join(f"{t:.4f}" for t in dt_t) + " s")
        files.append(sweep_figure(name, label, curves, out))
    print(f"wrote {len(files)} figures to {out} in {time.perf_counter() - start:.1f} s")
    return files


if __name__ == "__main__":
    main()
