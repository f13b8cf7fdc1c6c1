"""Robust feedforward: one pressure command for several scenarios of a clutch (multi-scenario collocation).

A scenario is a set of scene overrides (``{"friction.mu": 0.108, "oil.viscosity": 0.0884, ...}``,
e.g. the corners of an uncertainty box). The robust problem chooses one pressure command u(t) that
every scenario s meets with its own slip dynamics, its own free lock-up time T_s and its own end
conditions (w_rel = 0, the jump condition or penalty, the lock holds), with films above h_min and
T_s <= t_max, and minimises the mean (or the worst, by an epigraph variable z >= J_s) of the
scenarios' objectives J_s (the terms of :mod:`clutchocp.optimal.problem`: jerk, jump, smooth, ...).

How the scenarios share the command. A scenario that locks earlier sees only the start of the
command, and its lock-up time is free, so the command is a function of absolute time: continuous
and piecewise linear on a common grid of ``intervals`` equal steps h_c over [0, t_max] (it holds
its last value afterwards; its pressure and rate bounds are linear constraints on the node values).
Each scenario's collocation mesh is aligned with that grid: scenario s locks in command interval
K_s, its mesh is the K_s full command intervals plus a last interval of free length tau_s in
(0, h_c], and T_s = K_s h_c + tau_s. On a full interval the command is linear between two node
values with fixed weights; on the last one it is V_K + (V_K+1 - V_K) tau_s tau_j / h_c, smooth in
tau_s. So the NLP is smooth in every lock time. The two other ways were tried or weighed first: a
mesh scaled by T_s on which the command is interpolated makes the NLP only continuous in T_s (its
derivative jumps whenever a collocation point crosses a command node; measured on three corner
scenarios, 20 intervals: IPOPT cycled for 300 iterations without converging, and the dense
interpolation made every iteration slow), and one command copy per scenario needs the same
interpolation to tie the copies together. The price of the aligned mesh is that the interval a
scenario locks in is discrete: after a solve, a scenario whose tau_s sits on a bound of its
interval with a multiplier pushing beyond it moves to the next interval and the problem is solved
again from the last solution (a coarse presolve on 10 command steps finds the intervals first, so
the fine grid needs few such re-solves). The first lock-up intervals are those of each scenario's
IDAS replay of the nominal optimum (:meth:`RobustOCP.start_runs`). With one scenario that locks at t_max (the jerk optimum
uses all the time it may) the mesh is the nominal problem's and so is the optimum (checked in
tests/optimal/test_optimal_robust.py).

Lock-up torque jump: each scenario may meet the nominal jump condition (``jump="constraint"``, the
default of :class:`~clutchocp.optimal.problem.EngagementOCP`), but one command can rarely make
every scenario lock tangentially (measured: infeasible on the centre and the two extreme corners
of the default box), so the robust use is ``jump="penalty"`` with a ``jump`` weight: the jump of
every scenario is an objective term. ``aggregate="worst_jump"`` puts the largest jump in its place:
an epigraph variable z >= |locked - slipping| / locked torque of every scenario at its lock-up (the
share the Monte Carlo reports), and the objective w_jump z^2 + the mean of the scenarios' other
terms (jerk, smooth, ...). With one scenario this is the nominal jump penalty (the locked torque of
a driveline is a constant), checked in the tests.

Why one command cannot land every clutch without a jump (a two-inertia driveline, slip w_rel from
w_0, inertias J1, J2, locked torque T_L): the slip falls as w_rel' = (T_L - T_c)(1/J1 + 1/J2), so a
clutch whose slipping torque is g times a common T(t) (g: its friction) locks when
g F(t) = T_L (t + t_0), with F the integral of T and t_0 = w_0 / ((1/J1 + 1/J2) T_L) (0.23 s on
the default scene), and its jump share is d ln R / d ln(t + t_0) with R = F / (t + t_0). R must
rise by ln(g_max / g_min) (0.2 for mu +-10 %) between the first lock-up t_a and the last t_b, so
the worst jump share is at least ln(g_max / g_min) / ln((t_b + t_0) / (t_a + t_0)): the command
has to land the fastest clutch early and sweep slowly through the others. The "sweep" start
(:meth:`RobustOCP.start_runs`) is built that way, and :func:`lock_diagonal` adds scenarios between
the first and the last corner to lock, so that the worst jump between the box points is held too.

One dynamics function for all scenarios. The uncertain scene values are symbols of the model
(:class:`clutchocp.scene.symbolic.SymbolicScene`): :class:`~clutchocp.optimal.parametric.ParametricOCP`
builds the scaled dynamics, objective and end functions of the nominal problem with a parameter
vector theta of those values, and the robust NLP (the scenarios transcribed under the shared command
by :class:`~clutchocp.optimal.scenarios.SharedCommandCollocation`) evaluates the dynamics at every
collocation point of every scenario by one CasADi ``map`` (theta of the point's scenario as an
input), so the cost of the NLP functions grows linearly with the number of scenarios. Scales, state
groups and the initial state are those of the nominal scene.

Stages: as for the nominal problem, first the smooth forms of the switching laws, then a warm-started
polish on the exact forms. Derivatives: CasADi's automatic differentiation of the NLP graph (the
structured assembly of :mod:`clutchocp.optimal.derivatives` assumes one scenario on a uniform mesh).
"""

