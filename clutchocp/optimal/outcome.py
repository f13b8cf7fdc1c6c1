"""The result of :func:`clutchocp.optimize`: the optimum, its IDAS check and the baselines, at a glance."""

from dataclasses import dataclass, field

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
        from .report import profile_columns
        return Table(profile_columns(self.optimum, self.curve, self.clamp_run))

    def plot(self, path=None):
        """The pressure figure (command, IDAS replay, baseline); saved as PNG if ``path`` is given.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from ..output import save_figure
        from .report import pressure_figure
        fig = pressure_figure(self.scene, self.optimum, self.replay, self.ocp.baseline, self.summary, self.curve,
                              self.clamp_run)
        if path is not None:
            save_figure(fig, path)
        return fig
