"""Gain-scheduled speed controllers for the HVD, designed on exact linearisations.

At every scheduled speed of the spec the model is linearised (:mod:`clutchocp.hvd.linearize`),
discretised with a zero-order hold at the spec's sample time and a controller is designed:

* LQI: discrete LQR on the plant augmented with the integral of the speed error,
  xi[k+1] = xi[k] + Ts (r - w[k]); weights on deviations scaled by the rated speed, the valve
  pressure range and the film scale (Bryson's rule). Full state feedback: speed, valve pressure
  and film thickness (Cui measures the film through the piston displacement, Sec. 5).
* PI, ``method = "pole_placement"``: Skogestad's SIMC rules on a first-order-plus-delay model
  from the linear plant's time constants (half rule): k_p = tau / (K (tau_c + theta)),
  Ti = min(tau, 4 (tau_c + theta)), which puts the dominant closed-loop pole at -1/tau_c.
* PI, ``method = "loop_shaping"``: for a crossover frequency wc the integral time is
  Ti = N / wc (N = ``integral_ratio``) and the gain puts |L(e^{j wc Ts})| = 1; the fastest wc whose
  loop meets the phase margin, gain margin and sensitivity-peak targets is kept.

Both are written in one law (:class:`~clutchocp.hvd.controller.ScheduledController`)
u = u_op(r) + k_p e - K_x (x - x_op(r)) + I,  I[k+1] = I[k] + Ts k_i e[k],  e = r - w,
where u_op and x_op are the steady state at the reference (trim scheduling; u_op only with
``feedforward``). Margins are those of the loop broken at the plant input, computed by
python-control on the discrete loop; the PI targets of the spec are enforced.
"""

import warnings
from dataclasses import dataclass, field

import control
import numpy as np

from ..control.lqr import lqi
from ..errors import ModelError
from .controller import ScheduledController
from .linearize import SPEED_OUTPUT, describe, linearize
from .steady import operating_point, static_map


@dataclass
class DesignPoint:
    """The design at one scheduled speed."""

    fraction: float
    point: object                   # OperatingPoint
    plant: control.StateSpace       # continuous linear model (all inputs, speed output)
    plant_d: control.StateSpace     # discrete, full state output, input p_cmd
    K_x: np.ndarray                 # state-feedback gains [Pa per state unit]
    k_p: float                      # proportional gain on the speed error [Pa s/rad]
    k_i: float                      # integral gain [Pa/rad]
    loop: control.StateSpace        # discrete loop transfer broken at the plant input
    margins: dict = field(default_factory=dict)
    linear: dict = field(default_factory=dict)

    def closed_loop(self, Ts, feedforward_gain, state_per_speed):
        """Discrete closed loop reference -> speed at this point (linear, no saturation)."""
        Ad, Bd = self.plant_d.A, self.plant_d.B[:, :1]
        n = Ad.shape[0]
        C = np.zeros((1, n))
        C[0, 0] = 1.0
        K = (self.K_x + self.k_p * C).reshape(1, n)
        g = feedforward_gain + float(self.K_x @ state_per_speed) + self.k_p
        A = np.block([[Ad - Bd @ K, Bd], [-Ts * self.k_i * C, np.ones((1, 1))]])
        B = np.vstack([Bd * g, [[Ts * self.k_i]]])
        Cc = np.hstack([C, np.zeros((1, 1))])
        return control.ss(A, B, Cc, 0, dt=Ts, inputs=["speed_reference"], outputs=[SPEED_OUTPUT])


@dataclass
class ScheduledDesign:
    """All design points of a spec on a scene, and the controller that interpolates them."""

    spec: object
    model: object
    points: list
    controller: ScheduledController
    map_data: dict

    def worst_margins(self):
        """Smallest gain margin [dB] and phase margin [deg], largest sensitivity peak over the points."""
        gm = min(p.margins["gain_margin_dB"] for p in self.points)
        pm = min(p.margins["phase_margin_deg"] for p in self.points)
        ms = max(p.margins["sensitivity_peak"] for p in self.points)
        return {"gain_margin_dB": gm, "phase_margin_deg": pm, "sensitivity_peak": ms}


