"""Majumdar-Bhushan fractal asperity load of Cui 2019 (Eq. 10-17).

The contact spots follow the size distribution (Wang & Komvopoulos domain extension)
``n(a) = (D/2) Psi^{(2-D)/2} a_l^{D/2} a^{-(D+2)/2}``, 0 < a <= a_l.  Spots larger than the
critical area a_c deform elastically, ``f_e(a) = (4 sqrt(pi)/3) E G^{D-1} a^{(3-D)/2}``;
smaller ones plastically, ``f_p(a) = H a``.  Integrating gives Cui's Eq. 10-12 (re-derived
here, and checked against direct quadrature of the distribution in the tests).

The fractal dimension D must be a float (Psi is solved from Eq. 17 with a scalar root
finder); the real-area ratio and the material data may be floats, arrays or CasADi
SX/MX, so the load is also available symbolically.

Seed errata: Cui Eq. 17 prints the unknown as lower-case psi, the grooved-area
coefficient (0.78); the unknown is the domain extension factor Psi (1.7 < Psi < 2.7).
"""

import functools
import math

from scipy import optimize

from ..errors import PhysicalRangeError
from .backend import exp, fmin, is_symbolic, log, softplus

__all__ = [
    "domain_extension_factor",
    "fractal_g1",
    "fractal_g2",
    "critical_contact_area",
    "largest_contact_area",
    "cui_nominal_area",
    "fractal_contact_pressure",
    "fractal_contact_load",
]

_D_EQUALS_1P5 = 1e-9   # |D - 1.5| below which the logarithmic (D = 1.5) branch is used


def _check_dimension(D):
    if is_symbolic(D):
        raise PhysicalRangeError("fractal dimension D: must be a number, not a symbol")
    if not 1.0 < D < 2.0:
        raise PhysicalRangeError(f"fractal dimension D: must be in (1, 2), got {D}")
    return float(D)


@functools.lru_cache(maxsize=64)
def domain_extension_factor(D):
    """Domain extension factor Psi of the contact-spot size distribution (Cui Eq. 17).

    Parameters
    ----------
    D : fractal dimension, 1 < D < 2 [-].

    Returns
    -------
    Psi [-], the root > 1 of
    ``(Psi^{(2-D)/2} - (1 + Psi^{-D/2})^{-(2-D)/D}) / ((2-D)/D) = 1``
    (about 2.0 at D = 1.5; 2.618 as D -> 1, e - 1 as D -> 2).
    """
    D = _check_dimension(D)
    e = (2 - D) / D

    def residual(psi):   # Cui Eq. 17 with the unknown Psi
        return (psi ** ((2 - D) / 2) - (1 + psi ** (-D / 2)) ** (-e)) / e - 1

    return optimize.brentq(residual, 1.0, 10.0, xtol=1e-15, rtol=1e-15)


def fractal_g1(D):
    """``g1(D) = D/(3 - 2D) ((2 - D)/D)^{D/2}`` [-] (Cui Eq. 14); undefined at D = 1.5."""
    return D / (3 - 2 * D) * ((2 - D) / D) ** (D / 2)


def fractal_g2(D):
    """``g2(D) = (D/(2 - D))^{(2 - D)/2}`` [-] (Cui Eq. 14)."""
    return (D / (2 - D)) ** ((2 - D) / 2)


def critical_contact_area(D, G, E_equiv, yield_strength):
    """Critical contact-spot area between plastic and elastic deformation (Cui Eq. 13).

    Parameters
    ----------
    D : fractal dimension [-].
    G : fractal scale (roughness) parameter [m].
    E_equiv : equivalent elastic modulus [Pa].
    yield_strength : yield strength of the softer material [Pa].

    Returns
    -------
    a_c = G^2 (pi E^2 / (225 sigma_y^2))^{1/(D-1)} [m^2].
    """
    return G**2 * (math.pi * E_equiv**2 / (225 * yield_strength**2)) ** (1 / (D - 1))   # Cui Eq. 13


def largest_contact_area(real_area, D):
    """Area of the largest contact spot a_l from the real contact area (Cui Eq. 12 inverted).

    Parameters
    ----------
    real_area : real contact area A_r [m^2] (or its ratio to A_a, giving a_l / A_a).
    D : fractal dimension [-].

    Returns
    -------
    a_l = (2 - D)/D Psi^{-(2-D)/2} A_r [m^2].
    """
    psi = domain_extension_factor(D)
    return (2 - D) / D * psi ** (-(2 - D) / 2) * real_area   # Cui Eq. 12


