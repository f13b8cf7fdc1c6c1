"""Heat limits of the optimal engagement: the interface temperature and the specific power.

The limits enter the collocation problem as path constraints (see :class:`~clutchocp.optimal.problem.EngagementOCP`);
:func:`heat_check` compares the collocation prediction with the IDAS replay of the optimum.
"""

import numpy as np

from ..errors import ModelError

LIMIT_OPTIONS = ("max_temperature_C", "max_specific_power_W_mm2")


def heat_limits(model, max_temperature_C, max_specific_power_W_mm2):
    """Path limits of the slip phase from the options, as [(output name, limit in its SI unit)].

    Parameters
    ----------
    model : clutchocp.engagement.model.EngagementModel
    max_temperature_C : float or None
        Largest interface temperature [deg C] (needs a [thermal] part).
    max_specific_power_W_mm2 : float or None
        Largest interface heat power per friction area [W/mm^2]; becomes a limit on
        ``interface_heat_power_W`` [W] over the friction area n_interfaces pi (r2^2 - r1^2).
    """
    limits = []
    if max_temperature_C is not None:
        if not model.thermal.present:
            raise ModelError("max_temperature_C: the scene has no [thermal] part, so no interface temperature")
        if not (np.isfinite(max_temperature_C) and max_temperature_C > model.thermal.T_start):
            raise ModelError(f"max_temperature_C = {max_temperature_C!r}: must be above the initial plate "
                             f"temperature {model.thermal.T_start:g} degC")
        limits.append(("interface_temperature_C", float(max_temperature_C)))
    if max_specific_power_W_mm2 is not None:
        if not (np.isfinite(max_specific_power_W_mm2) and max_specific_power_W_mm2 > 0):
            raise ModelError(f"max_specific_power_W_mm2 = {max_specific_power_W_mm2!r}: must be a positive power "
                             "per friction area [W/mm^2]")
        limits.append(("interface_heat_power_W", float(max_specific_power_W_mm2) * friction_area_mm2(model)))
    return limits


def friction_area_mm2(model):
    """Nominal friction area of all interfaces [mm^2]."""
    return model.n * model.film.area * 1e6


def heat_check(ocp, opt, replay):
    """Peak interface temperature and specific power over the slip phase: collocation and IDAS.

    Parameters
    ----------
    ocp : clutchocp.optimal.problem.EngagementOCP
    opt : clutchocp.optimal.problem.OptimalEngagement
    replay : clutchocp.engagement.run.EngagementResult
        The IDAS run of the optimum (until its lock-up counts).

    Returns
    -------
    dict
        ``collocation`` and ``idas``, each with ``peak_specific_power_W_mm2`` and (with a [thermal]
        part) ``peak_interface_temperature_C``; ``temperature_diff_K`` (IDAS minus collocation) and
        ``limits`` (the options in force).
    """
    area = friction_area_mm2(ocp.model)
    t_lock = replay.summary["engagement_time_s"]
    t = replay.result.t
    slip = t <= (t_lock if t_lock is not None else t[-1])
    colloc = {"peak_specific_power_W_mm2": float(np.max(opt.outputs_points["interface_heat_power_W"])) / area}
    idas = {"peak_specific_power_W_mm2": float(np.max(replay.result["interface_heat_power_W"][slip])) / area}
    out = {"collocation": colloc, "idas": idas, "limits": {k: ocp.options[k] for k in LIMIT_OPTIONS}}
    if ocp.model.thermal.present:
        colloc["peak_interface_temperature_C"] = opt.terms["peak_interface_temperature_C"]
        idas["peak_interface_temperature_C"] = float(np.max(replay.result["interface_temperature_C"][slip]))
        out["temperature_diff_K"] = idas["peak_interface_temperature_C"] - colloc["peak_interface_temperature_C"]
    return out