def pressure_limits(model, spec):
    """Valve limits: the scene's range, narrowed by the spec if it says so [Pa]."""
    lo = model.p_min if spec.pressure_min is None else max(model.p_min, spec.pressure_min)
    hi = model.p_max if spec.pressure_max is None else min(model.p_max, spec.pressure_max)
    for key, value, valve, outside in (("pressure_max", spec.pressure_max, model.p_max, lambda v: v > model.p_max),
                                       ("pressure_min", spec.pressure_min, model.p_min, lambda v: v < model.p_min)):
        if value is not None and outside(value):
            warnings.warn(f"controller.{key} = {value:g} Pa is outside the valve's range (hvd.{key} = {valve:g} Pa "
                          f"of scene '{model.scene.name}'); the valve's limit {valve:g} Pa is used", stacklevel=2)
    if lo >= hi:
        raise ModelError(f"controller pressure limits {lo:g}..{hi:g} Pa leave no range inside the valve range "
                         f"{model.p_min:g}..{model.p_max:g} Pa of the scene")
    return lo, hi


def design(model, spec, map_data=None):
    """Design the gain-scheduled controller of ``spec`` for the HVD ``model``.

    Parameters
    ----------
    model : HvdModel
    spec : ControllerSpec
    map_data : dict, optional
        Static map (computed if not given).

    Returns
    -------
    ScheduledDesign
    """
    data = map_data if map_data is not None else static_map(model)
    p_lo, p_hi = pressure_limits(model, spec)
    Ts = spec.sample_time
    points = []
    for frac in spec.schedule:
        op = operating_point(model, frac * model.rated_speed, map_data=data)
        if not p_lo <= op.pressure <= p_hi:
            raise ModelError(f"controller.schedule: {frac:g} x rated speed needs {op.pressure:.4g} Pa, outside the "
                             f"pressure limits {p_lo:g}..{p_hi:g} Pa; remove it from the schedule")
        plant = linearize(model, op)
        n = plant.nstates
        full = control.ss(plant.A, plant.B[:, :1], np.eye(n), np.zeros((n, 1)))
        plant_d = control.c2d(full, Ts, method="zoh")
        try:
            if spec.type == "lqi":
                K_x, k_p, k_i, loop = _lqi(model, spec, plant_d, p_lo, p_hi)
            else:
                K_x, k_p, k_i, loop = _pi(spec, plant_d, plant)
        except ModelError as exc:
            raise ModelError(f"at {frac:g} x rated speed: {exc}") from None
        dp = DesignPoint(frac, op, plant, plant_d, K_x, k_p, k_i, loop)
        dp.margins = loop_margins(loop)
        dp.linear = describe(plant)
        points.append(dp)
    controller = ScheduledController(
        speeds=np.array([p.point.speed for p in points]),
        u_op=np.array([p.point.pressure for p in points]),
        x_op=np.array([p.point.x for p in points]),
        K_x=np.array([p.K_x for p in points]),
        k_p=np.array([p.k_p for p in points]),
        k_i=np.array([p.k_i for p in points]),
        sample_time=Ts, p_min=p_lo, p_max=p_hi,
        anti_windup=spec.anti_windup["method"], tracking_time=spec.anti_windup["tracking_time"],
        reference_time_constant=spec.reference_time_constant, feedforward=spec.feedforward)
    return ScheduledDesign(spec, model, points, controller, data)


def state_scales(model, p_lo, p_hi):
    """Deviation scales of the states (rated speed, pressure range, film scale) for the weights."""
    return np.array([model.rated_speed, p_hi - p_lo] + [model.film_scale] * model.n_states_film)


def _lqi(model, spec, plant_d, p_lo, p_hi):
    """The spec's LQI on the discretised plant, weights on scaled deviations; returns (K_x, 0, k_i, loop)."""
    w = spec.lqi
    q = [w["speed_weight"], w["pressure_weight"]] + [w["film_weight"]] * model.n_states_film + [w["integral_weight"]]
    scales = np.append(state_scales(model, p_lo, p_hi), model.rated_speed * 1.0)
    Q = np.diag(np.asarray(q) / scales**2)
    R = np.array([[w["input_weight"] / (p_hi - p_lo) ** 2]])
    K_x, k_i, loop = lqi(plant_d.A, plant_d.B, spec.sample_time, Q, R)
    return K_x, 0.0, k_i, loop


