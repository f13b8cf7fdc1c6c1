"""Finite-horizon, time-varying discrete LQR: the backward Riccati recursion.

For x_{k+1} = A_k x_k + B_k u_k, k = 0 .. N-1, minimise

    J = x_N' P_N x_N + sum_k (x_k' Q_k x_k + u_k' R_k u_k).

With P_N given, backwards for k = N-1 .. 0 (dynamic programming):

    K_k = (R_k + B_k' P_{k+1} B_k)^-1 B_k' P_{k+1} A_k
    P_k = Q_k + A_k' P_{k+1} (A_k - B_k K_k)

and the optimal control is u_k = -K_k x_k with cost-to-go x_k' P_k x_k. With constant matrices and a
long horizon K_0 tends to the stationary gain of :func:`clutchocp.hvd.design.lqr_gain`.
"""

import numpy as np

from ..errors import ModelError


def tvlqr(A, B, Q, R, P_final):
    """Gains and cost-to-go matrices of the finite-horizon time-varying LQR.

    Parameters
    ----------
    A : sequence of N arrays (n, n)
    B : sequence of N arrays (n, m)
    Q : sequence of N arrays (n, n)
        State weights (symmetric, positive semi-definite).
    R : sequence of N arrays (m, m)
        Input weights (symmetric, positive definite).
    P_final : array (n, n)
        Terminal weight P_N.

    Returns
    -------
    K : array (N, m, n)
        Gains, u_k = -K_k x_k.
    P : array (N + 1, n, n)
        Cost-to-go matrices P_0 .. P_N.
    """
    N = len(A)
    if not (len(B) == len(Q) == len(R) == N) or N == 0:
        raise ModelError(f"tvlqr: A, B, Q, R must hold the same number (>= 1) of steps, got "
                         f"{len(A)}, {len(B)}, {len(Q)}, {len(R)}")
    P_next = np.atleast_2d(np.asarray(P_final, float))
    n = P_next.shape[0]
    m = np.atleast_2d(B[0]).shape[1]
    K = np.zeros((N, m, n))
    P = np.zeros((N + 1, n, n))
    P[N] = P_next
    for k in range(N - 1, -1, -1):
        Ak, Bk = np.atleast_2d(A[k]), np.atleast_2d(B[k])
        Qk, Rk = np.atleast_2d(Q[k]), np.atleast_2d(R[k])
        S = Rk + Bk.T @ P_next @ Bk
        K[k] = np.linalg.solve(S, Bk.T @ P_next @ Ak)
        P_k = Qk + Ak.T @ P_next @ (Ak - Bk @ K[k])
        P_next = 0.5 * (P_k + P_k.T)        # keep it symmetric against round-off
        P[k] = P_next
    return K, P
