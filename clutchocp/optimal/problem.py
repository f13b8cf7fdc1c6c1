"""The optimal-control problem of an engagement: the pressure command over the slip phase.

Over the slip phase (mode ``pressing_slip_forward`` of :class:`~clutchocp.engagement.model.EngagementModel`)
the pressure command u(t) is chosen to minimise

    J = w_jerk int jerk^2 dt / J_ref + w_energy E / E_ref + w_time t_f / t_ref
        + w_jump (jump / T_ref)^2 + w_smooth int (dp/dt)^2 dt t_ref / p_ref^2

(jerk = d a_out / dt of the output, E = dissipated energy, jump = locked torque - slipping torque at
t_f, p = pressure) with a free final time t_f = lock-up time and the end conditions

* w_rel(t_f) = 0;
* slipping torque = (1 + lock_margin) x the torque the locked driveline carries (unless the jump
  is only penalised);
* the lock holds: the static capacity is not falling at t_f (it is the slipping torque there).

A jump-free lock (margin 0) that holds meets w_rel = 0 to third order: w_rel' = 0 because the
slipping torque is the locked one, w_rel'' = 0 because that torque is not falling. Its instant is
then ill-conditioned (a slip error e moves it by ~e^(1/3); measured: 0.8 % late in IDAS). The default
margin of 0.5 % makes the crossing transversal (measured: IDAS locks at the collocation time within
its event tolerance) and leaves a jump of -0.5 % of the locked torque.

Constraints: t_f <= t_max, E <= E_max, films h >= h_min, 0 <= u <= actuation.max_pressure,
|du/dt| <= rate limit, w_rel >= 0. The ``smooth`` term regularises the command: without it the
command reaches the objective only through two integrations (valve lag, film) and IPOPT meets a
nearly singular Hessian and a bang-bang command (measured on the default scene: weight 1e-4 gave a
rate-limited bang-bang command; 0.1, the default, a smooth one for 8 % more jerk integral).

Numerics: states scaled by the model's nominal values, time by t_ref, command by the pressure limit,
objective terms by references from the baseline run (its lock time and dissipated energy) and the
kinematic jerk bound at t_ref. Films that stay equal (massless pack) are one NLP state. The NLP is
first solved on the smooth forms of the switching laws, then polished on the exact forms from that
optimum (a warm start of a few iterations), so that the optimum is one of the model IDAS verifies.
Exact derivatives are assembled per collocation point (:mod:`clutchocp.optimal.derivatives`).
"""

import time
from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from ..engagement.model import EngagementModel
from ..engagement.run import simulate_engagement
from ..errors import ModelError, SolverError
from .bound import jerk_lower_bound, output_jerk_share
from .collocation import DirectCollocation, StagedProblem
from .derivatives import nlp_solver, structured_derivatives

OBJECTIVE_TERMS = ("jerk", "energy", "time", "jump", "smooth")
DEFAULT_WEIGHTS = {"jerk": 1.0, "energy": 0.0, "time": 0.0, "jump": 0.0, "smooth": 0.1}
JUMP_MODES = ("constraint", "penalty")
SLIP_MODE = "pressing_slip_forward"


def check_weights(weights):
    """Full weight dict from a partial one; unknown names or negative weights raise ModelError."""
    out = dict(DEFAULT_WEIGHTS)
    for name, value in (weights or {}).items():
        if name not in DEFAULT_WEIGHTS:
            raise ModelError(f"weights: unknown term '{name}'; allowed: {', '.join(OBJECTIVE_TERMS)}")
        try:
            value = float(value)
        except (TypeError, ValueError):
            raise ModelError(f"weights.{name} = {value!r}: must be a number >= 0") from None
        if not (np.isfinite(value) and value >= 0):
            raise ModelError(f"weights.{name} = {value!r}: must be a number >= 0")
        out[name] = value
    if sum(out[k] for k in ("jerk", "energy", "time", "jump")) == 0:
        raise ModelError("weights: at least one of jerk, energy, time, jump must be positive")
    return out


@dataclass
class Scales:
    """Reference values that make the NLP of order one."""

    time_s: float
    energy_J: float
    jerk_integral: float
    torque_Nm: float
    pressure_Pa: float


