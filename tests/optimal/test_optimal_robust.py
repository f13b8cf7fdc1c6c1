"""Robust feedforward: the multi-scenario collocation problem (clutchocp.optimal.robust)."""

import casadi as ca
import numpy as np
import pytest

from clutchocp.errors import ModelError
from clutchocp.optimal import robust
from clutchocp.optimal.clamp import ClampModel
from clutchocp.optimal.problem import OBJECTIVE_TERMS, SLIP_MODE, EngagementOCP, check_weights
from clutchocp.optimal.robust import SWEEP_CAPACITY, ParametricOCP, RobustOCP, lock_diagonal, solve_robust
from clutchocp.optimal.strategy import FASTEST_WEIGHTS
from clutchocp.scene import default_scene

N = 10                # no coarse presolve (PRESOLVE_INTERVALS) below this


@pytest.fixture(scope="module")
def scene():
    return default_scene()


@pytest.fixture(scope="module")
def nominal(scene):
    ocp = EngagementOCP(scene, intervals=N)
    return ocp, ocp.solve()


def test_parametric_dynamics_equal_the_overridden_scene(scene, nominal):
    """theta in the symbols gives the model of the scene with those values (a second build)."""
    ocp, _ = nominal
    names = ("friction.mu", "oil.viscosity", "load.torque")
    par = ParametricOCP(scene, names, intervals=3, baseline=ocp.baseline)
    values = {"friction.mu": 0.131, "oil.viscosity": 0.05, "load.torque": 117.0}
    other = EngagementOCP(scene.with_overrides(values), intervals=3, baseline=ocp.baseline)
    other.scales = par.scales                         # same scaling, so the functions compare 1:1
    fns = other._build_functions()                    # the slip phase's functions at those scales
    rng = np.random.default_rng(3)
    theta = [values[n] for n in names]
    weights = list(rng.uniform(0.1, 1.0, len(OBJECTIVE_TERMS)))
    for _ in range(3):
        x = np.append(par.x0 / par.nominal, 0.0) * rng.uniform(0.3, 1.2, par.x0.size + 1)
        u = rng.uniform(0.1, 0.9)
        for a, b in zip(par.dynamics_fn(x, u, weights + theta), fns["dynamics_fn"](x, u, weights)):
            np.testing.assert_allclose(np.array(a), np.array(b), rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(np.array(par.end_fn(x, u, 1.0, weights + theta)),
                                   np.array(fns["end_fn"](x, u, 1.0, weights)), rtol=1e-12, atol=1e-14)
    assert SLIP_MODE in par.model.modes


def test_one_scenario_is_the_nominal_problem(scene, nominal):
    ocp, opt = nominal
    assert opt.t_f == pytest.approx(opt.t_max, rel=1e-6)      # the jerk optimum uses all the time
    res = solve_robust(scene, [{}], intervals=N)
    assert res.success
    assert res.objective == pytest.approx(opt.objective, rel=1e-6)
    np.testing.assert_allclose(res.command, np.interp(res.command_times, opt.command_times, opt.command),
                               atol=1e-5 * ocp.p_max)
    assert res.lock_times[0] == pytest.approx(opt.t_f, rel=1e-6)
    terms = res.scenarios[0].terms
    assert terms["jerk_integral"] == pytest.approx(opt.terms["jerk_integral"], rel=1e-5)
    assert terms["lockup_torque_jump_Nm"] == pytest.approx(opt.terms["lockup_torque_jump_Nm"], rel=1e-5)


def test_a_margin_on_t_max_is_the_problem_at_the_shorter_limit(scene, nominal):
    """One scenario with t_max_margin m is the same problem as no margin with t_max (1 - m): same lock-up,
    same objective. (That one scenario is the nominal problem is test_one_scenario_is_the_nominal_problem; the
    problem at the shorter limit has several local optima, so it is compared with itself, not with a solve
    from another start.) m = 2 %: on the merged physics (shear-factor table, cavitation) the fastest lock-up
    that meets the end conditions on 10 intervals, a minimum-time solve, takes 0.13148 s = 0.974 t_max
    (t_max 0.13502 s), so the problem at 0.95 t_max has no solution (measured: the plain problem and the
    margin both stop at IPOPT's iteration limit there); the premise is asserted first."""
    ocp, opt = nominal
    margin = 0.02
    fastest = ocp.solve(t_max=np.inf, weights=FASTEST_WEIGHTS)
    assert fastest.t_f < (1 - margin) * opt.t_max
    res = solve_robust(scene, [{}], intervals=N, t_max=opt.t_max, t_max_margin=margin)
    short = solve_robust(scene, [{}], intervals=N, t_max=(1 - margin) * opt.t_max)
    assert res.t_max == pytest.approx((1 - margin) * opt.t_max, rel=1e-12)
    assert res.t_limit == pytest.approx(opt.t_max, rel=1e-12)
    assert short.t_limit == pytest.approx((1 - margin) * opt.t_max, rel=1e-12)
    assert res.lock_times[0] == pytest.approx(short.lock_times[0], rel=1e-6)
    assert res.objective == pytest.approx(short.objective, rel=1e-6)
    assert res.lock_times[0] <= (1 - margin) * opt.t_max * (1 + 1e-6)      # the bound, to IPOPT's tolerance
    assert res.objective > opt.objective                  # less time: more jerk


def test_the_nominal_start_locks_every_scenario(scene, nominal):
    """The start command (nominal optimum, then a ramp to the pressure limit) locks a scenario the
    nominal optimum alone leaves slipping (mu -10 %), and the lock-up guesses stay within t_max."""
    ocp, opt = nominal
    mu = scene.value("friction.mu")
    problem = RobustOCP(scene, [{"friction.mu": 0.9 * mu}, {"friction.mu": 1.1 * mu}], intervals=N,
                        baseline=ocp.baseline)
    problem._weights = check_weights(None)
    runs = problem.start_runs(opt.t_max)
    assert all(r.summary["engagement_time_s"] is not None for r in runs)
    guess = problem._lock_guess(opt.t_max)
    assert guess[1] < guess[0] <= opt.t_max


@pytest.mark.slow
def test_two_identical_scenarios_give_the_nominal_answer(scene, nominal):
    _, opt = nominal
    same = {"friction.mu": scene.value("friction.mu")}
    res = solve_robust(scene, [same, same], intervals=N)
    assert res.objective == pytest.approx(opt.objective, rel=1e-6)
    np.testing.assert_allclose(res.objectives, opt.objective, rtol=1e-6)


@pytest.mark.slow
def test_worst_of_one_scenario_is_the_nominal_problem(scene, nominal):
    _, opt = nominal
    res = solve_robust(scene, [{}], intervals=N, aggregate="worst")
    assert res.objective == pytest.approx(opt.objective, rel=1e-6)


@pytest.fixture(scope="module")
def spread(scene):
    mu = scene.value("friction.mu")
    problem = RobustOCP(scene, [{"friction.mu": 0.95 * mu}, {"friction.mu": 1.05 * mu}], intervals=12,
                        jump="penalty", polish=False)
    weights = {"jump": 30.0}
    return problem, problem.solve(weights=weights), problem.solve(weights=weights, aggregate="worst")


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="the worst-case solve ends in a local optimum: worst objective 4.226 "
                   "against the mean optimum's worst scenario 4.112 (the problem is not convex; before the "
                   "nominal start and the multi-start presolve it did not converge at all on today's default)")
