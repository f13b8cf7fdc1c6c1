"""Exact first and second derivatives of a collocation NLP, assembled from per-point blocks.

CasADi's automatic differentiation of the whole NLP graph pushes every colour of the Jacobian
(and Hessian) through the mapped dynamics at every collocation point. The NLP has a simple
structure, though: apart from linear terms, every constraint row and every Hessian entry comes from
one collocation point (or from the end point). So the exact derivatives are assembled here from

* the constant Jacobian of the linear part of g,
* per-point Jacobians of (-h xdot, c) and per-point Hessians of the point's share of the
  Lagrangian, -(T/N) lam.xdot + nu.c + T b mu.q (symbolic in SX, evaluated for all points by one
  ``map``), and
* the Jacobian and Hessian of the end function and of the end part of the objective,

scattered into the global sparse matrices by one constant sparse matrix product. The result is the
same Jacobian and Hessian (checked against CasADi's own in tests/optimal/test_optimal_collocation.py and
tests/optimal/test_optimal.py). Measured on the default problem (N = 100, degree 3): 2.7 ms per Jacobian
and 23 ms per Hessian, against 16 ms and 54 ms by CasADi's AD of the graph (and 0.1 s / 0.3 s
before equal films were merged into one state); expanding the whole NLP to SX instead took
10 minutes and 14 GB to build.

The objective must be linear in the integrals Q with coefficients that depend on the parameters
only (``J = J0(x_f, u_f, T, p) + mu(p).Q``).
"""

import casadi as ca
import numpy as np
from scipy import sparse

from .. import interrupt
from ..errors import ModelError

IPOPT_OPTIONS = {"print_level": 0, "sb": "yes", "tol": 1e-8, "max_iter": 500,
                 "mu_strategy": "adaptive", "nlp_scaling_method": "gradient-based"}
# Warm start from a previous primal-dual solution: start close to the central path. MUMPS' own
# scaling is switched off there: with it, the warm start of the default problem at N = 400 failed in
# the step computation after minutes of workspace reallocation (N = 50 .. 200 were unaffected).
# MUMPS without its own scaling, for the cold start of a problem with plate temperatures (a [thermal] part):
# with the scaling, the lining's conduction nodes made the KKT factorisations unreliable at N = 100
# (default_driveline_thermal: 500 iterations without an optimum; default_driveline: Error_In_Step_Computation
# after 121); without it 32 and 23 iterations (the lumped plates took 31 and 21).
MUMPS_UNSCALED = {"mumps_permuting_scaling": 0, "mumps_scaling": 0}
WARM_OPTIONS = {"warm_start_init_point": "yes", "mu_init": 1e-6, "warm_start_bound_push": 1e-9,
                "warm_start_bound_frac": 1e-9, "warm_start_slack_bound_push": 1e-9,
                "warm_start_slack_bound_frac": 1e-9, "warm_start_mult_bound_push": 1e-9,
                "mumps_permuting_scaling": 0, "mumps_scaling": 0}


def nlp_solver(tr, *, warm=False, name="ocp", derivatives=None, ipopt=None):
    """IPOPT (``casadi.nlpsol``) for a transcribed problem, with the structured exact derivatives.

    Parameters
    ----------
    tr : TranscribedNLP
    warm : bool
        Warm-start settings (start from given primal and dual values near the central path).
    name : str
        Solver name.
    derivatives : dict, optional
        Result of :func:`structured_derivatives` (built if not given).
    ipopt : dict, optional
        IPOPT options replacing the defaults.

    Returns
    -------
    casadi.Function
    """
    options = dict(IPOPT_OPTIONS, **(WARM_OPTIONS if warm else {}), **(ipopt or {}))
    derivatives = derivatives or structured_derivatives(tr)
    # the iteration callback stops IPOPT at the next iteration after a Ctrl-C (clutchocp.interrupt)
    # show_eval_warnings: a NaN at a trial point is IPOPT's to handle (it backtracks); CasADi's own warning
    # line about it is not the user's business
    return ca.nlpsol(name, "ipopt", tr.nlp, {"print_time": False, "ipopt": options, "error_on_fail": False,
                                             "show_eval_warnings": False,
                                             "iteration_callback": interrupt.ipopt_callback(), **derivatives})