import time
from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from .. import interrupt
from ..engagement.run import simulate_engagement
from ..errors import ModelError, SolverError
from .clamp import ClampModel
from .derivatives import IPOPT_OPTIONS, MUMPS_UNSCALED, WARM_OPTIONS
from .guess import guess_from_run
from .objective import OBJECTIVE_TERMS, check_weights
from .parametric import ParametricOCP
from .problem import EngagementOCP, OptimalEngagement
from .replay import simulate_command
from .scenarios import ScenarioNLP, SharedCommandCollocation

AGGREGATES = ("mean", "worst", "worst_jump")
PRESOLVE_INTERVALS = 10
# IPOPT iterations per solve: on the 9-point default box every converged solve took at most 68; the
# failing ones crawled on with a singular-looking step (regularisation ~1e7) to the default limit of 500
MAX_ITERATIONS = 200
STARTS = ("nominal", "ramp", "baseline", "sweep")      # start points tried in turn (see RobustOCP.start_runs)
# Start "sweep": the ramp of the command runs through the commands whose settled capacity is this
# multiple of each scenario's locked torque (the slipping torque a jump of that share leaves)
SWEEP_CAPACITY = 1.5
# Positions on the box diagonal from the first to the last corner to lock of the points lock_diagonal adds
DIAGONAL_FRACTIONS = (0.25, 0.75)


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
    t_max_margin: float = 0.0          # every scenario locks by (1 - t_max_margin) x the engagement-time limit

    @property
    def t_limit(self):
        """The engagement-time limit the margin is taken from [s] (``t_max`` is the lock-up bound solved for)."""
        return self.t_max / (1.0 - self.t_max_margin)

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
        Steps of the command grid over [0, t_max] (a scenario that locks at t_max has as many
        collocation intervals) and collocation points per interval.
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
        self._ocp_options = dict(ocp_options, degree=degree)
        self.thetas = np.array([self.ocp.nominal_theta(s) for s in self.scenes]).reshape(len(self.scenes), -1)
        self.intervals = int(intervals)
        self._nlps = {}
        self._solvers = {}
        self._fastest = None
        self._start = STARTS[0]

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
    def nlp(self, ocp, aggregate, t_max, lock_intervals):
        """The robust NLP on ``ocp``'s functions for a command grid over [0, t_max] and the
        command interval each scenario locks in."""
        key = (id(ocp), aggregate, float(t_max), tuple(lock_intervals))
        if key not in self._nlps:
            self._nlps[key] = _robust_nlp(ocp, aggregate, t_max / ocp.scales.time_s, self.intervals,
                                          tuple(int(k) for k in lock_intervals))
        return self._nlps[key]

    def solver(self, nlp, warm):
        key = (id(nlp), warm)
        if key not in self._solvers:
            cold = MUMPS_UNSCALED if self.ocp.model.thermal.present else {}    # as EngagementOCP.solver
            options = dict(IPOPT_OPTIONS, max_iter=MAX_ITERATIONS, **(WARM_OPTIONS if warm else cold))
            self._solvers[key] = ca.nlpsol(f"robust_{'warm' if warm else 'cold'}", "ipopt", nlp.nlp,
                                           {"print_time": False, "ipopt": options, "error_on_fail": False,
                                            # stops IPOPT at the next iteration after a Ctrl-C
                                            "iteration_callback": interrupt.ipopt_callback()})
        return self._solvers[key]

    # -- solving ------------------------------------------------------------------------------
    def solve(self, *, t_max=None, weights=None, aggregate="mean", scenario_weights=None, max_shifts=40,
              presolve_intervals=PRESOLVE_INTERVALS, t_max_margin=0.0):
        """Solve for the robust command (smooth stage, then the polish on the exact forms).

        Parameters
        ----------
        t_max : float, optional
            Latest lock-up of every scenario [s] (default: the nominal scene's, see
            :meth:`EngagementOCP.default_t_max`).
        t_max_margin : float
            Fraction of t_max kept free: every scenario must lock by (1 - t_max_margin) t_max, so that
            clutches between the scenarios (and the replay of the command on the exact model) still lock
            within t_max [-, in [0, 0.5)].
        weights : dict, optional
            Objective weights by term (``OBJECTIVE_TERMS``), the same for every scenario.
        aggregate : {"mean", "worst", "worst_jump"}
            Weighted mean of the scenario objectives, the worst (epigraph), or w_jump x the largest
            (|jump| / locked torque)^2 plus the weighted mean of the other terms (epigraph).
        scenario_weights : sequence of float, optional
            Weights of the scenarios in the mean (normalised; default equal).
        max_shifts : int
            Largest number of re-solves per stage that move a scenario's lock-up into the next command interval.
        presolve_intervals : int or None
            First solve the problem on this coarser command grid (smooth model only), where a
            re-solve moves a lock-up by a longer step, from every start (``STARTS``), and start from
            the lock-up times and states of the lowest objective (None, or not fewer than ``intervals``:
            start from the scenarios' runs under the first start that converges).

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
        self._weights = weights
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
        if not (isinstance(t_max_margin, (int, float)) and 0.0 <= t_max_margin < 0.5):
            raise ModelError(f"t_max_margin = {t_max_margin!r}: must be a fraction in [0, 0.5)")
        t_max = (1.0 - t_max_margin) * t_max                   # the lock-up bound of every scenario
        fastest = self.fastest_lockups()
        if np.any(fastest > t_max):
            k = int(np.argmax(fastest))
            raise ModelError(f"t_max = {t_max:.4g} s is below the fastest lock-up of scenarios[{k}] "
                             f"{self.overrides[k]} ({fastest[k]:.4g} s with a step to actuation.max_pressure); "
                             "raise t_max or the pressure limit")
        stages, start = [], None
        # the sweep start is built for the worst-jump objective and goes first there (on the 9-point default
        # box, 10 steps, jump weight 100, jerk 1, margin 0.05: worst |jump| 85 % from a hand-set sweep, 98 % from
        # the nominal start)
        starts = (("sweep",) + tuple(k for k in STARTS if k != "sweep")) if aggregate == "worst_jump" else STARTS
        if presolve_intervals is not None and presolve_intervals < self.intervals:
            coarse = RobustOCP(self.scene, self.overrides, intervals=presolve_intervals,
                               **dict(self._ocp_options, polish=False, baseline=ocp.baseline, models=ocp.models))
            coarse._fastest, coarse._weights = fastest, weights
            # The problem is not convex: the presolve runs from every start and keeps the lowest objective
            # (two scenarios mu +-5 %, 12 steps, mean: 4.07 from the ramp start, 4.66 from the nominal one).
            start = None
            for kind in starts:
                coarse._start = kind
                found = coarse._solve_model(coarse.ocp, t_max, weights, aggregate, omega, None, max_shifts, stages,
                                            f"smooth, {presolve_intervals} intervals, start {kind}")
                if found.success and (start is None or found.objective < start.objective):
                    start = found
        # From the presolve's solution if there is one, else (or if that fails) from each start in turn.
        for kind, guess in ([(None, start)] if start is not None else []) + [(k, None) for k in starts]:
            if kind is not None:
                self._start = kind
            result = self._solve_model(ocp, t_max, weights, aggregate, omega, guess, max_shifts, stages,
                                       "smooth" if kind is None else f"smooth, start {kind}")
            if result.success:
                break
        if ocp.polish and result.success:
            polished = self._solve_model(ocp.exact, t_max, weights, aggregate, omega, result, max_shifts, stages,
                                         "exact")
            if polished.success:
                result = polished
        # The status is the returned solution's own: a last re-solve that failed after it (a move of a
        # lock-up the problem could not take) does not make a converged solution a failure.
        result.stats = dict(result.stats, iterations=sum(s["iterations"] for s in stages),
                            wall_time_s=sum(s["wall_time_s"] for s in stages), stages=stages)
        result.t_max_margin = float(t_max_margin)
        if not result.success:
            raise SolverError(f"robust engagement: IPOPT stopped with {result.stats['status']} (scene "
                              f"'{self.scene.name}', {self.n_scenarios} scenarios, t_max = {t_max:.4g} s, "
                              f"{result.stats['iterations']} iterations); try another t_max, fewer or nearer "
                              "scenarios, or other weights")
        return result

    def _solve_model(self, ocp, t_max, weights, aggregate, omega, guess, max_shifts, stages, label):
        """Solve on one model (smooth or exact), moving lock-ups between command intervals until
        no scenario's lock-up sits on the end of its interval with a multiplier pushing it out."""
        h_c = t_max / self.intervals
        if guess is None:
            t_guess = self._lock_guess(t_max)
        else:
            t_guess = guess.lock_times
        lock_intervals = np.clip(np.ceil(t_guess / h_c - 1e-9).astype(int) - 1, 0, self.intervals - 1)
        result, converged, previous_moves = None, None, np.zeros(len(lock_intervals), int)
        for _ in range(max_shifts + 1):
            nlp = self.nlp(ocp, aggregate, t_max, lock_intervals)
            warm = result is None and guess is not None and guess.w.size == nlp.lbx.size \
                and tuple(guess.stats.get("lock_intervals", ())) == tuple(lock_intervals)
            result = self._solve_stage(ocp, nlp, t_max, weights, aggregate, omega, guess if warm else None,
                                       result or guess, warm)
            result.stats["model"] = label
            stages.append(dict(result.stats))
            if result.success:
                converged = result
            elif converged is not None:
                # A move made the problem fail: keep the last converged solution (its lock-up on the
                # bound of its interval is an optimum of the problem with that interval).
                return converged
            # A lock-up interval no command meets shows as a local infeasibility, with the lock-up
            # of the scenario at fault on a bound of its interval: move it there and solve again.
            last = result
            moves = nlp.grid.interval_moves(result.w, result.lam_x, stuck=not result.success)
            moves[moves == -previous_moves] = 0           # no move back: that oscillates between two intervals
            if not np.any(moves):
                break
            previous_moves = moves
            lock_intervals = lock_intervals + moves
            if not result.success:
                result = None
        return result if result is not None else last

    def start_runs(self, t_max):
        """IDAS runs of every scenario under the start command (cached per t_max and start).

        Start "nominal" (tried first): the nominal scene's optimum on this grid (:meth:`nominal_optimum`),
        then a ramp at the rate limit to the pressure limit, so that a scenario the optimum leaves
        slipping locks too. Its lock-up guesses lie near the robust optimum's: on the 9-point default
        box (10 command steps) the first solve converged in 19 iterations and two re-solves moved the
        lock-ups into place, where the ramp start needed 22 re-solves, one interval at a time. Start "baseline": the scene's own pressure profile (its baseline; the command guess is the
        nominal baseline's). Start "ramp": a ramp over the first command step to the pressure limit,
        then held. The grid represents the ramp exactly, so the lock-up intervals it gives can be
        met; the baseline may leave a slow scenario unlocked by t_max, and then the intervals put a
        fast and a slow corner into the same last interval, which no command meets (measured: the
        9-point box infeasible from the baseline; two scenarios 5 % apart in mu on 10 command steps
        converged from the baseline but not from the ramp within 500 iterations; the 9-point box on
        20 steps converged from the ramp and not with the baseline tried first). :meth:`solve` tries
        the ramp first and the baseline if that fails. Re-solves then move the lock-ups. Start
        "sweep" (first for ``aggregate="worst_jump"``, last otherwise; see the module notes): the
        pressure limit until one valve time constant before the fastest scenario would lock under
        it, then a linear sweep from the lowest to the highest of the scenarios' commands whose
        settled capacity is ``SWEEP_CAPACITY`` x their locked torque, reached at t_max (measured on
        the 9 box points, 10 steps, jump weight 100, jerk 1, margin 0.05: worst jump 85 % from a sweep
        of this shape set by hand, 98 % from the nominal start).
        """
        key = (float(t_max), self._start)
        if getattr(self, "_start_key", None) != key:
            h_c = t_max / self.intervals
            opt = self.nominal_optimum(t_max) if self._start == "nominal" else None
            sweep = self._sweep_command(t_max) if self._start == "sweep" else None
            if opt is not None:
                # the nominal optimum, then a ramp at the rate limit to the pressure limit, so that the
                # scenarios it leaves slipping (the weak corners) lock up too
                rate = self.ocp.rate_limit if np.isfinite(self.ocp.rate_limit) else self.ocp.p_max / h_c
                t_end, v_end = float(opt.command_times[-1]), float(opt.command[-1])
                times = np.append(opt.command_times, t_end + max(self.ocp.p_max - v_end, 0.0) / rate + 1e-9)
                values = np.append(opt.command, self.ocp.p_max)
                self._start_runs = [simulate_command(s, times, values, 2.0 * t_max, control="linear")
                                    for s in self.scenes]
            elif sweep is not None:
                times, values = sweep
                self._start_runs = [simulate_command(s, times, values, 2.0 * t_max, control="linear")
                                    for s in self.scenes]
            elif self._start in ("nominal", "ramp", "sweep"):    # (no nominal optimum or sweep: the ramp)
                times, values = [0.0, h_c], [self.ocp.scene.value("actuation.initial_pressure"), self.ocp.p_max]
                self._start_runs = [simulate_command(s, times, values, 2.0 * t_max, control="linear")
                                    for s in self.scenes]
            else:
                self._start_runs = [simulate_engagement(s) for s in self.scenes]
                base = self.ocp.nlp.unpack(guess_from_run(self.ocp, self.ocp.reference_run, t_max=t_max))
                times = self.ocp.transcription.node_times(base["T"])[0] * self.ocp.scales.time_s
                values = base["u"][:, 0] * self.ocp.scales.pressure_Pa
            self._start_key = key
            self._start_command = (times, values)
        return self._start_runs

    def _sweep_command(self, t_max):
        """Start "sweep": the pressure limit until one valve time constant before the fastest scenario
        would lock under it, then a ramp over [SWEEP_CAPACITY x balance] from the lowest scenario's to the
        highest scenario's by t_max, then the pressure limit: (times [s], command [Pa]), or None if the
        scenes have no clamp model (balance = the command whose settled capacity is the locked torque)."""
        try:
            clamps = [ClampModel(s).clamp_pressure(SWEEP_CAPACITY) for s in self.scenes]
        except ModelError:
            return None
        p_a, p_b = min(clamps), max(clamps)
        ocp = self.ocp
        rate = ocp.rate_limit if np.isfinite(ocp.rate_limit) else np.inf
        rise = max(t_max / self.intervals, ocp.p_max / rate)
        lag = self.scene.get("actuation.time_constant", 0.0) or rise
        t_drop = max(float(self.fastest_lockups().min()) - lag, rise)
        t_sweep = min(t_drop + max(lag, (ocp.p_max - p_a) / rate), 0.5 * (t_drop + t_max))
        times = [0.0, rise, t_drop, t_sweep, t_max, t_max + max(ocp.p_max - p_b, 0.0) / rate + 1e-9]
        values = [self.scene.value("actuation.initial_pressure"), ocp.p_max, ocp.p_max, p_a, p_b, ocp.p_max]
        return np.array(times), np.array(values)

    def nominal_optimum(self, t_max):
        """The nominal scene's optimum on this command grid (smooth model, the weights of the solve;
        cached per t_max), or None if IPOPT fails on it."""
        key = (float(t_max), tuple(sorted(self._weights.items())))
        if getattr(self, "_nominal_key", None) != key:
            options = dict(self._ocp_options, polish=False, baseline=self.ocp.baseline, models=self.ocp.models)
            try:
                self._nominal = EngagementOCP(self.scene, intervals=self.intervals, **options).solve(
                    t_max=t_max, weights=self._weights)
            except SolverError:
                self._nominal = None
            self._nominal_key = key
        return self._nominal

    def _lock_guess(self, t_max):
        """First guess of each scenario's lock-up [s]: under the start command (:meth:`start_runs`)."""
        return np.array([min(r.summary["engagement_time_s"] or t_max, t_max) for r in self.start_runs(t_max)])

    def _solve_stage(self, ocp, nlp, t_max, weights, aggregate, omega, warm_from, start_from, warm):
        sc = ocp.scales
        if warm:
            w0, lam_x0, lam_g0 = warm_from.w.copy(), warm_from.lam_x, warm_from.lam_g
        else:
            w0 = self._guess(ocp, nlp, t_max, start_from)
            lam_x0, lam_g0 = np.zeros_like(w0), np.zeros(nlp.lbg.size)
        w0 = np.clip(w0, nlp.lbx, nlp.ubx)
        p = np.concatenate([[weights[k] for k in OBJECTIVE_TERMS], self.thetas.ravel(), omega])
        if aggregate == "worst" and not warm:                 # the epigraph variable starts on its bound
            w0[nlp.grid.tau_slice.stop:] = np.max(np.array(nlp.objectives_fn(w0, p)))
        elif aggregate == "worst_jump" and not warm:
            w0[nlp.grid.tau_slice.stop:] = np.max(np.abs(np.array(nlp.jumps_fn(w0, p))))
        solver = self.solver(nlp, warm)
        start = time.perf_counter()
        with interrupt.in_solver():
            sol = solver(x0=w0, lam_x0=lam_x0, lam_g0=lam_g0, lbx=nlp.lbx, ubx=nlp.ubx, lbg=nlp.lbg, ubg=nlp.ubg,
                         p=p)
        interrupt.check("IPOPT (robust feedforward)")
        wall = time.perf_counter() - start
        st = solver.stats()
        stats = {"status": st["return_status"], "success": bool(st["success"]), "iterations": int(st["iter_count"]),
                 "wall_time_s": wall, "warm_start": bool(warm), "n_variables": int(w0.size),
                 "n_constraints": int(nlp.lbg.size), "n_scenarios": self.n_scenarios,
                 "lock_intervals": [int(k) for k in nlp.grid.lock_intervals]}
        return self._result(ocp, nlp, np.array(sol["x"]).ravel(), np.array(sol["lam_x"]).ravel(),
                            np.array(sol["lam_g"]).ravel(), float(sol["f"]), p, weights, aggregate, omega, t_max,
                            stats, sc)

    def _guess(self, ocp, nlp, t_max, previous):
        """Start point: a previous robust solution interpolated onto this mesh, or each scenario's
        run under a step of the command to the pressure limit (see :meth:`_lock_guess`)."""
        sc = ocp.scales
        t_lock = previous.lock_times if previous is not None else self._lock_guess(t_max)
        T = nlp.grid.clip_lock_times(t_lock / sc.time_s)
        times = nlp.grid.scenario_times(T)                      # scaled node / point times per scenario
        xs, xcs = [], []
        if previous is not None:
            for k, opt in enumerate(previous.scenarios):
                t_old = opt.t / sc.time_s

                def at(t, opt=opt, t_old=t_old):
                    cols = [np.interp(t, t_old, opt.states[name]) / nom for name, nom in zip(ocp.state_names,
                                                                                          ocp.nominal)]
                    cols.append(np.interp(t, t_old, opt.outputs["dissipated_energy_J"]) / sc.energy_J)
                    return np.stack(cols, axis=-1)
                xs.append(at(times[k][0]))
                xcs.append(at(times[k][1]))
            v = np.interp(nlp.grid.command_grid, previous.command_times / sc.time_s,
                          previous.command / sc.pressure_Pa)
            return nlp.grid.pack(xs, xcs, v, T)
        tr = ocp.transcription
        for k, run in enumerate(self.start_runs(t_max)):
            parts = ocp.nlp.unpack(guess_from_run(ocp, run, t_max=t_max))
            t_run = tr.node_times(parts["T"])[0]
            xcol = [np.stack([np.interp(t, t_run, parts["x"][:, i]) for i in range(parts["x"].shape[1])], axis=-1)
                    for t in times[k]]
            xs.append(xcol[0])
            xcs.append(xcol[1])
        times_c, values_c = self._start_command
        v = np.interp(nlp.grid.command_grid * sc.time_s, times_c, values_c) / sc.pressure_Pa
        return nlp.grid.pack(xs, xcs, v, T)

    def _result(self, ocp, nlp, w, lam_x, lam_g, objective, p, weights, aggregate, omega, t_max, stats, sc):
        parts = nlp.grid.unpack(w)
        command = np.clip(parts["v"], 0.0, 1.0) * sc.pressure_Pa
        J = np.array(nlp.objectives_fn(w, p)).ravel()
        times = nlp.grid.scenario_times(parts["T"])
        scenarios = []
        for k in range(self.n_scenarios):
            scenarios.append(_scenario_result(ocp, nlp, parts, k, times[k], float(J[k]), weights, stats, t_max,
                                              self.thetas[k]))
        return RobustEngagement(nlp.grid.command_grid * sc.time_s, command, scenarios, self.overrides, J, objective,
                                aggregate, weights, omega, t_max, stats, w, lam_x, lam_g)


