"""Robust feedforward: one pressure command for several scenarios of a clutch (multi-scenario collocation).

A scenario is a set of scene overrides (``{"friction.mu": 0.108, "oil.viscosity": 0.0884, ...}``,
e.g. the corners of an uncertainty box). The robust problem chooses one pressure command u(t) that
every scenario s meets with its own slip dynamics, its own free lock-up time T_s and its own end
conditions (w_rel = 0, the jump condition or penalty, the lock holds), with films above h_min and
T_s <= t_max, and minimises the mean (or the worst, by an epigraph variable z >= J_s) of the
scenarios' objectives J_s (the terms of :mod:`clutchocp.optimal.problem`: jerk, jump, smooth, ...).

How the scenarios share the command. A scenario that locks earlier sees only the start of the
command; its lock-up time is free. The command is therefore a function of absolute time: a
continuous piecewise-linear function on a common grid of ``intervals`` equal steps over [0, t_max]
(the pressure and rate bounds are then linear constraints on its node values). Each scenario keeps
the collocation mesh of the nominal problem on its own [0, T_s] (time scaled by T_s, as in
:mod:`clutchocp.optimal.collocation`), and the command at a collocation point at absolute time
t = T_s s_j is the command's linear interpolation there. The other way, a command per scenario mesh
tied together by equality constraints, needs the interpolation as well (the meshes differ whenever
the lock times do) and adds one copy of the command per scenario. With one scenario that locks at
t_max (the jerk-optimal engagement uses all the time it may) the command grid and the mesh coincide
and the problem is the nominal one (checked in tests/test_optimal_robust.py). The interpolation is
continuous but its derivative in T_s jumps where a collocation point crosses a command node; IPOPT
meets that only as a kink of measure zero (measured: the solves converge; see the README).

One dynamics function for all scenarios. The uncertain scene values are symbols of the model
(:class:`ParametricScene`): :class:`ParametricOCP` builds the scaled dynamics, objective and end
functions of the nominal problem with a parameter vector theta of those values, and the robust
NLP evaluates the dynamics at every collocation point of every scenario by one CasADi ``map``
(theta of the point's scenario as an input), so the cost of the NLP functions grows linearly with
the number of scenarios. Scales, state groups and the initial state are those of the nominal scene.

Stages: as for the nominal problem, first the smooth forms of the switching laws, then a warm-started
polish on the exact forms. Derivatives: CasADi's automatic differentiation of the NLP graph (the
structured assembly of :mod:`clutchocp.optimal.derivatives` assumes a command on the mesh).
"""

import time
from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from ..engagement.model import EngagementModel
from ..engagement.run import simulate_engagement
from ..errors import ModelError, SolverError
from .collocation import DirectCollocation, _repeat_columns, _sparse
from .derivatives import IPOPT_OPTIONS, WARM_OPTIONS
from .guess import guess_from_run
from .problem import OBJECTIVE_TERMS, EngagementOCP, OptimalEngagement, check_weights
from .replay import simulate_command

AGGREGATES = ("mean", "worst")


class ParametricScene:
    """A scene whose named values are CasADi symbols (everything else is the scene's).

    Parameters
    ----------
    scene : clutchocp.scene.Scene
    symbols : dict
        ``{"part.key": casadi.SX}``.
    """

    def __init__(self, scene, symbols):
        self._scene = scene
        self._symbols = dict(symbols)
        # The film law's static coefficient defaults to the (constant) friction coefficient at
        # rest, which it evaluates as a number: give it the symbol instead.
        if ("friction.mu" in self._symbols and scene.variant("friction") == "constant"
                and scene.get("friction.static_coefficient") is None):
            self._symbols["friction.static_coefficient"] = self._symbols["friction.mu"]

    def value(self, name):
        return self._symbols[name] if name in self._symbols else self._scene.value(name)

    def get(self, name, default=None):
        return self._symbols[name] if name in self._symbols else self._scene.get(name, default)

    def __getattr__(self, name):
        return getattr(self._scene, name)


