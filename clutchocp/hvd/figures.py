"""The figures of ``clutchocp control``: static map, loop Bode plots, linear steps, nonlinear closed loop."""

import numpy as np
from matplotlib.ticker import FormatStrFormatter, LogLocator, NullFormatter

from ..output import new_figure, save_figure
from .design import frequency_response, pressure_limits
from .workflow import linear_step


def draw_control(out, result):
    """static_map.png, bode.png, step.png (linear closed loops) and closed_loop.png of a :class:`ControlRun`.

    Returns
    -------
    list of pathlib.Path
    """
    model, spec, sched, run, data, scenario = (result.model, result.spec, result.design, result.closed_loop,
                                               result.map_data, result.scenario)
    files = []
    rated = model.rated_speed
    # static map
    fig, (a1, a2) = new_figure(2, width=5.2)
    inside = data["within_valve_range"] > 0
    a1.plot(data["pressure_Pa"] / 1e6, data["speed_rad_s"] / rated * 100, "-", color="0.6", label="outside valve range")
    a1.plot(data["pressure_Pa"][inside] / 1e6, data["speed_rad_s"][inside] / rated * 100, "-", lw=2, label="in range")
    a1.plot([p.point.pressure / 1e6 for p in sched.points], [100 * p.point.speed / rated for p in sched.points],
            "ko", mfc="none", label="scheduled points")
    for k, lim in enumerate((model.p_min, model.p_max)):
        a1.axvline(lim / 1e6, color="0.5", ls=":", lw=0.8, label="valve limits" if k == 0 else None)
    a1.set(xlabel="control pressure [MPa]", ylabel="output speed [% rated]", title=f"{model.scene.name}: static map")
    a1.legend(fontsize=8)
    a2.plot(data["film_ratio"], data["viscous_torque_Nm"], label="viscous")
    a2.plot(data["film_ratio"], data["contact_torque_Nm"], label="asperity")
    a2.set_xscale("log")
    a2.xaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))   # a log axis over less than a decade
    a2.xaxis.set_major_formatter(FormatStrFormatter("%g"))            # showed one label only
    a2.xaxis.set_minor_formatter(NullFormatter())
    a2.set(xlabel="film ratio h/sigma [-] (first film)", ylabel="torque [N m]", title="viscous to mixed friction")
    a2.legend(fontsize=8)
    for ax in (a1, a2):
        ax.grid(alpha=0.3)
    files.append(save_figure(fig, out / "static_map.png"))
    # Bode of the loop at every scheduled point
    fig, (a1, a2) = new_figure(2, width=5.2)
    for p in sched.points:
        omega = np.geomspace(1e-3, np.pi / spec.sample_time, 600)
        L = frequency_response(p.loop, omega)
        a1.loglog(omega, np.abs(L), label=f"{p.fraction:g} rated")
        a2.semilogx(omega, np.degrees(np.unwrap(np.angle(L))))
    a1.axhline(1.0, color="0.5", lw=0.8)
    a2.axhline(-180.0, color="0.5", lw=0.8)
    a1.set(xlabel="frequency [rad/s]", ylabel="|L|", title=f"loop gain ({spec.label}, broken at the plant input)")
    a2.set(xlabel="frequency [rad/s]", ylabel="phase of L [deg]", title="loop phase")
    a1.legend(fontsize=7)
    for ax in (a1, a2):
        ax.grid(alpha=0.3, which="both")
    files.append(save_figure(fig, out / "bode.png"))
    # linear closed-loop steps (reference filter included)
    fig, (ax,) = new_figure()
    t = np.arange(0.0, 10.0, spec.sample_time)
    for p in sched.points:
        y = linear_step(p, sched.controller, spec, t)
        ax.plot(t, y, label=f"{p.fraction:g} rated")
    ax.set(xlabel="time [s]", ylabel="speed / setpoint step [-]", title="linear closed loop, unit setpoint step")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    files.append(save_figure(fig, out / "step.png"))
    # nonlinear closed loop
    s = run.series
    fig, axes = new_figure(3, width=4.6)
    axes[0].plot(s["t"], s["w"] / rated * 100, label="speed")
    axes[0].plot(s["t"], s["setpoint"] / rated * 100, "k:", lw=1, label="setpoint")
    axes[0].plot(s["t"], s["reference"] / rated * 100, "--", lw=1, label="filtered reference")
    axes[0].set(xlabel="time [s]", ylabel="output speed [% rated]", title=f"{model.scene.name}, {spec.label}")
    axes[0].legend(fontsize=8)
    axes[1].plot(s["t"], s["command"] / 1e6, label="command")
    axes[1].plot(s["t"], s["p"] / 1e6, label="valve pressure")
    p_lo, p_hi = pressure_limits(model, spec)
    axes[1].axhline(p_hi / 1e6, color="C3", ls="--", lw=0.8, label=f"valve limits {p_lo / 1e6:.3g} / {p_hi / 1e6:.3g} MPa")
    axes[1].axhline(p_lo / 1e6, color="C3", ls="--", lw=0.8)
    axes[1].set(xlabel="time [s]", ylabel="pressure [MPa]", title="control pressure")
    axes[1].legend(fontsize=8)
    for name in model.film_names:
        axes[2].semilogy(s["t"], s[name] * 1e6, label=name)
    axes[2].set(xlabel="time [s]", ylabel="film [um]", title="film thickness")
    step = spec.scenario["load_step"]
    for ax in axes:
        ax.grid(alpha=0.3)
        for k, t_step in enumerate(scenario.load_times):
            ax.axvline(t_step, color="0.3", ls=":", lw=1.0,
                       label=f"load steps: +{100 * step:g} %, then -{100 * step:g} % of the fan torque" if k == 0
                       else None)
    for ax in axes[:2]:
        ax.legend(fontsize=7)
    files.append(save_figure(fig, out / "closed_loop.png"))
    return files
