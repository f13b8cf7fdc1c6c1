"""Phased collocation: the one-phase case, the fill phase and its impact link, a brake, a closed-form fill."""

import casadi as ca
import numpy as np
import pytest
from scipy.linalg import expm
from scipy.optimize import fsolve

from clutchocp.cli import main
from clutchocp.engagement.run import simulate_engagement
from clutchocp.errors import ModelError
from clutchocp.optimal import DirectCollocation, EngagementOCP, StagedProblem, nlp_solver, verify
from clutchocp.optimal.guess import guess_from_run
from clutchocp.optimal.phases import Phase, PhasedNLP, phased_derivatives
from clutchocp.scene import default_scene, load_scene

# Optimum of the default scene at 40 intervals (degree 3, Radau, default weights and t_max) computed by
# the slip-phase-only code before the phased machinery replaced it: 1.8414671417707076 at commit 6d64021;
# on the default scene with lumped plate temperatures the same code at commit 2b4e638 gave 1.6158362154164172.
# With the transmitted shear factor (phi_f + Phi_fs over h) and the film tension limit the one-phase problem
# gave 2.422578459271815. With the deterministic-flow shear-factor table (film.shear_factors = "table"), the
# cavitation limit at -1 bar and the smooth real-area cap (the merged physics) the one-phase problem (the same
# NLP vector, asserted below) gave 3.0787421374673976 at the scene's own lock-up time (0.135 s); at the default
# scene's engagement-time budget (actuation.engagement_time_limit = 0.3 s) the value below, from a run of this code.
SLIP_ONLY_OBJECTIVE_N40 = 0.23422801241932767


def test_one_phase_problem_equals_the_slip_phase_optimum():
    ocp = EngagementOCP(default_scene(), intervals=40, degree=3)
    assert [name for name, _ in ocp.phase_modes] == ["slip"]
    assert ocp.nlp is ocp.phased.parts[0]                  # no link, no total-time row, same vector
    assert ocp.phased.lbg.size == ocp.nlp.lbg.size and ocp.phased.lbx.size == ocp.nlp.lbx.size
    opt = ocp.solve()
    assert opt.objective == pytest.approx(SLIP_ONLY_OBJECTIVE_N40, rel=1e-6)
    assert [p["name"] for p in opt.phases] == ["slip"] and "kiss_speed_m_s" not in opt.terms


@pytest.fixture(scope="module")
def fill_scene():
    return load_scene("default_fill")


@pytest.fixture(scope="module")
def fill_ocp(fill_scene):
    return EngagementOCP(fill_scene, intervals=40, fill_intervals=12, degree=3)


@pytest.fixture(scope="module")
def fill_opt(fill_ocp):
    return fill_ocp.solve()


def test_fill_scene_has_a_fill_then_a_slip_phase(fill_ocp):
    assert fill_ocp.phase_modes == [("fill", "approach_slip_forward"), ("slip", "pressing_slip_forward")]
    # its own profile reaches the pack, then locks up (the events the phases follow)
    names = [e.name for e in fill_ocp.baseline.result.events]
    assert names[:2] == ["impact", "lockup"]


def test_states_and_command_are_continuous_across_the_kiss(fill_ocp, fill_opt):
    """The massless pack's impact reset is the identity: every state and the command carry over."""
    a, b = fill_opt.phases[0]["nodes"][1] - 1, fill_opt.phases[1]["nodes"][0]
    assert fill_opt.t[a] == pytest.approx(fill_opt.t[b], abs=1e-15)
    for name, values in fill_opt.states.items():
        assert values[b] == pytest.approx(values[a], rel=1e-9, abs=1e-12 * np.max(np.abs(values))), name
    assert fill_opt.states["x0"][a] == pytest.approx(fill_ocp.model.travel, rel=1e-9)
    assert np.all(np.diff(fill_opt.command_times) > 0)     # one command, no duplicate node at the link


