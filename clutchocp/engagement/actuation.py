"""The engagement pressure part: a prescribed profile p(t), or a valve lag whose output is a state."""

import csv

import casadi as ca
import numpy as np

from ..errors import SceneError


def read_table(path, field):
    """Read a two-column CSV (x, y) with an optional header; x must increase."""
    rows = []
    with open(path, newline="", encoding="utf-8") as handle:
        for row in csv.reader(handle):
            if not row or row[0].strip().startswith("#"):
                continue
            try:
                rows.append((float(row[0]), float(row[1])))
            except (ValueError, IndexError):
                if rows:
                    raise SceneError(f"{field}: line '{','.join(row)}' of {path} is not two numbers") from None
    data = np.array(rows)
    if len(data) < 2 or np.any(np.diff(data[:, 0]) <= 0) or not np.all(np.isfinite(data)):
        raise SceneError(f"{field}: {path} needs at least two rows with strictly increasing first column")
    return data


class Actuation:
    """Engagement pressure from the scene's [actuation] part.

    Publishes ``command(t)`` (the set pressure as a function of time, or a control symbol) and
    ``pressure(t, p_state)``.
    The ``valve_lag`` variant adds one state, the valve output pressure, with
    dp/dt = (command - p) / time_constant; the others have no state.
    """

    def __init__(self, scene, command=None):
        self.variant = scene.variant("actuation")
        self.control = command
        self.p_set = scene.value("actuation.pressure")
        self.p_initial = scene.value("actuation.initial_pressure")
        self.t_start = scene.value("actuation.t_start")
        self.time_constant = scene.get("actuation.time_constant")
        self.ramp_time = scene.get("actuation.ramp_time")
        self.table = None
        if self.variant == "table":
            self.table = read_table(scene.value("actuation.file"), "actuation.file")
        self.has_state = self.variant == "valve_lag"

    def command(self, t):
        """Commanded (or prescribed) pressure [Pa] at time t (SX or float).

        With a ``command`` symbol given to the constructor (the control of an optimal-control
        problem), that symbol is the command and the scene's profile is not used.
        """
        if self.control is not None:
            return self.control
        dp = self.p_set - self.p_initial
        tau = t - self.t_start
        on = ca.if_else(tau >= 0, 1.0, 0.0)
        if self.variant in ("step", "valve_lag"):
            return self.p_initial + dp * on
        if self.variant == "ramp":
            return self.p_initial + dp * ca.fmin(ca.fmax(tau / self.ramp_time, 0.0), 1.0)
        if self.variant == "first_order_lag":
            # Zhang 2021 Eq. 7: P_s = P_o (1 - exp(-t / t_s))
            return self.p_initial + dp * on * (1 - ca.exp(-ca.fmax(tau, 0.0) / self.time_constant))
        interp = ca.interpolant("pressure_table", "linear", [self.table[:, 0]], self.table[:, 1])
        t_clamped = ca.fmin(ca.fmax(t, self.table[0, 0]), self.table[-1, 0])
        return interp(t_clamped)

    def pressure(self, t, p_state=None):
        """Pressure acting on the piston or pack [Pa]."""
        return p_state if self.has_state else self.command(t)

    def state_rate(self, t, p_state):
        """dp/dt of the valve-lag state [Pa/s]."""
        return (self.command(t) - p_state) / self.time_constant

    def breakpoints(self):
        """Times at which the profile has a kink or jump (the integrator restarts there) [s]."""
        points = {self.t_start}
        if self.variant == "ramp":
            points.add(self.t_start + self.ramp_time)
        if self.variant == "table":
            points.update(self.table[:, 0].tolist())
        return sorted(p for p in points if p > 0)