def _pi_frequency(plant_d, theta):
    """P(e^{j theta}) of the discrete plant p_cmd -> w on a grid of normalised frequencies theta = w Ts."""
    siso = control.ss(plant_d.A, plant_d.B[:, :1], plant_d.C[:1, :], 0, dt=plant_d.dt)
    return frequency_response(siso, np.asarray(theta) / plant_d.dt)


def _grid_margins(L):
    """Gain margin [dB], phase margin [deg] and |1/(1+L)| peak from loop values on a frequency grid."""
    mag = np.abs(L)
    phase = np.unwrap(np.angle(L))
    cross = np.nonzero(np.diff(np.sign(mag - 1.0)))[0]
    pm = min((180.0 + np.degrees(phase[i])) % 360.0 for i in cross) if len(cross) else np.inf
    imag_cross = np.nonzero(np.diff(np.sign(L.imag)) != 0)[0]
    gm = min((-20 * np.log10(mag[i]) for i in imag_cross if L.real[i] < 0), key=abs, default=np.inf)
    ms = float(np.max(1.0 / np.abs(1.0 + L)))
    return abs(gm), pm, ms


def _pi(spec, plant_d, plant):
    """PI by loop shaping or pole placement (see the module docstring); returns (0, k_p, k_i, loop)."""
    Ts = spec.sample_time
    cfg = spec.pi
    n = plant_d.nstates
    dc = np.real(_pi_frequency(plant_d, np.array([0.0]))[0])
    sign = 1.0 if dc > 0 else -1.0
    if cfg["method"] == "pole_placement":
        unstable = [pole for pole in control.poles(plant) if pole.real >= 0]
        if unstable:
            raise ModelError(f"pi: pole placement (SIMC) needs a stable plant, but the linear model has the pole(s) "
                             f"{', '.join(f'{q:.3g}' for q in unstable)} 1/s here; use an LQI spec (state feedback)")
        tau, theta = _first_order_model(plant, Ts)
        tc = cfg["closed_loop_time_constant"]
        kp = tau / (dc * (tc + theta))                 # SIMC: closed-loop pole at -1/tc
        Ti = min(tau, 4 * (tc + theta))
        ki = kp / Ti
        loop = _pi_loop(plant_d, kp, ki, Ts)
        gm, pm, ms = _grid_margins(_loop_values(loop))
        if not (pm >= np.degrees(cfg["phase_margin"]) and gm >= cfg["gain_margin_dB"]
                and ms <= cfg["max_sensitivity"]):
            raise ModelError(f"pi: pole placement with pi.closed_loop_time_constant = "
                             f"{cfg['closed_loop_time_constant']:g} s gives phase margin {pm:.1f} deg, gain margin "
                             f"{gm:.1f} dB, sensitivity peak {ms:.2f}, short of the pi.* targets; lengthen it")
        return np.zeros(n), kp, ki, loop
    theta = np.geomspace(1e-6, np.pi, 4000)
    P = _pi_frequency(plant_d, theta)
    z = np.exp(1j * theta)
    best = None
    for wc in np.geomspace(1e-3, 0.5 * np.pi / Ts, 400):
        th = wc * Ts
        Ti = cfg["integral_ratio"] / wc
        zc = np.exp(1j * th)
        Pc = _pi_frequency(plant_d, np.array([th]))[0]
        kp = sign / abs(Pc * (1 + Ts / (Ti * (zc - 1))))
        ki = kp / Ti
        gm, pm, ms = _grid_margins((kp + ki * Ts / (z - 1)) * P)
        if pm >= np.degrees(cfg["phase_margin"]) and gm >= cfg["gain_margin_dB"] and ms <= cfg["max_sensitivity"]:
            loop = _pi_loop(plant_d, kp, ki, Ts)
            if np.all(np.abs(control.poles(control.feedback(loop, 1))) < 1):
                best = (kp, ki, loop)
    if best is None:
        raise ModelError(f"pi: no crossover meets phase margin {np.degrees(cfg['phase_margin']):.0f} deg, gain margin "
                         f"{cfg['gain_margin_dB']:g} dB and sensitivity peak {cfg['max_sensitivity']:g}; relax pi.*")
    kp, ki, loop = best
    return np.zeros(n), kp, ki, loop