def test_fill_optimum_is_confirmed_by_idas(fill_ocp, fill_opt):
    check, run = verify(fill_ocp.exact, fill_opt)
    assert check["passed"] and check["lock_time_rel_diff"] <= 0.01 and check["torque_jump_rel"] <= 0.02
    idas, colloc = check["idas"], check["collocation"]
    # the kiss: time, piston speed and the jerk just after it
    assert idas["kiss_time_s"] == pytest.approx(colloc["kiss_time_s"], rel=1e-3)
    assert idas["kiss_speed_m_s"] == pytest.approx(colloc["kiss_speed_m_s"], rel=1e-4)
    assert idas["kiss_jerk_rad_s3"] == pytest.approx(colloc["kiss_jerk_rad_s3"], rel=1e-3)
    assert idas["dissipated_energy_J"] == pytest.approx(colloc["dissipated_energy_J"], rel=2e-3)


@pytest.mark.parametrize("meshes", [None, {"fill": [0.3, 0.7], "slip": [0.5, 0.2, 0.3]}], ids=["uniform", "graded"])
def test_phased_derivatives_equal_casadi_ad(fill_scene, fill_ocp, meshes):
    small = EngagementOCP(fill_scene, intervals=3, fill_intervals=2, degree=2, baseline=fill_ocp.baseline,
                          jerk_max=5e3, meshes=meshes)
    if meshes is not None:
        assert np.allclose(small.phased.parts[1].transcription.mesh, meshes["slip"])
    nlp = small.phased
    reference = ca.nlpsol("reference", "ipopt", nlp.nlp,
                          {"print_time": False, "ipopt": {"print_level": 0, "sb": "yes"}})
    mine = phased_derivatives(nlp)
    rng = np.random.default_rng(5)
    w = guess_from_run(small, fill_ocp.baseline) * (1 + 0.01 * rng.normal(size=nlp.lbx.size))
    lam, p = rng.normal(size=nlp.lbg.size), [1.0, 0.3, 0.2, 0.5, 0.1, 0.4, 0.6]
    jac = np.array(ca.densify(mine["jac_g"](w, p)[1]))
    jac_ref = np.array(ca.densify(reference.get_function("nlp_jac_g")(w, p)[1]))
    assert np.allclose(jac, jac_ref, rtol=1e-9, atol=1e-10 * np.abs(jac_ref).max())
    hess = np.array(ca.densify(mine["hess_lag"](w, p, 0.7, lam)))
    hess_ref = np.array(ca.densify(reference.get_function("nlp_hess_l")(w, p, 0.7, lam)))
    assert np.allclose(hess, hess_ref, rtol=1e-8, atol=1e-9 * np.abs(hess_ref).max())


def test_impact_reset_in_the_ocp_equals_the_simulators():
    """bao2020 (plate masses): Bao Eq. 22 as the OCP link applies it, against the IDAS event record."""
    scene = load_scene("bao2020", {"actuation.max_pressure": "80 MPa"})
    run = simulate_engagement(scene)
    ocp = EngagementOCP(scene, intervals=4, fill_intervals=2, degree=2, baseline=run, polish=False,
                        quasi_static_plates=False)
    impact = next(e for e in run.result.events if e.name == "impact")
    names, nominal = ocp.state_names, ocp.nominal

    def scaled(x, energy):
        return np.append([x[n] for n in names] / nominal, energy / ocp.scales.energy_J)

    dissipated = ("E_slip", "E_film", "E_seal", "E_spline", "E_impact")
    energy = [sum(x[n] for n in dissipated if n in x) for x in (impact.x_before, impact.x_after)]
    after = np.array(ocp.impact_reset()(scaled(impact.x_before, energy[0]))).ravel()
    assert np.allclose(after, scaled(impact.x_after, energy[1]), rtol=1e-12, atol=1e-15)
    m0, m1 = scene.value("piston.mass"), scene.value("pack.plate_masses")[0]
    v = impact.x_before["v0"]
    assert after[names.index("v0")] * nominal[names.index("v0")] == pytest.approx(m0 * v / (m0 + m1), rel=1e-12)
    assert after[-1] > scaled(impact.x_before, energy[0])[-1]        # the impact loss is dissipated