class ParametricOCP(EngagementOCP):
    """The nominal engagement problem of a scene with some scene values as a parameter vector theta.

    ``dynamics_fn``, ``objective_fn`` and ``end_fn`` take ``[weights; theta]`` as their parameter,
    ``outputs_fn`` and ``jump_fn`` take theta as a third input. Scales, state groups, initial state
    and the baseline are the nominal scene's.

    Parameters
    ----------
    scene : clutchocp.scene.Scene
    names : sequence of str
        Scene fields (numeric, ``"part.key"``) that become theta.
    **options
        As for :class:`~clutchocp.optimal.problem.EngagementOCP`.
    """

    def __init__(self, scene, names, **options):
        self.parameter_names = tuple(names)
        self.theta = ca.SX.sym("theta", len(self.parameter_names))
        self.theta_value = self.nominal_theta(scene)
        super().__init__(scene, **options)

    def nominal_theta(self, scene):
        """theta of a scene (its SI values of the parameter names)."""
        values = []
        for name in self.parameter_names:
            value = scene.value(name)
            if not isinstance(value, (int, float, np.floating, np.integer)) or isinstance(value, bool):
                raise ModelError(f"{name}: a robust scenario may vary numeric scene values only (got {value!r})")
            values.append(float(value))
        return np.array(values)

    def _build_functions(self):
        numeric = self.model
        symbols = dict(zip(self.parameter_names, ca.vertsplit(self.theta)))
        try:
            self.model = EngagementModel(ParametricScene(self.scene, symbols), smooth=self.smooth,
                                         pressure_command=self.u)
            super()._build_functions()
        except (TypeError, RuntimeError, NotImplementedError) as exc:
            raise ModelError(f"{', '.join(self.parameter_names)}: the engagement model cannot take these values as "
                             f"symbols of one collocation problem ({type(exc).__name__}: {str(exc).splitlines()[0]})"
                             ) from None
        finally:
            self.model = numeric
        jump_theta = self.jump_fn
        self.jump_fn = lambda x, u: jump_theta(x, u, self.theta_value)

    def _evaluate(self, xs, us):
        n = len(us)
        values = np.array(self.outputs_fn.map(n)(np.asarray(xs).T, np.asarray(us)[None, :],
                                                 np.repeat(self.theta_value[:, None], n, axis=1)))
        return {name: values[i] for i, name in enumerate(self.output_names)}

    @property
    def exact(self):
        if self._exact is None:
            self._exact = ParametricOCP(self.scene, self.parameter_names, smooth=False, polish=False,
                                        baseline=self.baseline, transcription=self.transcription, **self.options)
        return self._exact


@dataclass
class RobustEngagement:
    """A solved (or failed) robust engagement.

    ``command_times`` [s] and ``command`` [Pa] are the nodes of the shared piecewise-linear
    command over [0, t_max] (it holds its last value afterwards); ``scenarios`` one
    :class:`~clutchocp.optimal.problem.OptimalEngagement` per scenario (its ``t_f`` is the
    scenario's lock-up time, its ``command`` the shared command at its own mesh nodes);
    ``overrides`` the scenario override dicts; ``objectives`` each scenario's J_s.
    """

    command_times: np.ndarray
    command: np.ndarray
    scenarios: list
    overrides: list
    objectives: np.ndarray
    objective: float
    aggregate: str
    weights: dict
    scenario_weights: np.ndarray
    t_max: float
    stats: dict
    w: np.ndarray = field(repr=False)
    lam_x: np.ndarray = field(repr=False)
    lam_g: np.ndarray = field(repr=False)

    @property
    def success(self):
        return self.stats["success"]

    @property
    def lock_times(self):
        """Lock-up time of each scenario [s]."""
        return np.array([s.t_f for s in self.scenarios])