def structured_derivatives(tr):
    """``jac_g`` and ``hess_lag`` functions for ``casadi.nlpsol`` of a :class:`TranscribedNLP`.

    Returns
    -------
    dict
        Options ``{"jac_g": Function, "hess_lag": Function}`` for ``casadi.nlpsol``.
    """
    prob, col = tr.problem, tr.transcription
    N, d = col.intervals, col.degree
    n_x, n_u, n_p = prob.n_x, prob.n_u, prob.n_p
    n_q, n_c = prob.dynamics.size1_out(1), prob.dynamics.size1_out(2)
    n_pts = N * d
    w, P = tr.nlp["x"], tr.nlp["p"]
    n_w, n_g = w.numel(), tr.nlp["g"].numel()

    # Per-point symbols: z = (x, u, T).
    x, u, T, p = ca.SX.sym("x", n_x), ca.SX.sym("u", n_u), ca.SX.sym("T"), ca.SX.sym("p", n_p)
    z = ca.vertcat(x, u, T)
    xdot, q, c = prob.dynamics(x, u, p)
    residual = ca.vertcat(-T / N * xdot, c)
    jac_local = ca.jacobian(residual, z)
    lam, nu, mu, b = ca.SX.sym("lam", n_x), ca.SX.sym("nu", n_c), ca.SX.sym("mu", n_q), ca.SX.sym("b")
    share = ca.dot(lam, -T / N * xdot) + ca.dot(nu, c) + T * b * ca.dot(mu, q)
    hess_local = ca.hessian(share, z)[0]
    jac_fn = ca.Function("point_jacobian", [x, u, T, p], [_nonzeros(jac_local)])
    hess_fn = ca.Function("point_hessian", [x, u, T, p, lam, nu, mu, b], [_nonzeros(hess_local)])

    # End point: z_e = (x_f, u_f, T).
    xf, uf, Q = ca.SX.sym("xf", n_x), ca.SX.sym("uf", n_u), ca.SX.sym("Q", n_q)
    z_e = ca.vertcat(xf, uf, T)
    J = prob.objective(xf, uf, Q, T, p)
    mu_fn = _integral_weights(J, ca.vertcat(xf, uf), Q, T, p)
    g_end = prob.end(xf, uf, T, p)
    sigma, lam_e = ca.SX.sym("sigma"), ca.SX.sym("lam_e", g_end.numel())
    end_share = sigma * ca.substitute(J, Q, ca.DM.zeros(n_q)) + ca.dot(lam_e, g_end)
    jac_end = ca.jacobian(g_end, z_e)
    hess_end = ca.hessian(end_share, z_e)[0]
    jac_end_fn = ca.Function("end_jacobian", [xf, uf, T, p], [_nonzeros(jac_end)])
    hess_end_fn = ca.Function("end_hessian", [xf, uf, T, p, sigma, lam_e], [_nonzeros(hess_end)])

    # Where each local variable lives in w (index, weight) and where each local row lives in g.
    maps = _IndexMaps(tr)
    # Symbolic inputs of the mapped blocks.
    Xc = ca.reshape(w[maps.xc_start:maps.xc_start + n_x * n_pts], n_x, n_pts)
    U = ca.reshape(w[maps.u_start:maps.u_start + n_u * col.n_controls], n_u, col.n_controls)
    Uc = col.control_at_points(U)
    Tk = w[tr.t_slice].T
    Tp = Tk[:, np.repeat(np.arange(N), d).tolist()]
    if not col.uniform:
        # a graded mesh: each point sees T_eff = stretch_k T (its step T_eff / N); the T column of
        # its local derivatives is scaled by stretch_k where it is placed (_IndexMaps)
        Tp = Tp * ca.DM(np.repeat(col.stretch, d)[None, :])
    Pp = ca.repmat(P, 1, n_pts)
    x_f = w[maps.x_start + n_x * N:maps.x_start + n_x * (N + 1)]
    u_f = U[:, -1]
    T_f = w[tr.t_slice.stop - 1]

    # Jacobian of g.
    A = _constant_jacobian(tr.g_linear, w)
    sources = [ca.vec(jac_fn.map(n_pts)(Xc, Uc, Tp, Pp)), jac_end_fn(x_f, u_f, T_f, P), ca.DM(1.0)]
    rows_l, cols_l = jac_local.sparsity().get_triplet()
    trip = [maps.point_triplets(rows_l, cols_l, jac_local.nnz(), local_row=lambda pt, r: maps.point_row(pt, r))]
    rows_e, cols_e = jac_end.sparsity().get_triplet()
    offset = n_pts * jac_local.nnz()
    trip.append(maps.end_triplets(rows_e, cols_e, offset, row_of=lambda r: tr.rows["end"].start + r))
    offset += jac_end.nnz()
    A_rows, A_cols = A.sparsity().get_triplet()
    trip.append((np.array(A_rows), np.array(A_cols), np.full(len(A_rows), offset), np.array(A.nonzeros())))
    jac = _assemble(trip, (n_g, n_w), ca.vertcat(*sources))
    jac_g = ca.Function("nlp_jac_g", [w, P], [tr.nlp["g"], jac], ["x", "p"], ["g", "jac_g_x"])

    # Hessian of the Lagrangian sigma f + lam_g.g (upper triangle).
    sigma_in, lam_g = ca.MX.sym("lam_f"), ca.MX.sym("lam_g", n_g)
    lam_pts = ca.reshape(lam_g[tr.rows["colloc"]], n_x, n_pts)
    nu_pts = ca.reshape(lam_g[tr.rows["path"]], n_c, n_pts) if n_c else ca.MX(0, n_pts)
    mu_val = sigma_in * mu_fn(P)
    b_pts = ca.DM(np.tile(col.B, N)[None, :] / N)                  # quadrature weight per unit T
    sources = [ca.vec(hess_fn.map(n_pts)(Xc, Uc, Tp, Pp, lam_pts, nu_pts, ca.repmat(mu_val, 1, n_pts), b_pts)),
               hess_end_fn(x_f, u_f, T_f, P, sigma_in, lam_g[tr.rows["end"]])]
    rows_l, cols_l = hess_local.sparsity().get_triplet()
    trip = [maps.point_triplets(rows_l, cols_l, hess_local.nnz(), local_row=None)]
    rows_e, cols_e = hess_end.sparsity().get_triplet()
    trip.append(maps.end_triplets(rows_e, cols_e, n_pts * hess_local.nnz(), row_of=None))
    hess = _assemble(trip, (n_w, n_w), ca.vertcat(*sources), upper=True)
    hess_lag = ca.Function("nlp_hess_l", [w, P, sigma_in, lam_g], [hess],
                           ["x", "p", "lam_f", "lam_g"], ["triu_hess_gamma_x_x"])
    return {"jac_g": jac_g, "hess_lag": hess_lag}


