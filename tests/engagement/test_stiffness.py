"""Stiffness along an engagement (clutchocp.engagement.stiffness): the Jacobian eigenvalues against
closed forms (the free piston's damped oscillator, the valve lag), finite differences of the
right-hand side, and the definitions of the stiffness ratio and the fastest time constant."""

import math

import numpy as np
import pytest

from clutchocp.engagement.run import simulate_engagement
from clutchocp.engagement.stiffness import (
    eigenvalue_statistics,
    jacobian_eigenvalues,
    stiffness_profile,
    write_stiffness,
)
from clutchocp.errors import ModelError
from clutchocp.scene.loader import load_scene


@pytest.fixture(scope="module")
def runs():
    return {name: simulate_engagement(load_scene(name)) for name in ("bao2020", "zhang2021", "default_driveline")}


def test_statistics_of_a_known_spectrum():
    # decaying -1, -1000 (-1e-3 is slower than the 10 s run: left out of the ratio), a zero, growth +2
    ratio, tau, growth = eigenvalue_statistics([-1.0, -1000.0, -1e-3, 0.0, 2.0 + 5j], t_end=10.0)
    assert ratio == pytest.approx(1000.0, rel=1e-14)
    assert tau == pytest.approx(1e-3, rel=1e-14)
    assert growth == 2.0
    assert math.isnan(eigenvalue_statistics([0.0, 3.0], t_end=1.0)[0])     # nothing decays: undefined
    assert eigenvalue_statistics([0.0], t_end=1.0)[1] == math.inf            # nothing moves: no time constant


def test_free_piston_is_a_damped_oscillator(runs):
    """Bao's piston before it meets the pack: m x'' = -k x - c x' + ..., so the Jacobian has
    -c/(2m) +- i sqrt(k/m - (c/2m)^2) (k = 2e6 N/m, m = 2 kg, c = eta L pi D / psi, Bao Eq. 16)."""
    scene = load_scene("bao2020")
    _, mode, eigenvalues = jacobian_eigenvalues(runs["bao2020"])
    assert mode[0] == "approach_slip_forward"
    k, m = scene.value("piston.spring_stiffness"), scene.value("piston.mass")
    c = (scene.value("oil.viscosity") * scene.value("piston.seal_length") * math.pi
         * scene.value("piston.seal_diameter") / scene.value("piston.seal_clearance"))
    expected = complex(-c / (2 * m), math.sqrt(k / m - (c / (2 * m)) ** 2))
    closest = min(eigenvalues[0], key=lambda ev: abs(ev - expected))
    assert abs(closest - expected) <= 1e-9 * abs(expected)
    assert np.conj(closest) == pytest.approx(min(eigenvalues[0], key=lambda ev: abs(ev - np.conj(expected))))


def test_valve_lag_eigenvalue_is_minus_one_over_its_time_constant(runs):
    """The valve state of the default driveline obeys p' = (command - p)/tau whatever the rest does
    (nothing feeds back into it), so -1/tau = -50 1/s is an eigenvalue at every sample."""
    tau = load_scene("default_driveline").value("actuation.time_constant")
    _, _, eigenvalues = jacobian_eigenvalues(runs["default_driveline"])
    assert all(np.min(np.abs(ev + 1 / tau)) <= 1e-9 / tau for ev in eigenvalues)


def test_eigenvalues_match_finite_differences_of_the_right_hand_side(runs):
    """Zhang's two states (film, disc speed) at a slipping sample: the exact CasADi Jacobian's
    eigenvalues against central differences of the compiled right-hand side."""
    run = runs["zhang2021"]
    t, mode, eigenvalues = jacobian_eigenvalues(run)
    k = int(np.searchsorted(t, 1.0))
    assert mode[k] == "pressing_slip_forward"
    cm = run.model.hybrid.compiled()[mode[k]]
    seg = next(s for s in run.result.segments if s.mode == mode[k])
    j = int(np.searchsorted(seg.t, t[k]))
    xs = np.array([seg.x[n][j] / nom for n, nom in zip(cm.x_names, cm.x_nominal)])
    keep = [cm.x_names.index(n) for n in ("h_1", "w_in")]
    J = np.zeros((2, 2))
    for col, i in enumerate(keep):
        step = 1e-6 * max(abs(xs[i]), 1.0)
        plus, minus = xs.copy(), xs.copy()
        plus[i] += step
        minus[i] -= step
        diff = (np.array(cm.f_ode(plus, [], [], t[k])) - np.array(cm.f_ode(minus, [], [], t[k]))).ravel() / (2 * step)
        J[:, col] = diff[keep]
    assert np.sort_complex(np.linalg.eigvals(J)) == pytest.approx(np.sort_complex(eigenvalues[k]), rel=1e-5)


def test_profile_measures_follow_their_definitions(runs):
    run = runs["bao2020"]
    t, _, eigenvalues = jacobian_eigenvalues(run)
    profile = stiffness_profile(run)
    t_end = t[-1] - t[0]
    for k in (0, len(t) // 3, len(t) - 1):
        re = np.real(eigenvalues[k])
        assert profile.fastest_time_constant_s[k] == pytest.approx(1 / np.max(np.abs(re)), rel=1e-12)
        decaying = -re[(re < 0) & (-re >= 1 / t_end)]
        if decaying.size:
            assert profile.stiffness_ratio[k] == pytest.approx(decaying.max() / decaying.min(), rel=1e-12)
    summary = profile.summary()
    assert summary["min_time_constant_s"] == pytest.approx(np.min(profile.fastest_time_constant_s))
    assert summary["stiffness_index"] == pytest.approx(profile.t_end / summary["min_time_constant_s"])
    # energy accumulators are left out: one eigenvalue per physical state of the mode
    assert max(ev.size for ev in eigenvalues) == run.model.n_states


def test_the_plate_masses_make_bao_far_stiffer_than_the_massless_packs(runs):
    """Plates as masses on squeeze films: time constants m/K down to ~1e-9 s against a 3 s run;
    the massless packs keep only the film and driveline time scales (milliseconds)."""
    bao = stiffness_profile(runs["bao2020"]).summary()
    for name in ("zhang2021", "default_driveline"):
        other = stiffness_profile(runs[name]).summary()
        assert other["min_time_constant_s"] > 1e4 * bao["min_time_constant_s"]
        assert other["max_stiffness_ratio"] < 1e-4 * bao["max_stiffness_ratio"]


def test_files_are_written_without_non_finite_numbers(runs, tmp_path):
    files = write_stiffness(stiffness_profile(runs["zhang2021"]), tmp_path)
    assert [f.name for f in files] == ["stiffness_zhang2021.csv", "stiffness_zhang2021.png"]
    text = files[0].read_text()
    assert "nan" not in text.lower() and "inf" not in text.lower()
    assert text.splitlines()[0] == "time_s,mode,stiffness_ratio,fastest_time_constant_s,max_growth_rate_1_s"


def test_a_model_with_a_pressure_input_is_refused():
    import casadi as ca

    from clutchocp.engagement.model import EngagementModel
    from clutchocp.engagement.run import EngagementResult

    scene = load_scene("zhang2021")
    model = EngagementModel(scene, pressure_command=ca.SX.sym("p_cmd"))
    with pytest.raises(ModelError, match="pressure command"):
        jacobian_eigenvalues(EngagementResult(model, None, {}))
