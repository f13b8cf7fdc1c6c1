"""Statistics of two rough surfaces with Gaussian heights: F_n functions and the average gap.

The combined roughness is ``sigma = sqrt(sigma_1^2 + sigma_2^2)`` and the film ratio
``H = h / sigma``.  ``F_n(H) = int_H^inf (s - H)^n phi(s) ds`` with ``phi`` the standard
normal density (Greenwood & Tripp).  ``F_0, F_1, F_2`` have closed forms; ``F_{5/2}`` has
none and is a C2 CasADi B-spline through ``log F_{5/2}`` tabulated by quadrature at import.

Every function accepts floats, numpy arrays and CasADi SX/MX/DM.
"""

import math

import casadi as ca
import numpy as np
from scipy import integrate, special


from .backend import apply_elementwise, declare_table, erfc, exp, fmax, fmin, if_else, is_symbolic, log, softplus, sqrt

__all__ = [
    "combined_sigma",
    "normal_pdf",
    "normal_cdf",
    "F0",
    "F1",
    "F2",
    "F52",
    "log_F52",
    "F52_bao_fit",
    "average_gap",
    "average_gap_derivative",
    "average_gap_patir",
]

_SQRT2 = math.sqrt(2.0)
_SQRT2PI = math.sqrt(2.0 * math.pi)


def _upper_tail(H):
    """1 - Phi(H), computed without cancellation for numeric input."""
    return 0.5 * erfc(H / _SQRT2)


def combined_sigma(sigma_1, sigma_2):
    """Combined RMS roughness of two surfaces.

    Parameters
    ----------
    sigma_1, sigma_2 : float, array or CasADi
        RMS roughness of each surface [m].

    Returns
    -------
    sigma : RMS roughness of the sum of heights, ``sqrt(sigma_1^2 + sigma_2^2)`` [m]
        (Cui 2019 Eq. 2).
    """
    return sqrt(sigma_1**2 + sigma_2**2)


def normal_pdf(H):
    """Standard normal density ``phi(H) = exp(-H^2/2) / sqrt(2 pi)`` [-], H [-]."""
    return exp(-0.5 * H**2) / _SQRT2PI


def normal_cdf(H):
    """Standard normal distribution ``Phi(H) = erfc(-H/sqrt2) / 2`` [-], H [-]."""
    return 0.5 * erfc(-H / _SQRT2)


def F0(H):
    """``F_0(H) = 1 - Phi(H)``: fraction of asperity heights above H [-].

    Parameters
    ----------
    H : film ratio h / sigma [-].
    """
    return _upper_tail(H)


def F1(H):
    """``F_1(H) = phi(H) - H (1 - Phi(H))`` [-], H = h / sigma [-]."""
    return normal_pdf(H) - H * _upper_tail(H)


def F2(H):
    """``F_2(H) = (1 + H^2)(1 - Phi(H)) - H phi(H)`` [-], H = h / sigma [-].

    Notes
    -----
    Symbolic (CasADi) evaluation uses ``1 - erf``: for H > ~6 it has an absolute error
    ~1e-15 (H^2) where F_2 itself is smaller than that.
    """
    return (1 + H**2) * _upper_tail(H) - H * normal_pdf(H)


# --------------------------------------------------------------------------------------
# F_{5/2}: log-tabulated by quadrature, C2 B-spline inside [_H_LO, _H_HI], asymptotic
# series outside (each matched in value at the end of the table).
# --------------------------------------------------------------------------------------
_H_LO, _H_HI, _H_STEP = -6.0, 12.0, 0.05


def _f52_quadrature(H):
    """F_{5/2}(H) = int_0^inf s^{5/2} phi(s + H) ds by adaptive quadrature (float H)."""
    value, _ = integrate.quad(
        lambda s: s**2.5 * math.exp(-0.5 * (s + H) ** 2) / _SQRT2PI,
        0.0, np.inf, epsabs=0.0, epsrel=1e-12, limit=200,
    )
    return value