def _first_order_model(plant, Ts):
    """First-order-plus-delay model (tau, theta) of p_cmd -> w by Skogestad's half rule [s].

    The plant has no zeros; its time constants are -1/p for real poles and 1/|p| (twice) for a
    complex pair. The largest, tau_1, plus half the second is tau; the other half, the rest and
    half a sample (zero-order hold) make the delay theta.
    """
    taus = []
    for pole in control.poles(plant):
        if pole.imag >= 0:
            taus += [-1.0 / pole.real] if abs(pole.imag) < 1e-12 else [1.0 / abs(pole)] * 2
    taus = sorted(taus, reverse=True)
    second = taus[1] if len(taus) > 1 else 0.0
    return taus[0] + second / 2, second / 2 + sum(taus[2:]) + Ts / 2


def _loop_values(loop, n=4000):
    theta = np.geomspace(1e-6, np.pi, n)
    return frequency_response(loop, theta / loop.dt)


def _pi_loop(plant_d, kp, ki, Ts):
    """Discrete loop C(z) P(z), C = kp + ki Ts / (z - 1) (forward-Euler integral, as implemented)."""
    siso = control.ss(plant_d.A, plant_d.B[:, :1], plant_d.C[:1, :], 0, dt=Ts)
    pi = control.ss([[1.0]], [[1.0]], [[ki * Ts]], [[kp]], dt=Ts)
    return control.series(siso, pi)


def frequency_response(sys, omega):
    """Values of a discrete SISO system at z = exp(j omega Ts) (vectorised) [complex]."""
    sys = sys if isinstance(sys, control.StateSpace) else control.ss(sys)
    A, B, C, D = (np.asarray(m, dtype=complex) for m in (sys.A, sys.B, sys.C, sys.D))
    z = np.exp(1j * np.asarray(omega, float) * sys.dt)
    n = A.shape[0]
    M = z[:, None, None] * np.eye(n) - A[None, :, :]
    X = np.linalg.solve(M, np.broadcast_to(B[:, :1], (z.size, n, 1)))
    return (C[:1, :] @ X)[:, 0, 0] + D[0, 0]


def loop_margins(loop, n_frequencies=4000):
    """Margins of a discrete loop (negative feedback), by python-control on a dense frequency grid.

    The loop's frequency response up to the Nyquist frequency is handed to
    ``control.stability_margins`` as (mag, phase, omega), which finds every crossover on it; the
    Nyquist frequency itself (z = -1, where L is real) is checked for a phase crossover too.

    Returns
    -------
    dict: ``gain_margin_dB`` (smallest |margin| over all phase crossovers, up or down; inf if
    none), ``phase_margin_deg`` (smallest over all gain crossovers), ``sensitivity_peak``
    (max |1/(1+L)| on the grid), ``crossover_rad_s`` (lowest gain crossover), ``stable``
    (closed-loop poles inside the unit circle).
    """
    omega = np.geomspace(1e-4, np.pi / loop.dt, n_frequencies)
    L = frequency_response(loop, omega)
    mag, phase = np.abs(L), np.unwrap(np.angle(L))
    gm, pm, _, _, wgc, _ = control.stability_margins((mag, np.degrees(phase), omega), returnall=True)
    gm_db = [abs(20 * np.log10(g)) for g in np.atleast_1d(gm) if np.isfinite(g) and g > 0]
    if L[-1].real < 0:                                       # phase crossover at the Nyquist frequency
        gm_db.append(abs(20 * np.log10(mag[-1])))
    pms = [abs(p) for p in np.atleast_1d(pm) if np.isfinite(p)]
    stable = bool(np.all(np.abs(control.poles(control.feedback(loop, 1))) < 1))
    return {
        "gain_margin_dB": float(min(gm_db)) if gm_db else float("inf"),
        "phase_margin_deg": float(min(pms)) if pms else float("inf"),
        "sensitivity_peak": float(np.max(1.0 / np.abs(1.0 + L))),
        "crossover_rad_s": float(min(np.atleast_1d(wgc))) if np.size(wgc) else 0.0,
        "stable": stable,
    }