def test_worst_aggregate_bounds_the_mean(spread):
    _, mean, worst = spread
    assert worst.objective == pytest.approx(worst.objectives.max(), rel=1e-6)
    # The worst-case optimum is no better in its worst scenario than the mean optimum is on average,
    # and no worse in its worst scenario than the mean optimum's worst.
    assert worst.objective >= mean.objective * (1 - 1e-6)
    assert worst.objective <= mean.objectives.max() * (1 + 1e-6)
    assert mean.objective == pytest.approx(mean.objectives.mean(), rel=1e-9)


@pytest.mark.slow
def test_every_scenario_meets_its_end_conditions(spread):
    problem, mean, _ = spread
    for res in mean.scenarios:
        assert abs(res.terms["final_slip_rad_s"]) < 1e-6
        assert res.t_f <= mean.t_max * (1 + 1e-7)        # IPOPT relaxes bounds by 1e-8 (bound_relax_factor)
        assert res.outputs["capacity_rate_Nm_s"][-1] >= -1e-6 * abs(res.terms["locked_torque_Nm"])
    # the faster (higher mu) scenario locks first; the shared command is within its limits
    assert mean.lock_times[1] < mean.lock_times[0]
    assert np.all(mean.command >= 0) and np.all(mean.command <= problem.ocp.p_max)
    rate = np.diff(mean.command) / np.diff(mean.command_times)
    assert np.max(np.abs(rate)) <= problem.ocp.rate_limit * (1 + 1e-6)


def test_bad_requests_are_model_errors(scene, nominal):
    ocp, _ = nominal
    with pytest.raises(ModelError, match="scenarios"):
        RobustOCP(scene, [], intervals=N)
    with pytest.raises(ModelError, match="numeric"):
        RobustOCP(scene, [{"film.flow_factor": "none"}], intervals=N)
    problem = RobustOCP(scene, [{"friction.mu": 0.12}], intervals=N, baseline=ocp.baseline)
    with pytest.raises(ModelError, match="aggregate"):
        problem.solve(aggregate="median")
    with pytest.raises(ModelError, match="scenario_weights"):
        problem.solve(scenario_weights=[1.0, 2.0])
    with pytest.raises(ModelError, match="fastest lock-up"):
        problem.solve(t_max=0.05)
    with pytest.raises(ModelError, match="t_max_margin"):
        problem.solve(t_max_margin=0.5)
    with pytest.raises(ModelError, match="control"):
        RobustOCP(scene, [{}], intervals=N, control="constant")