_GRID = np.linspace(_H_LO, _H_HI, round((_H_HI - _H_LO) / _H_STEP) + 1)
_LOG_TABLE = np.log([_f52_quadrature(H) for H in _GRID])
_LOG_F52_SPLINE = ca.interpolant("log_F52", "bspline", [_GRID.tolist()], _LOG_TABLE.tolist())
declare_table(_LOG_F52_SPLINE, _GRID)      # outputs and events on many samples: numpy, not de Boor per sample

# H -> -inf: F_{5/2}(H) = E[(s + a)^{5/2}], a = -H, = a^{5/2} sum_k C(5/2, 2k) (2k-1)!! a^{-2k}.
_LO_COEFFS = [special.binom(2.5, 2 * k) * math.prod(range(1, 2 * k, 2)) for k in range(6)]
# H -> +inf: F_{5/2}(H) = phi(H) sum_k (-1/2)^k / k! Gamma(7/2 + 2k) H^{-7/2-2k}.
_HI_COEFFS = [(-0.5) ** k / math.factorial(k) * math.gamma(3.5 + 2 * k) / math.gamma(3.5)
              for k in range(7)]


def _series(coeffs, inv_sq):
    return sum(c * inv_sq**k for k, c in enumerate(coeffs))


def _log_f52_low(H):
    """log of the large-negative-H series (up to a constant), valid for H <= _H_LO."""
    a = -H
    return 2.5 * log(a) + log(_series(_LO_COEFFS, 1 / a**2))


def _log_f52_high(H):
    """log of the large-positive-H series (up to a constant), valid for H >= _H_HI."""
    return -0.5 * H**2 - 3.5 * log(H) + log(_series(_HI_COEFFS, 1 / H**2))


def _log_f52_spline(H):
    """Evaluate the B-spline elementwise on floats, arrays or CasADi matrices."""
    return apply_elementwise(_LOG_F52_SPLINE, H)


def log_F52(H):
    """Natural log of :func:`F52` [-]; smooth (C2) and well scaled for large H.

    Parameters
    ----------
    H : film ratio h / sigma [-].
    """
    if not is_symbolic(H):
        H = np.asarray(H, dtype=float)
    inside = _log_f52_spline(H)
    # outside the table: asymptotic series, shifted to match the table value at its end
    # (continuous; the slope jumps by < 1e-6 relative there, measured 4e-7 at H = -6).
    h_low = fmin(H, _H_LO)
    h_high = fmax(H, _H_HI)
    low = _LOG_TABLE[0] + _log_f52_low(h_low) - _log_f52_low(_H_LO)
    high = _LOG_TABLE[-1] + _log_f52_high(h_high) - _log_f52_high(_H_HI)
    out = if_else(H < _H_LO, low, if_else(H > _H_HI, high, inside))
    return out if is_symbolic(out) else out[()]


def F52(H):
    """Greenwood-Tripp ``F_{5/2}(H) = int_H^inf (s - H)^{5/2} phi(s) ds`` [-].

    Parameters
    ----------
    H : float, array or CasADi
        Film ratio h / sigma [-].

    Returns
    -------
    F_{5/2}(H) [-]; F52(0) = 0.61663, F52(3) = 1.7087e-4.

    Notes
    -----
    ``log F_{5/2}`` is tabulated by adaptive quadrature on H in [-6, 12] (step 0.05) at
    import and interpolated by a cubic CasADi B-spline (C2, exact Hessians on SX/MX);
    floats and arrays evaluate the same spline, so numeric == symbolic.  Relative error
    < 1e-6 everywhere (measured 3e-8 on [-20, 20]); the spline's second derivative is
    within 2e-4 of the exact (15/4) F_{1/2}.  Beyond the table the asymptotic series
    ``(-H)^{5/2} (1 + 15/(8 H^2) - ...)`` (H < -6) and
    ``phi(H) Gamma(7/2) H^{-7/2} (1 - 63/(8 H^2) + ...)`` (H > 12) are used, scaled to
    match the table at its ends.
    """
    if isinstance(H, ca.SX) and H.is_scalar():
        # one SX function built once and inlined at each call: a model calls F52 once per film and
        # mode (84 times for default_driveline), and building the series anew each time was 58 % of
        # the model's assembly (136 of 235 ms); the inlined expression is the same
        return _f52_sx()(H)
    return exp(log_F52(H))


