"""Discrete Kalman filter: the stationary gain and the time-varying one along a trajectory.

For x_{k+1} = A_k x_k + B_k u_k + w_k, y_k = C_k x_k + v_k with white w_k ~ (0, Q_k), v_k ~ (0, R_k)
and x_0 ~ (x_hat_0, P_0), the filter alternates a measurement update at t_k and a prediction:

    M_k     = P_k^- C_k' (C_k P_k^- C_k' + R_k)^-1          (filter gain)
    x_k     = x_k^- + M_k (y_k - C_k x_k^-)
    P_k     = (I - M_k C_k) P_k^- (I - M_k C_k)' + M_k R_k M_k'   (Joseph form: symmetric, positive)
    x_{k+1}^- = A_k x_k + B_k u_k,   P_{k+1}^- = A_k P_k A_k' + Q_k

(:func:`tvkf`; Kalman 1960, in the notation of Simon, *Optimal State Estimation*, 2006, Eq. 5.19).
With constant matrices P_k^- tends to the solution of the filter's discrete algebraic Riccati
equation and A M_k to the predictor gain of python-control's ``dlqe`` (:func:`kalman_gain`).
"""

import control
import numpy as np

from ..errors import ModelError


def kalman_gain(A, C, Q, R, G=None):
    """Stationary Kalman filter of a time-invariant system (python-control ``dlqe``).

    Parameters
    ----------
    A : array (n, n)
    C : array (p, n)
    Q : array (q, q)
        Process-noise covariance (entering through ``G``, default the identity: q = n).
    R : array (p, p)
        Measurement-noise covariance (positive definite).
    G : array (n, q), optional

    Returns
    -------
    M : array (n, p)
        Filter gain (x_k = x_k^- + M (y_k - C x_k^-)).
    L : array (n, p)
        Predictor gain A M (x_{k+1}^- = A x_k^- + L (y_k - C x_k^-)), ``dlqe``'s.
    P : array (n, n)
        Stationary prior covariance P^-.
    """
    A, C, Q, R = (np.atleast_2d(np.asarray(m, float)) for m in (A, C, Q, R))
    G = np.eye(A.shape[0]) if G is None else np.atleast_2d(np.asarray(G, float))
    try:
        L, P, _ = control.dlqe(A, G, C, Q, R)
    except (np.linalg.LinAlgError, ValueError) as exc:
        raise ModelError(f"Kalman filter: the Riccati equation has no stabilising solution ({exc}); the "
                         "measured signals must see every unstable mode") from None
    P = np.asarray(P, float)
    M = P @ C.T @ np.linalg.inv(C @ P @ C.T + R)
    return M, np.asarray(L, float), P


def tvkf(A, C, Q, R, P0):
    """Gains and covariances of the time-varying Kalman filter over N samples (see the module docstring).

    Parameters
    ----------
    A : sequence of N arrays (n, n)
        Transition from sample k to k + 1 (only the first N - 1 are used for the covariances of
        samples 1 .. N - 1; the last predicts past the horizon).
    C : sequence of N arrays (p, n)
    Q : sequence of N arrays (n, n)
        Process-noise covariance of the step k -> k + 1.
    R : sequence of N arrays (p, p)
        Measurement-noise covariance at sample k (positive definite).
    P0 : array (n, n)
        Prior covariance of the state at sample 0.

    Returns
    -------
    M : array (N, n, p)
        Filter gains.
    P_prior : array (N + 1, n, n)
        P_k^- (P_N^-: the prediction past the last sample).
    P_post : array (N, n, n)
        P_k after the measurement update.
    """
    N = len(A)
    if not (len(C) == len(Q) == len(R) == N) or N == 0:
        raise ModelError(f"tvkf: A, C, Q, R must hold the same number (>= 1) of samples, got "
                         f"{len(A)}, {len(C)}, {len(Q)}, {len(R)}")
    P = np.atleast_2d(np.asarray(P0, float))
    n = P.shape[0]
    p = np.atleast_2d(C[0]).shape[0]
    M = np.zeros((N, n, p))
    P_prior = np.zeros((N + 1, n, n))
    P_post = np.zeros((N, n, n))
    eye = np.eye(n)
    for k in range(N):
        Ak, Ck = np.atleast_2d(A[k]), np.atleast_2d(C[k])
        Qk, Rk = np.atleast_2d(Q[k]), np.atleast_2d(R[k])
        P_prior[k] = P
        S = Ck @ P @ Ck.T + Rk
        M[k] = np.linalg.solve(S, Ck @ P).T            # P C' S^-1 (S and P symmetric)
        I_MC = eye - M[k] @ Ck
        P = I_MC @ P @ I_MC.T + M[k] @ Rk @ M[k].T
        P_post[k] = 0.5 * (P + P.T)
        P = Ak @ P_post[k] @ Ak.T + Qk
        P = 0.5 * (P + P.T)
    P_prior[N] = P
    return M, P_prior, P_post
