"""Friction-coefficient laws for the asperity (contact) friction of a wet clutch.

All SI at the interface (slip speed in m/s, pressure in Pa, temperature in deg C where a
seed fits it so); every function accepts floats, numpy arrays and CasADi SX/MX.  The laws
return the magnitude of the coefficient; the torque carries the sign of the slip.
"""

import math

import numpy as np

from ..errors import PhysicalRangeError
from .backend import exp, fabs, is_symbolic, log, sqrt

__all__ = ["mu_constant", "mu_stribeck", "mu_chen2021", "mu_cui2019"]

_PA_PER_MPA = 1e6


def _speed_magnitude(v, smooth, v_smooth):
    """|v|, or its smooth form sqrt(v^2 + v_smooth^2) (error <= v_smooth, 0.5 v_smooth^2/|v| far out)."""
    return sqrt(v**2 + v_smooth**2) if smooth else fabs(v)


def mu_constant(mu, v=None):
    """Constant friction coefficient.

    Parameters
    ----------
    mu : friction coefficient [-].
    v : slip speed [m/s], optional; if given the result has its shape.

    Returns
    -------
    mu [-].
    """
    return mu if v is None else mu + 0 * v


def mu_stribeck(v, mu_static, mu_kinetic, v_stribeck, exponent=2.0, viscous=0.0,
                smooth=False, v_smooth=None):
    """Stribeck curve ``mu_k + (mu_s - mu_k) exp(-(|v|/v_s)^exponent) + viscous |v|``.

    Parameters
    ----------
    v : slip speed [m/s] (either sign).
    mu_static : coefficient at zero slip [-].
    mu_kinetic : coefficient at large slip without the viscous term [-].
    v_stribeck : Stribeck speed [m/s].
    exponent : shape exponent of the decay [-] (2 = Gaussian, 1 = exponential).
    viscous : slope of the viscous rise [s/m].
    smooth : bool
        False (default): exact ``|v|``.  True: ``|v|`` -> ``sqrt(v^2 + v_smooth^2)``, so the
        law is smooth at v = 0 for any exponent (with exponent = 2 and viscous = 0 the exact
        form is already smooth).
    v_smooth : smoothing speed [m/s]; default 1e-3 v_stribeck.

    Returns
    -------
    mu [-]; mu(0) = mu_static, mu -> mu_kinetic + viscous |v| for |v| >> v_stribeck.
    """
    if v_smooth is None:
        v_smooth = 1e-3 * v_stribeck
    speed = _speed_magnitude(v, smooth, v_smooth)
    decay = exp(-((speed / v_stribeck) ** exponent))
    return mu_kinetic + (mu_static - mu_kinetic) * decay + viscous * speed


# Chen 2021 Eq. 5 is fitted with p in MPa; its first term's denominator changes sign at
# Theta = e^3.2 = 24.5 degC and at 28.3 p = 0.87^2.5, i.e. p = 25.0 kPa.
CHEN_THETA_MIN = math.exp(3.2)                      # [degC]
CHEN_P_MIN = 0.87**2.5 / 28.3 * _PA_PER_MPA         # [Pa]


def mu_chen2021(v, p, theta, smooth=False, v_smooth=1e-3):
    """Friction coefficient of copper-based sintered lining in oil (Chen 2021 Eq. 5).

    Parameters
    ----------
    v : slip (sliding) speed [m/s]; its magnitude is used.
    p : average contact pressure [Pa] (converted to MPa, the unit of the fit).
    theta : surface temperature [deg C].
    smooth : bool
        False (default): exact ``|v|`` (the law has a nonzero slope at v = 0, so |v| kinks
        there).  True: ``|v|`` -> ``sqrt(v^2 + v_smooth^2)``.
    v_smooth : smoothing speed [m/s] (smooth form only).

    Returns
    -------
    mu [-]; about 0.08 (0.2 MPa) to 0.07 (2 MPa) at Chen's 18.2 m/s and 100 degC.

    Raises
    ------
    PhysicalRangeError
        For numeric input outside the fit's domain, p <= 25.0 kPa or theta <= 24.5 degC,
        where the first term's exponent changes sign and mu explodes.  Symbolic input is
        not checked: pass e.g. ``fmax(p, 0.05e6)`` if the pressure can vanish.

    Notes
    -----
    The seed's "ln ⊖" is ln Theta (an OCR glyph).
    """
    if not is_symbolic(v, p, theta):
        if np.any(np.asarray(p) <= CHEN_P_MIN):
            raise PhysicalRangeError(
                f"mu_chen2021 pressure: must be > {CHEN_P_MIN:.4g} Pa (Chen 2021 Eq. 5 fit domain)")
        if np.any(np.asarray(theta) <= CHEN_THETA_MIN):
            raise PhysicalRangeError(
                f"mu_chen2021 temperature: must be > {CHEN_THETA_MIN:.4g} degC (Chen 2021 Eq. 5 fit domain)")
    speed = _speed_magnitude(v, smooth, v_smooth)
    p_mpa = p / _PA_PER_MPA
    # Chen 2021 Eq. 5, term by term
    stick = 23 * exp(-2.6 * speed / ((log(theta) - 3.2) * ((28.3 * p_mpa) ** 0.4 - 0.87)) - 5.16)
    thermal = 0.08 * (exp(-0.005 * theta) - 1) * (exp(-0.2 * speed) - 1)
    speed_rise = 0.01 * log(4 * speed + 1) / exp(0.005 * theta)
    return stick + thermal + speed_rise - 0.005 * log(28.3 * p_mpa) + 0.035


def mu_cui2019(p):
    """Contact friction coefficient of Cui's HVD friction pair, quartic in pressure (Cui 2019 Eq. 18).

    Parameters
    ----------
    p : contact pressure [Pa] (converted to MPa, the unit of the fit).

    Returns
    -------
    f_a [-]; fitted to Cui Table 1 on 0.1-1 MPa (max deviation 7.4e-4 at 0.3 MPa).
    """
    x = p / _PA_PER_MPA
    return 0.073 + x * (-0.1557 + x * (0.233 + x * (-0.1595 + x * 0.0379)))   # Cui Eq. 18