def _f52_sx():
    """``F52`` as a scalar SX function (built on first use)."""
    if "F52" not in _SX_FUNCTIONS:
        h = ca.SX.sym("H")
        _SX_FUNCTIONS["F52"] = ca.Function("F52", [h], [exp(log_F52(h))])
    return _SX_FUNCTIONS["F52"]


_SX_FUNCTIONS = {}


def F52_bao_fit(H, smooth=False, width=0.05):
    """Patir's fit of F_{5/2} used by Bao 2020 Eq. 19: ``4.4086e-5 (4 - H)^6.804``, 0 for H >= 4.

    Parameters
    ----------
    H : film ratio h / sigma [-].
    smooth : bool
        False (default): exact fit; it is already C6 at H = 4.  True: ``4 - H`` is replaced
        by ``softplus(4 - H, width)``, analytic and positive everywhere; relative
        difference < 1e-8 for H <= 3 with the default width.
    width : float
        Width of the softplus [-] (smooth form only).

    Notes
    -----
    Only a rough fit: 0.550 at H = 0 (exact 0.617) and 4.4e-5 at H = 3 (exact 1.71e-4).
    """
    gap = softplus(4 - H, width) if smooth else fmax(4 - H, 0)   # Bao 2020 Eq. 19
    return 4.4086e-5 * gap**6.804


def average_gap(h, sigma):
    """Average film thickness of a Gaussian rough contact (Bao 2020 Eq. 10, exact).

    Parameters
    ----------
    h : nominal film thickness (distance of the mean planes) [m].
    sigma : combined RMS roughness [m].

    Returns
    -------
    h_T = E[max(h + delta, 0)] = h Phi(H) + sigma phi(H), H = h / sigma [m].
    """
    H = h / sigma
    return h * normal_cdf(H) + sigma * normal_pdf(H)   # Bao 2020 Eq. 10 (erf form rewritten)


def average_gap_derivative(h, sigma):
    """``d h_T / d h = Phi(h / sigma)`` [-] (Bao 2020 Eq. 10, second line; Zhang's g(h)).

    Parameters
    ----------
    h : nominal film thickness [m].
    sigma : combined RMS roughness [m].
    """
    return normal_cdf(h / sigma)


def average_gap_patir(h, sigma):
    """Patir's polynomial average gap (Cui 2019 Eq. 1).

    Parameters
    ----------
    h : nominal film thickness [m].
    sigma : combined RMS roughness [m].

    Returns
    -------
    h_T [m]: ``(3 sigma/256)(35 + 128 z + 140 z^2 - 70 z^4 + 28 z^6 - 5 z^8)``, z = H/3,
    for -3 < H < 3; ``h`` for H >= 3 and 0 for H <= -3.

    Notes
    -----
    It is the exact average gap for the compact height density
    ``35/(96 sigma)(1 - d^2/(9 sigma^2))^3``, so the branches join with four continuous
    derivatives at H = +-3: no smooth form is needed.  Cui's Eq. 1 omits the H <= -3
    branch (the polynomial is 0 at z = -1 and wrong beyond).  Within 3 % of
    :func:`average_gap` for H >= 0 (2.8 % at H = 0).
    """
    H = h / sigma
    z = fmax(fmin(H / 3, 1), -1)
    poly = 35 + z * (128 + z * (140 + z**2 * (-70 + z**2 * (28 - 5 * z**2))))   # Cui Eq. 1
    return if_else(H >= 3, h, 3 * sigma / 256 * poly)
