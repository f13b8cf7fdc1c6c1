"""Baseline pressure profiles of a scene: a step, a linear ramp and Zhang's first-order lag.

Each baseline is the scene with its [actuation] part replaced (same set pressure and limits),
simulated with IDAS; Zhang 2021 Eq. 7 is the lag P_s = P_o (1 - exp(-t / t_s)).
"""

from ..engagement.run import simulate_engagement
from .verify import run_numbers

LAG_TIMES = (0.02, 0.04, 0.06, 0.08, 0.1)      # Zhang 2021's range of t_s [s]
RAMP_TIME = 0.1                                  # [s]
_PROFILE_KEYS = ("time_constant", "ramp_time", "file")


def baseline_scene(scene, kind, value=None):
    """The scene with the actuation replaced by a baseline profile.

    Parameters
    ----------
    scene : clutchocp.scene.Scene
    kind : {"step", "ramp", "first_order_lag"}
    value : float, optional
        Ramp time or lag time constant [s].

    Returns
    -------
    clutchocp.scene.Scene
    """
    overrides = {f"actuation.{key}": None for key in _PROFILE_KEYS}
    overrides["actuation.model"] = kind
    if kind == "ramp":
        overrides["actuation.ramp_time"] = value
    elif kind == "first_order_lag":
        overrides["actuation.time_constant"] = value
    return scene.with_overrides(overrides)


def baseline_label(scene):
    """Name of the scene's own profile as a baseline (a valve lag on a step is a first-order lag)."""
    variant = scene.variant("actuation")
    if variant in ("valve_lag", "first_order_lag"):
        return f"first-order lag, t_s = {scene.value('actuation.time_constant'):g} s"
    return variant


def simulate_baselines(scene, lags=LAG_TIMES, ramp_time=RAMP_TIME):
    """IDAS runs and numbers of the step, the ramp and the first-order lags.

    Returns
    -------
    dict
        ``{name: (EngagementResult, numbers)}`` with names ``step``, ``ramp_<T>s``, ``lag_<t_s>s``;
        ``numbers`` as :func:`clutchocp.optimal.verify.run_numbers`.
    """
    cases = {"step": baseline_scene(scene, "step"), f"ramp_{ramp_time:g}s": baseline_scene(scene, "ramp", ramp_time)}
    for t_s in lags:
        cases[f"lag_{t_s:g}s"] = baseline_scene(scene, "first_order_lag", t_s)
    out = {}
    for name, case in cases.items():
        run = simulate_engagement(case)
        out[name] = (run, run_numbers(run))
    return out
