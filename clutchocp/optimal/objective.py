"""The objective terms of the optimal engagement and their weights (see :mod:`clutchocp.optimal.problem`).

    J = w_jerk int jerk^2 dt / J_ref + w_energy E / E_ref + w_time t_f / t_ref
        + w_jump (jump / T_ref)^2 + w_smooth int (dp/dt)^2 dt t_ref / p_ref^2
        + w_fill_time t_fill / t_ref + w_kiss_speed (v_kiss / v_ref)^2

The weights are the NLP parameter vector, in the order of ``OBJECTIVE_TERMS``.
"""

import numpy as np

from ..errors import ModelError

OBJECTIVE_TERMS = ("jerk", "energy", "time", "jump", "smooth", "fill_time", "kiss_speed")
DEFAULT_WEIGHTS = {"jerk": 1.0, "energy": 0.0, "time": 0.0, "jump": 0.0, "smooth": 0.1, "fill_time": 0.0,
                   "kiss_speed": 0.0}
SMOOTH_PER_JERK = 0.1        # default smooth weight per unit jerk weight (see the problem module notes)


def check_weights(weights):
    """Full weight dict from a partial one; unknown names or negative weights raise ModelError.

    A missing ``smooth`` weight is ``SMOOTH_PER_JERK`` x the jerk weight (0.1 with the default jerk = 1).
    """
    out = dict(DEFAULT_WEIGHTS)
    for name, value in (weights or {}).items():
        if name not in DEFAULT_WEIGHTS:
            raise ModelError(f"weights: unknown term '{name}'; allowed: {', '.join(OBJECTIVE_TERMS)}")
        try:
            value = float(value)
        except (TypeError, ValueError):
            raise ModelError(f"weights.{name} = {value!r}: must be a number >= 0") from None
        if not (np.isfinite(value) and value >= 0):
            raise ModelError(f"weights.{name} = {value!r}: must be a number >= 0")
        out[name] = value
    if "smooth" not in (weights or {}):
        out["smooth"] = SMOOTH_PER_JERK * out["jerk"]
    if sum(out[k] for k in ("jerk", "energy", "time", "jump", "fill_time", "kiss_speed")) == 0:
        raise ModelError("weights: at least one of jerk, energy, time, jump, fill_time, kiss_speed must be positive")
    return out