def _piston_fill(m, k, c, area, preload, p_max, travel):
    """Closed-form minimum time of a mass-spring-damper piston from rest at 0 to rest at ``travel``,
    pressure p_max then 0 (bang-bang, one switch): the linear ODE's flow by matrix exponential,
    the two durations by Newton on the end state."""
    M = np.array([[0.0, 1.0], [-k / m, -c / m]])

    def flow(z, p, t):
        b = np.array([0.0, (p * area - k * preload) / m])
        eq = -np.linalg.solve(M, b)                          # equilibrium of the phase
        return eq + expm(M * t) @ (z - eq)

    def residual(times):
        z1 = flow(np.zeros(2), p_max, times[0])
        return flow(z1, 0.0, times[1]) - np.array([travel, 0.0])

    omega = np.sqrt(k / m)
    return fsolve(residual, [0.6 / omega, 0.6 / omega], xtol=1e-14)


def test_fill_only_minimum_time_is_the_bang_bang_answer():
    """Two phases (pressure at its limit, then none) with free durations reproduce the switch time and
    the minimum time of a mass-spring-damper piston (closed form above)."""
    m, k, c, area, preload, p_max, travel = 1.0, 1.0, 0.2, 1.0, 0.5, 2.0, 1.0
    x, u, p = ca.SX.sym("x", 2), ca.SX.sym("u"), ca.SX.sym("p")
    xdot = ca.vertcat(x[1], (u * area - k * (preload + x[0]) - c * x[1]) / m)
    dynamics = ca.Function("piston", [x, u, p], [xdot, ca.SX(0.0), x[0]])
    Q, T = ca.SX.sym("Q"), ca.SX.sym("T")
    objective = ca.Function("time", [x, u, Q, T, p], [T])
    free_end = ca.Function("none", [x, u, T, p], [x[0]])
    at_rest = ca.Function("rest", [x, u, T, p], [ca.vertcat(x[0] - travel, x[1])])
    inf = np.full(2, np.inf)

    def phase(name, x0, level, end, end_lb, end_ub):
        problem = StagedProblem(dynamics, x0, objective, end, -inf, inf, np.array([level]), np.array([level]),
                                np.array([-np.inf]), np.array([np.inf]), end_lb, end_ub)
        return Phase(name, name, problem, DirectCollocation(20, 3, "radau", "constant"))

    phases = [phase("pressure", np.zeros(2), p_max, free_end, np.array([-np.inf]), np.array([np.inf])),
              phase("release", None, 0.0, at_rest, np.zeros(2), np.zeros(2))]
    xe, xs = ca.MX.sym("xe", 2), ca.MX.sym("xs", 2)
    nlp = PhasedNLP(phases, [ca.Function("identity", [xe, xs], [xs - xe])])
    solver = nlp_solver(nlp, derivatives=phased_derivatives(nlp))
    parts = nlp.parts
    w0 = np.concatenate([part.pack(np.zeros((21, 2)), np.zeros((20, 3, 2)), np.full((20, 1), level), 1.0)
                         for part, level in zip(parts, (p_max, 0.0))])
    lbx, ubx = nlp.lbx.copy(), nlp.ubx.copy()
    for kk in range(2):
        lbx[nlp.t_slice(kk)], ubx[nlp.t_slice(kk)] = 0.01, 10.0
    ubg = nlp.ubg.copy()
    ubg[nlp.rows["total_time"]] = 100.0
    sol = solver(x0=w0, lbx=lbx, ubx=ubx, lbg=nlp.lbg, ubg=ubg, p=[0.0])
    assert solver.stats()["success"]
    w = np.array(sol["x"]).ravel()
    durations = [float(w[nlp.t_slice(kk)][-1]) for kk in range(2)]
    exact = _piston_fill(m, k, c, area, preload, p_max, travel)
    assert durations == pytest.approx(list(exact), rel=1e-7)
    assert float(sol["f"]) == pytest.approx(sum(exact), rel=1e-7)
    assert nlp.total_time(w) == pytest.approx(sum(exact), rel=1e-7)


