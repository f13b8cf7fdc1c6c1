"""Direct collocation and its structured derivatives against closed forms and python-control's LQR."""

import casadi as ca
import control
import numpy as np
import pytest
from scipy import integrate, optimize

from clutchocp.errors import ModelError
from clutchocp.optimal.bound import jerk_lower_bound
from clutchocp.optimal.collocation import (
    DirectCollocation,
    StagedProblem,
    collocation_coefficients,
)
from clutchocp.optimal.derivatives import nlp_solver, structured_derivatives

INF = np.inf


# -- collocation coefficients -------------------------------------------------------------------
@pytest.mark.parametrize("scheme, exact_degree", [("radau", lambda d: 2 * d - 2), ("legendre", lambda d: 2 * d - 1)])
@pytest.mark.parametrize("degree", [1, 2, 3, 4, 5])
def test_quadrature_is_exact_to_its_order(scheme, exact_degree, degree):
    tau, _, _, B = collocation_coefficients(degree, scheme)
    for k in range(exact_degree(degree) + 1):
        assert np.sum(B * tau**k) == pytest.approx(1.0 / (k + 1), abs=1e-13)
    # one degree more is not integrated exactly (the order is not higher than stated)
    k = exact_degree(degree) + 1
    assert abs(np.sum(B * tau**k) - 1.0 / (k + 1)) > 1e-8


@pytest.mark.parametrize("scheme", ["radau", "legendre"])
def test_derivative_and_end_matrices_are_exact_on_polynomials(scheme):
    degree = 4
    tau, C, D, _ = collocation_coefficients(degree, scheme)
    nodes = np.concatenate([[0.0], tau])
    rng = np.random.default_rng(3)
    poly = np.poly1d(rng.normal(size=degree + 1))        # degree d: represented exactly
    assert np.allclose(poly(nodes) @ C, poly.deriv()(tau), atol=1e-11)
    assert poly(nodes) @ D == pytest.approx(poly(1.0), abs=1e-12)
    if scheme == "radau":
        assert tau[-1] == pytest.approx(1.0)              # Radau IIA ends on the interval end


def test_bad_scheme_degree_and_mesh_are_model_errors():
    with pytest.raises(ModelError, match="scheme"):
        collocation_coefficients(3, "lobatto")
    with pytest.raises(ModelError, match="degree"):
        collocation_coefficients(0, "radau")
    with pytest.raises(ModelError, match="intervals"):
        DirectCollocation(intervals=1)
    with pytest.raises(ModelError, match="control"):
        DirectCollocation(control="cubic")
    with pytest.raises(ModelError, match="mesh"):
        DirectCollocation(intervals=3, mesh=[0.5, 0.5])
    with pytest.raises(ModelError, match="mesh"):
        DirectCollocation(intervals=2, mesh=[1.0, 0.0])


GRADED = [0.05, 0.1, 0.2, 0.3, 0.2, 0.1, 0.05]     # interval shares, finest at both ends


def test_graded_mesh_times_and_steps():
    tr = DirectCollocation(7, 3, "radau", "linear", mesh=np.array(GRADED) * 3.0)    # normalised
    starts, points = tr.node_times(2.0)
    assert np.allclose(np.diff(starts), 2.0 * np.array(GRADED), rtol=0, atol=1e-15)
    assert starts[-1] == 2.0 and np.allclose(tr.steps(2.0), np.diff(starts))
    assert np.allclose(points[:, -1], starts[1:])                # Radau: the last point ends the interval


