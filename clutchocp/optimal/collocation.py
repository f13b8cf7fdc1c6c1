"""Direct collocation: the transcription of an optimal-control problem into an NLP.

A problem on the normalised time s in [0, 1] with free final time T,

    dx/ds = T f(x, u, p),   integrals Q = int_0^1 T q(x, u, p) ds,   path bounds on c(x, u, p),

is cut into ``intervals`` pieces (equal by default, or of given shares of [0, 1]: a graded mesh); on each the state is the polynomial of degree ``degree``
through the interval start (tau = 0) and the collocation points tau_1 .. tau_d, which satisfies the
ODE at the collocation points (Radau IIA: tau_d = 1, stiffly accurate, order 2d - 1; Gauss-Legendre:
interior points, order 2d). The integrals use the quadrature on the same points, which is what the
collocation method integrates an extra state with.

The control is piecewise linear (continuous, one value per interval end) or piecewise constant (one
value per interval). The transcription object (:class:`DirectCollocation`) holds the scheme, the mesh
and the control form only; a problem (:class:`StagedProblem`) knows nothing of them, so the two are
chosen independently (``EngagementOCP(..., transcription=DirectCollocation(...))``).
"""

from dataclasses import dataclass

import casadi as ca
import numpy as np
from scipy import sparse

from ..errors import ModelError

SCHEMES = ("radau", "legendre")
CONTROLS = ("constant", "linear")


def collocation_coefficients(degree, scheme="radau"):
    """Collocation points and the matrices of the collocation polynomial on [0, 1].

    Parameters
    ----------
    degree : int
        Number of collocation points d (>= 1).
    scheme : {"radau", "legendre"}
        Radau IIA (right end included) or Gauss-Legendre points.

    Returns
    -------
    tau : ndarray (d,)
        Collocation points in (0, 1].
    C : ndarray (d + 1, d)
        ``C[r, j]`` = derivative at tau_j of the Lagrange basis polynomial of node r (node 0 is
        tau = 0): ``x'(tau_j) = sum_r C[r, j] x_r``.
    D : ndarray (d + 1,)
        Values of the basis polynomials at tau = 1: ``x(1) = sum_r D[r] x_r``.
    B : ndarray (d,)
        Quadrature weights on the collocation points: ``int_0^1 g = sum_j B[j] g(tau_j)``.
    """
    if scheme not in SCHEMES:
        raise ModelError(f"collocation scheme '{scheme}': allowed values are {', '.join(SCHEMES)}")
    if not (isinstance(degree, (int, np.integer)) and 1 <= degree <= 9):
        raise ModelError(f"collocation degree {degree!r}: an integer from 1 to 9 is allowed")
    tau = np.array(ca.collocation_points(int(degree), scheme))
    nodes = np.concatenate([[0.0], tau])
    C = np.zeros((degree + 1, degree))
    D = np.zeros(degree + 1)
    for r in range(degree + 1):
        basis = _lagrange(nodes, r)
        D[r] = basis(1.0)
        C[r] = basis.deriv()(tau)
    # Quadrature: integrate the interpolant through the collocation points only.
    B = np.array([_lagrange(tau, j).integ()(1.0) for j in range(degree)])
    return tau, C, D, B


def _lagrange(nodes, r):
    """The Lagrange basis polynomial of ``nodes[r]`` (a numpy poly1d)."""
    poly = np.poly1d([1.0])
    for s, node in enumerate(nodes):
        if s != r:
            poly *= np.poly1d([1.0, -node]) / (nodes[r] - node)
    return poly


