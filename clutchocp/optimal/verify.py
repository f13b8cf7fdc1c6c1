"""Verification of an optimum by IDAS, and the numbers of an IDAS engagement run.

The optimal command is replayed on the exact (non-smoothed) model with IDAS and its impact and
lock-up events; just after the collocation lock time the command steps to the holding pressure (the larger
of the last command and the scene's set pressure), as a transmission controller clamps a locked
clutch. The collocation prediction and the IDAS run are then compared side by side.

The lock-up jump is measured against the torque the locked clutch carries; where it carries none
(a brake with its output held; a prescribed input speed without load) the jump is the torque step
at the stop, measured against the peak slipping torque of the run.
"""

import numpy as np

from ..simulation import SimulationOptions
from ..simulation.locate import root_near
from .guess import DISSIPATED, engagement_samples
from .replay import simulate_command

LOCK_TIME_TOLERANCE = 0.01      # relative
JUMP_TOLERANCE = 0.02           # relative to the torque carried after lock-up (or the peak torque, see above)
HOLD_DELAY = 1e-3               # the holding command starts at (1 + HOLD_DELAY) t_f
FILM_PRESSURE_KEYS = ("min_film_pressure_Pa", "min_film_pressure_film", "min_film_pressure_time_s")


def run_numbers(run):
    """Engagement numbers of an IDAS run over its slip phase (JSON-ready, None if it never locks).

    Returns
    -------
    dict
        engagement_time_s, lockup_torque_jump_Nm, jerk_integral (int jerk^2 dt from t = 0 to
        lock-up, fill and slip [rad^2/s^5], trapezoidal on the output samples), peak_jerk_rad_s3, peak_torque_Nm,
        dissipated_energy_J (at lock-up), locked_torque_Nm, kiss_time_s and kiss_speed_m_s (the
        impact of the piston on the pack; None without free travel), kiss_jerk_rad_s3 (the jerk just
        after the kiss, part of the peak jerk), and the lowest mean film pressure of the whole run
        (min_film_pressure_Pa, its film and time; the film law limits it at film.cavitation_pressure).
        With the output held (a brake) the jerk is the input's, -dT/dt / I_in by differences of the
        clutch torque.
    """
    summary = run.summary
    out = {"engagement_time_s": summary["engagement_time_s"], "lockup_torque_jump_Nm": summary["lockup_torque_jump_Nm"],
           "jerk_integral": None, "peak_jerk_rad_s3": None, "peak_torque_Nm": summary["peak_torque_Nm"],
           "dissipated_energy_J": summary["dissipated_energy_J"], "locked_torque_Nm": None,
           "kiss_time_s": None, "kiss_speed_m_s": None, "kiss_jerk_rad_s3": None,
           **{k: summary[k] for k in FILM_PRESSURE_KEYS}}
    impact = [e for e in run.result.events if e.name == "impact"]
    if impact:
        out["kiss_time_s"], out["kiss_speed_m_s"] = float(impact[0].t), float(impact[0].x_before["v0"])
    if summary["engagement_time_s"] is None:
        return out
    t, idx = engagement_samples(run)
    model = run.model
    if output_held(model):
        jerk = -np.gradient(run.result["total_torque_Nm"][idx], t) / model.scene.value("driveline.input_inertia")
    else:
        jerk = run.result["output_jerk_rad_s3"][idx]
    out["jerk_integral"] = float(np.trapezoid(jerk**2, t))
    out["peak_jerk_rad_s3"] = float(np.max(np.abs(jerk)))
    if impact and not output_held(model):
        # the jerk just after the kiss: the sample of the pressing mode at the impact time
        after = np.flatnonzero((run.result.t == impact[0].t) & (np.asarray(run.result.mode) == "pressing_slip_forward"))
        out["kiss_jerk_rad_s3"] = float(run.result["output_jerk_rad_s3"][after[0]]) if after.size else None
        if after.size:
            out["peak_jerk_rad_s3"] = max(out["peak_jerk_rad_s3"], abs(out["kiss_jerk_rad_s3"]))
    out["peak_torque_Nm"] = float(np.max(np.abs(run.result["total_torque_Nm"][idx])))
    lock = next(e for e in run.result.events if e.name == "lockup" and e.target.endswith("locked"))
    out["dissipated_energy_J"] = float(sum(lock.x_before[name] for name in DISSIPATED if name in lock.x_before))
    out["locked_torque_Nm"] = float(lock.outputs_after["total_torque_Nm"])
    return out