def _integral_weights(J, xf, Q, T, p):
    """mu(p) with J = J0(x_f, T, p) + mu(p).Q; checked numerically (call nodes such as B-splines keep
    structural dependencies in derivatives even when their seeds are zero)."""
    mu_expr = ca.jacobian(J, Q)
    others = ca.vertcat(xf, Q, T)
    probe = ca.Function("probe", [others, p], [mu_expr])
    rng = np.random.default_rng(1)
    p_val = rng.uniform(0.5, 1.5, p.numel())
    values = [np.array(probe(rng.uniform(0.5, 1.5, others.numel()), p_val)) for _ in range(2)]
    if not np.allclose(values[0], values[1], rtol=1e-12, atol=1e-12):
        raise ModelError("structured derivatives need an objective linear in the integrals, with "
                         "coefficients that depend on the parameters only")
    return ca.Function("integral_weights", [p], [ca.substitute(mu_expr, others, ca.DM.zeros(others.numel())).T])


def _nonzeros(matrix):
    """The structural nonzeros of a sparse SX matrix as a column (column-major order)."""
    return ca.vertcat(*matrix.nonzeros()) if matrix.nnz() else ca.SX(0, 1)


def _constant_jacobian(g_linear, w):
    """Jacobian of the (affine) linear part of g, a constant sparse DM."""
    jac = ca.jacobian(g_linear, w)
    return ca.Function("linear_jacobian", [w], [jac])(np.zeros(w.numel()))


