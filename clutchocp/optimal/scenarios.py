"""Several scenarios of one problem under one shared command: the transcription of the robust problem.

The command is continuous and piecewise linear on a common grid of ``intervals`` equal steps h_c
over [0, t_end] (node values V_0 .. V_N, scaled). Scenario s locks in command interval K_s: its
collocation mesh is the K_s full command intervals plus a last interval of free length tau_s in
(tau_min, h_c], so its final time T_s = K_s h_c + tau_s. On a full interval the command at the
collocation point tau_j is V_i + (V_i+1 - V_i) tau_j; on the last one
V_K + (V_K+1 - V_K) tau_s tau_j / h_c, smooth in tau_s (why the mesh is aligned with the command
grid: :mod:`clutchocp.optimal.robust`). Each scenario has its own states and its own parameter
vector (the shared part, e.g. the objective weights, then its own columns, e.g. its scene values);
the dynamics of every collocation point of every scenario is one CasADi ``map``.

The collocation, continuity and quadrature rows are those of every transcription
(:class:`~clutchocp.optimal.collocation.CollocationScheme`).
"""

from dataclasses import dataclass

import casadi as ca
import numpy as np

from .collocation import CollocationScheme


@dataclass
class ScenarioNLP:
    """The variables, rows and bounds of a multi-scenario transcription, and how to read its variables.

    ``w`` is ``[X_s (each scenario's node states); Xc_s (its collocation states); V (command nodes);
    tau (the length of each scenario's last interval); extra variables]`` (scaled units); ``blocks`` the
    rows ``(expression, lower, upper)``: collocation, continuity, path, end conditions of every scenario
    and (with a rate limit) the command moves; ``objectives`` each scenario's objective J_s and ``ends``
    its ``(x_f, u_f, Q, T_s, p_s)`` (MX).

    Scenario s has ``lock_intervals[s]`` = K_s full command intervals, then a last interval of free
    length tau_s in (tau_min, h_c] (its lock-up at T_s = K_s h_c + tau_s).
    """

    w: ca.MX
    blocks: list
    objectives: list
    ends: list
    lbx: np.ndarray
    ubx: np.ndarray
    x_offsets: list                    # (start, n_nodes) of each scenario's node states in w
    xc_offsets: list                   # (start, n_points) of each scenario's point states in w
    v_slice: slice
    tau_slice: slice
    n_x: int
    degree: int
    tau: np.ndarray                    # collocation points in (0, 1]
    h_c: float
    lock_intervals: tuple
    command_grid: np.ndarray           # scaled times of the command nodes
    tau_min: float

    @property
    def t_upper(self):
        return self.command_grid[-1]

    def unpack(self, w):
        w = np.asarray(w, float).ravel()
        d, n_x = self.degree, self.n_x
        x = [w[a:a + n * n_x].reshape(n, n_x) for a, n in self.x_offsets]
        xc = [w[a:a + n * n_x].reshape(n // d, d, n_x) for a, n in self.xc_offsets]
        tau = w[self.tau_slice]
        T = np.array(self.lock_intervals) * self.h_c + tau
        return {"x": x, "xc": xc, "v": w[self.v_slice], "tau": tau, "T": T}

    def pack(self, x, xc, v, T):
        w = np.zeros(self.lbx.size)
        for (a, n), xs in zip(self.x_offsets, x):
            w[a:a + n * self.n_x] = np.asarray(xs, float).ravel()
        for (a, n), xcs in zip(self.xc_offsets, xc):
            w[a:a + n * self.n_x] = np.asarray(xcs, float).ravel()
        w[self.v_slice] = v
        w[self.tau_slice] = np.asarray(T, float) - np.array(self.lock_intervals) * self.h_c
        return w

    def clip_lock_times(self, T):
        """Scaled lock times moved into each scenario's lock interval."""
        K = np.array(self.lock_intervals)
        return np.clip(T, K * self.h_c + self.tau_min, (K + 1) * self.h_c)

    def scenario_times(self, T=None):
        """Scaled (node times, point times (K+1, d)) of each scenario (at lock times T, default the
        end of each lock interval)."""
        K = np.array(self.lock_intervals)
        T = (K + 1) * self.h_c if T is None else np.asarray(T, float)
        out = []
        for Ks, Ts in zip(K, T):
            starts = np.append(np.arange(Ks + 1) * self.h_c, Ts)
            steps = np.diff(starts)
            out.append((starts, starts[:-1, None] + steps[:, None] * self.tau[None, :]))
        return out

    def interval_moves(self, w, lam_x, tol=1e-6, stuck=False):
        """+1 / -1 for a scenario whose lock-up sits on the end / start of its command interval with a
        multiplier pushing it beyond (and a next / previous interval exists), else 0.

        ``stuck``: the solve failed; move every lock-up that sits on a bound (multipliers ignored).
        """
        tau, lam = w[self.tau_slice], lam_x[self.tau_slice]
        K = np.array(self.lock_intervals)
        n_int = self.command_grid.size - 1
        at_end = tau >= self.h_c * (1 - (1e-3 if stuck else 1e-6))
        at_start = tau <= self.tau_min + (1e-3 * self.h_c if stuck else 1e-3 * self.tau_min)
        up = at_end & ((lam > tol) | stuck) & (K < n_int - 1)
        down = at_start & ((lam < -tol) | stuck) & (K > 0)
        return up.astype(int) - down.astype(int)


class SharedCommandCollocation(CollocationScheme):
    """Scenarios of one :class:`~clutchocp.optimal.collocation.StagedProblem` (piecewise-linear
    command) under one command on a common grid (see the module notes).

    Parameters
    ----------
    t_end : float
        End of the command grid (scaled time).
    intervals : int
        Equal command steps over [0, t_end].
    lock_intervals : sequence of int
        The command interval K_s each scenario locks in.
    degree : int
        Collocation points per interval.
    scheme : {"radau", "legendre"}
    """

    def __init__(self, t_end, intervals, lock_intervals, degree=3, scheme="radau"):
        super().__init__(degree, scheme)
        self.intervals = int(intervals)
        self.h_c = t_end / self.intervals
        self.tau_min = 1e-3 * self.h_c
        self.grid = np.arange(self.intervals + 1) * self.h_c
        self.lock_intervals = tuple(int(k) for k in lock_intervals)

    def transcribe(self, problem, shared_p, scenario_p, extra=(), end_repeats_path=()):
        """The rows and bounds of every scenario of ``problem`` (see :class:`ScenarioNLP`).

        Parameters
        ----------
        problem : clutchocp.optimal.collocation.StagedProblem
            Its ``x0`` starts every scenario; its parameter is ``[shared_p; scenario_p[:, s]]``.
        shared_p : casadi.MX
            The part of the parameter all scenarios share.
        scenario_p : casadi.MX (n, n_scenarios)
            Each scenario's own part (a column each).
        extra : sequence of casadi.MX
            Further variables appended to w (their bounds free).
        end_repeats_path : sequence of int
            Path rows an end condition repeats at the lock-up node: left out at each scenario's last
            collocation point where that point is its end (Radau), since the same constraint twice
            (active, with equal gradients) has no unique multipliers.

        Returns
        -------
        ScenarioNLP
        """
        d, tau, h_c = self.degree, self.tau, self.h_c
        n_x, n_s = problem.n_x, len(self.lock_intervals)
        K = np.array(self.lock_intervals)
        n_nodes, n_ints = K + 2, K + 1
        X = [ca.MX.sym(f"X{s}", n_x, int(n_nodes[s])) for s in range(n_s)]
        Xc = [ca.MX.sym(f"Xc{s}", n_x, int(n_ints[s]) * d) for s in range(n_s)]
        V = ca.MX.sym("V", self.intervals + 1)
        tau_s = ca.MX.sym("tau", n_s)
        w = ca.veccat(*X, *Xc, V, tau_s, *extra)
        x_offsets, xc_offsets, start = [], [], 0
        for s in range(n_s):
            x_offsets.append((start, int(n_nodes[s])))
            start += int(n_nodes[s]) * n_x
        for s in range(n_s):
            xc_offsets.append((start, int(n_ints[s]) * d))
            start += int(n_ints[s]) * d * n_x
        v_slice = slice(start, start + self.intervals + 1)
        tau_slice = slice(v_slice.stop, v_slice.stop + n_s)

        Uc, step = self._command_at_points(V, tau_s)
        n_pts = step.size2()
        P_pts = ca.vertcat(ca.repmat(shared_p, 1, n_pts),
                           ca.horzcat(*[ca.repmat(scenario_p[:, s], 1, int(n_ints[s]) * d) for s in range(n_s)]))
        xdot, q, c = problem.dynamics.map(n_pts)(ca.horzcat(*Xc), Uc, P_pts)

        colloc, continuity, g_end, objectives, ends = [], [], [], [], []
        col = 0
        for s in range(n_s):
            cols = slice(col, col + int(n_ints[s]) * d)
            col = cols.stop
            hs = step[:, cols]
            colloc.append(ca.vec(self.collocation_rows(X[s], Xc[s], hs, xdot[:, cols])[1]))
            continuity.append(ca.vec(self.continuity_rows(X[s], Xc[s])))
            Q = self.quadrature(q[:, cols], hs)
            T_s = K[s] * h_c + tau_s[s]
            u_f = V[int(K[s])] + (V[int(K[s]) + 1] - V[int(K[s])]) * tau_s[s] / h_c
            p_s = ca.vertcat(shared_p, scenario_p[:, s])
            objectives.append(problem.objective(X[s][:, -1], u_f, Q, T_s, p_s))
            g_end.append(problem.end(X[s][:, -1], u_f, T_s, p_s))
            ends.append((X[s][:, -1], u_f, Q, T_s, p_s))
        n_c = problem.c_lb.size
        keep = np.ones((n_pts, n_c), bool)
        if np.isclose(tau[-1], 1.0):
            for row in end_repeats_path:
                keep[np.cumsum(n_ints * d) - 1, row] = False
        keep = np.flatnonzero(keep.ravel())                       # ca.vec(c) runs through the rows of each point
        blocks = [(ca.vertcat(*colloc), 0.0, 0.0), (ca.vertcat(*continuity), 0.0, 0.0),
                  (ca.vec(c)[keep.tolist()], np.tile(problem.c_lb, n_pts)[keep], np.tile(problem.c_ub, n_pts)[keep]),
                  (ca.vertcat(*g_end), np.tile(problem.end_lb, n_s), np.tile(problem.end_ub, n_s))]
        assert problem.end_lb.size * n_s == blocks[3][0].numel()
        if problem.u_rate is not None:
            limit = float(problem.u_rate[0]) * h_c
            blocks.append((V[1:] - V[:-1], -limit, limit))
        lbx, ubx = self._bounds(problem, w.numel(), x_offsets, xc_offsets, v_slice, tau_slice)
        return ScenarioNLP(w, blocks, objectives, ends, lbx, ubx, x_offsets, xc_offsets, v_slice, tau_slice, n_x, d,
                           np.asarray(tau), h_c, self.lock_intervals, self.grid, self.tau_min)

    def _command_at_points(self, V, tau_s):
        """Command and step at every collocation point of every scenario, as rows (1, points).

        Interval i < K_s of scenario s is command interval i (step h_c, u = V_i + (V_i+1 - V_i) tau_j);
        its last interval K_s has the step tau_s and u = V_K + (V_K+1 - V_K) tau_s tau_j / h_c.
        """
        d, tau, h_c = self.degree, self.tau, self.h_c
        left_idx, frac, step = [], [], []
        for s, K_s in enumerate(self.lock_intervals):
            for i in range(K_s + 1):
                left_idx += [i] * d
                if i < K_s:
                    frac.append(ca.DM(tau).T)
                    step.append(ca.DM.ones(1, d) * h_c)
                else:
                    frac.append(tau_s[s] * ca.DM(tau).T / h_c)
                    step.append(ca.repmat(tau_s[s], 1, d))
        frac, step = ca.horzcat(*frac), ca.horzcat(*step)
        left = V[left_idx].T
        right = V[[i + 1 for i in left_idx]].T
        return left + (right - left) * frac, step

    def _bounds(self, problem, n_w, x_offsets, xc_offsets, v_slice, tau_slice):
        """lbx, ubx: state bounds at every node and point, every scenario from ``problem.x0``, the
        command within its bounds (its first node at ``u_initial`` with a rate limit: no step at t = 0),
        each last interval in (tau_min, h_c]."""
        n_x = problem.n_x
        lbx, ubx = np.full(n_w, -np.inf), np.full(n_w, np.inf)
        for (a, n) in x_offsets + xc_offsets:
            lbx[a:a + n * n_x] = np.tile(problem.x_lb, n)
            ubx[a:a + n * n_x] = np.tile(problem.x_ub, n)
        for a, _ in x_offsets:                                 # every scenario starts from the initial state
            lbx[a:a + n_x] = ubx[a:a + n_x] = problem.x0
        lbx[v_slice], ubx[v_slice] = problem.u_lb[0], problem.u_ub[0]
        if problem.u_initial is not None and problem.u_rate is not None:
            lbx[v_slice.start] = ubx[v_slice.start] = problem.u_initial[0]     # no step at t = 0
        lbx[tau_slice], ubx[tau_slice] = self.tau_min, self.h_c
        return lbx, ubx
