"""The whole usable curve: after lock-up, a ramp to the clamp pressure that holds the lock, and hold.

An engagement command ends at lock-up. A transmission controller then raises the pressure to a
clamp level whose static torque capacity carries the locked torque with a margin, and holds it.
The clamp pressure p_c solves

    capacity(p_c) = margin x T_locked,

capacity(p) being the static capacity sum_i mu_s F_c,i(h_i*) r_eff of the pack once its films have
settled under the command p (every film rate zero: the face force is carried by the asperities and
the static fluid load, see :meth:`clutchocp.engagement.films.FilmLaw.load_coefficients`), and
T_locked the torque the locked driveline carries (:meth:`EngagementModel.locked_torque`).

The default margin 1.3 covers a friction coefficient 10 % below the model's together with a locked
torque 15 % above it (1.15 / 0.9 = 1.28): the spread of mu with temperature and wear and of the load
that the robust feedforward is designed for. A larger margin costs only hydraulic power; a margin
below 1 does not hold the lock.

The command ramps from its value at lock-up to p_c at the rate limit (default: the pressure limit
per 10 ms, as the optimisation's) and holds p_c; the curve is piecewise linear between its points.
"""

from dataclasses import dataclass

import casadi as ca
import numpy as np
from scipy import optimize

from ..engagement.edges import zero_gap_pressure
from ..engagement.model import EngagementModel
from ..errors import ModelError
from .feasibility import hardest_command, lock_state, plate_force, spring_applied, usable_pressure

DEFAULT_MARGIN = 1.3
LOCKED_MODE = "pressing_locked"


def check_margin(margin):
    """The margin as a float; a value that is not a number >= 1 raises ModelError."""
    try:
        value = float(margin)
    except (TypeError, ValueError):
        raise ModelError(f"clamp margin {margin!r}: must be a number >= 1 (static capacity / locked torque)") from None
    if not (np.isfinite(value) and value >= 1.0):
        raise ModelError(f"clamp margin {margin!r}: must be a number >= 1 (static capacity / locked torque)")
    return value


@dataclass
class ClampedCommand:
    """A command continued after lock-up: unpacks as ``times, pressures = ...``.

    ``times`` [s] and ``pressures`` [Pa] are piecewise linear between the points and the last value
    holds afterwards; the ramp to ``clamp_pressure_Pa`` runs from ``ramp_start_s`` (lock-up) to
    ``ramp_end_s`` at ``rate_limit_Pa_s``; ``margin`` = settled static capacity / ``locked_torque_Nm``
    (None for a clamp pressure given rather than sized: a lock that carries no torque).
    """

    times: np.ndarray
    pressures: np.ndarray
    clamp_pressure_Pa: float
    margin: float | None
    locked_torque_Nm: float
    ramp_start_s: float
    ramp_end_s: float
    rate_limit_Pa_s: float

    def __iter__(self):
        return iter((self.times, self.pressures))

    @property
    def basis(self):
        """How the clamp pressure was chosen (for progress lines and legends)."""
        if self.margin is None:
            return "holding pressure: the lock carries no torque"
        return f"capacity {self.margin:g} x the locked torque"