def _check_scenarios(scene, scenarios):
    """Parameter names and the scenario scenes (validated) of a list of override dicts."""
    if not isinstance(scenarios, (list, tuple)) or not scenarios:
        raise ModelError("scenarios: a non-empty list of override dicts {'part.key': value} is needed")
    for k, d in enumerate(scenarios):
        if not isinstance(d, dict):
            raise ModelError(f"scenarios[{k}]: an override dict {{'part.key': value}} is needed, got {d!r}")
    names = []
    for d in scenarios:
        names += [n for n in d if n not in names]
    scenes = [scene.with_overrides(d) for d in scenarios]
    for name in names:
        for k, s in enumerate(scenes):
            value = s.get(name)
            if isinstance(value, str):
                raise ModelError(f"scenarios[{k}]: {name} = {value!r}: a robust problem varies numeric scene values "
                                 "only; solve one robust problem per model choice")
    return tuple(names), scenes


class RobustOCP:
    """The multi-scenario collocation problem of a scene (see the module notes).

    Parameters
    ----------
    scene : clutchocp.scene.Scene
        The nominal scene (scales, initial state, baseline).
    scenarios : list of dict
        Override dicts, one per scenario (SI floats for numeric fields).
    intervals, degree : int
        Collocation intervals per scenario (also the steps of the command grid) and points per interval.
    **ocp_options
        Options of :class:`~clutchocp.optimal.problem.EngagementOCP` (rate_limit, h_min, jump,
        lock_margin, smooth, polish, scheme); the command is piecewise linear.
    """

    def __init__(self, scene, scenarios, *, intervals=60, degree=3, **ocp_options):
        if ocp_options.get("control", "linear") != "linear":
            raise ModelError("control: the robust command is piecewise linear (control='linear')")
        ocp_options.pop("control", None)
        self.scene = scene
        self.names, self.scenes = _check_scenarios(scene, scenarios)
        self.overrides = [dict(d) for d in scenarios]
        self.ocp = ParametricOCP(scene, self.names, intervals=intervals, degree=degree, **ocp_options)
        self.thetas = np.array([self.ocp.nominal_theta(s) for s in self.scenes]).reshape(len(self.scenes), -1)
        self.transcription = self.ocp.transcription
        self._nlps = {}
        self._solvers = {}
        self._fastest = None

    @property
    def n_scenarios(self):
        return len(self.scenes)

    # -- feasibility --------------------------------------------------------------------------
    def fastest_lockups(self):
        """Lock-up time of each scenario under a step of the command to the pressure limit [s] (IDAS, cached)."""
        if self._fastest is None:
            out = []
            for k, s in enumerate(self.scenes):
                t_end = s.value("simulation.t_end")
                run = simulate_command(s, [0.0], [self.ocp.p_max], t_end)
                t_lock = run.summary["engagement_time_s"]
                if t_lock is None:
                    raise ModelError(f"scenarios[{k}] {self.overrides[k]}: even a step to actuation.max_pressure does "
                                     f"not lock up within simulation.t_end = {t_end:g} s")
                out.append(t_lock)
            self._fastest = np.array(out)
        return self._fastest

    # -- transcription ------------------------------------------------------------------------
    def nlp(self, ocp, aggregate, t_max):
        """The robust NLP on ``ocp``'s functions (smooth or exact) for a command grid over [0, t_max]."""
        key = (id(ocp), aggregate, float(t_max))
        if key not in self._nlps:
            self._nlps[key] = _transcribe(ocp, self.n_scenarios, aggregate, t_max / ocp.scales.time_s)
        return self._nlps[key]

    def solver(self, ocp, aggregate, t_max, warm):
        key = (id(ocp), aggregate, float(t_max), warm)
        if key not in self._solvers:
            nlp = self.nlp(ocp, aggregate, t_max)
            options = dict(IPOPT_OPTIONS, **(WARM_OPTIONS if warm else {}))
            self._solvers[key] = ca.nlpsol(f"robust_{'warm' if warm else 'cold'}", "ipopt", nlp.nlp,
                                           {"print_time": False, "ipopt": options, "error_on_fail": False})
        return self._solvers[key]

    # -- solving ------------------------------------------------------------------------------
    def solve(self, *, t_max=None, weights=None, aggregate="mean", scenario_weights=None, guess=None):
        """Solve for the robust command (smooth stage, then the polish on the exact forms).

        Parameters
        ----------
        t_max : float, optional
            Latest lock-up of every scenario [s] (default: the nominal scene's, see
            :meth:`EngagementOCP.default_t_max`).
        weights : dict, optional
            Objective weights by term (``OBJECTIVE_TERMS``), the same for every scenario.
        aggregate : {"mean", "worst"}
            Weighted mean of the scenario objectives, or the worst (epigraph).
        scenario_weights : sequence of float, optional
            Weights of the scenarios in the mean (normalised; default equal).
        guess : RobustEngagement, optional
            A previous robust optimum of this problem (warm start).

        Returns
        -------
        RobustEngagement

        Raises
        ------
        ModelError
            Bad weights, aggregate or t_max (below a scenario's fastest lock-up).
        SolverError
            IPOPT did not converge.
        """
        ocp = self.ocp
        weights = check_weights(weights)
        if aggregate not in AGGREGATES:
            raise ModelError(f"aggregate '{aggregate}': allowed values are {', '.join(AGGREGATES)}")
        if ocp.jump_mode == "penalty" and weights["jump"] == 0:
            raise ModelError("weights.jump: must be > 0 when the jump is a penalty (jump='penalty')")
        omega = np.ones(self.n_scenarios) if scenario_weights is None else np.asarray(scenario_weights, float)
        if omega.shape != (self.n_scenarios,) or not np.all(np.isfinite(omega) & (omega >= 0)) or omega.sum() <= 0:
            raise ModelError(f"scenario_weights: {self.n_scenarios} numbers >= 0 (not all zero) are needed")
        omega = omega / omega.sum()
        t_max = ocp.default_t_max() if t_max is None else float(t_max)
        if not (np.isfinite(t_max) and t_max > 0):
            raise ModelError(f"t_max = {t_max!r}: must be a positive, finite time [s]")
        fastest = self.fastest_lockups()
        if np.any(fastest > t_max):
            k = int(np.argmax(fastest))
            raise ModelError(f"t_max = {t_max:.4g} s is below the fastest lock-up of scenarios[{k}] "
                             f"{self.overrides[k]} ({fastest[k]:.4g} s with a step to actuation.max_pressure); "
                             "raise t_max or the pressure limit")
        stages = []
        result = self._solve_stage(ocp, t_max, weights, aggregate, omega, guess)
        stages.append(dict(result.stats, model="smooth" if ocp.smooth else "exact"))
        if ocp.polish and result.success:
            polished = self._solve_stage(ocp.exact, t_max, weights, aggregate, omega, result)
            stages.append(dict(polished.stats, model="exact"))
            if polished.success:
                result = polished
        result.stats = dict(stages[-1], iterations=sum(s["iterations"] for s in stages),
                            wall_time_s=sum(s["wall_time_s"] for s in stages), stages=stages,
                            model=stages[-1]["model"] if result.success else stages[0]["model"])
        if not result.success:
            raise SolverError(f"robust engagement: IPOPT stopped with {result.stats['status']} (scene "
                              f"'{self.scene.name}', {self.n_scenarios} scenarios, t_max = {t_max:.4g} s, "
                              f"{result.stats['iterations']} iterations); try another t_max, fewer or nearer "
                              "scenarios, or other weights")
        return result

    def _solve_stage(self, ocp, t_max, weights, aggregate, omega, guess):
        nlp = self.nlp(ocp, aggregate, t_max)
        sc = ocp.scales
        warm = isinstance(guess, RobustEngagement) and guess.w.size == nlp.lbx.size
        if warm:
            w0, lam_x0, lam_g0 = guess.w.copy(), guess.lam_x, guess.lam_g
        else:
            w0 = self._guess(ocp, nlp, t_max)
            lam_x0, lam_g0 = np.zeros_like(w0), np.zeros(nlp.lbg.size)
        lbx, ubx = nlp.lbx.copy(), nlp.ubx.copy()
        lbx[nlp.T] = 1e-3 * t_max / sc.time_s
        ubx[nlp.T] = t_max / sc.time_s
        w0 = np.clip(w0, lbx, ubx)
        p = np.concatenate([[weights[k] for k in OBJECTIVE_TERMS], self.thetas.ravel(), omega])
        solver = self.solver(ocp, aggregate, t_max, warm)
        start = time.perf_counter()
        sol = solver(x0=w0, lam_x0=lam_x0, lam_g0=lam_g0, lbx=lbx, ubx=ubx, lbg=nlp.lbg, ubg=nlp.ubg, p=p)
        wall = time.perf_counter() - start
        st = solver.stats()
        stats = {"status": st["return_status"], "success": bool(st["success"]), "iterations": int(st["iter_count"]),
                 "wall_time_s": wall, "warm_start": bool(warm), "n_variables": int(w0.size),
                 "n_constraints": int(nlp.lbg.size), "n_scenarios": self.n_scenarios}
        w = np.array(sol["x"]).ravel()
        return self._result(ocp, nlp, w, np.array(sol["lam_x"]).ravel(), np.array(sol["lam_g"]).ravel(),
                            float(sol["f"]), p, weights, aggregate, omega, t_max, stats)

    def _guess(self, ocp, nlp, t_max):
        """Start point: each scenario's states from its own baseline run (compressed to t_max if
        slower), the command from the nominal scene's baseline run."""
        tr = ocp.transcription
        xs, xcs, Ts = [], [], []
        for s in self.scenes:
            run = simulate_engagement(s)
            parts = ocp.nlp.unpack(guess_from_run(ocp, run, t_max=0.95 * t_max))
            xs.append(parts["x"])
            xcs.append(parts["xc"])
            Ts.append(parts["T"])
        base = ocp.nlp.unpack(guess_from_run(ocp, ocp.reference_run, t_max=0.95 * t_max))
        t_base = tr.node_times(base["T"])[0]
        v = np.interp(nlp.command_grid, t_base, base["u"][:, 0])
        return nlp.pack(xs, xcs, v, np.array(Ts))

    def _result(self, ocp, nlp, w, lam_x, lam_g, objective, p, weights, aggregate, omega, t_max, stats):
        parts = nlp.unpack(w)
        sc, tr = ocp.scales, ocp.transcription
        command = np.clip(parts["v"], 0.0, 1.0) * sc.pressure_Pa
        times = nlp.command_grid * sc.time_s
        J = np.array(nlp.objectives_fn(w, p)).ravel()
        scenarios = []
        for k in range(self.n_scenarios):
            T = parts["T"][k]
            starts, _ = tr.node_times(T)
            u_nodes = np.interp(starts, nlp.command_grid, parts["v"])
            w_k = ocp.nlp.pack(parts["x"][k], parts["xc"][k], u_nodes[:, None], T)
            ocp.theta_value = self.thetas[k]
            scenarios.append(ocp._result(w_k, np.zeros_like(w_k), np.zeros(ocp.nlp.lbg.size), float(J[k]),
                                         weights, dict(stats)))
            scenarios[-1].t_max = t_max
        ocp.theta_value = ocp.nominal_theta(self.scene)
        return RobustEngagement(times, command, scenarios, self.overrides, J, objective, aggregate, weights, omega,
                                t_max, stats, w, lam_x, lam_g)


