"""Mesh refinement of the collocation problem: interval defects and a graded mesh that equidistributes them.

The defect of interval k is how far the collocation polynomial's end state lies from an accurate
integration (CVODES, tolerance 1e-10) of the same phase dynamics over the same interval, started
from the collocation state at its start and driven by the same command:

    e_k = max_i | x_i(t_k+1; x_k, u) - x_k+1,i |     (states scaled by their nominal values).

A collocation method with local error e_k ~ C_k h_k^q on a step h_k needs the step
h ~ C_k^(-1/q) for equal errors everywhere; the new mesh places its N nodes so that each interval
holds an equal share of the density rho_k = C_k^(1/q) = e_k^(1/q) / h_k (equidistribution, e.g.
Ascher, Mattheij, Russell, "Numerical solution of boundary value problems for ODEs", 1995, Sec.
9.3). q = d + 1 (the stage order plus one of Radau IIA / Gauss with d points): the convergence
order 2d - 1 of the nodes is not reached on the stiff, non-smooth engagement model, and a smaller q
grades more gently. Two guards keep the mesh regular: densities of neighbouring intervals within a
factor 2, then a floor on rho (a tenth of its mean, so no interval grows beyond 11 equal steps).
"""

import casadi as ca
import numpy as np

from ..errors import SolverError
from .objective import OBJECTIVE_TERMS
from .strategy import solve_robustly
from .verify import verify

ORDER_OVER_DEGREE = 1           # q = degree + 1
DENSITY_FLOOR = 0.1             # rho >= DENSITY_FLOOR x its mean over the phase
NEIGHBOUR_RATIO = 2.0           # rho_k / rho_k+-1 <= NEIGHBOUR_RATIO
DEFECT_TOL = 1e-10              # CVODES tolerances of the reference integration


def interval_defects(ocp, opt):
    """Defect of each collocation interval of each phase of an optimum (see the module notes).

    Parameters
    ----------
    ocp : clutchocp.optimal.problem.EngagementOCP
        The problem the optimum was solved on (its functions; the exact twin after a polish).
    opt : clutchocp.optimal.problem.OptimalEngagement

    Returns
    -------
    list of ndarray
        Per phase, the defect of each interval [scaled state units, nominal values = 1].
    """
    out = []
    weights = [opt.weights[k] for k in OBJECTIVE_TERMS]
    for k, (name, _) in enumerate(ocp.phase_modes):
        part = ocp.phased.parts[k]
        tr = part.transcription
        parts = part.unpack(ocp.phased.w_of(opt.w, k))
        fn = ocp.phase_functions[name]["dynamics_fn"]
        n_x = fn.size1_in(0)
        x, s = ca.SX.sym("x", n_x), ca.SX.sym("s")
        h, u0, u1 = ca.SX.sym("h"), ca.SX.sym("u0"), ca.SX.sym("u1")
        p = ca.SX.sym("p", fn.size1_in(2))
        xdot = fn(x, u0 + (u1 - u0) * s, p)[0]
        dae = {"x": x, "t": s, "p": ca.vertcat(h, u0, u1, p), "ode": h * xdot}
        integrator = ca.integrator("defect", "cvodes", dae, 0.0, 1.0,
                                   {"abstol": DEFECT_TOL, "reltol": DEFECT_TOL, "max_num_steps": 100000})
        N = tr.intervals
        u = parts["u"][:, 0]
        u_left = u[:N]
        u_right = u[1:N + 1] if tr.control == "linear" else u[:N]
        steps = tr.steps(parts["T"])
        P = np.vstack([steps, u_left, u_right, np.repeat(np.asarray(weights)[:, None], N, axis=1)])
        ends = np.array(integrator.map(N)(x0=parts["x"][:-1].T, p=P)["xf"])
        out.append(np.max(np.abs(ends - parts["x"][1:].T), axis=0))
    return out


def graded_mesh(shares, defects, degree):
    """Interval shares of a new mesh (same number of intervals) that equidistributes the defects.

    Parameters
    ----------
    shares : array (N,)
        The interval shares of the mesh the defects were measured on (summing to 1).
    defects : array (N,)
        Defect of each interval (:func:`interval_defects`).
    degree : int
        Collocation points per interval d (the error order q = d + 1).

    Returns
    -------
    ndarray (N,)
        New interval shares, summing to 1.
    """
    shares = np.asarray(shares, float)
    q = degree + ORDER_OVER_DEGREE
    e = np.maximum(np.asarray(defects, float), 1e-16)
    rho = e ** (1.0 / q) / shares
    for _ in range(rho.size):                 # neighbours within NEIGHBOUR_RATIO (raise the smaller)
        lifted = np.maximum(rho, np.maximum(np.r_[rho[1:], 0.0], np.r_[0.0, rho[:-1]]) / NEIGHBOUR_RATIO)
        if np.array_equal(lifted, rho):
            break
        rho = lifted
    # the floor adds at most DENSITY_FLOOR x the mass: no new interval is longer than
    # (1 + DENSITY_FLOOR) / (N DENSITY_FLOOR) (11 equal steps)
    rho = np.maximum(rho, DENSITY_FLOOR * np.sum(rho * shares))
    # cumulative density on the old nodes; the new nodes cut it into N equal parts
    nodes = np.concatenate([[0.0], np.cumsum(shares)])
    nodes[-1] = 1.0
    mass = np.concatenate([[0.0], np.cumsum(rho * shares)])
    targets = np.linspace(0.0, mass[-1], shares.size + 1)
    new_nodes = np.interp(targets, mass, nodes)
    new_nodes[0], new_nodes[-1] = 0.0, 1.0
    return np.diff(new_nodes)


MAX_REFINEMENTS = 2
COARSE_FRACTION = 0.6       # a phased problem starts on this share of its slip intervals