# zhang2021 with the roughness split equally between the surfaces (stops in 2.28 s). With the scene's
# own lining-rough pair the stop takes 1.60 s; see test_brake_on_the_lining_rough_pair_verifies.
BRAKE_EQUAL_SPLIT = {"actuation.max_pressure": "1.2 MPa", "roughness.sigma_1": 8.41e-6 / 2**0.5,
                     "roughness.sigma_2": 8.41e-6 / 2**0.5}


def test_brake_locks_as_the_input_comes_to_rest(tmp_path):
    """zhang2021 (output held): the optimum stops the input with a torque step of at most 2 % of its
    peak slipping torque, and IDAS stops it within 1 % of the collocation time."""
    scene = load_scene("zhang2021", BRAKE_EQUAL_SPLIT)
    ocp = EngagementOCP(scene, intervals=100, degree=3)
    assert ocp.output_held and not ocp.holds_torque
    opt = ocp.solve()
    assert opt.terms["locked_torque_Nm"] == 0.0
    assert opt.terms["lockup_torque_jump_Nm"] == pytest.approx(-ocp.lock_margin * ocp.scales.torque_Nm, rel=1e-6)
    assert opt.outputs["w_in_rad_s"][-1] == pytest.approx(0.0, abs=1e-6)
    check, _ = verify(ocp.exact, opt)
    assert check["passed"]
    assert check["jump_reference_Nm"] == pytest.approx(check["idas"]["peak_torque_Nm"])
    assert abs(check["torque_jump_Nm"]) <= 0.02 * check["idas"]["peak_torque_Nm"]


@pytest.mark.xfail(strict=True, reason=(
    "measured with the film tension limit and the engine's CVODES for ODE modes: the brake's optimum runs its "
    "film to -0.91 bar, into the corner of the limit, and the IDAS jerk integral (difference quotients of the "
    "torque on the output samples) is 1.131e6 at the scene tolerance and 1.152e6 at rtol 1e-10, against the "
    "collocation's 1.0995e6 (2.9 %); before the engine change it was 1.099e6 and 1.123e6: it does not converge "
    "to within 2 % of the collocation's with the tolerance"))
def test_brake_jerk_integral_of_idas_agrees_with_collocation():
    """With the output held the jerk is the input's: the IDAS difference quotient agrees with collocation."""
    scene = load_scene("zhang2021", BRAKE_EQUAL_SPLIT)
    ocp = EngagementOCP(scene, intervals=100, degree=3)
    opt = ocp.solve()
    check, _ = verify(ocp.exact, opt)
    assert check["idas"]["jerk_integral"] == pytest.approx(opt.terms["jerk_integral"], rel=2e-2)


@pytest.mark.slow
def test_brake_on_the_lining_rough_pair_verifies():
    """zhang2021 as it stands, at 1.2 MPa (twice its pressure limit). On 100 equal intervals (the pressure rise
    at the start unresolved) IDAS stops late, after the holding command has started, with a step of several % of
    the peak torque (the last command held to 1 % past t_f, then the holding pressure); one mesh graded from the
    interval defects passes."""
    from clutchocp.optimal.mesh import solve_verified
    scene = load_scene("zhang2021", {"actuation.max_pressure": "1.2 MPa"})
    solved = solve_verified(EngagementOCP(scene, intervals=100, degree=3))
    first, last = solved["history"][0], solved["history"][-1]
    assert not first["graded"] and not first["passed"] and first["torque_jump_rel"] > 0.05
    assert last["graded"] and last["passed"] and solved["check"]["passed"]
    assert last["lock_time_rel_diff"] <= 1e-3 and last["torque_jump_rel"] <= 0.02
    # the first interval of the graded mesh is several times finer than an equal one
    assert last["smallest_interval_s"]["slip"] < 0.2 * last["engagement_time_s"] / 100