def cui_nominal_area(r1, r2, psi_groove):
    """Nominal (land) contact area ``A_a = psi pi (r2^2 - r1^2)`` [m^2] (Cui Eq. 16).

    Parameters
    ----------
    r1, r2 : inner and outer radius [m].
    psi_groove : non-grooved fraction of the annulus [-] (Cui's psi, 0.78 in Table 2).
    """
    return psi_groove * math.pi * (r2**2 - r1**2)


def fractal_contact_pressure(area_ratio, D, G, E_equiv, hardness, yield_strength, nominal_area,
                             smooth=False, width=0.05):
    """Fractal (M-B) asperity load per nominal area ``W_a* = W_a / A_a`` [Pa] (Cui Eq. 10-11, 15).

    Parameters
    ----------
    area_ratio : real-to-nominal contact area A_r* = A_r / A_a [-] (Cui uses the GT k_a), > 0.
    D : fractal dimension, float in (1, 2) [-].
    G : fractal scale parameter [m].
    E_equiv : equivalent elastic modulus [Pa].
    hardness : hardness of the softer material [Pa].
    yield_strength : yield strength of the softer material [Pa].
    nominal_area : nominal contact area A_a [m^2] (:func:`cui_nominal_area`).
    smooth : bool
        False (default): exact switch between a_l > a_c (Eq. 10) and a_l <= a_c (Eq. 11).
        True: smooth switch (see Notes); relative difference < 1e-6 where
        ``|ln(a_l / a_c)| >= 1`` with the default width.
    width : width of the smooth switch in ln(a) [-].

    Returns
    -------
    W_a* [Pa].

    Notes
    -----
    Eq. 10 with a_c replaced by ``a_m = min(a_c, a_l)`` reduces to Eq. 11 (``H A_r*``) when
    a_l <= a_c, so one formula covers both branches; the smooth form takes
    ``ln a_m = ln a_c - softplus(ln a_c - ln a_l, width)``.  The load is continuous at
    a_l = a_c but its slope jumps there (with Cui's Table 2 data an elastic spot of area
    a_c carries ~44 times the plastic load H a_c); with Cui's data the switch lies at
    A_r* ~ 1e-17, far below any contact of interest.  The D = 1.5 branch of Eq. 10 is the limit of the
    general one and is used when ``|D - 1.5| < 1e-9``.
    """
    D = _check_dimension(D)
    psi = domain_extension_factor(D)
    g_star = G / nominal_area**0.5                                            # Cui Eq. 15
    a_c = critical_contact_area(D, G, E_equiv, yield_strength) / nominal_area  # Cui Eq. 13, 15
    a_l = largest_contact_area(area_ratio, D)                                 # Cui Eq. 12, 15
    if smooth:
        log_a_c = log(a_c)
        log_a_m = log_a_c - softplus(log_a_c - log(a_l), width)
        a_m = exp(log_a_m)
    else:
        a_m = fmin(a_c, a_l)
        log_a_m = log(a_m)
    spots = psi ** ((D - 2) ** 2 / 4) * area_ratio ** (D / 2)   # Psi^{(D-2)^2/4} A_r*^{D/2}
    plastic = hardness * fractal_g2(D) * spots * a_m ** ((2 - D) / 2)
    if abs(D - 1.5) < _D_EQUALS_1P5:
        # Cui Eq. 10, D = 1.5 (ln(A_r*/(3 Psi^{1/4} a_m)) = ln(a_l / a_m))
        elastic = (3**-0.75 * math.sqrt(math.pi) * E_equiv * g_star**0.5 * spots
                   * (log(a_l) - log_a_m))
    else:
        # Cui Eq. 10, D != 1.5
        q = (3 - 2 * D) / 2
        elastic = (4 * math.sqrt(math.pi) / 3 * E_equiv * g_star ** (D - 1) * fractal_g1(D)
                   * spots * (a_l**q - a_m**q))
    return elastic + plastic


def fractal_contact_load(area_ratio, D, G, E_equiv, hardness, yield_strength, nominal_area,
                         smooth=False, width=0.05):
    """Fractal asperity load ``W_a = A_a W_a*`` [N] (Cui Eq. 10-11, 15).

    Parameters are those of :func:`fractal_contact_pressure`.
    """
    return nominal_area * fractal_contact_pressure(
        area_ratio, D, G, E_equiv, hardness, yield_strength, nominal_area,
        smooth=smooth, width=width)