def _scenario_result(ocp, nlp, parts, k, times, objective, weights, stats, t_max, theta):
    """One scenario (parameter values ``theta``) of a robust solution as an OptimalEngagement (its own
    mesh, the shared command)."""
    sc, d = ocp.scales, ocp.transcription.degree
    starts, points = times
    T = parts["T"][k]
    x, xc = parts["x"][k], parts["xc"][k]
    v = np.clip(parts["v"], 0.0, 1.0)
    u_nodes = np.interp(starts, nlp.grid.command_grid, v)
    u_points = np.interp(points, nlp.grid.command_grid, v)
    outputs = ocp.outputs_at(x, u_nodes, theta=theta)
    outputs["dissipated_energy_J"] = x[:, -1] * sc.energy_J
    flat = ocp.outputs_at(xc.reshape(-1, xc.shape[-1]), u_points.ravel(), theta=theta)
    outputs_points = {name: value.reshape(points.shape) for name, value in flat.items()}
    steps = np.diff(starts)[:, None]                             # scaled interval lengths
    quad = ocp.transcription.B[None, :] * steps * sc.time_s
    terms = {
        "jerk_integral": float(np.sum(quad * outputs_points["output_jerk_rad_s3"] ** 2)),
        "slip_jerk_integral": float(np.sum(quad * outputs_points["slip_jerk_rad_s3"] ** 2)),
        "dissipated_energy_J": float(x[-1, -1] * sc.energy_J),
        "engagement_time_s": T * sc.time_s,
        "lockup_torque_jump_Nm": ocp.lockup_jump(x[-1], u_nodes[-1], theta),
        "final_slip_rad_s": float(outputs["w_rel_rad_s"][-1]),
        "locked_torque_Nm": float(outputs["locked_torque_Nm"][-1]),
        "peak_jerk_rad_s3": float(np.max(np.abs(outputs_points["output_jerk_rad_s3"]))),
        "peak_torque_Nm": float(np.max(np.abs(outputs_points["total_torque_Nm"]))),
        "objective": objective,
    }
    nominal = ocp.nominal
    states = {member: x[:, i] * nominal[i] for i, name in enumerate(ocp.state_names)
              for member in ocp.state_groups[name]}
    empty = np.zeros(0)
    result = OptimalEngagement(T * sc.time_s, starts * sc.time_s, points * sc.time_s, starts * sc.time_s,
                               u_nodes * sc.pressure_Pa, "linear", states, outputs, outputs_points, terms, objective,
                               dict(stats), empty, empty, empty, weights)
    result.t_max = t_max
    return result