# -- problems with known answers ----------------------------------------------------------------
def _double_integrator(rho=0.0, path=False):
    """y'' = v, minimise int v^2 dt + rho T, from (y0, v0) to (0, 0): the kinematic jerk problem."""
    x, u, p = ca.SX.sym("x", 2), ca.SX.sym("u"), ca.SX.sym("p", 1)
    c = x[0] + 10.0 if path else ca.SX(0, 1)               # an inactive path constraint y >= -10
    dyn = ca.Function("dyn", [x, u, p], [ca.vertcat(x[1], u), u**2, c])
    xf, uf, Q, T = ca.SX.sym("xf", 2), ca.SX.sym("uf"), ca.SX.sym("Q", 1), ca.SX.sym("T")
    obj = ca.Function("obj", [xf, uf, Q, T, p], [p[0] * Q[0] + rho * T])
    end = ca.Function("end", [xf, uf, T, p], [xf])
    c_lb = np.zeros(1) if path else np.zeros(0)
    c_ub = np.full(1, INF) if path else np.zeros(0)
    return StagedProblem(dyn, np.array([1.0, 0.5]), obj, end, np.full(2, -INF), np.full(2, INF),
                         np.array([-INF]), np.array([INF]), c_lb, c_ub, np.zeros(2), np.zeros(2))


def _solve(problem, transcription, T_bounds, p=(1.0,)):
    tr = transcription.transcribe(problem)
    lbx, ubx = tr.lbx.copy(), tr.ubx.copy()
    lbx[tr.t_slice], ubx[tr.t_slice] = T_bounds
    x0 = np.zeros(lbx.size)
    x0[tr.t_slice] = np.mean(T_bounds)
    solver = nlp_solver(tr, ipopt={"tol": 1e-12})
    sol = solver(x0=x0, lbx=lbx, ubx=ubx, lbg=tr.lbg, ubg=tr.ubg, p=list(p))
    assert solver.stats()["success"], solver.stats()["return_status"]
    return float(sol["f"]), tr.unpack(np.array(sol["x"]).ravel())


@pytest.mark.parametrize("mesh", [None, GRADED], ids=["uniform", "graded"])
@pytest.mark.parametrize("scheme", ["radau", "legendre"])
def test_minimum_jerk_with_linear_control_is_exact(scheme, mesh):
    """A cubic slip history is in the collocation space, its optimal v = y'' is linear: J exact (on
    any mesh, with its rate limit and quadrature on the graded steps)."""
    T = 1.3
    n = 8 if mesh is None else len(mesh)
    J, _ = _solve(_double_integrator(path=True), DirectCollocation(n, 3, scheme, "linear", mesh=mesh), (T, T))
    assert J == pytest.approx(jerk_lower_bound(1.0, 0.5, T), rel=1e-8)


def test_free_final_time_on_a_graded_mesh():
    rho = 2.0
    J_of_T = lambda T: jerk_lower_bound(1.0, 0.5, T) + rho * T
    ref = optimize.minimize_scalar(J_of_T, bounds=(0.2, 10.0), method="bounded", options={"xatol": 1e-12})
    J, parts = _solve(_double_integrator(rho), DirectCollocation(7, 3, "radau", "linear", mesh=GRADED), (0.1, 10.0))
    assert parts["T"] == pytest.approx(ref.x, rel=1e-6)
    assert J == pytest.approx(ref.fun, rel=1e-9)


def test_collocation_error_falls_as_intervals_grow():
    T, exact = 1.3, jerk_lower_bound(1.0, 0.5, 1.3)
    errors = [abs(_solve(_double_integrator(), DirectCollocation(n, 3, "radau", "constant"), (T, T))[0] - exact)
              for n in (10, 20, 40)]
    # piecewise-constant v approximates the linear optimum to O(h): the cost error falls as h^2
    assert errors[1] < errors[0] / 3.5 and errors[2] < errors[1] / 3.5


def test_free_final_time_matches_the_closed_form_minimum():
    rho = 2.0
    J_of_T = lambda T: jerk_lower_bound(1.0, 0.5, T) + rho * T
    ref = optimize.minimize_scalar(J_of_T, bounds=(0.2, 10.0), method="bounded", options={"xatol": 1e-12})
    J, parts = _solve(_double_integrator(rho), DirectCollocation(6, 3, "radau", "linear"), (0.1, 10.0))
    assert parts["T"] == pytest.approx(ref.x, rel=1e-6)
    assert J == pytest.approx(ref.fun, rel=1e-9)


