"""The discrete-time, gain-scheduled speed controller with pressure limits and anti-windup.

The setpoint r_set first passes a critically damped second-order filter (two first-order
stages with time constant T_r, discretised exactly), which gives the reference r that the
feedback follows (two-degree-of-freedom control: steps of the setpoint do not kick the command);
T_r = 0 passes the setpoint through. At each sample k (period Ts), with reference r, measured
state x (speed first) and e = r - w:

    u_unsat = u_op(r) + k_p(r) e - K_x(r) . (x - x_ref(r)) + I        (u_op only with feedforward)
    u       = min(max(u_unsat, p_min), p_max)
    I      <- I + Ts k_i(r) e + (Ts / T_t)(u - u_unsat)        ("back_calculation")

u_op, x_op and the gains are interpolated linearly between the scheduled speeds (held constant
outside them); x_ref is x_op with its speed replaced by r. ``"clamping"`` anti-windup stops
integrating while the command is saturated and the error would drive it further;
``"none"`` always integrates. The integral I is kept in pressure units, so changing gains
does not bump the command.
"""

import numpy as np

from ..errors import ModelError


class ScheduledController:
    """Discrete gain-scheduled controller (see the module docstring).

    Parameters
    ----------
    speeds : array (m,)
        Scheduled output speeds, increasing [rad/s].
    u_op : array (m,)
        Steady pressure at each speed [Pa].
    x_op : array (m, n)
        Steady state at each speed.
    K_x : array (m, n)
        State-feedback gains.
    k_p, k_i : array (m,)
        Proportional [Pa s/rad] and integral [Pa/rad] gains on the speed error.
    sample_time : float
        Ts [s].
    p_min, p_max : float
        Command limits [Pa].
    anti_windup : {"back_calculation", "clamping", "none"}
    tracking_time : float
        T_t of back-calculation [s].
    reference_time_constant : float
        T_r of the setpoint filter [s] (0: no filter).
    feedforward : bool
        Add the scheduled steady pressure u_op(r) (else the integral carries it).
    """

    def __init__(self, speeds, u_op, x_op, K_x, k_p, k_i, sample_time, p_min, p_max,
                 anti_windup="back_calculation", tracking_time=None, reference_time_constant=0.0,
                 feedforward=True):
        self.speeds = np.asarray(speeds, float)
        if self.speeds.ndim != 1 or np.any(np.diff(self.speeds) <= 0):
            raise ModelError("ScheduledController: scheduled speeds must increase strictly")
        self.u_op = np.asarray(u_op, float)
        self.x_op = np.atleast_2d(np.asarray(x_op, float))
        self.K_x = np.atleast_2d(np.asarray(K_x, float))
        self.k_p = np.asarray(k_p, float)
        self.k_i = np.asarray(k_i, float)
        self.Ts = float(sample_time)
        self.p_min, self.p_max = float(p_min), float(p_max)
        if anti_windup not in ("back_calculation", "clamping", "none"):
            raise ModelError(f"anti_windup = {anti_windup!r}: allowed values are back_calculation, clamping, none")
        self.anti_windup = anti_windup
        self.tracking_time = float(tracking_time) if tracking_time else 10 * self.Ts
        self.reference_time_constant = float(reference_time_constant)
        self.feedforward = bool(feedforward)
        # exact discretisation of one first-order stage: y+ = a y + (1 - a) x
        self._a = float(np.exp(-self.Ts / self.reference_time_constant)) if self.reference_time_constant > 0 else 0.0
        self.reset()

    def reset(self, setpoint=0.0, x=None, pressure=None):
        """Start: setpoint-filter states at ``setpoint`` [rad/s]; I = 0, or, given the state x and
        the valve pressure, the I that makes the first command equal that pressure (bumpless)."""
        self._filter = [float(setpoint), float(setpoint)]
        self.integral = 0.0
        if x is not None and pressure is not None:
            self.integral = float(pressure) - self.command(setpoint, x)[1]

    def reference(self, setpoint):
        """The filtered reference for this sample (the filter advances in :meth:`step`) [rad/s]."""
        return self._filter[1] if self._a else float(setpoint)

    def _advance_filter(self, setpoint):
        a = self._a
        first = a * self._filter[0] + (1 - a) * setpoint
        second = a * self._filter[1] + (1 - a) * self._filter[0]
        self._filter = [first, second]

    def _interp(self, r, table):
        if table.ndim == 1:
            return float(np.interp(r, self.speeds, table))
        return np.array([np.interp(r, self.speeds, table[:, j]) for j in range(table.shape[1])])

    def schedule_slopes(self, r):
        """(du_op/dr, dx_op/dr) of the interpolated trim at r, on the interval above r (below at the top)."""
        j = int(np.clip(np.searchsorted(self.speeds, r, side="right") - 1, 0, len(self.speeds) - 2))
        dr = self.speeds[j + 1] - self.speeds[j]
        du = (self.u_op[j + 1] - self.u_op[j]) / dr if self.feedforward else 0.0
        return du, (self.x_op[j + 1] - self.x_op[j]) / dr

    def command(self, setpoint, x):
        """(u, u_unsat) for the setpoint [rad/s] and state x, without updating I or the filter."""
        r = self.reference(setpoint)
        x = np.asarray(x, float)
        e = r - x[0]
        x_ref = self._interp(r, self.x_op)
        x_ref[0] = r
        u_ff = self._interp(r, self.u_op) if self.feedforward else 0.0
        u_unsat = (u_ff + self._interp(r, self.k_p) * e
                   - float(self._interp(r, self.K_x) @ (x - x_ref)) + self.integral)
        return min(max(u_unsat, self.p_min), self.p_max), u_unsat

    def step(self, setpoint, x):
        """Command for this sample; updates the integral and the filter for the next one. Returns u [Pa]."""
        u, u_unsat = self.command(setpoint, x)
        r = self.reference(setpoint)
        e = r - float(x[0])
        increment = self.Ts * self._interp(r, self.k_i) * e
        if self.anti_windup == "back_calculation":
            increment += self.Ts / self.tracking_time * (u - u_unsat)
        elif self.anti_windup == "clamping" and u != u_unsat and np.sign(increment) == np.sign(u_unsat - u):
            increment = 0.0
        self.integral += increment
        self._advance_filter(setpoint)
        return u

    def saturated(self, u):
        """True if the command u sits on a limit."""
        return u <= self.p_min or u >= self.p_max
