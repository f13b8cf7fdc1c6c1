"""The result of :func:`clutchocp.optimize`: the optimum, its IDAS check and the baselines, at a glance;
the rows of its pressure profile."""

from dataclasses import dataclass, field

import numpy as np

from ..output import save_figure
from ..simulation.result import Table


@dataclass(repr=False)
class OptimizationResult:
    """An optimal engagement pressure with everything needed to judge it.

    Attributes
    ----------
    scene : clutchocp.scene.Scene
    summary : dict
        The numbers written to summary.json by ``clutchocp optimize`` (see the README).
    ocp : clutchocp.optimal.problem.EngagementOCP
        The problem (reuse it for further solves).
    optimum : clutchocp.optimal.problem.OptimalEngagement
        The collocation solution (command, states, terms, IPOPT statistics).
    replay : clutchocp.engagement.run.EngagementResult
        The optimal command re-simulated with IDAS.
    baselines : dict
        ``{label: (EngagementResult, numbers)}`` of the step, ramp and lag profiles.
    curve : clutchocp.optimal.clamp.ClampedCommand
        The whole usable command: the optimum, then the ramp to the clamp pressure and its hold.
    clamp_run : clutchocp.engagement.run.EngagementResult
        IDAS replay of the whole curve (through lock-up and the clamp ramp).
    fill : dict or None
        On a scene with a fill phase: the minimum-time optimum against the tuned "fill pulse, hold,
        ramp" baseline (``summary``, ``optimal_run``, ``baseline_run``); None otherwise.
    figure : callable
        ``figure(result) -> matplotlib.figure.Figure``: the pressure figure of :meth:`plot` (given by
        the ``optimize`` workflow, :func:`clutchocp.optimal.figures.result_figure`).
    """

    scene: object
    summary: dict
    ocp: object
    optimum: object
    replay: object
    baselines: dict = field(default_factory=dict)
    fill: dict = None
    curve: object = None
    clamp_run: object = None
    figure: object = field(default=None, repr=False)

    def __repr__(self):
        s = self.summary
        opt, ver = s["optimal"], s["verification"]
        return (f"OptimizationResult(scene={self.scene.name!r}, {s['solver']['status']}, lock-up "
                f"{opt['engagement_time_s']:.4g} s, jump {opt['lockup_torque_jump_Nm']:.3g} N m, "
                f"jerk integral {opt['jerk_integral']:.4g} rad^2/s^5, IDAS check "
                f"{'passed' if ver['passed'] else 'FAILED'})")

    @property
    def success(self):
        """True if IPOPT converged and the IDAS replay confirmed the lock-up."""
        return bool(self.optimum.success and self.summary["verification"]["passed"])

    def table(self):
        """The whole pressure curve as in pressure_profile.csv: ``time_s``, ``pressure_command_Pa``,
        ``pressure_Pa``, ``phase``, ``to_next``."""
        return Table(profile_columns(self.optimum, self.curve, self.clamp_run))

    def plot(self, path=None):
        """The pressure figure (command, IDAS replay, baseline); saved as PNG if ``path`` is given.

        Returns
        -------
        matplotlib.figure.Figure
        """
        fig = self.figure(self)
        if path is not None:
            save_figure(fig, path)
        return fig


def profile_columns(opt, curve, run):
    """The columns of pressure_profile.csv: {name with unit: array}.

    Rows are the nodes of the piecewise-linear command ``curve`` (the optimum ``opt`` continued by the
    clamp ramp, :class:`~clutchocp.optimal.clamp.ClampedCommand`): ``to_next`` says how the command goes
    on to the next row ("linear") or after the last one ("hold": constant). ``phase`` names the segment a
    row starts: "engagement" before lock-up, "clamp_ramp" from the lock-up row, "clamp_hold" on the last
    row. ``pressure_Pa`` is the pressure the collocation predicts up to lock-up and the IDAS replay of
    the whole curve (``run``) after it.
    """
    times, command = curve.times, curve.pressures
    engaged = times <= opt.t_f
    pressure = np.where(engaged, np.interp(times, opt.t, opt.outputs["pressure_Pa"]),
                        np.interp(times, run.result.t, run.result["pressure_Pa"]))
    phase = np.where(times < opt.t_f, "engagement", "clamp_ramp").astype(object)   # the segment a row starts
    if times[-1] > opt.t_f:
        phase[-1] = "clamp_hold"
    to_next = ["linear"] * (times.size - 1) + ["hold"]
    return {"time_s": times, "pressure_command_Pa": command, "pressure_Pa": pressure,
            "phase": list(phase), "to_next": to_next}


def format_quantity(value, unit, fmt="{:.4g}"):
    """``value unit`` for a progress line or a title ("none" for None)."""
    return "none" if value is None else f"{fmt.format(value)} {unit}"