@dataclass
class RobustNLP:
    """The robust NLP: the scenarios' transcription (``grid``: layout, unpack, lock intervals) with the
    aggregate objective and its rows.

    ``objectives_fn (w, p)`` gives each scenario's J_s, ``jumps_fn (w, p)`` each scenario's
    (locked - slipping) / locked torque at its lock-up; the NLP parameter p is ``[weights; theta of
    each scenario; scenario weights]``.
    """

    grid: ScenarioNLP
    nlp: dict
    lbg: np.ndarray
    ubg: np.ndarray
    objectives_fn: ca.Function
    jumps_fn: ca.Function

    @property
    def lbx(self):
        return self.grid.lbx

    @property
    def ubx(self):
        return self.grid.ubx


def _robust_nlp(ocp, aggregate, t_grid_end, n_int, lock_intervals):
    """The robust NLP on the functions of ``ocp`` (see :class:`RobustNLP`): every scenario transcribed
    under the shared command (:class:`~clutchocp.optimal.scenarios.SharedCommandCollocation`), then the
    aggregate of their objectives (mean, worst, worst jump; epigraph rows)."""
    tr = ocp.transcription
    n_s = len(lock_intervals)
    W = ca.MX.sym("weights", len(OBJECTIVE_TERMS))
    Theta = ca.MX.sym("theta", ocp.theta.numel(), n_s)
    omega = ca.MX.sym("omega", n_s)
    z = ca.MX.sym("z", 1 if aggregate in ("worst", "worst_jump") else 0)
    prob = ocp.staged_problem()                   # its energy end row is free: no e_max in the robust problem
    # path row 0 (w_rel >= 0) is the end condition w_rel = 0 at a Radau lock-up node
    grid = SharedCommandCollocation(t_grid_end, n_int, lock_intervals, tr.degree, tr.scheme).transcribe(
        prob, W, Theta, extra=(z,), end_repeats_path=(0,))
    J_all = ca.vertcat(*grid.objectives)
    relative_jump = _relative_jump_fn(ocp)
    jumps = ca.vertcat(*[relative_jump(x_f, u_f, Theta[:, s]) for s, (x_f, u_f, _, _, _) in enumerate(grid.ends)])
    blocks = list(grid.blocks)
    if aggregate == "worst":
        f = z
        blocks.append((J_all - z, -np.inf, 0.0))
    elif aggregate == "worst_jump":
        # the scenarios' other terms (their jump terms off: the worst jump takes their place), and the
        # epigraph of the largest |jump| / locked torque: -z <= jump_s <= z (z >= 0 follows)
        no_jump = np.ones(len(OBJECTIVE_TERMS))
        no_jump[OBJECTIVE_TERMS.index("jump")] = 0.0
        J_rest = [prob.objective(x_f, u_f, Q, T_s, ca.vertcat(W * no_jump, Theta[:, s]))
                  for s, (x_f, u_f, Q, T_s, _) in enumerate(grid.ends)]
        f = W[OBJECTIVE_TERMS.index("jump")] * z**2 + ca.dot(omega, ca.vertcat(*J_rest))
        blocks.append((ca.vertcat(jumps - z, jumps + z), np.r_[np.full(n_s, -np.inf), np.zeros(n_s)],
                       np.r_[np.zeros(n_s), np.full(n_s, np.inf)]))
    else:
        f = ca.dot(omega, J_all)
    g = ca.vertcat(*[b[0] for b in blocks])
    lbg = np.concatenate([np.broadcast_to(b[1], (b[0].numel(),)) for b in blocks])
    ubg = np.concatenate([np.broadcast_to(b[2], (b[0].numel(),)) for b in blocks])
    P = ca.vertcat(W, ca.vec(Theta), omega)
    nlp = {"x": grid.w, "f": f, "g": g, "p": P}
    return RobustNLP(grid, nlp, lbg, ubg, ca.Function("scenario_objectives", [grid.w, P], [J_all]),
                     ca.Function("scenario_jumps", [grid.w, P], [jumps]))