def test_a_value_the_model_cannot_take_as_a_symbol_is_named(scene, nominal):
    ocp, _ = nominal
    with pytest.raises(ModelError, match="plates.n_interfaces"):
        ParametricOCP(scene, ("plates.n_interfaces",), intervals=3, baseline=ocp.baseline)
    assert isinstance(ca.SX.sym("x"), ca.SX)


def test_worst_jump_of_one_scenario_is_the_mean_with_the_jump_penalty(scene, nominal, monkeypatch):
    """aggregate='worst_jump' with one scenario: the epigraph z = |jump| / locked torque is tight, so the
    objective is w_jump (jump / locked)^2 + the other terms, the jump penalty of the mean aggregate (whose
    one-scenario problem is the nominal one; the locked torque of this driveline is a constant). Both
    from the same start: the problem is not convex (this one from the nominal start ends at 1.45, from
    the sweep start at 1.13). At the scene's own lock-up time (0.135 s), where the penalised jump is large enough
    for the epigraph's tightness (IPOPT's tolerance, ~1e-8) to show at rel 1e-6; at the scene's 0.3 s budget it is
    0.45 % of the locked torque."""
    monkeypatch.setattr(robust, "STARTS", ("sweep",))
    weights = {"jump": 30.0}
    t_max = nominal[0].baseline.summary["engagement_time_s"]
    res = solve_robust(scene, [{}], intervals=N, jump="penalty", weights=weights, aggregate="worst_jump", t_max=t_max)
    ref = solve_robust(scene, [{}], intervals=N, jump="penalty", weights=weights, aggregate="mean", t_max=t_max)
    assert res.success and ref.success
    assert res.objective == pytest.approx(ref.objective, rel=1e-6)
    assert res.lock_times[0] == pytest.approx(ref.lock_times[0], rel=1e-6)
    terms = res.scenarios[0].terms
    assert terms["lockup_torque_jump_Nm"] == pytest.approx(ref.scenarios[0].terms["lockup_torque_jump_Nm"], rel=1e-5)
    # the epigraph variable is the relative jump of the scenario
    assert res.w[-1] == pytest.approx(abs(terms["lockup_torque_jump_Nm"] / terms["locked_torque_Nm"]), rel=1e-6)


def test_the_sweep_start_runs_through_the_capacity_band(scene, nominal):
    """Start "sweep": the pressure limit, a drop one valve time constant before the fastest scenario would
    lock under it, then a ramp from the command whose settled capacity is SWEEP_CAPACITY x the locked
    torque of the strongest clutch to the one of the weakest, at t_max; both scenarios lock under it,
    the stronger first."""
    ocp, opt = nominal
    mu = scene.value("friction.mu")
    weak, strong = scene.with_overrides({"friction.mu": 0.9 * mu}), scene.with_overrides({"friction.mu": 1.1 * mu})
    problem = RobustOCP(scene, [{"friction.mu": 0.9 * mu}, {"friction.mu": 1.1 * mu}], intervals=N,
                        baseline=ocp.baseline)
    problem._weights = check_weights(None)
    times, values = problem._sweep_command(opt.t_max)
    lag = scene.value("actuation.time_constant")
    assert values[1] == values[2] == problem.ocp.p_max
    assert times[2] == pytest.approx(problem.fastest_lockups()[1] - lag, rel=1e-12)
    assert times[4] == opt.t_max
    for clutch, p in ((strong, values[3]), (weak, values[4])):      # capacity = 1.5 x locked torque
        clamp = ClampModel(clutch)
        assert clamp.capacity(p) == pytest.approx(SWEEP_CAPACITY * clamp.locked_torque(), rel=1e-6)
    problem._start = "sweep"
    lock = [r.summary["engagement_time_s"] for r in problem.start_runs(opt.t_max)]
    assert lock[1] < lock[0]


def test_lock_diagonal_runs_from_the_first_to_the_last_corner_to_lock(scene):
    mu = scene.value("friction.mu")
    corners = [{"friction.mu": 0.9 * mu, "load.torque": 80.0}, {"friction.mu": 1.1 * mu, "load.torque": 120.0}]
    points = lock_diagonal(scene, corners, fractions=(0.25,))
    # the stronger clutch locks first: a quarter of the way from it
    assert points == [pytest.approx({"friction.mu": 1.05 * mu, "load.torque": 110.0}, rel=1e-12)]
    with pytest.raises(ModelError, match="fractions"):
        lock_diagonal(scene, corners, fractions=(0.5, 1.0))
