"""The optimal-control problem of an engagement: one pressure command over its phases.

The engagement follows the modes of :class:`~clutchocp.engagement.model.EngagementModel` as a
sequence of phases (:mod:`clutchocp.optimal.phases`): with free piston travel a ``fill`` phase
(mode ``approach_slip_forward``: the piston strokes against its return spring, plates at rest) that
ends when the piston reaches the pack (x0 = travel, the kiss point), the impact reset (Bao Eq. 22,
the simulator's own reset map), then the ``slip`` phase (mode ``pressing_slip_forward``) up to
lock-up. Without free travel the slip phase is the only phase, and the problem is the one below.
Plate masses (``pack.model = "masses"``, bao2020) are taken as massless in the OCP: their axial
dynamics is overdamped and 1e5-1e8 times faster than the slip (PHYSICS.md), which no mesh of the
engagement resolves; the IDAS verification replays the optimum on the full model.

Over the slip phase the pressure command u(t) is chosen to minimise

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

The fill phase adds w_jerk and w_smooth integrals of the same kind, its duration to the time term,
and two terms of its own: w_fill_time t_fill / t_ref and w_kiss_speed (v_kiss / v_ref)^2 with the
piston speed at the kiss point v_kiss (Bao 2020 blames the collision speed for shift shock) and v_ref
the kiss speed of the reference run.

A clutch whose locked driveline carries no torque (a brake with its output held, zhang2021; a
prescribed input speed with no load, bao2020) meets lock-up as the moving side coming to rest
relative to the other; its lock-up jump is the torque step at that instant, the slipping torque
before it (after it the clutch carries nothing). Its end condition asks for a slipping torque of
lock_margin x the peak torque of the reference run (transversal: the slip still falls at t_f), and
it has no holding condition (a lock that carries nothing always holds). With the output held the jerk
term is the jerk of the input (the braked inertia), as the output does not move.

Before any run the scene is checked for what no command can do (:mod:`clutchocp.optimal.feasibility`:
the pack's capacity at the pressure limit and at the contact's film floor against the locked torque,
the kiss point; in :meth:`EngagementOCP.solve` t_max and the heat limits); a refusal is one line with
both numbers. :func:`clutchocp.optimal.strategy.solve_robustly` wraps :meth:`EngagementOCP.solve` for
clutches whose first solve does not converge.

Constraints: t_f <= t_max, E <= E_max, films h >= h_min (at least
:data:`~clutchocp.optimal.feasibility.FILM_FLOOR` sigma where the contact cannot carry the largest plate
pressure at that film), 0 <= u <= actuation.max_pressure,
|du/dt| <= rate limit, w_rel >= 0; behind a piston each film opens no faster than its Reynolds film
would at 3 x film.cavitation_pressure (the film law itself holds its mean pressure at that pressure, see
:meth:`EngagementOCP._cavitation_rows`); with a spring-applied piston, films h <= their gap at the kiss
in the slip phase (the piston not behind the kiss point, Bao Eq. 13); optionally interface temperature <= max_temperature_C (a scene
with [thermal]) and interface heat per friction area <= max_specific_power_W_mm2 (path constraints,
:mod:`clutchocp.optimal.heat`). The ``smooth`` term regularises the command: without it the
command reaches the objective only through two integrations (valve lag, film) and IPOPT meets a
nearly singular Hessian and a bang-bang command (measured on the default scene: weight 1e-4 gave a
rate-limited bang-bang command; 0.1, the default, a smooth one for 8 % more jerk integral). The
default smooth weight is 0.1 x the jerk weight: it regularises the jerk objective only, so a time or
energy objective without jerk is not held back by it (``--weights jerk=0,time=1`` gave a lock-up at
0.206 s with a fixed 0.1 and 0.153 s with smooth = 0).

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

from .. import interrupt
from ..engagement.run import simulate_engagement
from ..errors import ModelError, SolverError
from .bound import jerk_lower_bound, output_jerk_share
from .collocation import DirectCollocation, StagedProblem
from .derivatives import MUMPS_UNSCALED, nlp_solver
from .feasibility import (FILM_FLOOR, check_heat, check_pack, film_floor, hardest_command, holding_capacity,
                          locked_torque_at_lock, own_profile_within_contact, plate_force, spring_applied,
                          usable_pressure)
from .guess import guess_from_optimum, guess_from_run
from .heat import heat_limits
from .mesh import graded_mesh, interval_defects
from .models import SceneModels
from .objective import DEFAULT_WEIGHTS, OBJECTIVE_TERMS, SMOOTH_PER_JERK, check_weights  # noqa: F401 (public here)
from .phases import Phase, PhasedNLP, phased_derivatives
from .quiet import native_output_caught
from .replay import simulate_command

LOCK_MARGIN = 0.005      # slipping over locked torque at lock-up, minus one (the default; see above)
JUMP_MODES = ("constraint", "penalty")
# A film may open (cavitated) no faster than its averaged Reynolds film would at this multiple of the
# cavitation pressure (see EngagementOCP._cavitation_rows)
CAVITATION_DEPTH = 3.0
BARRIERS = ("adaptive", "monotone")         # IPOPT's mu_strategy: the default first
SLIP_MODE = "pressing_slip_forward"
FILL_MODE = "approach_slip_forward"


@dataclass
class Scales:
    """Reference values that make the NLP of order one."""

    time_s: float
    energy_J: float
    jerk_integral: float
    torque_Nm: float
    pressure_Pa: float
    speed_m_s: float = 1.0


@dataclass
class OptimalEngagement:
    """A solved (or failed) optimal engagement.

    ``t`` are the interval starts (N + 1), ``t_points`` the collocation times (N, d);
    ``states`` and ``outputs`` hold arrays at the interval starts (``*_points`` at the collocation
    points); ``command`` the command values (N, or N + 1 for a linear command) on ``command_times``.
    With several phases these run over all phases in turn (the node at a phase link appears twice,
    before and after the reset; the command once); ``phases`` lists each phase's name, mode, start
    and end time [s] and its node range in ``t``.
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
    phases: list = field(default_factory=list)
    meshes: list = field(default_factory=list, repr=False)

    @property
    def success(self):
        return self.stats["success"]

    def __repr__(self):
        return (f"OptimalEngagement(t_f={self.t_f:.6g} s, {self.control} command on {self.command.size} nodes, "
                f"objective {self.objective:.6g}, {self.stats.get('status')}, {self.stats.get('iterations')} iterations)")


