"""Asperity contact of two rough surfaces: Greenwood-Tripp, Zhang's GW variant, plasticity.

All SI; every function accepts floats, numpy arrays and CasADi SX/MX.

Seed errata handled here
------------------------
* Bao 2020 Eq. 12 and Eq. 18 write ``(eta beta sigma)^2`` and call eta "the viscosity"; it
  must be the asperity density n_a [1/m^2] (Bao Table 1 "rough peak density" 7e7 has unit
  1/m^2, not "/m" as printed).
* Bao 2020 Eq. 20 and Eq. 25 multiply the Greenwood-Tripp pressure by the area ratio C
  again (F_c = pi C (r2^2 - r1^2) P_c).  The GT pressure is already the load per nominal
  area, so the contact force is F_c = p_c A_n (PHYSICS.md); only the fluid load and the
  viscous torque carry the (1 - C) factor.
* Zhang 2021 Eq. 5 writes the exponent as -(h / (sqrt2 sigma))^2 / 2; the GW integral
  gives -H^2 / 2 with H = h / sigma (F_1(H) below).
"""

import math

from ..errors import UnknownVariantError
from .backend import sqrt
from .roughness import F1, F2, F52, F52_bao_fit

__all__ = [
    "greenwood_tripp_coefficient",
    "greenwood_tripp_area_ratio",
    "greenwood_tripp_pressure",
    "zhang_area_ratio",
    "zhang_contact_pressure",
    "plasticity_index",
    "effective_radius",
]

_GT_FITS = ("exact", "patir")
_RADIUS_RULES = ("bao", "cui")


def greenwood_tripp_coefficient(n_a, beta, sigma):
    """Greenwood-Tripp pressure coefficient ``K' = (16 sqrt2 / 15) pi (n_a beta sigma)^2 sqrt(sigma / beta)``.

    Parameters
    ----------
    n_a : asperity density [1/m^2] (Bao's "eta", Cui's eta_p).
    beta : asperity tip radius [m].
    sigma : combined RMS roughness [m].

    Returns
    -------
    K' [-]: contact pressure = K' E' F_{5/2}(H).
    """
    return 16 * math.sqrt(2) / 15 * math.pi * (n_a * beta * sigma) ** 2 * sqrt(sigma / beta)


def greenwood_tripp_area_ratio(H, n_a, beta, sigma, n0=1.0):
    """Real-to-nominal contact area ratio ``A_c/A_n = n0 pi^2 (n_a beta sigma)^2 F_2(H)``.

    Parameters
    ----------
    H : film ratio h / sigma [-].
    n_a : asperity density [1/m^2].
    beta : asperity tip radius [m].
    sigma : combined RMS roughness [m].
    n0 : Bao's elastoplastic area factor, 1 <= n0 <= 2 [-]; 1 = elastic (Greenwood-Tripp).

    Returns
    -------
    A_c / A_n [-] (Bao 2020 Eq. 18 with eta = n_a; Cui 2019 Eq. 3 is the same with n0 = 1).

    Notes
    -----
    Not capped at 1: with large n_a beta sigma (Bao Table 1: 0.53) it exceeds 1 for H <~ 0.
    """
    return n0 * math.pi**2 * (n_a * beta * sigma) ** 2 * F2(H)   # Bao Eq. 18, Cui Eq. 3


def greenwood_tripp_pressure(H, E_equiv, n_a, beta, sigma, fit="exact", smooth=False):
    """Greenwood-Tripp asperity contact pressure (load per nominal area) ``K' E' F_{5/2}(H)``.

    Parameters
    ----------
    H : film ratio h / sigma [-].
    E_equiv : composite elastic modulus E' [Pa].
    n_a : asperity density [1/m^2].
    beta : asperity tip radius [m].
    sigma : combined RMS roughness [m].
    fit : {"exact", "patir"}
        "exact" (default): the quadrature-based F_{5/2} (already C2, ``smooth`` is ignored).
        "patir": Bao 2020 Eq. 19, ``4.4086e-5 (4 - H)^6.804`` for H < 4, else 0.
    smooth : bool
        With fit="patir", use the softplus form of :func:`F52_bao_fit`.

    Returns
    -------
    p_c [Pa].
    """
    if fit == "exact":
        f52 = F52(H)
    elif fit == "patir":
        f52 = F52_bao_fit(H, smooth=smooth)   # Bao Eq. 19
    else:
        raise UnknownVariantError(f"contact fit: unknown value {fit!r}; allowed: {', '.join(_GT_FITS)}")
    return greenwood_tripp_coefficient(n_a, beta, sigma) * E_equiv * f52


def zhang_area_ratio(H, n_a, beta, sigma):
    """Greenwood-Williamson area ratio used by Zhang 2021 Eq. 5: ``pi n_a beta sigma F_1(H)``.

    Parameters
    ----------
    H : film ratio h / sigma [-].
    n_a : asperity density [1/m^2] (Zhang's lambda).
    beta : asperity tip radius [m] (Zhang's gamma).
    sigma : combined RMS roughness [m].

    Returns
    -------
    A_c / A_n [-].  Zhang's bracket phi(H) + H (g(h) - 1), with g = Phi, is F_1(H).
    """
    return math.pi * n_a * beta * sigma * F1(H)   # Zhang Eq. 5, exponent -H^2/2 (typo fixed)


def zhang_contact_pressure(H, E_equiv, n_a, beta, sigma):
    """Zhang 2021 Eq. 6 asperity pressure ``P_c = E * (A_c / A_n)`` [Pa].

    Parameters
    ----------
    H : film ratio h / sigma [-].
    E_equiv : equivalent elastic modulus of the friction pair [Pa].
    n_a, beta, sigma : as in :func:`zhang_area_ratio`.

    Notes
    -----
    A named variant to reproduce Zhang; not a contact mechanics law (see Greenwood-Tripp).
    """
    return E_equiv * zhang_area_ratio(H, n_a, beta, sigma)   # Zhang Eq. 6


def plasticity_index(E_equiv, hardness, sigma, beta):
    """Greenwood-Williamson plasticity index ``Omega = (E'/H') sqrt(sigma / beta)`` [-] (Bao Eq. 17).

    Parameters
    ----------
    E_equiv : composite elastic modulus E' [Pa].
    hardness : hardness of the softer surface H' [Pa].
    sigma : RMS roughness [m].
    beta : asperity tip radius [m].

    Returns
    -------
    Omega [-]: < 0.6 elastic, > 1 mostly plastic; 1.04 for Bao Table 1.
    """
    return E_equiv / hardness * sqrt(sigma / beta)   # Bao Eq. 17


def effective_radius(r1, r2, rule="bao"):
    """Radius at which the friction force of an annulus acts.

    Parameters
    ----------
    r1, r2 : inner and outer radius of the friction annulus [m].
    rule : {"bao", "cui"}
        "bao": uniform pressure, ``2 (r2^3 - r1^3) / (3 (r2^2 - r1^2))`` (Bao Eq. 25-26:
        T_c = f p_c (2 pi / 3)(r2^3 - r1^3) = f p_c A_n r_eff).
        "cui": mean radius ``(r1 + r2) / 2`` (Cui 2019 Eq. 19).

    Returns
    -------
    r_eff [m].
    """
    if rule == "bao":
        return 2 * (r2**3 - r1**3) / (3 * (r2**2 - r1**2))   # Bao Eq. 25-26
    if rule == "cui":
        return (r1 + r2) / 2   # Cui Eq. 19
    raise UnknownVariantError(f"effective radius rule: unknown value {rule!r}; allowed: {', '.join(_RADIUS_RULES)}")