@dataclass
class OptimalEngagement:
    """A solved (or failed) optimal engagement.

    ``t`` are the interval starts (N + 1), ``t_points`` the collocation times (N, d);
    ``states`` and ``outputs`` hold arrays at the interval starts (``*_points`` at the collocation
    points); ``command`` the command values (N, or N + 1 for a linear command) on ``command_times``.
    """

    t_f: float
    t: np.ndarray
    t_points: np.ndarray
    command_times: np.ndarray
    command: np.ndarray
    control: str
    states: dict
    outputs: dict
    outputs_points: dict
    terms: dict
    objective: float
    stats: dict
    w: np.ndarray = field(repr=False)
    lam_x: np.ndarray = field(repr=False)
    lam_g: np.ndarray = field(repr=False)
    weights: dict = field(default_factory=dict)
    t_max: float | None = None
    e_max: float | None = None

    @property
    def success(self):
        return self.stats["success"]


class EngagementOCP:
    """The optimal engagement pressure problem of a scene, transcribed by direct collocation.

    Parameters
    ----------
    scene : clutchocp.scene.Scene
        An engagement scene whose pack is pressed from t = 0 (no free piston travel), with
        ``actuation.max_pressure``.
    intervals : int
        Number of collocation intervals N.
    degree : int
        Collocation points per interval.
    scheme : {"radau", "legendre"}
        Collocation points.
    control : {"linear", "constant"}
        Piecewise-linear (continuous, default) or piecewise-constant pressure command. A rate-limited
        ramp is exact in the linear form; the constant form lags it by half an interval, which made
        its objective converge only to first order (1 % off at N = 100 against 1e-5 for the linear).
    rate_limit : float, optional
        Largest command rate [Pa/s] (default: the pressure limit per 10 ms; ``numpy.inf``: none).
    h_min : float, optional
        Smallest film thickness allowed [m] (default: none).
    jump : {"constraint", "penalty"}
        Lock-up torque jump fixed by an end condition, or only the ``jump`` objective term.
    lock_margin : float
        Slipping torque at lock-up over the locked torque, minus one (the jump left: -lock_margin
        times the locked torque); 0 asks for a jump-free (tangential) lock.
    smooth : bool
        Solve on the smooth forms of the switching laws (then polish on the exact forms if ``polish``).
    polish : bool
        After a smooth solve, re-solve on the exact forms from the smooth optimum.
    transcription : object, optional
        Replaces ``DirectCollocation(intervals, degree, scheme, control)``.
    baseline : clutchocp.engagement.run.EngagementResult, optional
        IDAS run of the scene's own profile (initial guess and scales; simulated if not given).
    """

    # Scene values that are a parameter vector of the NLP functions (appended to the weights; the
    # outputs and jump functions take it as a third input); empty here, set by
    # clutchocp.optimal.robust.ParametricOCP for the scenarios of a robust problem.
    theta = ca.SX(0, 1)

    def __init__(self, scene, *, intervals=100, degree=3, scheme="radau", control="linear", rate_limit=None,
                 h_min=None, jump="constraint", lock_margin=0.005, smooth=True, polish=True,
                 transcription=None, baseline=None):
        if jump not in JUMP_MODES:
            raise ModelError(f"jump '{jump}': allowed values are {', '.join(JUMP_MODES)}")
        if scene.kind != "engagement":
            raise ModelError(f"scene '{scene.name}' is a {scene.kind} scene; the optimal engagement pressure needs "
                             "kind = 'engagement'")
        self.scene = scene
        self.jump_mode = jump
        self.p_max = scene.get("actuation.max_pressure")
        if self.p_max is None:
            raise ModelError("actuation.max_pressure: the optimisation needs an upper pressure limit; "
                             "add e.g. max_pressure = \"1.5 MPa\" to [actuation]")
        if not (np.isfinite(lock_margin) and 0 <= lock_margin < 0.5):
            raise ModelError(f"lock_margin = {lock_margin!r}: must be a fraction in [0, 0.5)")
        self.options = {"intervals": intervals, "degree": degree, "scheme": scheme, "control": control,
                        "rate_limit": rate_limit, "h_min": h_min, "jump": jump, "lock_margin": lock_margin}
        self.u = ca.SX.sym("pressure_command")
        self.lock_margin = float(lock_margin)
        self.smooth = bool(smooth)
        self.polish = bool(polish) and self.smooth
        self._exact = None
        self.model = EngagementModel(scene, smooth=smooth, pressure_command=self.u)
        start_mode = self.model.initial_mode()
        if start_mode != SLIP_MODE:
            raise ModelError(f"scene '{scene.name}' starts in mode '{start_mode}'; the optimisation covers a "
                             f"slip phase that starts with the pack pressed and w_in > w_out "
                             f"(no free piston travel, input_speed > output_speed)")
        self.transcription = transcription or DirectCollocation(intervals, degree, scheme, control)
        self.baseline = baseline if baseline is not None else simulate_engagement(scene)
        self._fastest = None
        # The run that seeds the first solve and sets the scales: the baseline if it locks up.
        self.reference_run = self.baseline if self.baseline.summary["engagement_time_s"] is not None \
            else self.fastest_run()
        self.rate_limit = self.p_max / 0.01 if rate_limit is None else float(rate_limit)
        if not self.rate_limit > 0:
            raise ModelError(f"rate_limit = {rate_limit!r}: must be a positive rate [Pa/s]")
        self.h_min = h_min
        self.output_jerk_share = output_jerk_share(scene)
        self.has_valve = self.model.actuation.has_state
        self.state_groups = self._state_groups()
        self.state_names = tuple(self.state_groups)  # the NLP adds the dissipated energy as a last state
        self._names = list(self.state_names)
        self._phys = [self.model.index[n] for n in self._names]
        self.nominal = self.model.nominal[self._phys]
        self.x0 = self.model.initial_state[self._phys]
        self.scales = self._scales()
        self._build_functions()
        self.nlp = self.transcription.transcribe(self._staged_problem())
        self._solvers = {}
        self._derivatives = None

    # -- set-up ---------------------------------------------------------------------------------
    def _state_groups(self):
        """Physical states of the NLP: {representative: [model states it stands for]}.

        Films that start equal and whose rates are equal whenever their thicknesses are (a massless
        pack without spline friction: the same law and the same load on every film) stay equal, so
        one NLP state carries them all. The check is numerical, at random states on that diagonal.
        """
        model = self.model
        names = [n for n in model.state_names if not n.startswith("E_")]
        films = [n for n in names if n.startswith("h_")]
        groups = {n: [n] for n in names}
        x0 = model.initial_state
        if len(films) < 2 or len({x0[model.index[f]] for f in films}) != 1:
            return groups
        ode = ca.Function("ode", [model.x, self.u], [ca.vertcat(*model.modes[SLIP_MODE].ode)])
        rng = np.random.default_rng(0)
        for _ in range(4):
            x = x0 + model.nominal * rng.uniform(-0.5, 0.5, x0.size)
            x[[model.index[f] for f in films]] = model.nominal[model.index[films[0]]] * rng.uniform(0.3, 12.0)
            rates = np.array(ode(x, rng.uniform(0.0, self.p_max))).ravel()[[model.index[f] for f in films]]
            if not np.allclose(rates, rates[0], rtol=1e-10, atol=0.0):
                return groups
        for f in films[1:]:
            del groups[f]
        groups[films[0]] = films
        return groups

    def initial_slip(self):
        """Slip speed and its rate at t = 0: (w_rel [rad/s], dw_rel/dt [rad/s^2])."""
        w_in, w_out = self.model.speeds()
        f = ca.Function("slip", [self.model.x], [w_in - w_out, self._slip_rate()])
        return tuple(float(v) for v in f(self.model.initial_state))

    def _scales(self):
        summary = self.reference_run.summary
        t_ref = summary["engagement_time_s"]
        w_rel0, rate0 = self.initial_slip()
        locked0 = float(ca.Function("locked", [self.model.x], [self.model.locked_torque()])(self.model.initial_state))
        jerk_ref = jerk_lower_bound(w_rel0, rate0, t_ref) * max(self.output_jerk_share, 1e-3) ** 2
        return Scales(time_s=t_ref, energy_J=max(summary["dissipated_energy_J"], 1e-6), jerk_integral=jerk_ref,
                      torque_Nm=max(abs(locked0), 1.0), pressure_Pa=self.p_max)

    def _slip_rate(self):
        """d w_rel / dt in the slip mode (SX of the full state)."""
        mode = self.model.modes[SLIP_MODE]
        w_in, w_out = self.model.speeds()
        return ca.jtimes(w_in - w_out, self.model.x, ca.vertcat(*mode.ode))

    def _build_functions(self):
        """Scaled dynamics, objective and end conditions, and the physical outputs (SX functions)."""
        model, mode, sc = self.model, self.model.modes[SLIP_MODE], self.scales
        n = len(self._phys)
        xs = ca.SX.sym("xs", n + 1)                 # physical states, then the dissipated energy
        us = ca.SX.sym("us")
        x_full = ca.SX.zeros(len(model.state_names))
        for k, name in enumerate(self._names):
            for member in self.state_groups[name]:
                x_full[model.index[member]] = xs[k] * self.nominal[k]
        u = us * sc.pressure_Pa
        ode = ca.vertcat(*mode.ode)
        w_in, w_out = model.speeds()
        w_rel = w_in - w_out
        rate = ca.jtimes(w_rel, model.x, ode)
        p = mode.outputs["pressure_Pa"]
        physical = {
            "pressure_Pa": p, "command_Pa": self.u,
            "w_in_rad_s": w_in, "w_out_rad_s": w_out, "w_rel_rad_s": w_rel,
            "slip_acceleration_rad_s2": rate, "slip_jerk_rad_s3": ca.jtimes(rate, model.x, ode),
            "total_torque_Nm": mode.outputs["total_torque_Nm"], "locked_torque_Nm": model.locked_torque(),
            "output_acceleration_rad_s2": mode.outputs["output_acceleration_rad_s2"],
            "output_jerk_rad_s3": mode.outputs["output_jerk_rad_s3"],
            "dissipated_power_W": mode.outputs["dissipated_power_W"],
            "pressure_rate_Pa_s": ca.jtimes(p, model.x, ode),
            "static_capacity_Nm": mode.outputs["static_capacity_Nm"],
            "capacity_rate_Nm_s": ca.jtimes(mode.outputs["static_capacity_Nm"], model.x, ode),
        }
        for i in range(model.n):
            physical[f"h_{i + 1}_m"] = mode.outputs[f"h_{i + 1}_m"]
        physical = {k: ca.SX(v) for k, v in physical.items()}
        if ca.depends_on(ca.vertcat(ode, *physical.values()), model.t):
            raise ModelError("the optimisation needs a time-invariant slip mode (a pressure command, not a profile)")

        def subs(expr):
            # cse merges the copies of equal films (and other repeated subexpressions)
            return ca.cse(ca.substitute(expr, ca.vertcat(model.x, self.u), ca.vertcat(x_full, u)))

        self.output_names = list(physical)
        theta = [self.theta] if self.theta.numel() else []
        self.outputs_fn = ca.Function("outputs", [xs, us, *theta], [subs(ca.vertcat(*physical.values()))])
        t_ref = sc.time_s
        xdot = ca.vertcat(subs(ode[self._phys]) / self.nominal,
                          subs(physical["dissipated_power_W"]) / sc.energy_J) * t_ref
        q = ca.vertcat(subs(physical["output_jerk_rad_s3"]) ** 2 * t_ref / sc.jerk_integral,
                       (subs(physical["pressure_rate_Pa_s"]) * t_ref / sc.pressure_Pa) ** 2)
        w_scale = max(self.scene.value("driveline.input_speed"), self.scene.get("driveline.output_speed", 0.0), 1.0)
        slip = subs(w_rel) / w_scale
        weights = ca.SX.sym("weights", len(OBJECTIVE_TERMS))
        params = ca.vertcat(weights, self.theta)
        self.dynamics_fn = ca.Function("dynamics", [xs, us, params], [xdot, q, slip])
        # Objective and end conditions (w_rel = 0, jump = 0 unless penalised, energy <= E_max).
        Q = ca.SX.sym("Q", 2)
        T = ca.SX.sym("T")
        locked, slipping = subs(physical["locked_torque_Nm"]), subs(physical["total_torque_Nm"])
        jump = (locked - slipping) / sc.torque_Nm
        jump_condition = (locked * (1 + self.lock_margin) - slipping) / sc.torque_Nm
        w = dict(zip(OBJECTIVE_TERMS, ca.vertsplit(weights)))
        J = w["jerk"] * Q[0] + w["energy"] * xs[n] + w["time"] * T + w["jump"] * jump**2 + w["smooth"] * Q[1]
        self.objective_fn = ca.Function("objective", [xs, us, Q, T, params], [J])
        # The lock must hold: the static capacity (about the slipping torque at lock-up) may not be
        # falling at t_f. Without this row the optimum lets the pressure fall through lock-up.
        capacity_rate = subs(physical["capacity_rate_Nm_s"]) * t_ref / sc.torque_Nm
        g_end = [slip] + ([jump_condition] if self.jump_mode == "constraint" else []) + [capacity_rate, xs[n]]
        self.end_fn = ca.Function("end", [xs, us, T, params], [ca.vertcat(*g_end)])
        self.jump_fn = ca.Function("jump", [xs, us, *theta], [jump * sc.torque_Nm])

    def _staged_problem(self):
        n = len(self._phys)
        x_lb, x_ub = np.full(n + 1, -np.inf), np.full(n + 1, np.inf)
        for i, name in enumerate(self._names):
            if name.startswith("h_"):
                x_lb[i] = (self.h_min or 0.0) / self.nominal[i]
        n_end = 3 + (self.jump_mode == "constraint")
        end_lb, end_ub = np.zeros(n_end), np.zeros(n_end)
        end_ub[-2] = np.inf                                          # capacity rate >= 0
        end_lb[-1], end_ub[-1] = -np.inf, np.inf                     # energy row: set per solve
        p0 = self.scene.value("actuation.initial_pressure") / self.scales.pressure_Pa
        return StagedProblem(self.dynamics_fn, np.append(self.x0 / self.nominal, 0.0), self.objective_fn,
                             self.end_fn, x_lb, x_ub, np.array([0.0]), np.array([1.0]), np.array([0.0]),
                             np.array([np.inf]), end_lb, end_ub,
                             u_rate=np.array([self.rate_limit * self.scales.time_s / self.scales.pressure_Pa])
                             if np.isfinite(self.rate_limit) else None,
                             u_initial=np.array([p0]))

    # -- solving --------------------------------------------------------------------------------
    def solver(self, warm=False):
        """The IPOPT solver of the NLP (built once per kind, cold or warm start)."""
        key = "warm" if warm else "cold"
        if key not in self._solvers:
            if self._derivatives is None:
                self._derivatives = structured_derivatives(self.nlp)
            self._solvers[key] = nlp_solver(self.nlp, warm=warm, name=f"engagement_{key}",
                                            derivatives=self._derivatives)
        return self._solvers[key]

    @property
    def exact(self):
        """The twin problem on the exact forms (the polish stage), built on first use."""
        if self._exact is None:
            self._exact = EngagementOCP(self.scene, smooth=False, polish=False, baseline=self.baseline,
                                        transcription=self.transcription, **self.options)
        return self._exact

    def solve(self, *, t_max=None, e_max=None, weights=None, guess=None):
        """Solve for the optimal command (and polish it on the exact model, see the class notes).

        Parameters
        ----------
        t_max : float, optional
            Largest engagement (lock-up) time [s]; default: :meth:`default_t_max`; ``numpy.inf``:
            no limit (then give the time or energy a weight).
        e_max : float, optional
            Largest dissipated energy [J].
        weights : dict, optional
            Objective weights by term (see ``OBJECTIVE_TERMS``); missing terms take ``DEFAULT_WEIGHTS``.
        guess : OptimalEngagement or EngagementResult, optional
            Start point: a previous optimum (warm start, with its multipliers if the mesh is the
            same) or a simulated run (default: the baseline run of the scene).

        Returns
        -------
        OptimalEngagement
            ``stats`` holds the IPOPT status, iterations and wall time (both stages summed) and
            ``stats["stages"]`` each stage.

        Raises
        ------
        ModelError
            t_max below the fastest lock-up the pressure limit allows; bad weights or limits.
        SolverError
            IPOPT did not converge (the message gives its status and what to change).
        """
        weights = check_weights(weights)
        if self.jump_mode == "penalty" and weights["jump"] == 0:
            raise ModelError("weights.jump: must be > 0 when the jump is a penalty (jump='penalty')")
        if t_max is None:
            t_max = self.default_t_max()
        if not (t_max > 0):
            raise ModelError(f"t_max = {t_max!r}: must be a positive time [s]")
        self.check_feasible_time(t_max)
        if e_max is not None and not (np.isfinite(e_max) and e_max > 0):
            raise ModelError(f"e_max = {e_max!r}: must be a positive energy [J]")
        result = self._solve_stage(t_max, e_max, weights, guess)
        stages = [dict(result.stats, model="smooth" if self.smooth else "exact")]
        if self.polish and result.success:
            polished = self.exact._solve_stage(t_max, e_max, weights, result)
            stages.append(dict(polished.stats, model="exact"))
            if polished.success:
                result = polished
        result.stats = dict(stages[-1], model=stages[-1]["model"] if result.success else stages[0]["model"],
                            warm_start=stages[0]["warm_start"], iterations=sum(s["iterations"] for s in stages),
                            wall_time_s=sum(s["wall_time_s"] for s in stages), stages=stages)
        if not result.success:
            raise SolverError(self._failure_message(result.stats, t_max))
        return result

    def _solve_stage(self, t_max, e_max, weights, guess):
        """One IPOPT solve of this problem (no polish)."""
        from .guess import guess_from_optimum, guess_from_run
        nlp, sc = self.nlp, self.scales
        warm = isinstance(guess, OptimalEngagement) and guess.w.size == nlp.lbx.size
        if warm:
            w0, lam_x0, lam_g0 = guess.w.copy(), guess.lam_x, guess.lam_g
        else:
            if isinstance(guess, OptimalEngagement):
                w0 = guess_from_optimum(self, guess, t_max=t_max)
            else:
                w0 = guess_from_run(self, guess if guess is not None else self.reference_run, t_max=t_max)
            lam_x0, lam_g0 = np.zeros_like(w0), np.zeros(nlp.lbg.size)
        lbx, ubx = nlp.lbx.copy(), nlp.ubx.copy()
        t_upper = min(t_max, 20.0 * sc.time_s)
        lbx[nlp.t_slice] = 1e-3 * t_upper / sc.time_s
        ubx[nlp.t_slice] = t_upper / sc.time_s
        w0[nlp.t_slice] = np.clip(w0[nlp.t_slice], lbx[nlp.t_slice], ubx[nlp.t_slice])
        lbg, ubg = nlp.lbg.copy(), nlp.ubg.copy()
        ubg[nlp.end_rows.stop - 1] = e_max / sc.energy_J if e_max is not None else np.inf
        p = [weights[k] for k in OBJECTIVE_TERMS]
        solver = self.solver(warm)
        start = time.perf_counter()
        sol = solver(x0=w0, lam_x0=lam_x0, lam_g0=lam_g0, lbx=lbx, ubx=ubx, lbg=lbg, ubg=ubg, p=p)
        wall = time.perf_counter() - start
        st = solver.stats()
        stats = {"status": st["return_status"], "success": bool(st["success"]), "iterations": int(st["iter_count"]),
                 "wall_time_s": wall, "warm_start": bool(warm), "n_variables": int(w0.size),
                 "n_constraints": int(lbg.size)}
        result = self._result(np.array(sol["x"]).ravel(), np.array(sol["lam_x"]).ravel(),
                              np.array(sol["lam_g"]).ravel(), float(sol["f"]), weights, stats)
        result.t_max, result.e_max = t_max, e_max
        return result

    def _failure_message(self, stats, t_max):
        status = stats["status"]
        where = (f"scene '{self.scene.name}', t_max = {t_max:.4g} s, {self.transcription.intervals} intervals, "
                 f"{stats['iterations']} iterations")
        if status == "Infeasible_Problem_Detected":
            hint = (f"no command within the pressure and rate limits locks up by t_max with the end conditions "
                    f"(the fastest lock-up, a step to the pressure limit, takes {self.fastest_lockup():.4g} s); "
                    f"raise t_max, e_max or the limits")
        elif status == "Maximum_Iterations_Exceeded":
            hint = "start from a nearby solution (warm start) or use fewer intervals"
        else:
            hint = "try another t_max, more intervals or other weights"
        return f"optimal engagement: IPOPT stopped with {status} ({where}); {hint}"

    def _result(self, w, lam_x, lam_g, objective, weights, stats):
        parts = self.nlp.unpack(w)
        sc, tr = self.scales, self.transcription
        T = parts["T"] * sc.time_s
        starts, points = tr.node_times(T)
        x_nodes = parts["x"][:, :-1] * self.nominal
        n_u = tr.n_controls
        # IPOPT relaxes bounds by 1e-8 (bound_relax_factor): report the command inside its limits.
        u_values = np.clip(parts["u"][:, 0], 0.0, 1.0) * sc.pressure_Pa
        command_times = starts[:n_u] if tr.control == "constant" else starts
        # Outputs at the nodes use the command of the interval they start (the last node: the last value).
        u_nodes = np.concatenate([u_values, u_values[-1:]]) if tr.control == "constant" else u_values
        outputs = self._evaluate(parts["x"], u_nodes / sc.pressure_Pa)
        outputs["dissipated_energy_J"] = parts["x"][:, -1] * sc.energy_J
        xc = parts["xc"].reshape(-1, parts["xc"].shape[-1])
        uc = np.array(tr.control_at_points(ca.DM(parts["u"].T))).ravel()
        outputs_points = {k: v.reshape(points.shape) for k, v in self._evaluate(xc, uc).items()}
        quad = tr.B[None, :] * (T / tr.intervals)
        terms = {
            "jerk_integral": float(np.sum(quad * outputs_points["output_jerk_rad_s3"] ** 2)),
            "slip_jerk_integral": float(np.sum(quad * outputs_points["slip_jerk_rad_s3"] ** 2)),
            "dissipated_energy_J": float(parts["x"][-1, -1] * sc.energy_J),
            "engagement_time_s": T,
            "lockup_torque_jump_Nm": float(self.jump_fn(parts["x"][-1], parts["u"][-1])),
            "final_slip_rad_s": float(outputs["w_rel_rad_s"][-1]),
            "locked_torque_Nm": float(outputs["locked_torque_Nm"][-1]),
            "peak_jerk_rad_s3": float(np.max(np.abs(outputs_points["output_jerk_rad_s3"]))),
            "peak_torque_Nm": float(np.max(np.abs(outputs_points["total_torque_Nm"]))),
            "objective": objective,
        }
        states = {member: x_nodes[:, i] for i, name in enumerate(self._names) for member in self.state_groups[name]}
        return OptimalEngagement(T, starts, points, command_times, u_values, tr.control, states, outputs,
                                 outputs_points, terms, objective, stats, w, lam_x, lam_g, weights)

    def _evaluate(self, xs, us):
        values = np.array(self.outputs_fn.map(len(us))(np.asarray(xs).T, np.asarray(us)[None, :]))
        return {name: values[i] for i, name in enumerate(self.output_names)}

    # -- feasibility ----------------------------------------------------------------------------
    def default_t_max(self):
        """The baseline's lock-up time (no slower than the scene's own profile), or 1.5 x the fastest
        lock-up if the baseline does not lock up [s]."""
        t_lock = self.baseline.summary["engagement_time_s"]
        return t_lock if t_lock is not None else 1.5 * self.fastest_lockup()

    def fastest_run(self):
        """IDAS run of a step of the command to the pressure limit (cached)."""
        if self._fastest is None:
            from .replay import simulate_command
            t_end = self.scene.value("simulation.t_end")
            run = simulate_command(self.scene, [0.0], [self.p_max], t_end)
            if run.summary["engagement_time_s"] is None:
                raise ModelError(f"scene '{self.scene.name}': even a step to actuation.max_pressure = "
                                 f"{self.p_max / 1e6:.3g} MPa does not lock up within simulation.t_end = "
                                 f"{t_end:g} s; raise the pressure limit or t_end")
            self._fastest = run
        return self._fastest

    def fastest_lockup(self):
        """Lock-up time [s] of a step to the pressure limit (no profile under the limit locks sooner)."""
        return self.fastest_run().summary["engagement_time_s"]

    def check_feasible_time(self, t_max):
        """Raise ModelError if no command under the pressure limit locks up by ``t_max``."""
        if t_max >= self.scales.time_s and self.baseline.summary["engagement_time_s"] is not None:
            return
        fastest = self.fastest_lockup()
        if t_max < fastest:
            raise ModelError(f"t_max = {t_max:.4g} s is below the fastest lock-up the pressure limit allows "
                             f"({fastest:.4g} s with a step to actuation.max_pressure = {self.p_max / 1e6:.3g} MPa); "
                             f"raise t_max or the pressure limit")