def _lq_slip(S=None):
    """Linear slip model: w_rel' = -tau / I, tau' = (u - tau) / t_s; cost int (q w^2 + r u^2) + x_f' S x_f."""
    I_eq, t_s, q, r = 1.0, 0.2, 1.0, 0.1
    A = np.array([[0.0, -1.0 / I_eq], [0.0, -1.0 / t_s]])
    B = np.array([[0.0], [1.0 / t_s]])
    Qm = np.diag([q, 0.0])
    x, u, p = ca.SX.sym("x", 2), ca.SX.sym("u"), ca.SX.sym("p", 1)
    dyn = ca.Function("dyn", [x, u, p], [ca.mtimes(A, x) + B[:, 0] * u, ca.bilin(Qm, x, x) + r * u**2, ca.SX(0, 1)])
    xf, uf, Q, T = ca.SX.sym("xf", 2), ca.SX.sym("uf"), ca.SX.sym("Q", 1), ca.SX.sym("T")
    obj = ca.Function("obj", [xf, uf, Q, T, p], [Q[0] + ca.bilin(ca.DM(S), xf, xf)])
    end = ca.Function("end", [xf, uf, T, p], [ca.SX(0, 1)])
    problem = StagedProblem(dyn, np.array([1.0, 0.0]), obj, end, np.full(2, -INF), np.full(2, INF),
                            np.array([-INF]), np.array([INF]), np.zeros(0), np.zeros(0), np.zeros(0), np.zeros(0))
    return A, B, Qm, np.array([[r]]), problem


@pytest.mark.parametrize("scheme", ["radau", "legendre"])
def test_lq_slip_model_matches_python_control_lqr(scheme):
    """With the Riccati matrix as terminal cost the finite-horizon optimum is x0' S x0 for any horizon."""
    A, B, Qm, R, _ = _lq_slip(np.zeros((2, 2)))
    K, S, _ = control.lqr(A, B, Qm, R)
    *_, problem = _lq_slip(S)
    J, parts = _solve(problem, DirectCollocation(40, 3, scheme, "linear"), (1.5, 1.5))
    x0 = problem.x0
    assert J == pytest.approx(x0 @ S @ x0, rel=1e-4)
    assert parts["u"][0, 0] == pytest.approx(-(K @ x0)[0], rel=1e-3)


@pytest.mark.parametrize("mesh", [None, [0.1, 0.2, 0.3, 0.4]], ids=["uniform", "graded"])
@pytest.mark.parametrize("control_kind", ["constant", "linear"])
def test_structured_derivatives_equal_casadi_ad(control_kind, mesh):
    """The assembled Jacobian and Hessian are CasADi's own, also with a rate limit and a path row."""
    problem = _double_integrator(rho=0.5, path=True)
    problem.u_rate, problem.u_initial = np.array([3.0]), np.array([0.2])
    xf, uf, T, p = ca.SX.sym("xf", 2), ca.SX.sym("uf"), ca.SX.sym("T"), ca.SX.sym("p", 1)
    problem.end = ca.Function("end", [xf, uf, T, p], [ca.vertcat(xf[0] * uf**2, xf[1] + T * uf)])
    tr = DirectCollocation(4, 3, "radau", control_kind, mesh=mesh).transcribe(problem)
    reference = ca.nlpsol("reference", "ipopt", tr.nlp, {"print_time": False, "ipopt": {"print_level": 0, "sb": "yes"}})
    mine = structured_derivatives(tr)
    rng = np.random.default_rng(7)
    w, lam, p = rng.normal(size=tr.lbx.size), rng.normal(size=tr.lbg.size), [1.3]
    jac_ref = reference.get_function("nlp_jac_g")(w, p)[1]
    hess_ref = reference.get_function("nlp_hess_l")(w, p, 0.7, lam)
    assert np.allclose(np.array(ca.densify(mine["jac_g"](w, p)[1])), np.array(ca.densify(jac_ref)), atol=1e-12)
    assert np.allclose(np.array(ca.densify(mine["hess_lag"](w, p, 0.7, lam))), np.array(ca.densify(hess_ref)),
                       atol=1e-12)