class _IndexMaps:
    """Positions of the per-point variables in w and of the per-point rows in g."""

    def __init__(self, tr):
        col, prob = tr.transcription, tr.problem
        self.N, self.d = col.intervals, col.degree
        self.n_x, self.n_u = prob.n_x, prob.n_u
        self.n_c = prob.dynamics.size1_out(2)
        self.x_start = tr.layout["x"][0]
        self.xc_start = tr.layout["xc"][0]
        self.u_start = tr.layout["u"][0]
        self.t_start = tr.t_slice.start
        self.rows = tr.rows
        self.linear = col.control == "linear"
        self.n_controls = col.n_controls
        self.tau = col.tau
        self.stretch = col.stretch

    def variable_images(self, pt, a):
        """Global indices and weights of local variable a (x, u, T) at point pt."""
        k, j = divmod(pt, self.d)
        if a < self.n_x:
            return [(self.xc_start + pt * self.n_x + a, 1.0)]
        if a < self.n_x + self.n_u:
            i = a - self.n_x
            if not self.linear:
                return [(self.u_start + k * self.n_u + i, 1.0)]
            tau = self.tau[j]
            return [(self.u_start + k * self.n_u + i, 1.0 - tau), (self.u_start + (k + 1) * self.n_u + i, tau)]
        return [(self.t_start + k, float(self.stretch[k]))]

    def end_images(self, a):
        """Global index of local end variable a (x_f, u_f, T)."""
        if a < self.n_x:
            return [(self.x_start + self.N * self.n_x + a, 1.0)]
        if a < self.n_x + self.n_u:
            return [(self.u_start + (self.n_controls - 1) * self.n_u + a - self.n_x, 1.0)]
        return [(self.t_start + self.N - 1, 1.0)]

    def point_row(self, pt, r):
        """Row in g of local residual r at point pt (collocation rows, then path rows)."""
        if r < self.n_x:
            return self.rows["colloc"].start + pt * self.n_x + r
        return self.rows["path"].start + pt * self.n_c + (r - self.n_x)

    def point_triplets(self, rows, cols, nnz, local_row):
        """(row, col, source, weight) of every local nonzero at every point.

        ``local_row=None``: a Hessian (rows are variables too).
        """
        out_r, out_c, out_s, out_w = [], [], [], []
        for pt in range(self.N * self.d):
            images = {}
            for e, (r, cl) in enumerate(zip(rows, cols)):
                rr = local_row(pt, r) if local_row else None
                col_images = images.setdefault(cl, self.variable_images(pt, cl))
                row_images = [(rr, 1.0)] if local_row else images.setdefault(r, self.variable_images(pt, r))
                for gr, wr in row_images:
                    for gc, wc in col_images:
                        out_r.append(gr)
                        out_c.append(gc)
                        out_s.append(pt * nnz + e)
                        out_w.append(wr * wc)
        return np.array(out_r), np.array(out_c), np.array(out_s), np.array(out_w)

    def end_triplets(self, rows, cols, offset, row_of):
        out_r, out_c, out_s, out_w = [], [], [], []
        for e, (r, cl) in enumerate(zip(rows, cols)):
            row_images = [(row_of(r), 1.0)] if row_of else self.end_images(r)
            for gr, wr in row_images:
                for gc, wc in self.end_images(cl):
                    out_r.append(gr)
                    out_c.append(gc)
                    out_s.append(offset + e)
                    out_w.append(wr * wc)
        return np.array(out_r, int), np.array(out_c, int), np.array(out_s, int), np.array(out_w, float)


def _assemble(triplets, shape, source, upper=False):
    """Sparse MX matrix whose nonzeros are S @ source, S built from (row, col, source, weight) triplets.

    ``upper=True`` keeps the upper triangle (row <= col) of a symmetric matrix.
    """
    rows, cols, srcs, weights = (np.concatenate(parts) for parts in zip(*triplets))
    keep = (weights != 0) & ((rows <= cols) if upper else True)
    rows, cols, srcs, weights = rows[keep], cols[keep], srcs[keep], weights[keep]
    keys = cols.astype(np.int64) * shape[0] + rows              # column-major order, as CasADi stores
    unique, position = np.unique(keys, return_inverse=True)
    S = sparse.csc_matrix((weights, (position, srcs)), shape=(unique.size, source.numel()))
    S.sum_duplicates()                       # explicit zeros stay: every row keeps its entry
    pattern = ca.Sparsity.triplet(shape[0], shape[1], (unique % shape[0]).tolist(), (unique // shape[0]).tolist())
    S_dm = ca.DM(ca.Sparsity(S.shape[0], S.shape[1], S.indptr.tolist(), S.indices.tolist()), S.data.tolist())
    return ca.sparsity_cast(ca.mtimes(S_dm, source), pattern)