@dataclass
class StagedProblem:
    """A scaled optimal-control problem on s in [0, 1] with free final time (what is transcribed).

    Every number here is already scaled (states, controls, time and objective of order one).
    An integral that is constrained belongs in the state (as an accumulator): ``end`` sees the
    final state, control and time only, so no constraint row depends on every node (such a dense row, like
    a dense column, makes CasADi's Jacobian colouring useless).

    Parameters
    ----------
    dynamics : casadi.Function
        ``(x[n_x], u[n_u], p[n_p]) -> (xdot[n_x], q[n_q], c[n_c])``: state derivative per unit
        (scaled) time, integrands of the objective integrals Q and path expressions c.
    x0 : array (n_x,) or None
        Initial state (fixed); None: free (a later phase, whose start is linked to the phase before).
    objective : casadi.Function
        ``(x_f[n_x], u_f[n_u], Q[n_q], T, p[n_p]) -> J`` (u_f: the last control value).
    end : casadi.Function
        ``(x_f[n_x], u_f[n_u], T, p[n_p]) -> g_end[n_e]``: end constraints.
    x_lb, x_ub : array (n_x,)
        Bounds on the state at every node.
    u_lb, u_ub : array (n_u,)
        Bounds on the control.
    c_lb, c_ub : array (n_c,)
        Bounds on the path expressions at the collocation points.
    end_lb, end_ub : array (n_e,)
        Bounds on the end constraints.
    u_rate : array (n_u,) or None
        Largest |du/dt| (scaled units per scaled time); None: no limit.
    u_initial : array (n_u,) or None
        Control value before s = 0: with a rate limit, the first move is limited as well (a
        piecewise-linear control then starts from this value).
    """

    dynamics: ca.Function
    x0: np.ndarray
    objective: ca.Function
    end: ca.Function
    x_lb: np.ndarray
    x_ub: np.ndarray
    u_lb: np.ndarray
    u_ub: np.ndarray
    c_lb: np.ndarray
    c_ub: np.ndarray
    end_lb: np.ndarray
    end_ub: np.ndarray
    u_rate: np.ndarray | None = None
    u_initial: np.ndarray | None = None

    @property
    def n_x(self):
        return self.dynamics.size1_in(0)

    @property
    def n_u(self):
        return self.dynamics.size1_in(1)

    @property
    def n_p(self):
        return self.dynamics.size1_in(2)


@dataclass
class TranscribedNLP:
    """The NLP of a transcribed problem and how to read its variables.

    ``nlp`` is the dict for ``casadi.nlpsol`` (``x``, ``f``, ``g``, ``p``); ``lbx, ubx, lbg, ubg``
    the default bounds. The final time is carried by one copy per interval (linked by equality
    constraints, so that no constraint column is dense); ``t_slice`` selects the copies, whose
    bounds are set per solve.
    """

    nlp: dict
    lbx: np.ndarray
    ubx: np.ndarray
    lbg: np.ndarray
    ubg: np.ndarray
    t_slice: slice
    layout: dict
    rows: dict
    transcription: "DirectCollocation"
    problem: StagedProblem
    g_linear: ca.MX

    @property
    def end_rows(self):
        """Rows of the end constraints in g."""
        return self.rows["end"]

    def unpack(self, w):
        """Split an NLP vector into ``{"x": (N+1, n_x), "xc": (N, d, n_x), "u": (N or N+1, n_u), "T": float}``."""
        w = np.asarray(w, dtype=float).ravel()
        out = {name: w[start:start + int(np.prod(shape))].reshape(shape)
               for name, (start, shape) in self.layout.items()}
        out["T"] = float(w[self.t_slice][-1])
        return out

    def pack(self, x, xc, u, T):
        """The NLP vector of node states x (N+1, n_x), collocation states xc (N, d, n_x), controls u (rows), time T."""
        w = np.zeros(self.lbx.size)
        for name, value in (("x", x), ("xc", xc), ("u", u)):
            start, shape = self.layout[name]
            value = np.asarray(value, dtype=float)
            if value.shape != shape:
                raise ModelError(f"initial guess '{name}': expected shape {shape}, got {value.shape}")
            w[start:start + value.size] = value.ravel()
        w[self.t_slice] = T
        return w

    def node_times(self, T):
        """Times (scaled) of the interval starts (N + 1,) and of the collocation points (N, d)."""
        return self.transcription.node_times(T)