@dataclass
class _RobustNLP:
    """The robust NLP and how to read its variables (scaled units)."""

    nlp: dict
    lbx: np.ndarray
    ubx: np.ndarray
    lbg: np.ndarray
    ubg: np.ndarray
    layout: dict
    T: slice
    command_grid: np.ndarray            # scaled times of the command nodes
    objectives_fn: ca.Function          # (w, p) -> J_s of each scenario

    def unpack(self, w):
        w = np.asarray(w, float).ravel()
        out = {name: w[start:start + int(np.prod(shape))].reshape(shape) for name, (start, shape) in self.layout.items()}
        out["T"] = w[self.T]
        return out

    def pack(self, x, xc, v, T):
        w = np.zeros(self.lbx.size)
        for name, value in (("x", x), ("xc", xc), ("v", v)):
            start, shape = self.layout[name]
            value = np.asarray(value, float)
            if value.shape != shape:
                raise ModelError(f"robust guess '{name}': expected shape {shape}, got {value.shape}")
            w[start:start + value.size] = value.ravel()
        w[self.T] = T
        return w


def _transcribe(ocp, n_s, aggregate, t_grid_end):
    """Transcribe the robust problem of ``n_s`` scenarios on the functions of ``ocp``.

    The NLP parameter is ``[weights (5); theta of each scenario; scenario weights (n_s)]``.
    """
    tr, prob = ocp.transcription, ocp._staged_problem()
    N, d = tr.intervals, tr.degree
    n_x, n_th = prob.n_x, ocp.theta.numel()
    M = N                                             # command steps over [0, t_max]
    h_c = t_grid_end / M
    grid = np.arange(M + 1) * h_c
    X = ca.MX.sym("X", n_x, (N + 1) * n_s)
    Xc = ca.MX.sym("Xc", n_x, N * d * n_s)
    V = ca.MX.sym("V", M + 1)
    T = ca.MX.sym("T", n_s)
    z = ca.MX.sym("z", 1 if aggregate == "worst" else 0)
    W = ca.MX.sym("weights", len(OBJECTIVE_TERMS))
    Theta = ca.MX.sym("theta", n_th, n_s)
    omega = ca.MX.sym("omega", n_s)
    w = ca.veccat(X, Xc, V, T, z)
    layout = {"x": (0, (n_s, N + 1, n_x)), "xc": (X.numel(), (n_s, N, d, n_x)), "v": (X.numel() + Xc.numel(), (M + 1,))}
    t_start = X.numel() + Xc.numel() + M + 1
    T_slice = slice(t_start, t_start + n_s)

    # The command at absolute (scaled) time t: linear interpolation of V on the grid (hat functions).
    t_sym, v_sym = ca.SX.sym("t"), ca.SX.sym("v", M + 1)
    hats = ca.fmax(0, 1 - ca.fabs(t_sym / h_c - ca.DM(np.arange(M + 1))))
    command = ca.Function("command", [t_sym, v_sym], [ca.dot(v_sym, hats)])

    # Every collocation point of every scenario: its time, command and parameters, then one map.
    s_pts = (np.arange(N)[:, None] + tr.tau[None, :]).ravel() / N            # normalised times
    Tp = _repeat_columns(T.T, N * d)                                          # (1, n_s N d)
    t_pts = Tp * ca.DM(np.tile(s_pts, n_s)).T
    Uc = command.map(N * d * n_s)(t_pts, ca.repmat(V, 1, N * d * n_s))
    P_pts = ca.vertcat(ca.repmat(W, 1, N * d * n_s), _repeat_columns(Theta, N * d))
    xdot, q, c = prob.dynamics.map(N * d * n_s)(Xc, Uc, P_pts)

    C0 = np.tile(tr.C[0], N)[None, :]
    Cin = _sparse(np.kron(np.eye(N), tr.C[1:]))
    Dm = _sparse(np.kron(np.eye(N), tr.D[1:, None]))
    B = ca.DM(np.tile(tr.B, N))
    colloc, continuity, g_end, J_s = [], [], [], []
    for s in range(n_s):
        Xs = X[:, s * (N + 1):(s + 1) * (N + 1)]
        cols = slice(s * N * d, (s + 1) * N * d)
        Xcs, h = Xc[:, cols], T[s] / N
        colloc.append(ca.vec(_repeat_columns(Xs[:, :-1], d) * ca.DM(np.repeat(C0, n_x, axis=0))
                             + ca.mtimes(Xcs, Cin) - h * xdot[:, cols]))
        continuity.append(ca.vec(Xs[:, 1:] - (Xs[:, :-1] * tr.D[0] + ca.mtimes(Xcs, Dm))))
        Q = ca.mtimes(q[:, cols] * h, B)
        u_f = command(T[s], V)
        p_s = ca.vertcat(W, Theta[:, s])
        J_s.append(prob.objective(Xs[:, -1], u_f, Q, T[s], p_s))
        g_end.append(prob.end(Xs[:, -1], u_f, T[s], p_s))
    J_all = ca.vertcat(*J_s)
    blocks = [(ca.vertcat(*colloc), 0.0, 0.0), (ca.vertcat(*continuity), 0.0, 0.0),
              (ca.vec(c), np.tile(prob.c_lb, N * d * n_s), np.tile(prob.c_ub, N * d * n_s)),
              (ca.vertcat(*g_end), np.tile(prob.end_lb, n_s), np.tile(prob.end_ub, n_s))]
    if prob.u_rate is not None:
        moves = V[1:] - V[:-1]
        limit = float(prob.u_rate[0]) * h_c
        blocks.append((moves, -limit, limit))
    if aggregate == "worst":
        f = z
        blocks.append((J_all - z, -np.inf, 0.0))
    else:
        f = ca.dot(omega, J_all)
    g = ca.vertcat(*[b[0] for b in blocks])
    lbg = np.concatenate([np.broadcast_to(b[1], (b[0].numel(),)) for b in blocks])
    ubg = np.concatenate([np.broadcast_to(b[2], (b[0].numel(),)) for b in blocks])
    # The energy end row is unbounded (no e_max in the robust problem).
    n_e = prob.end_lb.size
    end_start = sum(b[0].numel() for b in blocks[:3])
    for s in range(n_s):
        row = end_start + s * n_e + n_e - 1
        lbg[row], ubg[row] = -np.inf, np.inf

    lbx = np.concatenate([np.tile(prob.x_lb, (N + 1) * n_s), np.tile(prob.x_lb, N * d * n_s),
                          np.full(M + 1, prob.u_lb[0]), np.zeros(n_s), np.full(z.numel(), -np.inf)])
    ubx = np.concatenate([np.tile(prob.x_ub, (N + 1) * n_s), np.tile(prob.x_ub, N * d * n_s),
                          np.full(M + 1, prob.u_ub[0]), np.full(n_s, np.inf), np.full(z.numel(), np.inf)])
    for s in range(n_s):                               # each scenario starts from the initial state
        lbx[s * (N + 1) * n_x:s * (N + 1) * n_x + n_x] = prob.x0
        ubx[s * (N + 1) * n_x:s * (N + 1) * n_x + n_x] = prob.x0
    v0 = layout["v"][0]
    if prob.u_initial is not None and prob.u_rate is not None:
        lbx[v0] = ubx[v0] = prob.u_initial[0]         # no step at t = 0
    P = ca.vertcat(W, ca.vec(Theta), omega)
    nlp = {"x": w, "f": f, "g": g, "p": P}
    objectives_fn = ca.Function("scenario_objectives", [w, P], [J_all])
    return _RobustNLP(nlp, lbx, ubx, lbg, ubg, layout, T_slice, grid, objectives_fn)


def solve_robust(scene, scenarios, *, t_max=None, weights=None, aggregate="mean", intervals=60, degree=3,
                 scenario_weights=None, **ocp_options):
    """One pressure command for several scenarios of a clutch (see the module notes).

    Parameters
    ----------
    scene : clutchocp.scene.Scene
        The nominal scene.
    scenarios : list of dict
        Override dicts ``{"part.key": SI value}`` (e.g. ``Uncertainty.corners()``), one per scenario.
    t_max : float, optional
        Latest lock-up of every scenario [s] (default: the nominal baseline's lock-up time).
    weights : dict, optional
        Objective weights by term (jerk, energy, time, jump, smooth).
    aggregate : {"mean", "worst"}
    intervals, degree : int
        Collocation intervals (and command steps) and points per interval.
    scenario_weights : sequence of float, optional
        Weights of the scenarios in the mean.
    **ocp_options
        Options of :class:`~clutchocp.optimal.problem.EngagementOCP`.

    Returns
    -------
    RobustEngagement
    """
    problem = RobustOCP(scene, scenarios, intervals=intervals, degree=degree, **ocp_options)
    return problem.solve(t_max=t_max, weights=weights, aggregate=aggregate, scenario_weights=scenario_weights)
