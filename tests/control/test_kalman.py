"""Kalman filter: scalar closed form, the stationary limit against python-control's dlqe, and the
estimation errors of a simulated run against the covariance the filter predicts."""

import control
import numpy as np
import pytest

from clutchocp.control.kalman import kalman_gain, tvkf
from clutchocp.errors import ModelError


def test_scalar_stationary_gain_closed_form():
    # x+ = a x + w, y = x + v: the prior variance solves P = a^2 P r / (P + r) + q, i.e.
    # P^2 + (r (1 - a^2) - q) P - q r = 0, and the filter gain is P / (P + r)
    a, q, r = 0.95, 0.3, 2.0
    b = r * (1 - a * a) - q
    P = 0.5 * (-b + np.sqrt(b * b + 4 * q * r))
    M, L, P_s = kalman_gain([[a]], [[1.0]], [[q]], [[r]])
    assert P_s[0, 0] == pytest.approx(P, rel=1e-10)
    assert M[0, 0] == pytest.approx(P / (P + r), rel=1e-10)
    assert L[0, 0] == pytest.approx(a * P / (P + r), rel=1e-10)
    # the time-varying filter with constant matrices reaches the same gain
    N = 200
    Mk, P_prior, _ = tvkf([[[a]]] * N, [[[1.0]]] * N, [[[q]]] * N, [[[r]]] * N, [[10.0]])
    assert Mk[-1, 0, 0] == pytest.approx(P / (P + r), rel=1e-10)
    assert P_prior[-1, 0, 0] == pytest.approx(P, rel=1e-10)


def test_time_varying_filter_tends_to_dlqe():
    """A two-inertia driveline sampled at 10 ms (speeds measured, clutch and load torque random walks):
    the time-varying gain from a wide prior converges to python-control's stationary one."""
    Ts, J_in, J_out = 0.01, 0.25, 2.0
    A = np.eye(4)
    A[0, 2] = -Ts / J_in                  # w_in  -= Ts T_c / J_in
    A[1, 2], A[1, 3] = Ts / J_out, -Ts / J_out
    C = np.array([[1.0, 0, 0, 0], [0, 1.0, 0, 0]])
    Q = np.diag([1e-4, 1e-4, 25.0, 1.0])
    R = np.diag([0.04, 0.01])
    L_ref, P_ref, _ = control.dlqe(A, np.eye(4), C, Q, R)
    M, L, P = kalman_gain(A, C, Q, R)
    np.testing.assert_allclose(L, L_ref, rtol=1e-12)
    np.testing.assert_allclose(A @ M, L_ref, rtol=1e-9, atol=1e-12)
    N = 400
    Mk, P_prior, P_post = tvkf([A] * N, [C] * N, [Q] * N, [R] * N, np.diag([1.0, 1.0, 1e4, 1e4]))
    np.testing.assert_allclose(A @ Mk[-1], L_ref, rtol=1e-8, atol=1e-12)
    np.testing.assert_allclose(P_prior[-2], P_ref, rtol=1e-8, atol=1e-12)
    # the update shrinks the covariance: P_k <= P_k^- in every direction
    assert np.all(np.linalg.eigvalsh(P_prior[5] - P_post[5]) > -1e-12)


def test_errors_of_a_simulated_run_match_the_predicted_covariance():
    """On 400 simulated runs of a time-varying system the spread of the estimation error at each sample
    is the filter's P_k (normalised error squared averages n), and the innovations are white."""
    rng = np.random.default_rng(3)
    N, n, runs = 40, 3, 400
    A = [np.array([[1.0, 0.01 * (1 + 0.5 * np.sin(k / 5)), 0.0], [0.0, 0.98, 0.02], [0.0, 0.0, 1.0]])
         for k in range(N)]
    C = [np.array([[1.0, 0.0, 0.0], [0.0, 1.0 if k % 3 else 0.2, 0.0]]) for k in range(N)]
    Q = [np.diag([1e-6, 1e-4, 1e-5])] * N
    R = [np.eye(C[k].shape[0]) * 0.01 for k in range(N)]
    P0 = np.diag([0.1, 0.5, 1.0])
    M, P_prior, P_post = tvkf(A, C, Q, R, P0)
    nees = np.zeros(N)
    innovations = []
    for _ in range(runs):
        x = rng.multivariate_normal(np.zeros(n), P0)
        x_hat = np.zeros(n)
        for k in range(N):
            y = C[k] @ x + rng.multivariate_normal(np.zeros(C[k].shape[0]), R[k])
            nu = y - C[k] @ x_hat
            innovations.append(nu[0] / np.sqrt((C[k] @ P_prior[k] @ C[k].T + R[k])[0, 0]))
            x_hat = x_hat + M[k] @ nu
            e = x - x_hat
            nees[k] += e @ np.linalg.solve(P_post[k], e) / runs
            x = A[k] @ x + rng.multivariate_normal(np.zeros(n), Q[k])
            x_hat = A[k] @ x_hat
    # chi-square with n degrees of freedom over 400 runs: mean n, standard error sqrt(2 n / 400) = 0.12
    assert np.mean(nees) == pytest.approx(n, abs=0.15)
    assert np.all(np.abs(nees - n) < 5 * np.sqrt(2 * n / runs))
    z = np.asarray(innovations)
    assert np.mean(z ** 2) == pytest.approx(1.0, abs=0.05)


def test_bad_input():
    with pytest.raises(ModelError, match="same number"):
        tvkf([np.eye(2)] * 3, [np.eye(2)] * 2, [np.eye(2)] * 3, [np.eye(2)] * 3, np.eye(2))
    with pytest.raises(ModelError, match="Riccati"):
        # an unstable mode the measurement cannot see
        kalman_gain(np.diag([1.5, 0.5]), [[0.0, 1.0]], np.eye(2), [[1.0]])