class CollocationScheme:
    """What every collocation transcription shares: the points and matrices of one scheme and the rows
    they give on a run of intervals (collocation equations, continuity, quadrature).

    A transcription decides its variables and the step of each interval and builds its NLP from these
    rows (as Dymos keeps its transcriptions under one base class): :class:`DirectCollocation` (one phase
    of free duration on a mesh) and
    :class:`~clutchocp.optimal.scenarios.SharedCommandCollocation` (several scenarios under one
    command on a common grid, the robust problem).

    Parameters
    ----------
    degree : int
        Collocation points per interval d.
    scheme : {"radau", "legendre"}
        Radau IIA (default) or Gauss-Legendre points.
    """

    def __init__(self, degree=3, scheme="radau"):
        self.degree = int(degree)
        self.scheme = scheme
        self.tau, self.C, self.D, self.B = collocation_coefficients(self.degree, scheme)

    def collocation_rows(self, X, Xc, h, xdot):
        """The collocation equations sum_r C[r, j] x_r = h xdot_j (x_0 the interval start) of N intervals.

        Parameters
        ----------
        X : casadi.MX (n_x, N + 1)
            States at the interval starts (and the end).
        Xc : casadi.MX (n_x, N d)
            States at the collocation points.
        h : casadi.MX (1, N d)
            Step of each point's interval.
        xdot : casadi.MX (n_x, N d)
            State derivatives at the collocation points.

        Returns
        -------
        (casadi.MX, casadi.MX)
            The linear part sum_r C[r, j] x_r and the residual (linear part - h xdot), both (n_x, N d).
        """
        N, d, n_x = X.size2() - 1, self.degree, X.size1()
        C0 = np.tile(self.C[0], N)[None, :]                         # weight of the interval start
        linear = repeat_columns(X[:, :-1], d) * ca.DM(np.repeat(C0, n_x, axis=0))
        linear = linear + ca.mtimes(Xc, sparse_dm(sparse.kron(sparse.eye(N), self.C[1:])))   # (N d, N d) blocks
        return linear, linear - ca.repmat(h, n_x, 1) * xdot

    def continuity_rows(self, X, Xc):
        """x_k+1 - x(1) of each interval k, x(1) = sum_r D[r] x_r its polynomial at the end (n_x, N)."""
        N = X.size2() - 1
        ends = X[:, :-1] * self.D[0] + ca.mtimes(Xc, sparse_dm(sparse.kron(sparse.eye(N), self.D[1:, None])))
        return X[:, 1:] - ends

    def quadrature(self, q, h):
        """Integrals of the integrands ``q`` (n_q, N d) at the collocation points with steps ``h`` (1, N d)."""
        N = q.size2() // self.degree
        return ca.mtimes(q * ca.repmat(h, q.size1(), 1), ca.DM(np.tile(self.B, N)))


