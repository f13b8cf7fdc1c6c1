"""Discrete LQR: the stationary gain (with integral action) and the finite-horizon time-varying one.

Stationary (:func:`lqr_gain`, :func:`lqi`): u = -K x minimising sum x'Qx + u'Ru over an infinite
horizon, by python-control's ``dlqr`` (the discrete algebraic Riccati equation).

Finite horizon, time-varying (:func:`tvlqr`): for x_{k+1} = A_k x_k + B_k u_k, k = 0 .. N-1, minimise

    J = x_N' P_N x_N + sum_k (x_k' Q_k x_k + u_k' R_k u_k).

With P_N given, backwards for k = N-1 .. 0 (dynamic programming):

    K_k = (R_k + B_k' P_{k+1} B_k)^-1 B_k' P_{k+1} A_k
    P_k = Q_k + A_k' P_{k+1} (A_k - B_k K_k)

and the optimal control is u_k = -K_k x_k with cost-to-go x_k' P_k x_k. With constant matrices and a
long horizon K_0 tends to the stationary gain of :func:`lqr_gain`.
"""

import control
import numpy as np

from ..errors import ModelError


def lqr_gain(A, B, Q, R):
    """Discrete LQR state-feedback gain K (u = -K x) minimising sum x'Qx + u'Ru (python-control dlqr)."""
    try:
        K, _, _ = control.dlqr(np.atleast_2d(A), np.atleast_2d(B), np.atleast_2d(Q), np.atleast_2d(R))
    except (np.linalg.LinAlgError, ValueError) as exc:
        raise ModelError(f"controller [lqi] weights: the LQR problem has no solution ({exc}); use weights of "
                         "similar size (speed_weight, integral_weight, input_weight within 1e-6 ... 1e6)") from None
    if not np.all(np.isfinite(K)):
        raise ModelError("controller [lqi] weights: the LQR gain is not finite; use weights of similar size")
    return np.atleast_2d(np.asarray(K))


def lqi(Ad, Bd, Ts, Q, R):
    """Discrete LQR with integral action on the first state (the speed).

    The plant x[k+1] = Ad x + Bd u is augmented with xi[k+1] = xi[k] + Ts (r - x_1[k]) and
    ``lqr_gain`` is applied with the (n+1)x(n+1) weight Q and the input weight R.

    Returns
    -------
    K_x : (n,) gains on the state deviation; k_i : integral gain (I[k+1] = I[k] + Ts k_i e);
    loop : discrete loop transfer K (zI - A_aug)^-1 B_aug broken at the plant input.
    """
    Ad, Bd = np.atleast_2d(Ad), np.atleast_2d(Bd)
    n = Ad.shape[0]
    C = np.zeros((1, n))
    C[0, 0] = 1.0
    A_aug = np.block([[Ad, np.zeros((n, 1))], [-Ts * C, np.ones((1, 1))]])
    B_aug = np.vstack([Bd, [[0.0]]])
    K = lqr_gain(A_aug, B_aug, Q, R).ravel()
    loop = control.ss(A_aug, B_aug, K.reshape(1, -1), 0, dt=Ts)
    # u = -K_x dx - K_xi xi and xi integrates e = r - w, so I = -K_xi xi and k_i = -K_xi
    return K[:n], -K[n], loop


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