class ClampModel:
    """Static capacity of a scene's pack against the settled command pressure, and the locked torque.

    Parameters
    ----------
    scene : clutchocp.scene.Scene
        An engagement scene with a massless pack (``pack.model = "massless"``). With a piston the
        settled pack also has the piston at rest on it (v0 = 0, its acceleration zero: pressure force
        minus return spring equals the face force).
    model, command : EngagementModel, casadi.SX, optional
        The exact model of ``scene`` already built with ``pressure_command=command`` (default: built here).
    """

    def __init__(self, scene, model=None, command=None):
        if scene.variant("pack") != "massless":
            raise ModelError("clamp pressure: computed for a massless pack (pack.model = 'massless')")
        if model is None:
            command = ca.SX.sym("command")
            model = EngagementModel(scene, smooth=False, pressure_command=command)
        u = command
        self.model = model
        mode = model.modes[LOCKED_MODE]
        self.films = [model.index[f"h_{i + 1}"] for i in range(model.n)]
        x = model.x
        if model.actuation.has_state:            # settled valve: its pressure is the command
            x = ca.substitute(x, model.state("p_valve"), u)
        rates = ca.vertcat(*[mode.ode[i] for i in self.films])
        self.x_lock = lock_state(model)                     # both sides at the lock-up speed
        self.piston = model.has_piston
        if self.piston:
            # the piston at rest: with v0 = 0 the film rates of equal films vanish for any thickness,
            # and its acceleration (pressure force - return spring - face force) / m is what settles;
            # scaled to a force fraction of the largest pressure force
            i_v0 = model.index["v0"]
            force = scene.value("piston.mass") / (scene.value("piston.area") * scene.get("actuation.max_pressure", 1e6))
            rates = ca.vertcat(mode.ode[i_v0] * force * (model.H0 / 0.01), rates)
            self.x_lock[i_v0] = 0.0
        self.n_rates = rates.numel()                     # the residual rows; then capacity and pressure
        outputs = [mode.outputs["static_capacity_Nm"], mode.outputs["pressure_Pa"]]
        self._fn = ca.Function("clamp", [model.x, u], [ca.substitute(ca.vertcat(rates, *outputs), model.x, x)])
        self._locked = ca.Function("locked", [model.x], [model.locked_torque()])
        self.p_max = scene.get("actuation.max_pressure")

    def locked_torque(self, state=None):
        """Torque the locked driveline carries [N m] (at ``state``, default: both sides at the output speed)."""
        return float(self._locked(self.x_lock if state is None else state))

    def settled_films(self, pressure):
        """Film thicknesses [m] at which every film rate vanishes under the command ``pressure`` [Pa]."""
        model = self.model
        H0 = model.H0
        n_rates = self.n_rates

        def residual(h):
            x = self.x_lock.copy()
            x[self.films] = h
            return np.array(self._fn(x, pressure)).ravel()[:n_rates] / (H0 / 0.01)

        # All films carry the same face force: solve one film first (bisection on a bracket),
        # then all of them together from there.
        def first(h):
            return residual(np.full(len(self.films), h))[0]

        lo, hi = 1e-3 * model.sigma, H0
        if first(lo) * first(hi) > 0:
            contact = zero_gap_pressure(model.film)
            raise ModelError(f"clamp pressure: {pressure / 1e6:.4g} MPa presses the pack with "
                             f"{plate_force(model, pressure) / model.film.area / 1e6:.4g} MPa, which no film between "
                             f"{lo:.3g} and {hi:.3g} m carries (the contact carries at most {contact / 1e6:.4g} MPa "
                             "at zero gap)")
        h0 = optimize.brentq(first, lo, hi, xtol=1e-15, rtol=1e-13)
        sol = optimize.least_squares(residual, np.full(len(self.films), h0), x_scale=model.sigma, xtol=1e-15,
                                     ftol=1e-15, gtol=1e-15)
        return sol.x

    def capacity(self, pressure):
        """Static capacity [N m] of the settled pack under the command ``pressure`` [Pa]."""
        x = self.x_lock.copy()
        x[self.films] = self.settled_films(pressure)
        return float(np.array(self._fn(x, pressure)).ravel()[self.n_rates])

    def pressure_range(self):
        """Commands that press the settled pack [Pa], from the one that presses it least to the one that
        presses it hardest: a pressure-applied piston from just above its kiss pressure (without a piston
        from 1e-6 of the limit) to the limit; a spring-applied one from just below the pressure that
        releases it down to zero. Either end is capped where the contact could not carry the pack's
        pressure at a positive film (:func:`~clutchocp.optimal.feasibility.usable_pressure`)."""
        model, p_max = self.model, self.p_max
        hardest = usable_pressure(model, p_max)
        F0, slope = plate_force(model, 0.0), plate_force(model, 1.0) - plate_force(model, 0.0)
        if spring_applied(model):
            return min(0.99 * (-F0 / slope), p_max), hardest        # slope < 0: the pressure releases the pack
        least = 1e-6 * p_max
        if self.piston and self.model.travel > 0:     # below the kiss pressure the piston does not press the pack
            least = max(least, 1.01 * (-F0 / slope))
        return least, hardest

    def largest_margin(self, locked_torque=None):
        """Settled static capacity at the command that presses the pack hardest over the locked torque [-]."""
        demand = abs(self.locked_torque() if locked_torque is None else float(locked_torque))
        return self.capacity(self.pressure_range()[1]) / demand

    def clamp_pressure(self, margin=DEFAULT_MARGIN, locked_torque=None):
        """Command pressure [Pa] whose settled capacity is ``margin`` x the locked torque.

        Raises
        ------
        ModelError
            The pressure limit cannot give that capacity.
        """
        margin = check_margin(margin)
        demand = abs(self.locked_torque() if locked_torque is None else float(locked_torque))
        target = margin * demand
        if self.p_max is None:
            raise ModelError("actuation.max_pressure: the clamp pressure needs an upper pressure limit")
        least, hardest = self.pressure_range()
        top = self.capacity(hardest)
        if top < target:
            if hardest != hardest_command(self.model, self.p_max):
                why, fix = ("the most the contact carries at a positive film", "raise roughness.sigma_*, "
                            "roughness.asperity_density or contact.E_equiv")
            elif spring_applied(self.model):
                why, fix = "zero pressure, the springs alone", "raise piston.spring_preload"
            else:
                why, fix = "the pressure limit", "raise actuation.max_pressure"
            raise ModelError(f"clamp margin {margin:g}: the pack's static capacity at {hardest / 1e6:.4g} MPa ({why}) "
                             f"is {top:.4g} N m, {top / demand:.4g} x the locked torque {demand:.4g} N m; "
                             f"--clamp-margin must be at most {np.floor(top / demand * 1000) / 1000:.3f} for this "
                             f"clutch, or {fix}")
        if self.capacity(least) >= target:
            return least
        return optimize.brentq(lambda p: self.capacity(p) - target, min(least, hardest), max(least, hardest),
                               xtol=1e-6, rtol=1e-12)