class EngagementOCP:
    """The optimal engagement pressure problem of a scene, transcribed by direct collocation.

    Parameters
    ----------
    scene : clutchocp.scene.Scene
        An engagement scene that starts slipping forward (w_in > w_out), with ``actuation.max_pressure``.
        With free piston travel the problem has a fill phase before the slip phase.
    intervals : int
        Number of collocation intervals N of the slip phase.
    fill_intervals : int
        Number of collocation intervals of the fill phase (scenes with free piston travel).
    jerk_max : float, optional
        Largest |jerk| [rad/s^3] of the jerk term's signal (output; input for a held output) at every
        collocation point and just after the kiss (default: none).
    quasi_static_plates : bool, optional
        Take plate masses (``pack.model = "masses"``) as massless in the OCP (default: yes for such a
        scene); the verification replays the optimum on the full model.
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
        Smallest film thickness allowed [m] (default: none, or the film floor where the contact cannot
        carry the largest plate pressure above it; see :func:`~clutchocp.optimal.feasibility.film_floor`).
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
    meshes : dict, optional
        Interval shares of a graded mesh by phase name (``{"slip": array, "fill": array}``, each of
        its phase's number of intervals; see :class:`~clutchocp.optimal.collocation.DirectCollocation`);
        default: equal intervals. :meth:`refined` grades them from an optimum's interval defects.
    baseline : clutchocp.engagement.run.EngagementResult, optional
        IDAS run of the scene's own profile (initial guess and scales; simulated if not given).
    max_temperature_C : float, optional
        Largest interface temperature [deg C] over the slip phase (needs a [thermal] part).
    max_specific_power_W_mm2 : float, optional
        Largest interface heat power per friction area [W/mm^2] over the slip phase.
    models : clutchocp.optimal.models.SceneModels, optional
        The engagement models of ``scene``, shared with other problems and replays of the same scene
        (its twins, the IDAS checks); default: new ones.
    kiss_bound : bool
        Fill phase of a spring-applied piston: keep the piston behind the kiss point (x0 <= travel).
        :meth:`solve` sets it itself (solving again) where an optimum without it passes the kiss point.
    """

    # Scene values that are a parameter vector of the NLP functions (appended to the weights; the
    # outputs and jump functions take it as a third input) and their values; empty here, set by
    # clutchocp.optimal.parametric.ParametricOCP.
    theta = ca.SX(0, 1)
    theta_value = np.zeros(0)

    def __init__(self, scene, *, intervals=100, degree=3, scheme="radau", control="linear", rate_limit=None,
                 h_min=None, jump="constraint", lock_margin=LOCK_MARGIN, smooth=True, polish=True,
                 transcription=None, baseline=None, fill_intervals=30, jerk_max=None, quasi_static_plates=None,
                 max_temperature_C=None, max_specific_power_W_mm2=None, meshes=None, models=None, kiss_bound=False):
        if jump not in JUMP_MODES:
            raise ModelError(f"jump '{jump}': allowed values are {', '.join(JUMP_MODES)}")
        if scene.kind != "engagement":
            raise ModelError(f"scene '{scene.name}' is a {scene.kind} scene; the optimal engagement pressure needs "
                             "kind = 'engagement'")
        self.scene = scene
        self.jump_mode = jump
        self.p_max = scene.get("actuation.max_pressure")
        if self.p_max is None:
            raise ModelError("actuation.max_pressure: the optimisation needs an upper pressure limit; set it "
                             "with --set actuation.max_pressure='1.5 MPa' or add max_pressure = \"1.5 MPa\" to "
                             "[actuation]")
        if not (np.isfinite(lock_margin) and 0 <= lock_margin < 0.5):
            raise ModelError(f"lock_margin = {lock_margin!r}: must be a fraction in [0, 0.5)")
        if jerk_max is not None and not (np.isfinite(jerk_max) and jerk_max > 0):
            raise ModelError(f"jerk_max = {jerk_max!r}: must be a positive jerk [rad/s^3]")
        self.options = {"intervals": intervals, "degree": degree, "scheme": scheme, "control": control,
                        "rate_limit": rate_limit, "h_min": h_min, "jump": jump, "lock_margin": lock_margin,
                        "fill_intervals": fill_intervals, "jerk_max": jerk_max,
                        "quasi_static_plates": quasi_static_plates, "max_temperature_C": max_temperature_C,
                        "max_specific_power_W_mm2": max_specific_power_W_mm2, "meshes": meshes,
                        "kiss_bound": bool(kiss_bound)}
        self.kiss_bound = bool(kiss_bound)
        self.jerk_max = jerk_max
        self.lock_margin = float(lock_margin)
        self.smooth = bool(smooth)
        self.polish = bool(polish) and self.smooth
        self._exact = None
        # Plate masses: their axial dynamics is 1e5-1e8 times faster than the slip (overdamped by the
        # squeeze films, see PHYSICS.md), which no collocation mesh of the engagement resolves; the
        # OCP takes the plates as massless (quasi-static) by default and IDAS verifies the optimum on
        # the full model with its masses and the Bao Eq. 22 impact.
        masses = scene.variant("pack") == "masses"
        self.quasi_static_plates = masses if quasi_static_plates is None else bool(quasi_static_plates) and masses
        self.models = SceneModels(scene) if models is None else models
        if self.models.scene is not scene:
            raise ValueError("models: built for another scene")
        # the model this problem transcribes (and its pressure command symbol)
        self.model, self.u = self.models.commanded(self.smooth, self.quasi_static_plates)
        self.heat_limits = heat_limits(self.model, max_temperature_C, max_specific_power_W_mm2)
        start_mode = self.model.initial_mode()
        if start_mode not in (SLIP_MODE, FILL_MODE):
            raise ModelError(f"scene '{scene.name}' starts in mode '{start_mode}'; the optimisation covers an "
                             f"engagement that starts slipping forward (driveline.input_speed > output_speed)")
        meshes = dict(meshes or {})
        # Phases (name, mode): the fill phase first if the piston starts with free travel.
        self.phase_modes = ([("fill", FILL_MODE)] if start_mode == FILL_MODE else []) + [("slip", SLIP_MODE)]
        self.transcription = transcription or DirectCollocation(intervals, degree, scheme, control,
                                                                mesh=meshes.get("slip"))
        self.fill_transcription = DirectCollocation(fill_intervals, degree, scheme, control, mesh=meshes.get("fill")) \
            if start_mode == FILL_MODE else None
        # Output held (a brake): the braked side is the input; its jerk is the one felt.
        self.output_held = not self.model.output_inertia and self.model.input_inertia
        # The torque the locked driveline carries, at the lock-up speed (a load that rises with speed
        # carries more there than at the start), and what the pack can hold against it: checked before
        # any run (:mod:`clutchocp.optimal.feasibility`).
        self.lock_torque = locked_torque_at_lock(self.model)
        check_pack(self)
        # Films stay above a floor where the contact cannot carry the largest plate pressure there
        # (feasibility.film_floor): at h = 0 the contact law ends (the model's edge) and the
        # Patir-Cheng shear factor's third derivative (H^2.31) is infinite, a NaN in the jerk Hessian.
        floor = film_floor(self.model.film, plate_force(self.model, hardest_command(self.model, self.p_max))
                           / self.model.film.area)
        self.h_min = max(h_min or 0.0, floor) or h_min
        # the scene's own profile, held within what the contact carries at zero gap where it presses harder
        self.baseline_scene, self.baseline_note = own_profile_within_contact(scene, self.model, self.p_max)
        self.baseline = baseline if baseline is not None else simulate_engagement(self.baseline_scene)
        self._fastest = None
        # The run that seeds the first solve and sets the scales: the baseline if it locks up.
        self.reference_run = self.baseline if self.baseline.summary["engagement_time_s"] is not None \
            else self.fastest_run()
        self.rate_limit = self.p_max / 0.01 if rate_limit is None else float(rate_limit)
        if not self.rate_limit > 0:
            raise ModelError(f"rate_limit = {rate_limit!r}: must be a positive rate [Pa/s]")
        self.output_jerk_share = 1.0 if self.output_held else output_jerk_share(scene)
        self.has_valve = self.model.actuation.has_state
        self.state_groups = self._state_groups(self.model)
        self.state_names = tuple(self.state_groups)  # the NLP adds the dissipated energy as a last state
        self._names = list(self.state_names)
        self._phys = [self.model.index[n] for n in self._names]
        self.nominal = self.model.nominal[self._phys]
        self.x0 = self.model.initial_state[self._phys]
        self.scales, self.holds_torque = self._references(self.model)
        self.phase_functions = self._phase_functions()
        for key, fn in self.phase_functions["slip"].items():     # the slip phase's blocks, as before
            setattr(self, key, fn)
        self.phased = self._phased_nlp()
        self.nlp = self.phased.parts[0] if len(self.phased.parts) == 1 else self.phased
        self._solvers = {}
        self._derivatives = None
        self._relaxed = None

    # -- set-up ---------------------------------------------------------------------------------
    def _state_groups(self, model):
        """Physical states of the NLP for ``model`` (numeric, built with the command ``self.u``):
        {representative: [model states it stands for]}.

        Films that start equal and whose rates are equal whenever their thicknesses are (a massless
        pack without spline friction: the same law and the same load on every film) stay equal, so
        one NLP state carries them all. The check is numerical, at random states on that diagonal.
        """
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

    def initial_slip(self, model=None):
        """Slip speed and its rate at t = 0: (w_rel [rad/s], dw_rel/dt [rad/s^2]) (of ``model``, default
        this problem's)."""
        model = self.model if model is None else model
        w_in, w_out = model.speeds()
        f = ca.Function("slip", [model.x], [w_in - w_out, _slip_rate(model)])
        return tuple(float(v) for v in f(model.initial_state))

    def _references(self, model):
        """The scales of the problem on ``model`` (numeric) with the reference run, and whether its lock
        carries torque: (Scales, holds_torque)."""
        summary = self.reference_run.summary
        t_ref = summary["engagement_time_s"]
        w_rel0, rate0 = self.initial_slip(model)
        locked0 = locked_torque_at_lock(model)       # at the lock-up speed (a load rising with speed)
        jerk_ref = jerk_lower_bound(w_rel0, rate0, t_ref) * max(self.output_jerk_share, 1e-3) ** 2
        peak = summary["peak_torque_Nm"]
        # A lock that carries (almost) no torque: the jump is the slipping torque before it, measured
        # against the peak torque of the reference run.
        holds_torque = abs(locked0) > 0.01 * peak
        torque = max(abs(locked0), 1.0) if holds_torque else peak
        return Scales(time_s=t_ref, energy_J=max(summary["dissipated_energy_J"], 1e-6), jerk_integral=jerk_ref,
                      torque_Nm=torque, pressure_Pa=self.p_max, speed_m_s=self._reference_kiss_speed()), holds_torque

    def _reference_kiss_speed(self):
        """Piston speed at the kiss point of the reference run [m/s] (1 without a fill phase)."""
        impact = [e for e in self.reference_run.result.events if e.name == "impact"]
        if not impact:
            return 1.0
        return max(abs(impact[0].x_before["v0"]), 1e-6)

    def transcribed_model(self):
        """The model whose equations the NLP functions hold: this problem's (numeric) model."""
        return self.model

    def _phase_functions(self):
        """The NLP functions of each phase ({phase name: :meth:`_build_functions` dict}) on the
        :meth:`transcribed_model`."""
        model = self.transcribed_model()
        functions = {"slip": self._build_functions(SLIP_MODE, "slip", model)}
        if self.phase_modes[0][0] == "fill":
            self.kiss_jerk_fn = self._kiss_jerk_fn(functions["slip"])
            functions["fill"] = self._build_functions(FILL_MODE, "fill", model)
        return functions

    def _build_functions(self, mode_name=SLIP_MODE, role="slip", model=None):
        """Scaled dynamics, objective and end conditions, and the physical outputs of one phase.

        Parameters
        ----------
        mode_name, role : str
            The model mode of the phase and its name (``"slip"`` or ``"fill"``).
        model : clutchocp.engagement.model.EngagementModel, optional
            The model whose equations are transcribed (default: this problem's): built with the command
            ``self.u`` and the states of this problem's model, its values numbers or the symbols theta.

        Returns
        -------
        dict
            ``dynamics_fn (xs, us, params) -> (xdot, q, c)``, ``objective_fn (xs, us, Q, T, params)``,
            ``end_fn (xs, us, T, params)``, ``outputs_fn (xs, us[, theta])``, ``jump_fn (xs, us[, theta])``,
            ``subs`` (physical SX of the model state -> SX of the scaled NLP state) and ``output_names``;
            ``params`` is ``[weights; theta]``.
        """
        model = self.model if model is None else model
        mode, sc = model.modes[mode_name], self.scales
        n = len(self._phys)
        xs = ca.SX.sym("xs", n + 1)                 # physical states, then the dissipated energy
        us = ca.SX.sym("us")
        x_full = self._full_state(xs, model)
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
            physical[f"film_{i + 1}_mean_pressure_Pa"] = mode.outputs[f"film_{i + 1}_mean_pressure_Pa"]
            physical[f"film_{i + 1}_reynolds_pressure_Pa"] = mode.outputs[f"film_{i + 1}_reynolds_pressure_Pa"]
        physical.update(piston_outputs(model, mode_name))
        physical.update({k: mode.outputs[k] for k in ("interface_heat_power_W", "interface_temperature_C")
                         if k in mode.outputs})
        physical = {k: ca.SX(v) for k, v in physical.items()}
        if ca.depends_on(ca.vertcat(ode, *physical.values()), model.t):
            raise ModelError("the optimisation needs a time-invariant slip mode (a pressure command, not a profile)")

        def subs(expr):
            # cse merges the copies of equal films (and other repeated subexpressions)
            return ca.cse(ca.substitute(expr, ca.vertcat(model.x, self.u), ca.vertcat(x_full, u)))

        # The jerk that is felt: the output's, or with the output held (a brake) the input's.
        felt_jerk = physical["slip_jerk_rad_s3"] if self.output_held else physical["output_jerk_rad_s3"]
        t_ref = sc.time_s
        xdot = ca.vertcat(subs(ode[self._phys]) / self.nominal,
                          subs(physical["dissipated_power_W"]) / sc.energy_J) * t_ref
        q = ca.vertcat(subs(felt_jerk) ** 2 * t_ref / sc.jerk_integral,
                       (subs(physical["pressure_rate_Pa_s"]) * t_ref / sc.pressure_Pa) ** 2)
        w_scale = max(self.scene.value("driveline.input_speed"), self.scene.get("driveline.output_speed", 0.0), 1.0)
        slip = subs(w_rel) / w_scale
        c = slip if self.jerk_max is None else ca.vertcat(slip, subs(felt_jerk) / self.jerk_max)
        c = ca.vertcat(c, *[subs(physical[name]) / limit for name, limit in self.heat_limits])
        c = ca.vertcat(c, *self._cavitation_rows(physical, subs, model))
        weights = ca.SX.sym("weights", len(OBJECTIVE_TERMS))
        w = dict(zip(OBJECTIVE_TERMS, ca.vertsplit(weights)))
        # A robust problem's scenario values (self.theta, empty here) follow the weights in the parameter
        # of the dynamics, objective and end functions, and are a third input of the outputs and jump.
        theta = [self.theta] if self.theta.numel() else []
        params = ca.vertcat(weights, self.theta)
        out = {"output_names": list(physical), "subs": subs,
               "outputs_fn": ca.Function("outputs", [xs, us, *theta], [subs(ca.vertcat(*physical.values()))]),
               "dynamics_fn": ca.Function("dynamics", [xs, us, params], [xdot, q, c])}
        Q = ca.SX.sym("Q", 2)
        T = ca.SX.sym("T")
        locked, slipping = subs(physical["locked_torque_Nm"]), subs(physical["total_torque_Nm"])
        jump = (locked - slipping) / sc.torque_Nm
        if role == "fill":
            # Fill phase: ends at the kiss point x0 = travel; its own terms are its time and kiss speed.
            kiss = subs(physical["piston_speed_m_s"]) / sc.speed_m_s
            J = (w["jerk"] * Q[0] + w["smooth"] * Q[1] + (w["time"] + w["fill_time"]) * T
                 + w["kiss_speed"] * kiss**2)
            out["objective_fn"] = ca.Function("objective", [xs, us, Q, T, params], [J])
            i_x0 = self._names.index("x0")
            g_end = [xs[i_x0] - model.travel / self.nominal[i_x0]]
            if self.jerk_max is not None:     # the jerk just after the kiss (slip mode, after the reset)
                g_end.append(self.kiss_jerk_fn(xs, us) / self.jerk_max)
            out["end_fn"] = ca.Function("end", [xs, us, T, params], [ca.vertcat(*g_end)])
            out["jump_fn"] = ca.Function("jump", [xs, us, *theta], [jump * sc.torque_Nm])
            return out
        if self.holds_torque:
            jump_condition = (locked * (1 + self.lock_margin) - slipping) / sc.torque_Nm
        else:   # a lock that carries nothing: a small slipping torque left, so the slip still falls at t_f
            jump_condition = (self.lock_margin * sc.torque_Nm - slipping) / sc.torque_Nm
        J = w["jerk"] * Q[0] + w["energy"] * xs[n] + w["time"] * T + w["jump"] * jump**2 + w["smooth"] * Q[1]
        out["objective_fn"] = ca.Function("objective", [xs, us, Q, T, params], [J])
        # The lock must hold: the static capacity (about the slipping torque at lock-up) may not be
        # falling at t_f. Without this row the optimum lets the pressure fall through lock-up.
        capacity_rate = subs(physical["capacity_rate_Nm_s"]) * t_ref / sc.torque_Nm
        g_end = [slip] + ([jump_condition] if self.jump_mode == "constraint" else []) \
            + ([capacity_rate] if self.holds_torque else []) + [xs[n]]
        out["end_fn"] = ca.Function("end", [xs, us, T, params], [ca.vertcat(*g_end)])
        out["jump_fn"] = ca.Function("jump", [xs, us, *theta], [jump * sc.torque_Nm])
        return out

    def _film_representatives(self):
        """Numbers k of the films that are NLP states (one per group of equal films)."""
        return [int(name[2:]) for name in self._names if name.startswith("h_")]

    def _cavitation_rows(self, physical, subs, model):
        """Path rows (>= 0) for a pack behind a piston: each film opens no faster than the averaged Reynolds
        film would at CAVITATION_DEPTH x film.cavitation_pressure, (p_Reynolds - depth p_cav) / |p_cav|.

        The film law limits the fluid load smoothly at p_cav (:mod:`clutchocp.physics.cavitation`): a
        film pulled harder cavitates and opens, its mean pressure held at about p_cav, and its Reynolds
        pressure (the mean pressure of the averaged Reynolds film at the same closing speed, without the
        limit) measures how fast it opens: -3 bar is three times the speed at which it starts to
        cavitate. A pack pressed by the pressure directly (no piston) opens quasi-statically once
        cavitated, as fast as its asperities unload (C(h) = F - L), whatever the limit's residual slope,
        so it gets no row: zhang2021's optimum opens its film that way (its mean pressure at -1.04 bar
        in the IDAS replay); with the row at depth 3 its solve did not converge. Behind a piston the
        pressure can pull the pack open, and then the piston's mass and the residual slope, not the
        film, set how fast (microseconds, no mesh resolves it), and the residual resistance adds suction:
        bao2020's optimum without the row verifies but pulls its films to -1.23 bar in the IDAS replay;
        with depth 3 it verifies (IDAS lock-up within 0.03 %, jump 0.61 %) with its films at -1.02 bar.
        """
        if not model.has_piston:
            return []
        p_cav = model.film.cavitation_pressure
        scale = max(abs(p_cav), 1e4)
        return [(subs(physical[f"film_{k}_reynolds_pressure_Pa"]) - CAVITATION_DEPTH * p_cav) / scale
                for k in self._film_representatives()]

    def _full_state(self, xs, model=None):
        """The state (SX, SI) of ``model`` (default: this problem's) from the scaled NLP state ``xs``
        (equal films copied)."""
        model = self.model if model is None else model
        x_full = ca.SX.zeros(len(model.state_names))
        for k, name in enumerate(self._names):
            for member in self.state_groups[name]:
                x_full[model.index[member]] = xs[k] * self.nominal[k]
        return x_full

    def staged_problem(self, role="slip"):
        """The scaled problem of one phase (``x0`` given for the first phase only)."""
        n = len(self._phys)
        fns = self.phase_functions[role]
        first = self.phase_modes[0][0] == role
        x_lb, x_ub = np.full(n + 1, -np.inf), np.full(n + 1, np.inf)
        for i, name in enumerate(self._names):
            if name.startswith("h_"):
                x_lb[i] = (self.h_min or 0.0) / self.nominal[i]
        if role == "fill":
            # The model has no piston stop. A spring-applied piston may not move back by more than
            # 10 % of its stroke: without a bound the bao2020 optimum drew it back against its spring
            # with the pressure and let it go, a 20 m/s kiss. A pressure-applied piston gets no bound:
            # its optimum does not move back, and an inactive bound (at 1 or 10 % of the stroke)
            # made IPOPT take 262 or 111 iterations instead of 47 on default_fill.
            if self.spring_applied:
                i_x0 = self._names.index("x0")
                x_lb[i_x0] = -0.1 * self.model.travel / self.nominal[i_x0]
            end_lb, end_ub = np.zeros(1), np.zeros(1)
            if self.jerk_max is not None:
                end_lb, end_ub = np.array([0.0, -1.0]), np.array([0.0, 1.0])
        else:
            n_end = 2 + (self.jump_mode == "constraint") + self.holds_torque
            end_lb, end_ub = np.zeros(n_end), np.zeros(n_end)
            if self.holds_torque:
                end_ub[-2] = np.inf                                  # capacity rate >= 0
            end_lb[-1], end_ub[-1] = -np.inf, np.inf                 # energy row: set per solve
        c_lb, c_ub = np.array([0.0]), np.array([np.inf])
        if self.jerk_max is not None:
            c_lb, c_ub = np.array([0.0, -1.0]), np.array([np.inf, 1.0])
        c_lb = np.append(c_lb, [-np.inf] * len(self.heat_limits))      # heat limits: value / limit <= 1
        c_ub = np.append(c_ub, [1.0] * len(self.heat_limits))
        n_films = len(self._film_representatives()) if self.model.has_piston else 0    # cavitation rows
        c_lb, c_ub = np.append(c_lb, np.zeros(n_films)), np.append(c_ub, np.full(n_films, np.inf))
        p0 = self.scene.value("actuation.initial_pressure") / self.scales.pressure_Pa
        u_rate = np.array([self.rate_limit * self.scales.time_s / self.scales.pressure_Pa]) \
            if np.isfinite(self.rate_limit) else None
        return StagedProblem(fns["dynamics_fn"], np.append(self.x0 / self.nominal, 0.0) if first else None,
                             fns["objective_fn"], fns["end_fn"], x_lb, x_ub, np.array([0.0]), np.array([1.0]),
                             c_lb, c_ub, end_lb, end_ub, u_rate=u_rate,
                             u_initial=np.array([p0]) if first else None)

    def _phased_nlp(self):
        """The phases and their links (the impact reset between fill and slip)."""
        phases = []
        for name, mode in self.phase_modes:
            tr = self.fill_transcription if name == "fill" else self.transcription
            phases.append(Phase(name, mode, self.staged_problem(name), tr))
        links = [self.impact_link()] if len(phases) > 1 else []
        nlp = PhasedNLP(phases, links)
        if len(phases) > 1 and self.spring_applied:
            self._bound_films_by_the_gap(nlp)
            if self.kiss_bound:
                self._bound_piston_by_the_kiss(nlp)
        return nlp

    def passes_kiss(self, opt):
        """True if the fill phase of an optimum carries the piston past the kiss point (x0 > travel at a node
        or collocation point before the phase's end; see :meth:`_bound_piston_by_the_kiss`)."""
        if len(opt.phases) < 2:
            return False
        fill = opt.phases[0]
        a, b = fill["nodes"]
        reach = max(np.max(opt.states["x0"][a:b - 1]),
                    np.max(opt.outputs_points["piston_position_m"][:fill["intervals"]].ravel()[:-1]))
        return reach > self.model.travel * (1 + 1e-6)

    def _bound_piston_by_the_kiss(self, nlp):
        """Fill phase of a spring-applied piston: the piston not past the kiss point, x0 <= travel.

        The fill mode has no plates, so without this bound its optimum may carry the piston past the
        kiss point and back, to end the phase at x0 = travel moving backwards; IDAS meets the kiss at
        the first crossing instead. Measured on the catalogue's helicopter_spring_applied_90C: a
        collocation kiss at 0.043 s at -0.083 m/s against IDAS's at 0.0099 s at +0.31 m/s, and IDAS
        locking 2.6 % early with a jump of 15 % of the locked torque; with the bound, IDAS within
        0.001 % and 0.5 %. The phase's end (node N and the last Radau point, equal to it), where the
        end condition sets x0 = travel, is left free. Only where an optimum passes the kiss point
        (``kiss_bound``, set by :meth:`solve`): on bao2020, whose optimum does not, the bound made the
        solve on 100 intervals from the 60-interval optimum fail (a step IPOPT could not compute).
        """
        part, off = nlp.parts[0], int(nlp.offsets[0])
        n_x = part.problem.n_x
        (xs, (n_nodes, _)), (xcs, (N, d, _)) = part.layout["x"], part.layout["xc"]
        i = self._names.index("x0")
        kiss = self.model.travel / self.nominal[i]
        nlp.ubx[off + xs + i:off + xs + (n_nodes - 1) * n_x:n_x] = kiss                  # nodes 0 ... N-1
        nlp.ubx[off + xcs + i:off + xcs + (N * d - 1) * n_x:n_x] = kiss                  # all points but the last

    def _bound_films_by_the_gap(self, nlp):
        """Slip phase of a spring-applied piston: no film thicker than its gap at the kiss, H0.

        The pressing mode has no separation and its squeeze films carry tension, so a pressure above the
        spring's can pull the piston back behind the kiss point (x0 = travel + sum (H0 - h_i) < travel,
        Bao Eq. 13) with the pack held to it by suction. Without this bound the bao2020_as_published
        optimum did so (films at 1.94 H0 at 0.16 s, then shut within one 20 ms interval, defect 3.0
        nominal values) and IDAS locked 4.9 % late. The slip phase's first node is left free: the impact
        link sets its films to H0 exactly, and a bound there would leave the barrier method no interior.
        With the bound bao2020_as_published verifies (IDAS 0.014 %, jump 0.66 %) and bao2020 takes 368
        iterations instead of 498 to the same lock-up. A pressure-applied piston's return spring could
        pull it back as well; that was not measured, and its problem is left unbounded (unchanged).
        """
        part, off = nlp.parts[1], int(nlp.offsets[1])
        n_x = part.problem.n_x
        (xs, (n_nodes, _)), (xcs, (N, d, _)) = part.layout["x"], part.layout["xc"]
        for i, name in enumerate(self._names):
            if name.startswith("h_"):
                gap = self.model.H0 / self.nominal[i]
                nlp.ubx[off + xs + n_x + i:off + xs + n_nodes * n_x:n_x] = gap           # nodes 1 ... N
                nlp.ubx[off + xcs + i:off + xcs + N * d * n_x:n_x] = gap                # every collocation point

    def impact_reset(self):
        """The impact reset map on the scaled NLP state: ``(xs_before) -> xs_after`` (casadi.Function).

        It is the simulator's own map (the ``impact`` event of the fill mode: Bao Eq. 22 with plate
        masses, the identity with a massless pack); the impact's kinetic-energy loss is added to the
        dissipated-energy state.
        """
        n = len(self._phys)
        xs = ca.SX.sym("xs", n + 1)
        event = next(e for e in self.model.modes[FILL_MODE].events if e.name == "impact")
        x_full = self._full_state(xs)

        def subs(expr):
            return ca.substitute(ca.SX(expr), self.model.x, x_full)

        reset = event.reset or {}
        after = []
        for k, name in enumerate(self._names):
            after.append(subs(reset[name]) / self.nominal[k] if name in reset else xs[k])
        loss = subs(reset["E_impact"] - self.model.state("E_impact")) if "E_impact" in reset else 0.0
        after.append(xs[n] + loss / self.scales.energy_J)
        return ca.Function("impact_reset", [xs], [ca.vertcat(*after)])

    def _kiss_jerk_fn(self, slip):
        """The felt jerk just after the kiss [rad/s^3]: the slip mode's (``slip``: its functions), at the
        impact-reset state."""
        n = len(self._phys)
        xs, us = ca.SX.sym("xs", n + 1), ca.SX.sym("us")
        index = slip["output_names"].index("slip_jerk_rad_s3" if self.output_held else "output_jerk_rad_s3")
        return ca.Function("kiss_jerk", [xs, us], [slip["outputs_fn"](self.impact_reset()(xs), us)[index]])

    def impact_link(self):
        """Link residual of the fill -> slip junction: ``(x_end, x_start) -> x_start - reset(x_end)``."""
        n = len(self._phys)
        x_end, x_start = ca.MX.sym("x_end", n + 1), ca.MX.sym("x_start", n + 1)
        return ca.Function("impact_link", [x_end, x_start], [x_start - self.impact_reset()(x_end)])

    # -- solving --------------------------------------------------------------------------------
    def solver(self, warm=False, barrier=BARRIERS[0]):
        """The IPOPT solver of the NLP (built once per kind: cold or warm start, barrier-parameter update
        ``"adaptive"`` (default) or ``"monotone"``)."""
        if barrier not in BARRIERS:
            raise ModelError(f"barrier '{barrier}': allowed values are {', '.join(BARRIERS)}")
        key = ("warm" if warm else "cold") + ("" if barrier == BARRIERS[0] else f"_{barrier}")
        if key not in self._solvers:
            if self._derivatives is None:
                self._derivatives = phased_derivatives(self.phased)
            self._solvers[key] = nlp_solver(self.phased, warm=warm, name=f"engagement_{key}",
                                            derivatives=self._derivatives,
                                            ipopt=dict(MUMPS_UNSCALED if self.model.thermal.present and not warm else {},
                                                       mu_strategy=barrier))
        return self._solvers[key]

    @property
    def exact(self):
        """The twin problem on the exact forms (the polish stage), built on first use."""
        if self._exact is None:
            self._exact = EngagementOCP(self.scene, smooth=False, polish=False, baseline=self.baseline,
                                        transcription=self.transcription, models=self.models, **self.options)
        return self._exact

    def refined(self, opt):
        """The same problem on meshes graded from the interval defects of an optimum of this problem.

        Each phase keeps its number of intervals; its new interval shares equidistribute the defects
        (:func:`clutchocp.optimal.mesh.graded_mesh`). The baseline run is shared.
        """
        solved_on = self.exact if self.polish and opt.stats.get("model") == "exact" else self
        defects = interval_defects(solved_on, opt)
        return self.with_meshes({name: graded_mesh(part.transcription.mesh, e, part.transcription.degree)
                                 for (name, _), part, e in zip(self.phase_modes, self.phased.parts, defects)})

    def coarsened(self, fraction):
        """The same problem with ``fraction`` of the slip intervals (equal intervals; the fill phase
        keeps its mesh); the baseline is shared."""
        tr = self.transcription
        options = dict(self.options, meshes=None, intervals=max(2, int(round(fraction * tr.intervals))),
                       degree=tr.degree, scheme=tr.scheme, control=tr.control)
        twin = EngagementOCP(self.scene, smooth=self.smooth, polish=self.polish, baseline=self.baseline,
                             models=self.models, **options)
        twin._fastest = self._fastest
        return twin

    def relaxed(self):
        """The same problem (same meshes) with the lock-up jump as a penalty instead of an end condition,
        built once: the start of :func:`clutchocp.optimal.strategy.solve_robustly` where this one fails."""
        if self._relaxed is None:
            tr = self.transcription
            meshes = {name: part.transcription.mesh for (name, _), part in zip(self.phase_modes, self.phased.parts)}
            options = dict(self.options, jump="penalty", meshes=meshes, intervals=tr.intervals, degree=tr.degree,
                           scheme=tr.scheme, control=tr.control)
            self._relaxed = EngagementOCP(self.scene, smooth=self.smooth, polish=False, baseline=self.baseline,
                                          models=self.models, **options)
            self._relaxed._fastest = self._fastest
        return self._relaxed

    def with_meshes(self, meshes):
        """The same problem on other meshes (``{phase name: interval shares}``); the baseline is shared."""
        tr = self.transcription
        options = dict(self.options, meshes=meshes, intervals=tr.intervals, degree=tr.degree, scheme=tr.scheme,
                       control=tr.control)
        twin = EngagementOCP(self.scene, smooth=self.smooth, polish=self.polish, baseline=self.baseline,
                             models=self.models, **options)
        twin._fastest = self._fastest
        return twin

    def solve(self, *, t_max=None, e_max=None, weights=None, guess=None, barrier=BARRIERS[0], warm_start=True):
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
        barrier : {"adaptive", "monotone"}
            IPOPT's update of the barrier parameter in the first stage (the polish is a warm start
            either way): adaptive (default) or monotone (Fiacco-McCormick), slower but steadier where
            adaptive collapses the barrier early (see :mod:`clutchocp.optimal.strategy`).
        warm_start : bool
            Start from an optimum ``guess`` with its multipliers where its NLP has this one's size
            (default); False: from its states and command only.

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
        check_heat(self, t_max, min(t_max, self.fastest_lockup()) if self.heat_limits else t_max)
        if e_max is not None and not (np.isfinite(e_max) and e_max > 0):
            raise ModelError(f"e_max = {e_max!r}: must be a positive energy [J]")
        result = self._solve_stage(t_max, e_max, weights, guess, barrier, warm_start)
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
            error = SolverError(self._failure_message(result.stats, t_max))
            error.status = result.stats["status"]
            raise error
        if not self.kiss_bound and self.spring_applied and self.passes_kiss(result):
            # from now on bounded; again from this optimum's states and command (cold: its multipliers
            # know no such bound)
            self.bound_kiss()
            return self.solve(t_max=t_max, e_max=e_max, weights=weights, guess=result, barrier=barrier,
                              warm_start=False)
        return result

    def floor_films(self):
        """Keep every film above :data:`~clutchocp.optimal.feasibility.FILM_FLOOR` sigma from now on (this
        problem, its exact and relaxed twins and the twins built from it).

        The films' default lower bound is zero, the model's edge: IPOPT relaxes bounds by 1e-8, so a
        trial point may sit at h = 0, where the third derivative of the Patir-Cheng shear factor
        (H^2.31) in the jerk term's Hessian is infinite, a NaN. :func:`clutchocp.optimal.strategy.solve_robustly`
        sets the floor after such a failure and before its minimum-time solve, which presses the films
        hardest (measured on a user's 7-interface paper clutch: the minimum-time solve stopped on a NaN
        without the floor).
        """
        floor = FILM_FLOOR * self.model.film.sigma
        if (self.h_min or 0.0) >= floor:
            return
        self.h_min = floor
        self.options["h_min"] = floor
        for k, part in enumerate(self.phased.parts):
            off, n_x = int(self.phased.offsets[k]), part.problem.n_x
            (xs, (n_nodes, _)), (xcs, (N, d, _)) = part.layout["x"], part.layout["xc"]
            for i, name in enumerate(self._names):
                if name.startswith("h_"):
                    value = floor / self.nominal[i]
                    for start, count in ((xs, n_nodes), (xcs, N * d)):
                        sl = slice(off + start + i, off + start + count * n_x, n_x)
                        self.phased.lbx[sl] = np.maximum(self.phased.lbx[sl], value)
        for twin in (self._exact, self._relaxed):
            if twin is not None:
                twin.floor_films()

    def bound_kiss(self):
        """Keep the piston behind the kiss point in the fill phase from now on (this problem, its exact twin
        and the twins built from it; see :meth:`_bound_piston_by_the_kiss`)."""
        if self.kiss_bound or len(self.phase_modes) < 2 or not self.spring_applied:
            return
        self.kiss_bound = True
        self.options["kiss_bound"] = True
        self._bound_piston_by_the_kiss(self.phased)
        if self._exact is not None:
            self._exact.bound_kiss()
        if self._relaxed is not None:
            self._relaxed.bound_kiss()

    def _solve_stage(self, t_max, e_max, weights, guess, barrier=None, warm_start=True):
        """One IPOPT solve of this problem (no polish)."""
        barrier = barrier or BARRIERS[0]
        nlp, sc = self.phased, self.scales
        warm = warm_start and isinstance(guess, OptimalEngagement) and guess.w.size == nlp.lbx.size \
            and guess.lam_g.size == nlp.lbg.size and self._same_meshes(guess)
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
        for k, (name, _) in enumerate(self.phase_modes):
            t_slice = nlp.t_slice(k)
            # a fill phase may be a hundredth of the engagement: its lower bound is ten times smaller
            lbx[t_slice] = (1e-3 if name == "slip" else 1e-4) * t_upper / sc.time_s
            ubx[t_slice] = t_upper / sc.time_s
            w0[t_slice] = np.clip(w0[t_slice], lbx[t_slice], ubx[t_slice])
        lbg, ubg = nlp.lbg.copy(), nlp.ubg.copy()
        ubg[nlp.rows["total_time"]] = t_upper / sc.time_s
        ubg[nlp.end_rows(len(nlp.parts) - 1).stop - 1] = e_max / sc.energy_J if e_max is not None else np.inf
        p = self.parameter_values(weights)
        solver = self.solver(warm, barrier)
        start = time.perf_counter()
        with interrupt.in_solver(), native_output_caught() as native:
            sol = solver(x0=w0, lam_x0=lam_x0, lam_g0=lam_g0, lbx=lbx, ubx=ubx, lbg=lbg, ubg=ubg, p=p)
        wall = time.perf_counter() - start
        interrupt.check(f"IPOPT (scene '{self.scene.name}', t_max = {t_max:.4g} s)")
        st = solver.stats()
        stats = {"status": st["return_status"], "success": bool(st["success"]), "iterations": int(st["iter_count"]),
                 "wall_time_s": wall, "warm_start": bool(warm), "n_variables": int(w0.size),
                 "n_constraints": int(lbg.size), "native_output": native[0] if native else ""}
        result = self._result(np.array(sol["x"]).ravel(), np.array(sol["lam_x"]).ravel(),
                              np.array(sol["lam_g"]).ravel(), float(sol["f"]), weights, stats)
        result.t_max, result.e_max = t_max, e_max
        return result

    def parameter_values(self, weights):
        """The NLP parameter vector of a solve: the objective weights (a subclass with scene values
        as parameters, :mod:`clutchocp.study.parametric_ocp`, appends them)."""
        return [weights[k] for k in OBJECTIVE_TERMS]

    def _same_meshes(self, opt):
        """True if an optimum was solved on this problem's meshes (its vector can be reused as is)."""
        mine = [part.transcription.mesh for part in self.phased.parts]
        if not opt.meshes:              # an optimum built elsewhere (robust problem): equal intervals
            return all(part.transcription.uniform for part in self.phased.parts)
        return len(opt.meshes) == len(mine) and all(a.shape == b.shape and np.allclose(a, b, rtol=1e-12, atol=0.0)
                                                    for a, b in zip(opt.meshes, mine))

    def _failure_message(self, stats, t_max):
        """One line for a solve that ended without an optimum: what the solver's status means for the user."""
        status = stats["status"]
        where = (f"scene '{self.scene.name}', t_max = {t_max:.4g} s, {self.transcription.intervals} intervals, "
                 f"{stats['iterations']} iterations")
        return f"optimal engagement: no optimum found ({where}): {solver_verdict(status)}"

    def _result(self, w, lam_x, lam_g, objective, weights, stats):
        sc = self.scales
        t_offset, pieces, phases = 0.0, [], []
        for k, (part, (name, mode)) in enumerate(zip(self.phased.parts, self.phase_modes)):
            piece = self._phase_result(part, self.phase_functions[name], part.unpack(self.phased.w_of(w, k)), t_offset)
            phases.append({"name": name, "mode": mode, "t_start_s": t_offset, "t_end_s": t_offset + piece["T"],
                           "intervals": part.transcription.intervals})
            pieces.append(piece)
            t_offset += piece["T"]
        last, tr = pieces[-1], self.phased.parts[-1]
        n_nodes = 0
        for phase, piece in zip(phases, pieces):
            phase["nodes"] = [n_nodes, n_nodes + piece["t"].size]
            n_nodes += piece["t"].size

        def cat(key, sub=None):
            return np.concatenate([piece[key][sub] if sub else piece[key] for piece in pieces])

        t = cat("t")
        t_points = np.concatenate([piece["t_points"] for piece in pieces])
        # the command is continuous across a link: its first value in a later phase is dropped
        command_times = np.concatenate([pieces[0]["command_times"]] + [p["command_times"][1:] for p in pieces[1:]]) \
            if tr.transcription.control == "linear" else cat("command_times")
        command = np.concatenate([pieces[0]["command"]] + [p["command"][1:] for p in pieces[1:]]) \
            if tr.transcription.control == "linear" else cat("command")
        outputs = {key: np.concatenate([p["outputs"][key] for p in pieces]) for key in last["outputs"]}
        outputs_points = {key: np.concatenate([p["outputs_points"][key] for p in pieces])
                          for key in last["outputs_points"]}
        states = {key: np.concatenate([p["states"][key] for p in pieces]) for key in last["states"]}
        T = t_offset
        felt = "slip_jerk_rad_s3" if self.output_held else "output_jerk_rad_s3"
        xf, uf = last["x"][-1], last["u"][-1]
        terms = {
            "jerk_integral": sum(p["integrals"][felt] for p in pieces),
            "slip_jerk_integral": sum(p["integrals"]["slip_jerk_rad_s3"] for p in pieces),
            "dissipated_energy_J": float(xf[-1] * sc.energy_J),
            "engagement_time_s": T,
            "lockup_torque_jump_Nm": self.lockup_jump(xf, uf),
            "final_slip_rad_s": float(outputs["w_rel_rad_s"][-1]),
            "locked_torque_Nm": float(outputs["locked_torque_Nm"][-1]) if self.holds_torque else 0.0,
            "peak_jerk_rad_s3": float(np.max(np.abs(outputs_points[felt]))),
            "peak_torque_Nm": float(np.max(np.abs(outputs_points["total_torque_Nm"]))),
            "objective": objective,
        }
        if len(pieces) > 1:
            fill = pieces[0]
            terms["fill_time_s"] = fill["T"]
            terms["kiss_speed_m_s"] = float(fill["outputs"]["piston_speed_m_s"][-1])
            # the jerk just after the kiss (at the slip phase's first node, which no collocation point sees)
            terms["kiss_jerk_rad_s3"] = float(last["outputs"][felt][0]) if len(pieces) == 2 else None
            terms["peak_jerk_rad_s3"] = max(terms["peak_jerk_rad_s3"], abs(terms["kiss_jerk_rad_s3"]))
        # the lowest mean film pressure at the nodes and collocation points (the film law limits it at
        # film.cavitation_pressure: a value near that limit means the optimum pulls the plates apart)
        terms["min_film_pressure_Pa"] = float(min(min(outputs[k].min(), outputs_points[k].min())
                                                  for k in outputs if k.endswith("_mean_pressure_Pa")))
        if "interface_temperature_C" in outputs:
            terms["peak_interface_temperature_C"] = float(max(outputs["interface_temperature_C"].max(),
                                                              outputs_points["interface_temperature_C"].max()))
        return OptimalEngagement(T, t, t_points, command_times, command, tr.transcription.control, states, outputs,
                                 outputs_points, terms, objective, stats, w, lam_x, lam_g, weights, phases=phases,
                                 meshes=[part.transcription.mesh for part in self.phased.parts])

    def _phase_result(self, part, fns, parts, t_offset):
        """Times, command, states and outputs of one phase (physical units, times from t_offset)."""
        sc, tr = self.scales, part.transcription
        T = parts["T"] * sc.time_s
        starts, points = tr.node_times(T)
        x_nodes = parts["x"][:, :-1] * self.nominal
        n_u = tr.n_controls
        # IPOPT relaxes bounds by 1e-8 (bound_relax_factor): report the command inside its limits.
        u_values = np.clip(parts["u"][:, 0], 0.0, 1.0) * sc.pressure_Pa
        command_times = starts[:n_u] if tr.control == "constant" else starts
        # Outputs at the nodes use the command of the interval they start (the last node: the last value).
        u_nodes = np.concatenate([u_values, u_values[-1:]]) if tr.control == "constant" else u_values
        outputs = self.outputs_at(parts["x"], u_nodes / sc.pressure_Pa, fns)
        outputs["dissipated_energy_J"] = parts["x"][:, -1] * sc.energy_J
        xc = parts["xc"].reshape(-1, parts["xc"].shape[-1])
        uc = np.array(tr.control_at_points(ca.DM(parts["u"].T))).ravel()
        outputs_points = {k: v.reshape(points.shape) for k, v in self.outputs_at(xc, uc, fns).items()}
        quad = tr.B[None, :] * tr.steps(T)[:, None]
        integrals = {key: float(np.sum(quad * outputs_points[key] ** 2))
                     for key in ("output_jerk_rad_s3", "slip_jerk_rad_s3")}
        states = {member: x_nodes[:, i] for i, name in enumerate(self._names) for member in self.state_groups[name]}
        return {"T": T, "t": t_offset + starts, "t_points": t_offset + points,
                "command_times": t_offset + command_times, "command": u_values, "outputs": outputs,
                "outputs_points": outputs_points, "states": states, "integrals": integrals,
                "x": parts["x"], "u": parts["u"]}

    def outputs_at(self, xs, us, fns=None, theta=None):
        """Physical outputs at scaled states ``xs`` (rows) and commands ``us`` of a phase (``fns``: its
        functions, default the slip phase's), at the parameter values ``theta`` (default
        :attr:`theta_value`): {output name: array}."""
        fns = fns or self.phase_functions["slip"]
        n = len(us)
        values = np.array(fns["outputs_fn"].map(n)(np.asarray(xs).T, np.asarray(us)[None, :],
                                                   *self._theta_columns(n, theta)))
        return {name: values[i] for i, name in enumerate(fns["output_names"])}

    def lockup_jump(self, xs, us, theta=None):
        """Locked minus slipping torque [N m] at the scaled end state ``xs`` and command ``us`` (slip phase),
        at the parameter values ``theta`` (default :attr:`theta_value`)."""
        return float(self.jump_fn(xs, us, *self._theta_columns(1, theta)))

    def _theta_columns(self, n, theta=None):
        """The parameter values as the extra input of the outputs and jump functions for ``n`` points
        (none without parameters)."""
        if not self.theta.numel():
            return []
        value = np.asarray(self.theta_value if theta is None else theta, float)
        return [np.repeat(value[:, None], n, axis=1)]

    # -- feasibility ----------------------------------------------------------------------------
    @property
    def declared_t_max(self):
        """The scene's own engagement-time budget, ``actuation.engagement_time_limit`` [s] (None if absent)."""
        return self.scene.get("actuation.engagement_time_limit")

    def default_t_max(self):
        """The scene's ``actuation.engagement_time_limit`` if it declares one; else the baseline's lock-up
        time (no slower than the scene's own profile), or 1.5 x the fastest lock-up if the baseline does not
        lock up or is itself the fastest lock-up (bao2020: the spring applies the clutch at once; no smooth
        lock-up can be as fast) [s]."""
        if self.declared_t_max is not None:
            return float(self.declared_t_max)
        t_lock = self.baseline.summary["engagement_time_s"]
        if t_lock is None or t_lock <= 1.001 * self.fastest_lockup():
            return 1.5 * self.fastest_lockup()
        return t_lock

    def default_t_max_source(self):
        """Where :meth:`default_t_max` comes from, in words (for progress lines and summary.json)."""
        if self.declared_t_max is not None:
            return "the scene's engagement-time budget (actuation.engagement_time_limit)"
        t_lock = self.baseline.summary["engagement_time_s"]
        if t_lock is None:
            return f"1.5 x the fastest lock-up (a step to {self.apply_label()}): the scene's own profile does not lock up"
        if t_lock <= 1.001 * self.fastest_lockup():
            return (f"1.5 x the fastest lock-up (a step to {self.apply_label()}): the scene's own profile locks up "
                    f"no later than that")
        return "the lock-up time of the scene's own profile"

    def fastest_run(self):
        """IDAS run of a step of the command to the pressure that applies the clutch hardest (cached):
        the pressure limit, or zero for a spring-applied piston (the pressure releases it)."""
        if self._fastest is None:
            t_end = self.scene.value("simulation.t_end")
            run = simulate_command(self.scene, [0.0], [self.apply_pressure], t_end, model=self.models.replay())
            if run.summary["engagement_time_s"] is None:
                capacity = holding_capacity(self.model, self.apply_pressure)[0]
                raise ModelError(f"scene '{self.scene.name}': even a step to {self.apply_label()} does not lock up "
                                 f"within simulation.t_end = {t_end:g} s (the pack holds {capacity:.4g} N m there, "
                                 f"the locked driveline needs {abs(self.lock_torque):.4g} N m); raise simulation.t_end "
                                 f"(--set simulation.t_end=...) or actuation.max_pressure")
            self._fastest = run
        return self._fastest

    @property
    def spring_applied(self):
        """True for a spring-applied piston (the pressure releases the clutch)."""
        return spring_applied(self.model)

    @property
    def apply_pressure(self):
        """Command that applies the clutch hardest [Pa]: 0 for a spring-applied piston, else the limit;
        where the contact cannot carry that at zero gap, the command whose settled plate pressure is the
        contact's at the film floor (:func:`~clutchocp.optimal.feasibility.usable_pressure`)."""
        return usable_pressure(self.model, self.p_max)

    def apply_label(self):
        """The command that applies the clutch hardest, in words (for messages)."""
        p = self.apply_pressure
        if self.spring_applied:
            return "zero pressure (spring-applied)" if p == 0.0 else \
                f"{p / 1e6:.4g} MPa (spring-applied; the contact carries no more at a positive film)"
        if p < self.p_max:
            return (f"{p / 1e6:.4g} MPa (the most the contact carries at a positive film; actuation.max_pressure "
                    f"= {self.p_max / 1e6:.4g} MPa)")
        return f"actuation.max_pressure = {self.p_max / 1e6:.4g} MPa"

    def fastest_lockup(self):
        """Lock-up time [s] of a step to :attr:`apply_pressure` (no command within the limits locks sooner)."""
        return self.fastest_run().summary["engagement_time_s"]

    def check_feasible_time(self, t_max, t_ref=None):
        """Raise ModelError if no command under the pressure limit locks up by ``t_max``.

        ``t_ref``: the lock-up time of the baseline [s] (default: the time scale, its lock-up time)."""
        t_ref = self.scales.time_s if t_ref is None else t_ref
        if t_max >= t_ref and self.baseline.summary["engagement_time_s"] is not None:
            return
        fastest = self.fastest_lockup()
        if t_max < fastest:
            field = "actuation.engagement_time_limit (or --t-max)" if t_max == self.declared_t_max else "--t-max"
            raise ModelError(f"scene '{self.scene.name}': t_max = {t_max:.4g} s is below the fastest lock-up the "
                             f"pressure limit allows: {field} must be at least {fastest:.4g} s for this clutch (a step "
                             f"to {self.apply_label()} locks up then), or raise actuation.max_pressure")