def _relative_jump_fn(ocp):
    """The jump as a share of the scenario's own locked torque, (locked - slipping) / locked at the end
    state (the measure of the Monte Carlo): ``(xs, us, theta) -> share`` (the worst-jump epigraph)."""
    xs, us = ca.SX.sym("xs", ocp.x0.size + 1), ca.SX.sym("us")
    fns = ocp.phase_functions["slip"]
    values = fns["outputs_fn"](xs, us, *([ocp.theta] if ocp.theta.numel() else []))
    locked = values[fns["output_names"].index("locked_torque_Nm")]
    slipping = values[fns["output_names"].index("total_torque_Nm")]
    return ca.Function("relative_jump", [xs, us, ocp.theta], [(locked - slipping) / locked])


def lock_diagonal(scene, corners, fractions=DIAGONAL_FRACTIONS):
    """Scenarios inside the box on the segment from the corner that locks first to the one that locks last.

    One shared command lands each clutch at its own lock-up time, and its jump depends mostly on that
    time; the box points leave gaps in the lock-up times (on the default box the centre locks 40 ms
    before the slowest corners), where the command of a worst-jump solve is free to bulge (measured:
    worst |jump| 81 % on the 9 box points, 95 % over 200 draws between them). Points on this diagonal
    fill the gaps.

    Parameters
    ----------
    scene : clutchocp.scene.Scene
    corners : list of dict
        Override dicts of the box corners (``Uncertainty.corners()``), SI values.
    fractions : sequence of float
        Positions on the segment, 0 = the first corner to lock, 1 = the last, each in (0, 1).

    Returns
    -------
    list of dict
        One override dict per fraction (numeric fields interpolated linearly).
    """
    fractions = [float(f) for f in fractions]
    if not all(0.0 < f < 1.0 for f in fractions):
        raise ModelError(f"fractions {fractions}: positions on the diagonal are in (0, 1)")
    if len(corners) < 2 or not fractions:
        return []
    p_max = scene.value("actuation.max_pressure")
    t_end = scene.value("simulation.t_end")
    times = []
    for d in corners:
        t = simulate_command(scene.with_overrides(d), [0.0], [p_max], t_end).summary["engagement_time_s"]
        times.append(np.inf if t is None else t)
    first, last = corners[int(np.argmin(times))], corners[int(np.argmax(times))]
    return [{name: first[name] + f * (last[name] - first[name]) for name in first} for f in fractions]


