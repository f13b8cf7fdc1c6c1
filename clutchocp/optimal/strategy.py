"""A start and a path that converge: how ``clutchocp optimize`` reaches an optimum where one solve does not.

The first solve starts from the scene's own engagement (its IDAS run, stretched onto the mesh). On
a clutch the scene's profile does not fit, that start can be far from any command that meets the end
conditions (a profile that locks with a torque jump of three times the locked torque), and IPOPT
ends at a local point of infeasibility or at its iteration limit. :func:`solve_robustly` then

0. after a NaN at a trial point (a film at the model's edge, h = 0) keeps the films above a floor
   (:meth:`~clutchocp.optimal.problem.EngagementOCP.floor_films`), as it does before step 2;
   solves again from the same start with the monotone (Fiacco-McCormick) update of the barrier
   parameter, and uses it in the steps below, after a stall (its iteration limit, a NaN, a failed step)
   and after a local point of infeasibility alike (IPOPT's local verdict; the limits were checked before
   solving). Measured on the catalogue's tractor_powershift_fill_60C (60 slip intervals): the adaptive
   update drove the barrier to 1e-11 within 100 iterations and crept along to the iteration limit (500,
   objective 3.49); the monotone one converged in 209 iterations to 2.12. On bao2020_as_published (60 slip
   intervals, t_max 1.188 s) the adaptive update ended at a local point of infeasibility after 257
   iterations, the monotone one converged from the same start in 208;

1. **relaxes the end condition**: the same problem with the lock-up jump as a penalty
   (:data:`RELAXED_JUMP_WEIGHT`) instead of a constraint is feasible from any start that locks up,
   and its optimum, a lock-up with a small jump, starts the constrained problem (continuation from a
   relaxed limit);
2. **finds the fastest lock-up that meets the end conditions**: a minimum-time solve (no time
   limit; from the relaxed optimum or the scene's run). Its lock-up time T* is the real lower bound
   of t_max: a step to the pressure limit (the bound checked before solving) locks sooner only with
   a torque jump. A t_max below T* is refused with T* as the number to give (``--t-max``); without
   a given t_max the default, the lock-up time of the scene's own profile, becomes
   :data:`DEFAULT_T_MAX_SLACK` x T* (and says so). Otherwise the minimum-time optimum, which meets
   every constraint, starts the solve at t_max (a feasible start).

Every step is a full IPOPT solve; none runs on a clutch whose first solve converges, so the shipped
scenes' optima are the ones of a single solve.
"""

import numpy as np

from ..errors import ModelError, SolverError
from .objective import check_weights

RELAXED_JUMP_WEIGHT = 100.0       # weight of (jump / locked torque)^2 in the relaxed problem
FASTEST_WEIGHTS = {"jerk": 0.0, "time": 1.0, "smooth": 0.01}     # minimum time (a little smoothing)
DEFAULT_T_MAX_SLACK = 1.1         # default t_max over the fastest lock-up, where the scene's own is faster
T_MAX_TOLERANCE = 1e-4            # relative: T* above t_max by less than this is taken as t_max