def test_objective_must_be_linear_in_the_integrals():
    problem = _double_integrator()
    xf, uf, Q, T, p = ca.SX.sym("xf", 2), ca.SX.sym("uf"), ca.SX.sym("Q", 1), ca.SX.sym("T"), ca.SX.sym("p", 1)
    problem.objective = ca.Function("obj", [xf, uf, Q, T, p], [Q[0] ** 2])
    tr = DirectCollocation(3, 2).transcribe(problem)
    with pytest.raises(ModelError, match="linear in the integrals"):
        structured_derivatives(tr)


def test_quadrature_of_the_objective_matches_scipy():
    """The collocation integral of v^2 for the (exact) cubic equals scipy's quadrature of it."""
    T = 1.3
    _, parts = _solve(_double_integrator(), DirectCollocation(8, 3, "radau", "linear"), (T, T))
    a = 3 * (-1.0 - 0.5 * T) / T**2 + 0.5 / T
    b = -0.5 / T**2 + 2 * (1.0 + 0.5 * T) / T**3
    ref, _ = integrate.quad(lambda t: (2 * a + 6 * b * t) ** 2, 0.0, T)
    assert jerk_lower_bound(1.0, 0.5, T) == pytest.approx(ref, rel=1e-12)
    starts = np.linspace(0.0, T, 9)
    assert np.allclose(parts["u"][:, 0], 2 * a + 6 * b * starts, atol=1e-7)


# -- mesh grading ---------------------------------------------------------------------------------
def test_graded_mesh_equidistributes_the_predicted_error():
    """Local error C_k h^q with C 2^q times larger on the right half: the new mesh halves the right
    half's steps, so that C h^q is equal everywhere (q = degree + 1)."""
    from clutchocp.optimal.mesh import graded_mesh
    degree, N = 3, 12
    q = degree + 1
    shares = np.full(N, 1.0 / N)
    C = np.where(np.arange(N) < N // 2, 1.0, 2.0**q)
    new = graded_mesh(shares, C * shares**q, degree)
    assert new.sum() == pytest.approx(1.0, abs=1e-15)
    assert np.allclose(new, np.r_[np.full(4, 0.125), np.full(8, 0.0625)], rtol=0, atol=1e-14)
    C_new = np.where(np.cumsum(new) - new / 2 < 0.5, 1.0, 2.0**q)
    assert np.allclose(C_new * new**q, (0.125**q), rtol=1e-12)


def test_graded_mesh_guards_keep_it_regular():
    """One interval with a huge defect: the new intervals crowd into it and grow away from it at most
    by the density ratio 2 per old interval; none is longer than (1 + floor) / (N x floor)."""
    from clutchocp.optimal.mesh import DENSITY_FLOOR, graded_mesh
    N = 20
    defects = np.full(N, 1e-12)
    defects[0] = 1.0
    new = graded_mesh(np.full(N, 1.0 / N), defects, 3)
    nodes = np.r_[0.0, np.cumsum(new)]
    assert np.sum(nodes < 1.0 / N) >= N // 3                     # a third of the nodes in the first interval
    inside = new[:np.searchsorted(nodes, 1.0 / N) - 1]
    assert np.allclose(inside, inside[0], rtol=1e-9)              # equal steps where the density is constant
    # the density halves per old interval away from it: the second old interval holds half as many nodes
    in_second = np.sum((nodes >= 1.0 / N) & (nodes < 2.0 / N))
    assert in_second == pytest.approx(np.sum(nodes < 1.0 / N) / 2, abs=1)
    assert new.max() <= (1 + DENSITY_FLOOR) / (N * DENSITY_FLOOR) * (1 + 1e-12)

