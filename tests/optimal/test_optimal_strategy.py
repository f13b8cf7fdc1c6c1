"""The robust solve of clutchocp.optimal.strategy: relaxed start, the fastest lock-up that meets the end
conditions (minimum time), a default t_max raised to it, a given one refused with it."""

import numpy as np
import pytest

from clutchocp.errors import ModelError, SolverError
from clutchocp.optimal.problem import EngagementOCP
from clutchocp.optimal.strategy import DEFAULT_T_MAX_SLACK, solve_robustly
from clutchocp.scene import default_scene

BIG_PACK = {"plates.r_inner": 0.075, "plates.r_outer": 0.098, "plates.n_interfaces": 6}


@pytest.fixture(scope="module")
def small():
    return EngagementOCP(default_scene(), intervals=15, degree=2)


def test_a_t_max_the_end_conditions_cannot_meet_is_refused_with_the_fastest_jump_free_lockup(small):
    """1.02 x the step's lock-up passes the bound checked before solving, but no jump-free lock is that fast:
    the refusal gives the minimum-time lock-up (which the problem then meets) as the number to give."""
    t_max = 1.02 * small.fastest_lockup()
    with pytest.raises(SolverError) as plain:
        small.solve(t_max=t_max)
    assert "\n" not in str(plain.value) and "ipopt" not in str(plain.value).lower() and "e_max" not in str(plain.value)
    with pytest.raises(ModelError) as info:
        solve_robustly(small, t_max=t_max)
    message = str(info.value)
    assert "\n" not in message and "--t-max must be at least" in message and f"t_max = {t_max:.4g} s" in message
    t_star = float(message.split("--t-max must be at least ")[1].split(" s")[0])
    assert t_star > t_max
    opt = small.solve(t_max=1.001 * t_star)                # the number given is enough
    assert opt.success and opt.t_f <= 1.001 * t_star * (1 + 1e-6)


def test_the_scene_engagement_time_budget_is_the_default_t_max_and_is_not_adapted(small):
    """The default scene declares actuation.engagement_time_limit = 0.3 s: that is the default t_max (its own
    profile locks at 0.135 s); a declared budget the end conditions cannot meet is refused naming the field,
    not raised as the baseline's lock-up time would be."""
    assert small.default_t_max() == 0.3 and "actuation.engagement_time_limit" in small.default_t_max_source()
    plain = EngagementOCP(default_scene().with_overrides({"actuation.engagement_time_limit": None}), intervals=15,
                          degree=2)
    assert plain.default_t_max() == pytest.approx(plain.baseline.summary["engagement_time_s"])
    assert 0.13 < plain.default_t_max() < 0.14 and "own profile" in plain.default_t_max_source()
    short = 1.02 * small.fastest_lockup()
    tight = EngagementOCP(default_scene().with_overrides({"actuation.engagement_time_limit": short}), intervals=15,
                          degree=2)
    with pytest.raises(ModelError) as info:
        solve_robustly(tight)
    message = str(info.value)
    assert "\n" not in message and "actuation.engagement_time_limit (or --t-max) must be at least" in message
    step = EngagementOCP(default_scene().with_overrides({"actuation.engagement_time_limit": 0.05}), intervals=15,
                         degree=2)                            # below even a step to the pressure limit
    with pytest.raises(ModelError, match=r"actuation.engagement_time_limit \(or --t-max\) must be at least"):
        solve_robustly(step)


@pytest.mark.slow
def test_a_default_t_max_faster_than_any_jump_free_lock_is_raised():
    """default_driveline with a larger pack (75-98 mm, 6 interfaces): its own profile locks in 0.1195 s with
    a jump of 480 N m; no jump-free lock is that fast. Without a t_max the problem is solved for 1.1 x the
    fastest jump-free lock-up; with t_max = 0.1195 s given, that lock-up is the number the refusal names."""
    ocp = EngagementOCP(default_scene().with_overrides({**BIG_PACK, "actuation.engagement_time_limit": None}),
                        intervals=40)
    opt, t_max, info = solve_robustly(ocp)
    t_star = info["fastest_lockup_s"]
    assert t_star > ocp.default_t_max() and t_max == pytest.approx(DEFAULT_T_MAX_SLACK * t_star)
    assert opt.success and opt.t_f <= t_max * (1 + 1e-6) and "fastest lock-up" in info["t_max_source"]
    assert abs(opt.terms["lockup_torque_jump_Nm"]) < 0.01 * ocp.lock_torque
    with pytest.raises(ModelError, match=f"--t-max must be at least {t_star:.4g} s"):
        solve_robustly(ocp, t_max=ocp.default_t_max())


class _LocallyInfeasibleWithTheAdaptiveBarrier:
    """A problem whose adaptive barrier update ends at a local point of infeasibility and whose monotone one
    converges from the same start (as bao2020_as_published's first solve on 60 slip intervals did)."""

    declared_t_max = None

    def __init__(self):
        self.calls = []

    def default_t_max(self):
        return 1.0

    def default_t_max_source(self):
        return "the lock-up time of the scene's own profile"

    def solve(self, *, t_max, weights, guess, e_max=None, barrier="adaptive"):
        self.calls.append(barrier)
        if barrier == "adaptive":
            error = SolverError("optimal engagement: no optimum found: a local point of infeasibility")
            error.status = "Infeasible_Problem_Detected"
            raise error
        return type("Optimum", (), {"stats": {"status": "Solve_Succeeded", "iterations": 208, "wall_time_s": 1.0}})()


def test_a_local_point_of_infeasibility_is_solved_again_with_the_monotone_barrier():
    problem = _LocallyInfeasibleWithTheAdaptiveBarrier()
    opt, t_max, info = solve_robustly(problem)
    assert problem.calls == ["adaptive", "monotone"] and t_max == 1.0
    assert opt.stats["status"] == "Solve_Succeeded" and info["barrier"] == "monotone"
    assert [a["stage"] for a in info["attempts"]] == ["solve", "solve (monotone barrier)"]