def test_optimize_without_a_pressure_limit_says_to_set_it(capsys, tmp_path):
    """A scene without actuation.max_pressure (zhang2021 with that line removed) is refused in one line."""
    from clutchocp.scene.loader import builtin_scene_dir
    text = (builtin_scene_dir() / "zhang2021.toml").read_text(encoding="utf-8")
    lines = [line for line in text.splitlines() if not line.startswith("max_pressure")]
    assert len(lines) == len(text.splitlines()) - 1
    path = tmp_path / "no_limit.toml"
    path.write_text("\n".join(lines).replace('name = "zhang2021"', 'name = "no_limit"') + "\n", encoding="utf-8")
    assert main(["optimize", str(path), "--out", str(tmp_path / "a")]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "actuation.max_pressure" in err and "--set actuation.max_pressure=" in err
    assert not (tmp_path / "a").exists()


def test_optimize_set_overrides_the_scene(capsys, tmp_path):
    """--set reaches the scene: a bad key is a one-line error, a limit below the fastest lock is refused."""
    assert main(["optimize", "zhang2021", "--set", "actuation.max_presure=1e6", "--out", str(tmp_path / "b")]) == 2
    assert "actuation.max_presure" in capsys.readouterr().err
    assert main(["optimize", "zhang2021", "--set", "actuation.max_pressure='1.2 MPa'", "--t-max", "0.01",
                 "--out", str(tmp_path / "c")]) == 2
    err = capsys.readouterr().err
    assert "t_max = 0.01 s" in err and "1.2 MPa" in err


def test_jerk_limit_is_checked():
    with pytest.raises(ModelError, match="jerk_max"):
        EngagementOCP(default_scene(), intervals=5, jerk_max=-1.0)


@pytest.mark.slow
def test_quasi_static_plates_match_the_plate_masses_of_bao2020():
    """The OCP takes bao2020's plates as massless: under the same release command IDAS gives the same
    kiss and lock-up with and without the plate masses (their dynamics is far faster than the slip)."""
    from clutchocp.optimal.replay import simulate_command
    scene = load_scene("bao2020", {"actuation.initial_pressure": "63.66 MPa"})
    massless = scene.with_overrides({"pack.model": "massless", "pack.plate_masses": None})
    runs = [simulate_command(s, [0.0, 0.3], [63.66e6, 0.0], 1.0, control="linear") for s in (scene, massless)]
    locks = [r.summary["engagement_time_s"] for r in runs]
    kisses = [next(e.t for e in r.result.events if e.name == "impact") for r in runs]
    assert locks[0] == pytest.approx(locks[1], rel=1e-4)
    assert kisses[0] == pytest.approx(kisses[1], rel=1e-4)


@pytest.mark.slow
def test_spring_applied_bao2020_optimum_is_confirmed_by_idas():
    """bao2020: the command shapes the release; quasi-static plates in the OCP, IDAS on the plate masses."""
    scene = load_scene("bao2020", {"actuation.max_pressure": "80 MPa", "actuation.initial_pressure": "63.66 MPa"})
    ocp = EngagementOCP(scene, intervals=60)
    assert ocp.quasi_static_plates and ocp.apply_pressure == 0.0 and not ocp.holds_torque
    opt = ocp.solve()
    check, _ = verify(ocp.exact, opt)
    assert check["passed"] and check["lock_time_rel_diff"] <= 0.01
    assert abs(check["torque_jump_Nm"]) <= 0.02 * check["idas"]["peak_torque_Nm"]
    assert check["holding_pressure_Pa"] == 0.0                  # after lock-up the spring clamps
    assert check["idas"]["kiss_speed_m_s"] == pytest.approx(opt.terms["kiss_speed_m_s"], rel=1e-4)


ENGAGEMENT_SCENES = ("bao2020", "bao2020_as_published", "default_driveline", "default_driveline_thermal",
                     "default_fill", "zhang2021")


def test_every_engagement_scene_is_listed_and_carries_a_pressure_limit():
    from clutchocp.scene import list_scenes
    assert sorted(s.name for s in list_scenes() if s.kind == "engagement") == sorted(ENGAGEMENT_SCENES)
    for name in ENGAGEMENT_SCENES:
        assert load_scene(name).get("actuation.max_pressure") is not None, name
    assert load_scene("zhang2021").value("actuation.max_pressure") == 6e5          # Zhang Table 1, P_o


@pytest.mark.parametrize("name", ["bao2020", "bao2020_as_published"])
def test_bao_starts_held_released_by_the_pressure_that_balances_the_preload(name):
    """initial_pressure x area = spring rate x preload (Bao Eq. 21 at x0 = 0 is zero): the piston
    starts at rest; the limit leaves a margin above it."""
    scene = load_scene(name)
    k = scene.value("piston.spring_stiffness") * scene.value("piston.spring_count")
    balance = k * scene.value("piston.spring_preload") / scene.value("piston.area")
    assert scene.value("actuation.initial_pressure") == pytest.approx(balance, rel=1e-4)
    assert scene.value("actuation.max_pressure") >= 1.2 * balance
    from clutchocp.engagement.model import EngagementModel
    model = EngagementModel(scene)
    assert float(model.drive_force(scene.value("actuation.initial_pressure"), 0.0)) == pytest.approx(0.0, abs=10.0)


@pytest.mark.slow
@pytest.mark.parametrize("name", ENGAGEMENT_SCENES)
def test_optimize_succeeds_on_every_engagement_scene(name, tmp_path):
    """The done-when of the phased optimiser: no --set, the IDAS replay within its tolerances, no NaN."""
    import json
    assert main(["optimize", name, "--out", str(tmp_path / name)]) == 0
    text = (tmp_path / name / "summary.json").read_text(encoding="utf-8")
    assert "NaN" not in text and "Infinity" not in text
    summary = json.loads(text)
    assert summary["verification"]["passed"]
    assert summary["verification"]["lock_time_rel_diff"] <= 0.01
    assert summary["verification"]["torque_jump_rel"] <= 0.02


def test_slip_films_of_a_spring_applied_piston_are_bounded_by_their_gap_at_the_kiss():
    """The piston may not stand behind the kiss point in the slip phase (Bao Eq. 13: x0 = travel +
    sum (H0 - h_i) >= travel): every film node but the first (fixed to H0 by the impact link) and every
    collocation point is at most H0; nothing else is bounded above, and the fill phase not at all."""
    ocp = EngagementOCP(load_scene("bao2020_as_published"), intervals=6, fill_intervals=4)
    nlp = ocp.phased
    fill, slip = nlp.unpack(nlp.ubx)
    films = [i for i, name in enumerate(ocp.state_names) if name.startswith("h_")]
    others = [i for i in range(len(ocp.state_names)) if i not in films]
    gap = ocp.model.H0 / ocp.nominal[films]
    assert np.all(np.isinf(slip["x"][0, films]))
    assert np.allclose(slip["x"][1:, films], gap, rtol=1e-15) and np.allclose(slip["xc"][..., films], gap, rtol=1e-15)
    assert np.all(np.isinf(slip["x"][:, others])) and np.all(np.isinf(fill["x"][1:, films]))
    # a pressure-applied piston gets none (its problem is left as it was)
    other = EngagementOCP(load_scene("default_fill"), intervals=6, fill_intervals=4)
    assert np.all(np.isinf(other.phased.unpack(other.phased.ubx)[1]["x"][:, :-1]))


def test_interval_defects_fall_with_the_order_the_grading_assumes():
    """Halving the mesh of the default scene's optimum divides the median interval defect by about
    2^q with q = degree + 1 = 4 (measured 19), between the stage order + 1 and the nonstiff local
    order 2d = 6 of Radau IIA: the defect is a local error of the collocation, measured by CVODES."""
    from clutchocp.optimal.mesh import ORDER_OVER_DEGREE, interval_defects
    scene = default_scene()
    baseline = simulate_engagement(scene)
    t_max = baseline.summary["engagement_time_s"]
    medians = []
    for n in (20, 40):
        ocp = EngagementOCP(scene, intervals=n, baseline=baseline)
        opt = ocp.solve(t_max=t_max)
        medians.append(np.median(interval_defects(ocp.exact, opt)[0]))
    q = 3 + ORDER_OVER_DEGREE
    assert 2 ** (q - 0.5) < medians[0] / medians[1] < 2 ** 6