def solve_robustly(ocp, *, t_max=None, weights=None, e_max=None, guess=None, say=None, adapt_t_max=None):
    """Solve ``ocp``, and where that fails, relax, find the fastest lock-up and start from it.

    Parameters
    ----------
    ocp : clutchocp.optimal.problem.EngagementOCP
    t_max : float, optional
        Largest engagement time [s] (default: :meth:`~clutchocp.optimal.problem.EngagementOCP.default_t_max`).
    weights, e_max, guess
        As :meth:`~clutchocp.optimal.problem.EngagementOCP.solve`.
    say : callable, optional
        Progress lines.
    adapt_t_max : bool, optional
        Whether t_max may be raised to :data:`DEFAULT_T_MAX_SLACK` x the fastest lock-up (default:
        when t_max is not given).

    Returns
    -------
    (OptimalEngagement, float, dict)
        The optimum, the t_max it was solved for and how: ``{"t_max_source", "attempts", "barrier"}``
        (each attempt: ``stage``, ``status``, ``iterations``, ``wall_time_s``; the fastest lock-up's time;
        the barrier update of the solve that reached the optimum).

    Raises
    ------
    ModelError
        t_max below the fastest lock-up that meets the end conditions (the message gives it), or a
        limit checked before solving.
    SolverError
        No step found an optimum (the message says what each ended with).
    """
    say = say or (lambda *a, **k: None)
    given = t_max is not None
    # a limit the user gives (--t-max, or the scene's engagement-time budget) is a specification: not adapted
    adapt = (not given and ocp.declared_t_max is None) if adapt_t_max is None else bool(adapt_t_max)
    t_max = ocp.default_t_max() if t_max is None else float(t_max)
    weights = check_weights(weights)
    info = {"t_max_source": "given" if given else ocp.default_t_max_source(), "attempts": []}
    if not given:
        say(f"  t_max = {t_max:.4g} s: {info['t_max_source']}")

    def attempt(stage, problem, **kwargs):
        try:
            result = problem.solve(e_max=e_max, **kwargs)
        except SolverError as exc:
            info["attempts"].append({"stage": stage, "status": getattr(exc, "status", "failed"), "message": str(exc)})
            return None
        info["attempts"].append({"stage": stage, "status": result.stats["status"],
                                 "iterations": result.stats["iterations"], "wall_time_s": result.stats["wall_time_s"]})
        info["barrier"] = kwargs.get("barrier", "adaptive")      # the update that reached this optimum
        return result

    opt = attempt("solve", ocp, t_max=t_max, weights=weights, guess=guess)
    if opt is not None:
        return opt, t_max, info
    barrier = "adaptive"
    if info["attempts"][-1]["status"] == "Invalid_Number_Detected":
        ocp.floor_films()                 # a NaN at a trial point: a film at the model's edge
    # a stall, or a local point of infeasibility (IPOPT's local verdict, not one on the limits): the same
    # start with the steadier barrier update
    barrier = "monotone"
    say(f"  no optimum from the scene's own engagement as a start ({_last(info)}); again with IPOPT's "
        f"monotone barrier update")
    opt = attempt("solve (monotone barrier)", ocp, t_max=t_max, weights=weights, guess=guess, barrier=barrier)
    if opt is not None:
        return opt, t_max, info
    say(f"  no optimum from the scene's own engagement as a start ({_last(info)}); solving with the lock-up jump "
        f"as a penalty first")
    relaxed = attempt("relaxed (jump as a penalty)", ocp.relaxed(), t_max=t_max,
                      weights=dict(weights, jump=RELAXED_JUMP_WEIGHT), guess=guess, barrier=barrier)
    if relaxed is not None:
        opt = attempt("solve from the relaxed optimum", ocp, t_max=t_max, weights=weights, guess=relaxed,
                      barrier=barrier)
        if opt is not None:
            return opt, t_max, info
    say("  finding the fastest lock-up that meets the end conditions (minimum time)")
    ocp.floor_films()                     # the fastest lock-up presses the films hardest
    fastest = attempt("fastest lock-up (minimum time)", ocp, t_max=np.inf, weights=FASTEST_WEIGHTS,
                      guess=relaxed if relaxed is not None else guess, barrier=barrier)
    if fastest is None:
        raise SolverError(f"optimal engagement: no optimum found for scene '{ocp.scene.name}' at t_max = "
                          f"{t_max:.4g} s: " + "; ".join(f"{a['stage']}: {a['message'].split(': ', 2)[-1]}"
                                                           for a in info["attempts"] if "message" in a))
    t_star = fastest.t_f
    info["fastest_lockup_s"] = t_star
    if t_star > t_max * (1 + T_MAX_TOLERANCE):
        if not adapt:
            raise ModelError(too_slow_message(ocp, t_max, t_star, declared=not given))
        t_max = DEFAULT_T_MAX_SLACK * t_star
        info["t_max_source"] = f"{DEFAULT_T_MAX_SLACK:g} x the fastest lock-up that meets the end conditions"
        say(f"  the scene's own profile locks up sooner than any command that meets the end conditions can: "
            f"t_max = {DEFAULT_T_MAX_SLACK:g} x the fastest, {t_star:.4g} s = {t_max:.4g} s")
    opt = attempt("solve from the fastest lock-up", ocp, t_max=t_max, weights=weights, guess=fastest, barrier=barrier)
    if opt is None:
        raise SolverError(f"optimal engagement: no optimum found for scene '{ocp.scene.name}' at t_max = "
                          f"{t_max:.4g} s although a lock-up meeting the end conditions takes {t_star:.4g} s: "
                          f"{_last(info)}")
    return opt, t_max, info


def too_slow_message(ocp, t_max, t_star, declared=False):
    """One line: t_max below the fastest lock-up that meets the end conditions, and the number to give
    (``declared``: t_max is the scene's ``actuation.engagement_time_limit``, named as the field to raise)."""
    step = ocp.fastest_lockup()
    limits = [f"a step to {ocp.apply_label()} locks up in {step:.4g} s but with a torque jump"]
    if ocp.heat_limits:
        limits.append("within the heat limits")
    return (f"scene '{ocp.scene.name}': t_max = {t_max:.4g} s is below the fastest lock-up that meets the end "
            f"conditions (slipping torque = the locked torque, the lock holding): "
            f"{'actuation.engagement_time_limit (or --t-max)' if declared else '--t-max'} must be at least "
            f"{t_star:.4g} s for this clutch ({'; '.join(limits)}), or raise actuation.max_pressure")


def _last(info):
    a = info["attempts"][-1]
    return a.get("message", a["status"]).split(": ", 2)[-1]
