"""Kinematic lower bound of the jerk integral of an engagement.

Whatever the clutch physics, the slip speed y(t) = w_rel(t) of an engagement that locks at T starts
from its value y0 and rate v0 and ends at y(T) = 0 with the rate v1 of the locked driveline (v1 = 0:
both sides turn together). Among all smooth y with these four end values, the integral

    J[y] = int_0^T y''(t)^2 dt

is smallest for a cubic. Derivation: for a perturbation e(t) with e = e' = 0 at both ends,
dJ = 2 int y'' e'' dt = 2 int y'''' e dt (integrating by parts twice), so the minimiser has y'''' = 0.
Write y = y0 + v0 t + a t^2 + b t^3; the end conditions

    a T^2 + b T^3 = A := y1 - y0 - v0 T,      2 a T + 3 b T^2 = Bv := v1 - v0

give a = 3 A / T^2 - Bv / T and b = Bv / T^2 - 2 A / T^3, and

    J_min = int_0^T (2 a + 6 b t)^2 dt = 4 a^2 T + 12 a b T^2 + 12 b^2 T^3
          = 12 (D - T (v0 + v1) / 2)^2 / T^3 + (v1 - v0)^2 / T,     D = y1 - y0,

which for y1 = v1 = 0 is 4 (3 y0^2 + 3 y0 v0 T + v0^2 T^2) / T^3. No pressure profile can beat it,
so J / J_min >= 1 measures how much of the jerk is due to the clutch physics and the limits.

With constant input and load torques the output jerk is a fixed share of the slip jerk:
w_rel'' = -T_c' (1/I_in + 1/I_out) and a_out' = T_c' / I_out, so a_out' = -s w_rel'' with
s = I_in / (I_in + I_out) (s = 1 for a prescribed input speed, 0 for a held output).
"""

import numpy as np

from ..errors import ModelError


def minimum_jerk_coefficients(y0, v0, T, y1=0.0, v1=0.0):
    """Coefficients (a, b) of the minimising cubic y = y0 + v0 t + a t^2 + b t^3.

    Parameters
    ----------
    y0, v0 : float
        Initial slip speed [rad/s] and its rate [rad/s^2].
    T : float
        Engagement time [s] (> 0).
    y1, v1 : float
        Final slip speed [rad/s] and rate [rad/s^2] (0 and 0 at lock-up).

    Returns
    -------
    a [rad/s^3], b [rad/s^4]
    """
    if not (np.isfinite(T) and T > 0):
        raise ModelError(f"engagement time T = {T!r}: must be a positive time [s]")
    A = y1 - y0 - v0 * T
    Bv = v1 - v0
    return 3 * A / T**2 - Bv / T, Bv / T**2 - 2 * A / T**3


def jerk_lower_bound(y0, v0, T, y1=0.0, v1=0.0):
    """Smallest int_0^T (d^2 w_rel / dt^2)^2 dt of any smooth slip history [rad^2/s^5].

    Parameters
    ----------
    y0, v0 : float
        Initial slip speed w_rel(0) [rad/s] and rate dw_rel/dt(0) [rad/s^2].
    T : float
        Engagement time [s].
    y1, v1 : float
        Final slip speed and rate (lock-up: 0, and the locked driveline's 0).

    Returns
    -------
    float
        ``12 (D - T (v0 + v1)/2)^2 / T^3 + (v1 - v0)^2 / T`` with D = y1 - y0.
    """
    if not (np.isfinite(T) and T > 0):
        raise ModelError(f"engagement time T = {T!r}: must be a positive time [s]")
    D = y1 - y0
    return 12.0 * (D - T * (v0 + v1) / 2) ** 2 / T**3 + (v1 - v0) ** 2 / T


def minimum_jerk_slip(t, y0, v0, T, y1=0.0, v1=0.0):
    """The minimising slip history and its second derivative at times t (0 <= t <= T).

    Returns
    -------
    y [rad/s], y'' [rad/s^3] : ndarray
    """
    a, b = minimum_jerk_coefficients(y0, v0, T, y1, v1)
    t = np.asarray(t, dtype=float)
    return y0 + v0 * t + a * t**2 + b * t**3, 2 * a + 6 * b * t


def output_jerk_share(scene):
    """s with output jerk = -s * slip jerk under constant torques [-] (see the module notes)."""
    if scene.value("driveline.output") == "fixed":
        return 0.0
    if scene.value("driveline.input") != "inertia":
        return 1.0
    I_in, I_out = scene.value("driveline.input_inertia"), scene.value("driveline.output_inertia")
    return I_in / (I_in + I_out)