def extend_to_clamp(scene, command_times, command, t_lock, *, margin=DEFAULT_MARGIN, rate_limit=None,
                    locked_torque=None, clamp_pressure=None, model=None):
    """The engagement command up to lock-up continued by a ramp to the clamp pressure.

    Parameters
    ----------
    scene : clutchocp.scene.Scene
    command_times, command : array
        Nodes of the piecewise-linear engagement command [s], [Pa] (it may go on past t_lock).
    t_lock : float
        Lock-up time [s].
    margin : float
        Static torque capacity at the clamp pressure over the locked torque (>= 1).
    rate_limit : float, optional
        Ramp rate [Pa/s] (default: actuation.max_pressure per 10 ms, the optimisation's default).
    locked_torque : float, optional
        Torque the locked driveline carries [N m] (default: from the model, both sides at the output speed).
    clamp_pressure : float, optional
        The pressure to ramp to [Pa], given instead of sized by ``margin``: for a lock that carries no
        torque (a brake with its output held, a prescribed input speed without load), which no
        capacity margin can size; the ClampedCommand's margin is then None.
    model : ClampModel, optional
        The clamp model of ``scene`` already built.

    Returns
    -------
    ClampedCommand
        Unpacks as ``times, pressures`` (piecewise linear between the points, the last value held
        afterwards); also holds the clamp pressure, margin, locked torque and the ramp.
    """
    margin = check_margin(margin)
    times, values = np.asarray(command_times, float), np.asarray(command, float)
    if times.size != values.size or times.size < 1 or np.any(np.diff(times) <= 0):
        raise ModelError("command: increasing times with one value each are needed")
    if not (np.isfinite(t_lock) and times[0] < t_lock):
        raise ModelError(f"t_lock = {t_lock!r}: must be a time after the command starts [s]")
    if clamp_pressure is None:
        clamp = ClampModel(scene) if model is None else model
        p_c, p_max = clamp.clamp_pressure(margin, locked_torque), clamp.p_max
        demand = abs(clamp.locked_torque() if locked_torque is None else float(locked_torque))
    else:           # nothing to size: no clamp model (any pack)
        p_c, p_max = float(clamp_pressure), scene.get("actuation.max_pressure")
        demand = abs(float(locked_torque or 0.0))
    if rate_limit is None and p_max is None:
        raise ModelError("actuation.max_pressure: the clamp ramp's default rate (the limit per 10 ms) needs it")
    rate = p_max / 0.01 if rate_limit is None else float(rate_limit)
    if not (np.isfinite(rate) and rate > 0):
        raise ModelError(f"rate_limit = {rate_limit!r}: must be a positive rate [Pa/s]")
    keep = times < t_lock
    p_lock = float(np.interp(t_lock, times, values))
    t_end = t_lock + abs(p_c - p_lock) / rate
    out_t = np.concatenate([times[keep], [t_lock], [t_end] if t_end > t_lock else []])
    out_p = np.concatenate([values[keep], [p_lock], [p_c] if t_end > t_lock else []])
    return ClampedCommand(out_t, out_p, p_c, margin if clamp_pressure is None else None, demand, float(t_lock),
                          float(t_end), rate)