class DirectCollocation(CollocationScheme):
    """Direct collocation transcription of a :class:`StagedProblem`.

    Parameters
    ----------
    intervals : int
        Number of equal intervals N (>= 2).
    degree : int
        Collocation points per interval d.
    scheme : {"radau", "legendre"}
        Radau IIA (default) or Gauss-Legendre points.
    control : {"linear", "constant"}
        Continuous piecewise-linear or piecewise-constant control.
    mesh : array (intervals,), optional
        Share of each interval in [0, 1] (positive, summing to 1; normalised here); default: equal
        intervals. Interval k has the step T mesh[k].
    """

    def __init__(self, intervals=100, degree=3, scheme="radau", control="linear", mesh=None):
        if not (isinstance(intervals, (int, np.integer)) and intervals >= 2):
            raise ModelError(f"intervals {intervals!r}: an integer >= 2 is needed")
        if control not in CONTROLS:
            raise ModelError(f"control '{control}': allowed values are {', '.join(CONTROLS)}")
        self.intervals = int(intervals)
        self.control = control
        super().__init__(degree, scheme)
        if mesh is None:
            self.mesh = np.full(self.intervals, 1.0 / self.intervals)
            self.uniform = True
        else:
            mesh = np.asarray(mesh, dtype=float).ravel()
            if mesh.size != self.intervals or not np.all(np.isfinite(mesh)) or not np.all(mesh > 0):
                raise ModelError(f"mesh: {self.intervals} positive interval shares are needed")
            self.mesh = mesh / mesh.sum()
            self.uniform = False
        # step of each interval per unit T, relative to the equal step 1/N (1 on a uniform mesh)
        self.stretch = np.ones(self.intervals) if self.uniform else self.mesh * self.intervals

    def __repr__(self):
        graded = "" if self.uniform else f", graded mesh {self.mesh.min():.3g}..{self.mesh.max():.3g}"
        return (f"DirectCollocation(intervals={self.intervals}, degree={self.degree}, "
                f"scheme={self.scheme!r}, control={self.control!r}{graded})")

    def with_mesh(self, mesh):
        """The same transcription on another mesh (interval shares, see the class parameters)."""
        return DirectCollocation(self.intervals if mesh is None else len(mesh), self.degree, self.scheme,
                                 self.control, mesh)

    def _stretch_row(self, repeat):
        """Row DM of the interval stretches, each repeated ``repeat`` times (None on a uniform mesh)."""
        return None if self.uniform else ca.DM(np.repeat(self.stretch, repeat)[None, :])

    @property
    def n_controls(self):
        """Number of control values (N, or N + 1 for a piecewise-linear control)."""
        return self.intervals + (self.control == "linear")

    def node_times(self, T):
        """Interval starts (N + 1,) and collocation times (N, d) for final time T."""
        if self.uniform:
            h = T / self.intervals
            starts = np.arange(self.intervals + 1) * h
            return starts, starts[:-1, None] + h * self.tau[None, :]
        h = T * self.mesh
        starts = np.concatenate([[0.0], np.cumsum(h)])
        starts[-1] = T
        return starts, starts[:-1, None] + h[:, None] * self.tau[None, :]

    def steps(self, T):
        """Step of each interval (N,) for final time T."""
        return T * self.mesh

    def control_at_points(self, U):
        """Control at the collocation points from the control values (columns), as (n_u, N*d)."""
        N, d = self.intervals, self.degree
        if self.control == "constant":
            return repeat_columns(U, d)
        left = repeat_columns(U[:, :-1], d)
        right = repeat_columns(U[:, 1:], d)
        weight = np.tile(self.tau, N)[None, :]
        return left + (right - left) * ca.DM(np.repeat(weight, U.size1(), axis=0))

    def transcribe(self, problem):
        """Build the NLP of a :class:`StagedProblem`.

        Returns
        -------
        TranscribedNLP
        """
        N, d = self.intervals, self.degree
        n_x, n_u, n_p = problem.n_x, problem.n_u, problem.n_p
        X = ca.MX.sym("X", n_x, N + 1)            # states at the interval starts (and the end)
        Xc = ca.MX.sym("Xc", n_x, N * d)          # states at the collocation points
        U = ca.MX.sym("U", n_u, self.n_controls)
        Tk = ca.MX.sym("T", 1, N)                 # the final time, one copy per interval
        P = ca.MX.sym("P", n_p)
        w = ca.veccat(X, Xc, U, Tk)
        # Column-major blocks, read back row-wise: x (N+1, n_x), xc (N, d, n_x), u (n_controls, n_u).
        layout = {"x": (0, (N + 1, n_x)), "xc": (n_x * (N + 1), (N, d, n_x)),
                  "u": (n_x * (N + 1) + n_x * N * d, (self.n_controls, n_u))}
        t_start = layout["u"][0] + n_u * self.n_controls
        t_slice = slice(t_start, t_start + N)

        Uc = self.control_at_points(U)
        xdot, q, c = problem.dynamics.map(N * d)(Xc, Uc, ca.repmat(P, 1, N * d))
        h = repeat_columns(Tk, d) / N                               # step of each point's interval
        if not self.uniform:
            h = h * self._stretch_row(d)
        colloc_linear, colloc = self.collocation_rows(X, Xc, h, xdot)
        continuity = self.continuity_rows(X, Xc)
        Q = self.quadrature(q, h)                                     # integrals over [0, T]
        T = Tk[-1]
        J = problem.objective(X[:, -1], U[:, -1], Q, T, P)
        g_end = problem.end(X[:, -1], U[:, -1], T, P)
        links = ca.vec(Tk[1:] - Tk[:-1])

        # Rows: collocation, continuity, path, time links, end, rate limit. ``g_linear`` is g with
        # the nonlinear terms (dynamics, path, end) left out (for the structured derivatives).
        blocks = [("colloc", ca.vec(colloc), ca.vec(colloc_linear), 0.0, 0.0),
                  ("continuity", ca.vec(continuity), ca.vec(continuity), 0.0, 0.0),
                  ("path", ca.vec(c), ca.MX(c.numel(), 1), np.tile(problem.c_lb, N * d), np.tile(problem.c_ub, N * d)),
                  ("links", links, links, 0.0, 0.0),
                  ("end", g_end, ca.MX(g_end.numel(), 1), problem.end_lb, problem.end_ub)]
        if problem.u_rate is not None:
            if problem.u_initial is not None and self.control == "constant":
                moves = U - ca.horzcat(ca.DM(problem.u_initial), U[:, :-1])
                steps = Tk / N if self.uniform else Tk / N * self._stretch_row(1)
            else:
                moves = U[:, 1:] - U[:, :-1]
                steps = Tk[:, :moves.size2()] / N
                if not self.uniform:
                    steps = steps * self._stretch_row(1)[:, :moves.size2()]
            limit = ca.mtimes(ca.DM(problem.u_rate), steps)          # (n_u, moves)
            rate = ca.vertcat(ca.vec(moves - limit), ca.vec(-moves - limit))
            blocks.append(("rate", rate, rate, -np.inf, 0.0))
        rows, lbg, ubg, start = {}, [], [], 0
        for name, expr, _, lo, hi in blocks:
            rows[name] = slice(start, start + expr.numel())
            start += expr.numel()
            lbg.append(np.broadcast_to(lo, (expr.numel(),)))
            ubg.append(np.broadcast_to(hi, (expr.numel(),)))
        g = ca.vertcat(*[b[1] for b in blocks])
        g_linear = ca.vertcat(*[b[2] for b in blocks])

        lbx = np.concatenate([np.tile(problem.x_lb, N + 1), np.tile(problem.x_lb, N * d),
                              np.tile(problem.u_lb, self.n_controls), np.zeros(N)])
        ubx = np.concatenate([np.tile(problem.x_ub, N + 1), np.tile(problem.x_ub, N * d),
                              np.tile(problem.u_ub, self.n_controls), np.full(N, np.inf)])
        if problem.x0 is not None:
            lbx[:n_x] = ubx[:n_x] = problem.x0
        if problem.u_rate is not None and problem.u_initial is not None and self.control == "linear":
            start = layout["u"][0]                                  # no step at s = 0 either
            lbx[start:start + n_u] = ubx[start:start + n_u] = problem.u_initial
        nlp = {"x": w, "f": J, "g": g, "p": P}
        return TranscribedNLP(nlp, lbx, ubx, np.concatenate(lbg), np.concatenate(ubg), t_slice, layout,
                              rows, self, problem, g_linear)


def sparse_dm(matrix):
    """A CasADi DM with the sparsity of a scipy sparse matrix (a dense DM would make the Jacobian dense)."""
    m = sparse.csc_matrix(matrix)
    m.eliminate_zeros()
    pattern = ca.Sparsity(m.shape[0], m.shape[1], m.indptr.tolist(), m.indices.tolist())
    return ca.DM(pattern, m.data.tolist())


def repeat_columns(M, times):
    """Each column of M repeated ``times`` times, side by side (MX or DM)."""
    index = np.repeat(np.arange(M.size2()), times)
    return M[:, index.tolist()]