def output_held(model):
    """True for a brake: the output is held and the input is the braked inertia."""
    return model.input_inertia and not model.output_inertia


def jump_reference(ocp, numbers):
    """Torque the lock-up jump is measured against [N m]: the locked torque, or for a lock that
    carries none the peak slipping torque."""
    return abs(numbers["locked_torque_Nm"]) if ocp.holds_torque else abs(numbers["peak_torque_Nm"])


def holding_pressure(ocp, opt):
    """Command after lock-up [Pa]: the larger of the last command and the set pressure of the baseline's
    profile (the smaller for a spring-applied piston, where pressure releases the clutch); that profile
    is the scene's own, held within what the contact carries at zero gap (``ocp.baseline_scene``). Where
    the contact cannot carry the pressure limit, no more than the command it carries at the film floor
    (``ocp.apply_pressure``; a spring-applied piston: no less): a locked pack pressed harder closes a film."""
    if ocp.spring_applied:
        return float(max(min(opt.command[-1], ocp.baseline_scene.value("actuation.pressure")), ocp.apply_pressure))
    return float(min(max(opt.command[-1], ocp.baseline_scene.value("actuation.pressure")), ocp.apply_pressure))


def located_lock_time(run):
    """Where the slip speed of the IDAS run reaches zero [s], located between its samples.

    The engine's lock-up event is accepted once |w_rel| is within its value tolerance, and a lock-up
    at the command's last node is taken at that node (the input break restarts the run there), so
    the event time can equal the collocation's t_f exactly while the slip crossed zero a little
    earlier. Here the zero is located on the cubic through the last samples of the slip before the
    event (:func:`clutchocp.simulation.locate.root_near`); None if there is no lock-up.
    """
    lock = next((e for e in run.result.events if e.name == "lockup" and e.target.endswith("locked")), None)
    if lock is None:
        return None
    seg = next((s for s in run.result.segments if s.t.size and s.t[-1] == lock.t and s.mode == lock.source), None)
    if seg is None or "w_in_rad_s" not in seg.outputs or "w_out_rad_s" not in seg.outputs:
        return None
    w_rel = np.asarray(seg.outputs["w_in_rad_s"]) - np.asarray(seg.outputs["w_out_rad_s"])
    keep = np.append(np.diff(seg.t) > 0, True)
    return root_near(seg.t[keep], w_rel[keep], lock.t)