# What an IPOPT status means for the user (its own words stay out of the messages).
SOLVER_VERDICTS = {
    "Infeasible_Problem_Detected": "the solver ended at a point that breaks the end conditions or limits, a local "
                                   "verdict rather than a proof that none meets them",
    "Maximum_Iterations_Exceeded": "the solver did not converge within its iteration limit",
    "Invalid_Number_Detected": "the model gave an invalid number (NaN) at a trial point",
    "Restoration_Failed": "the solver could not get back to the end conditions and limits from a trial point",
    "Error_In_Step_Computation": "the solver could not compute a step (a singular or ill-scaled problem)",
    "Search_Direction_Becomes_Too_Small": "the solver stalled (its steps became too small)",
    "Diverging_Iterates": "the solver's iterates diverged",
    "User_Requested_Stop": "interrupted",
}


def solver_verdict(status):
    """What the solver's ``status`` means, in words (for messages)."""
    return SOLVER_VERDICTS.get(status, "the solver stopped without converging")


def _slip_rate(model):
    """d w_rel / dt in the slip mode of ``model`` (SX of the full state)."""
    mode = model.modes[SLIP_MODE]
    w_in, w_out = model.speeds()
    return ca.jtimes(w_in - w_out, model.x, ca.vertcat(*mode.ode))


def piston_outputs(model, mode_name):
    """The piston's outputs in a mode (SX): position, speed, spring force at p = 0 (Bao Eq. 21, signed)
    and pack force; none for a model without a piston."""
    if not model.has_piston:
        return {}
    mode = model.modes[mode_name]
    x0 = model.piston_position(mode_name.split("_")[0])
    return {"piston_position_m": x0, "piston_speed_m_s": model.state("v0"),
            "spring_force_N": model.drive_force(0.0, x0), "pack_force_N": mode.outputs["pack_force_N"]}
