"""Time-varying discrete LQR: scalar closed form, cost-to-go identity, stationary limit, bad input."""

import numpy as np
import pytest

from clutchocp.errors import ModelError
from clutchocp.control.lqr import lqr_gain, tvlqr


def test_scalar_time_varying_riccati_closed_form():
    # x+ = a_k x + b_k u, q = 0: P_k = a_k^2 P_{k+1} r / (r + b_k^2 P_{k+1}), i.e.
    # 1/P_k = (1/P_{k+1} + b_k^2 / r) / a_k^2, so 1/P_k has a closed form by telescoping.
    rng = np.random.default_rng(1)
    N, r, P_N = 25, 0.7, 3.0
    a = rng.uniform(0.8, 1.2, N)
    b = rng.uniform(0.2, 2.0, N)
    K, P = tvlqr([[[v]] for v in a], [[[v]] for v in b], [[[0.0]]] * N, [[[r]]] * N, [[P_N]])
    for k in range(N):
        inv = 1.0 / P_N
        for j in range(N - 1, k - 1, -1):
            inv = (inv + b[j] ** 2 / r) / a[j] ** 2
        assert P[k, 0, 0] == pytest.approx(1.0 / inv, rel=1e-12)
        P_next = P[k + 1, 0, 0]
        assert K[k, 0, 0] == pytest.approx(a[k] * b[k] * P_next / (r + b[k] ** 2 * P_next), rel=1e-12)


def test_cost_to_go_equals_the_closed_loop_cost():
    rng = np.random.default_rng(2)
    N, n, m = 30, 3, 2
    A = [np.eye(n) + 0.2 * rng.standard_normal((n, n)) for _ in range(N)]
    B = [rng.standard_normal((n, m)) for _ in range(N)]
    Q = []
    for _ in range(N):
        M = rng.standard_normal((n, n))
        Q.append(M @ M.T)
    R = [np.diag(rng.uniform(0.5, 2.0, m)) for _ in range(N)]
    P_N = np.eye(n) * 2.0
    K, P = tvlqr(A, B, Q, R, P_N)
    x0 = rng.standard_normal(n)
    x, cost = x0.copy(), 0.0
    for k in range(N):
        u = -K[k] @ x
        cost += x @ Q[k] @ x + u @ R[k] @ u
        x = A[k] @ x + B[k] @ u
    cost += x @ P_N @ x
    assert cost == pytest.approx(x0 @ P[0] @ x0, rel=1e-10)
    # no other input sequence does better (the cost is a convex quadratic in the inputs)
    for _ in range(3):
        x, cost_other = x0.copy(), 0.0
        for k in range(N):
            u = -K[k] @ x + 0.05 * rng.standard_normal(m)
            cost_other += x @ Q[k] @ x + u @ R[k] @ u
            x = A[k] @ x + B[k] @ u
        cost_other += x @ P_N @ x
        assert cost_other > cost


def test_long_horizon_tends_to_the_stationary_gain():
    A = np.array([[1.0, 0.01], [0.0, 0.98]])
    B = np.array([[0.0], [0.01]])
    Q, R = np.diag([1.0, 0.1]), np.array([[0.01]])
    K, _ = tvlqr([A] * 3000, [B] * 3000, [Q] * 3000, [R] * 3000, np.zeros((2, 2)))
    np.testing.assert_allclose(K[0], lqr_gain(A, B, Q, R), rtol=1e-8)


def test_mismatched_lengths_raise():
    with pytest.raises(ModelError, match="same number"):
        tvlqr([np.eye(1)] * 2, [np.eye(1)], [np.eye(1)] * 2, [np.eye(1)] * 2, np.eye(1))