def verify(ocp, opt, *, model=None, rtol=None, atol=None):
    """Replay an optimum with IDAS and compare it with the collocation prediction.

    Parameters
    ----------
    ocp : clutchocp.optimal.problem.EngagementOCP
    opt : clutchocp.optimal.problem.OptimalEngagement
    model : clutchocp.optimal.replay.CommandModel, optional
        A command model of the scene already built (same control kind; default: the problem's,
        ``ocp.models``).
    rtol, atol : float, optional
        IDAS tolerances (default: the scene's).

    Returns
    -------
    (dict, clutchocp.engagement.run.EngagementResult)
        The comparison (JSON-ready) and the IDAS run.
    """
    model = model or ocp.models.replay(opt.control)
    t_f = opt.t_f
    # The hold starts a little after t_f: a lock-up located exactly on an input break (IDAS finds it
    # at t_f within the event tolerance) made the engine skip that break and keep the last ramp.
    # Until then the last piece of the command goes on, and then its value holds while IDAS may still
    # lock within the lock-time tolerance: a lock-up late by less than that is measured against the
    # optimum's own command, not against the step to the holding pressure (which, on the catalogue's
    # spring-applied helicopter clutch with plate masses, locking 0.5 % late, made a jump of 2.2 % of
    # the locked torque out of one of 0.5 %).
    times, command = np.asarray(opt.command_times, float), np.asarray(opt.command, float)
    if opt.control == "linear" and times.size > 1:
        t_on = t_f * (1 + HOLD_DELAY)
        slope = (command[-1] - command[-2]) / (times[-1] - times[-2])
        p_on = float(np.clip(command[-1] + slope * (t_on - times[-1]), 0.0, ocp.p_max))
        # the last node moves along its ramp to t_on (no new input break at t_f)
        times = np.append(times[:-1], [t_on, t_f * (1 + LOCK_TIME_TOLERANCE)])
        command = np.append(command[:-1], [p_on, p_on])
        hold = (t_f * (1 + LOCK_TIME_TOLERANCE) * (1 + HOLD_DELAY), holding_pressure(ocp, opt))
    else:
        hold = (t_f * (1 + HOLD_DELAY), holding_pressure(ocp, opt))
    dense = np.linspace(0.0, t_f, 20 * ocp.transcription.intervals + 1)
    near_lock = np.linspace(0.97 * t_f, 1.03 * t_f, 301)
    # samples 2e-6 t_f apart just before t_f, where the slip reaches zero: located_lock_time's cubic
    # then finds the crossing to ~1e-9 t_f (on the 2e-4 t_f spacing above it was off by 6e-6 t_f)
    at_lock = np.linspace(0.9996 * t_f, t_f, 201)
    run = simulate_command(ocp.scene, times, command, 1.5 * t_f, hold=hold, model=model,
                           control=opt.control, points=301, extra_times=np.concatenate([dense, near_lock, at_lock]),
                           rtol=rtol, atol=atol)
    idas = run_numbers(run)
    colloc = {k: opt.terms[k] for k in ("engagement_time_s", "lockup_torque_jump_Nm", "jerk_integral",
                                        "peak_jerk_rad_s3", "peak_torque_Nm", "dissipated_energy_J",
                                        "locked_torque_Nm")}
    colloc["kiss_time_s"], colloc["kiss_speed_m_s"] = opt.terms.get("fill_time_s"), opt.terms.get("kiss_speed_m_s")
    colloc["kiss_jerk_rad_s3"] = opt.terms.get("kiss_jerk_rad_s3")
    colloc["min_film_pressure_Pa"] = opt.terms.get("min_film_pressure_Pa")
    # IDAS locates lock-up to |w_rel| / w_scale <= event_value_tol; at the final slip rate that is:
    w_scale = max(ocp.scene.value("driveline.input_speed"), 1.0)
    rate = abs(opt.outputs["slip_acceleration_rad_s2"][-1])
    resolution = SimulationOptions().event_value_tol * w_scale / rate if rate > 0 else None
    out = {"collocation": colloc, "idas": idas, "holding_pressure_Pa": hold[1], "lock_time_resolution_s": resolution,
           "lock_time_rel_diff": None, "torque_jump_Nm": idas["lockup_torque_jump_Nm"],
           "torque_jump_rel": None, "jump_reference_Nm": None, "passed": False}
    if idas["engagement_time_s"] is not None:
        located = located_lock_time(run)
        idas["located_lock_time_s"] = located
        t_idas = located if located is not None else idas["engagement_time_s"]
        out["lock_time_rel_diff"] = abs(t_idas - t_f) / t_f
        out["jump_reference_Nm"] = jump_reference(ocp, idas)
        out["torque_jump_rel"] = abs(idas["lockup_torque_jump_Nm"]) / max(out["jump_reference_Nm"], 1e-9)
        out["passed"] = bool(out["lock_time_rel_diff"] <= LOCK_TIME_TOLERANCE
                             and out["torque_jump_rel"] <= JUMP_TOLERANCE)
    return out, run