def solve_verified(ocp, *, refinements=MAX_REFINEMENTS, command_model=None, say=None, **solve_kwargs):
    """Solve, verify with IDAS, and while the replay misses its tolerances grade the mesh and re-solve.

    A phased problem (fill and slip) without a ``guess`` is first solved on ``COARSE_FRACTION`` of
    its slip intervals and then on its own mesh from that optimum: on bao2020 a cold solve on 100
    equal intervals ended at an optimum that IDAS locked 6 % later (one interval's defect 2e3
    nominal values); 60 intervals and then 100 from there converge to an optimum IDAS confirms.

    Each refinement grades every phase's mesh from the optimum's interval defects
    (:meth:`~clutchocp.optimal.problem.EngagementOCP.refined`, same number of intervals) and solves
    again from that optimum (its states and command interpolated onto the new mesh). The result is
    the last solve; it stops early once the IDAS replay passes. A solve on a graded mesh that fails
    (IPOPT) ends the refinement with the previous optimum, and the history records the failure.

    Parameters
    ----------
    ocp : clutchocp.optimal.problem.EngagementOCP
    refinements : int
        Largest number of mesh refinements after a replay that misses (0: solve and verify only).
    command_model : clutchocp.optimal.replay.CommandModel, optional
        The replay model (built once for the scene).
    say : callable, optional
        Progress lines.
    **solve_kwargs
        Passed to :meth:`~clutchocp.optimal.problem.EngagementOCP.solve` (t_max, e_max, weights, guess).

    Returns
    -------
    dict
        ``ocp`` (the problem of the last solve), ``optimum``, ``check`` and ``replay`` (its
        verification, :func:`clutchocp.optimal.verify.verify`) and ``history``: per solve its
        ``stage`` ("coarse start", "solve", "graded mesh"), mesh (intervals, smallest and largest
        interval [s] of each phase), IPOPT iterations and wall time [s], objective, and the
        verification's lock-time difference and jump share (None for the coarse start; a failed
        solve: ``{"stage": "graded mesh", "graded": True, "failed": message}``).
    """
    say = say or (lambda *a, **k: None)
    history = []
    coarse = None
    adapt = solve_kwargs.get("t_max") is None          # a default t_max may be raised (strategy module)
    strategy = {}
    if len(ocp.phase_modes) > 1 and solve_kwargs.get("guess") is None:
        coarse_ocp = ocp.coarsened(COARSE_FRACTION)
        say(f"  phased problem: solving on {coarse_ocp.transcription.intervals} slip intervals first")
        coarse, t_max, strategy["coarse start"] = solve_robustly(coarse_ocp, say=say, adapt_t_max=adapt,
                                                                 **solve_kwargs)
        solve_kwargs = dict(solve_kwargs, t_max=t_max, guess=coarse)
        history.append(_entry(coarse_ocp, coarse, None, stage="coarse start"))
    opt, t_max, strategy["solve"] = solve_robustly(ocp, say=say, adapt_t_max=adapt, **solve_kwargs)
    solve_kwargs = dict(solve_kwargs, t_max=t_max)
    if "coarse start" in strategy and strategy["solve"]["t_max_source"] == "given":
        strategy["solve"]["t_max_source"] = strategy["coarse start"]["t_max_source"]
    stage = "solve"
    while True:
        check, replay = verify(ocp.exact if ocp.polish else ocp, opt, model=command_model)
        history.append(_entry(ocp, opt, check, stage))
        stage = "graded mesh"
        if check["passed"] or sum(h["stage"] == "graded mesh" for h in history) >= refinements:
            return {"ocp": ocp, "optimum": opt, "check": check, "replay": replay, "history": history,
                    "strategy": strategy}
        say(f"  IDAS replay off (lock-up {_pct(check['lock_time_rel_diff'])} from the collocation's, jump "
            f"{_pct(check['torque_jump_rel'])}): grading the mesh from the interval defects and solving again")
        refined = ocp.refined(opt)
        try:
            # with the barrier update that reached the optimum it starts from (bao2020_as_published: the
            # adaptive update stopped at its iteration limit on the graded mesh where the optimum was monotone's)
            opt_new = refined.solve(**dict(solve_kwargs, guess=opt, barrier=strategy["solve"].get("barrier", "adaptive")))
        except SolverError as exc:         # keep the last optimum; its check says it missed
            say(f"  the solve on the graded mesh failed ({exc}); keeping the previous optimum")
            history.append({"stage": "graded mesh", "graded": True, "failed": str(exc)})
            return {"ocp": ocp, "optimum": opt, "check": check, "replay": replay, "history": history,
                    "strategy": strategy}
        ocp, opt = refined, opt_new


def _entry(ocp, opt, check, stage):
    """One solve of :func:`solve_verified` for its history."""
    steps = [np.diff(opt.t[ph["nodes"][0]:ph["nodes"][1]]) for ph in opt.phases]
    return {"stage": stage, "graded": not all(part.transcription.uniform for part in ocp.phased.parts),
            "intervals": {ph["name"]: ph["intervals"] for ph in opt.phases},
            "smallest_interval_s": {ph["name"]: float(h.min()) for ph, h in zip(opt.phases, steps)},
            "largest_interval_s": {ph["name"]: float(h.max()) for ph, h in zip(opt.phases, steps)},
            "iterations": opt.stats["iterations"], "wall_time_s": opt.stats["wall_time_s"],
            "objective": opt.objective, "engagement_time_s": opt.t_f,
            "lock_time_rel_diff": None if check is None else check["lock_time_rel_diff"],
            "torque_jump_rel": None if check is None else check["torque_jump_rel"],
            "passed": None if check is None else check["passed"]}


def _pct(value):
    return "none" if value is None else f"{100 * value:.3g} %"