def solve_robust(scene, scenarios, *, t_max=None, weights=None, aggregate="mean", intervals=60, degree=3,
                 scenario_weights=None, presolve_intervals=PRESOLVE_INTERVALS, t_max_margin=0.0, **ocp_options):
    """One pressure command for several scenarios of a clutch (see the module notes).

    Parameters
    ----------
    scene : clutchocp.scene.Scene
        The nominal scene.
    scenarios : list of dict
        Override dicts ``{"part.key": SI value}`` (e.g. ``Uncertainty.corners()``), one per scenario.
    t_max : float, optional
        Engagement-time limit [s] (default: the nominal baseline's lock-up time).
    t_max_margin : float
        Every scenario locks by (1 - t_max_margin) t_max [-, in [0, 0.5)], so that clutches between the
        scenarios still lock within t_max (``RobustEngagement.t_max`` is that bound, ``.t_limit`` t_max).
    weights : dict, optional
        Objective weights by term (jerk, energy, time, jump, smooth).
    aggregate : {"mean", "worst", "worst_jump"}
        Weighted mean of the scenario objectives, the largest one, or w_jump x the largest
        (|jump| / locked torque)^2 plus the mean of the other terms.
    intervals, degree : int
        Steps of the command grid over [0, t_max] and collocation points per interval.
    scenario_weights : sequence of float, optional
        Weights of the scenarios in the mean.
    presolve_intervals : int or None
        Command steps of the coarse first solve that finds the lock-up intervals (see :meth:`RobustOCP.solve`).
    **ocp_options
        Options of :class:`~clutchocp.optimal.problem.EngagementOCP`.

    Returns
    -------
    RobustEngagement
    """
    problem = RobustOCP(scene, scenarios, intervals=intervals, degree=degree, **ocp_options)
    return problem.solve(t_max=t_max, weights=weights, aggregate=aggregate, scenario_weights=scenario_weights,
                         presolve_intervals=presolve_intervals, t_max_margin=t_max_margin)
