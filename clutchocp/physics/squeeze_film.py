"""Averaged axisymmetric Reynolds squeeze film of an annular friction pair.

The film between two flat annular plates (inner radius r1, outer radius r2) obeys the
Patir–Cheng averaged Reynolds equation with a permeable lining and Bao's centrifugal term
(Zhang 2021 Eq. 1, Bao 2020 Eq. 7)::

    (1/r) d/dr( r D dp/dr ) / (12 eta) = dh_T/dt + (centrifugal pumping),   D = phi_r (h^3 + 12 Phi_p d)

i.e. (1/r)(r p')' = 4 E with E = E_s + E_c, E_s = 3 eta h_T' / D and
E_c = rho (3 w1^2 + 3 w2^2 + 4 w1 w2) / (20 phi_r).  With p(r1) = P0 and p(r2) = 0::

    p(r) = E (r^2 - r2^2) + [E (r2^2 - r1^2) + P0] ln(r2/r) / ln(r2/r1)          (Bao Eq. 8/11)
    W    = -(pi/2) E G + P0 [ (pi/2)(r2^2 - r1^2)/ln(r2/r1) - pi r1^2 ]
    G    = r2^4 - r1^4 - (r2^2 - r1^2)^2 / ln(r2/r1)

W > 0 pushes the plates apart: squeezing (h_T' < 0) makes E_s < 0 and W > 0; centrifugal
pumping (E_c > 0) sucks the film and lowers W (Liao's "- F2").

Errata found in the seeds (derived and tested in tests/physics/test_squeeze_film.py):
- Zhang 2021 Eq. 4 writes (b^2 - a^2) / (2 ln(a/b)); the factor 2 is wrong (then p(r1) != 0).
- Liao 2021 Eq. 7 (F3 = 3 pi mu G delta' / delta^3) lacks the factor 1/2 of W above.
- Bao 2020 Eq. 12 (the expanded load) is not readable as printed; W above is the exact
  integral of Bao's Eq. 11 pressure and is checked against quadrature.
- Liao 2021 Eq. 6 (F2 = rho pi (r2^4 - r1^4)(w1^2 - w1 dw + 0.3 dw^2)/6) has the same speed
  combination as E_c but a different radial factor: the Reynolds solution with p(r1) = p(r2) = 0
  gives (pi/4) rho K G / phi_r, K = (3 w1^2 + 3 w2^2 + 4 w1 w2)/10 (see ``film_load``).

Units: SI throughout (m, s, Pa, Pa s, kg/m^3, rad/s, N).
"""

from clutchocp.errors import PhysicalRangeError
from clutchocp.physics.backend import exp, fmax, fmin, is_symbolic, log, softplus

import numpy as np

# Patir & Cheng (1978) isotropic (gamma = 1) pressure flow factor, fitted for H > 0.5.
_PC_C = 0.90
_PC_R = 0.56
_H_FIT_MIN = 0.5


def _pc_fit(H):
    """Patir–Cheng fit phi_r = 1 - 0.90 exp(-0.56 H) (valid for H > 0.5)."""
    return 1.0 - _PC_C * exp(-_PC_R * H)


# C2 extension below H0 = 0.5: phi_ext(x) = phi0 exp(a x + b x^2), x = H - H0, with a, b chosen
# so that value, slope and curvature match the fit at H0. b < 0, so phi_ext is positive and
# decays like a Gaussian as H -> -inf (the film stops conducting when the asperities close it).
_PHI0 = 1.0 - _PC_C * np.exp(-_PC_R * _H_FIT_MIN)           # 0.31979
_D1 = _PC_C * _PC_R * np.exp(-_PC_R * _H_FIT_MIN)           # phi'(H0)  = 0.38090
_D2 = -_PC_C * _PC_R**2 * np.exp(-_PC_R * _H_FIT_MIN)       # phi''(H0) = -0.21330
_EXT_A = _D1 / _PHI0                                        # 1.19109
_EXT_B = 0.5 * (_D2 / _PHI0 - _EXT_A**2)                    # -1.04287


def _pc_extension(x):
    """C2 continuation of the fit for x = H - 0.5 <= 0: phi0 exp(a x + b x^2)."""
    x = fmax(x, -40.0)       # avoids x*x overflow; the value there is exp(-1700) = 0 in doubles
    return _PHI0 * exp(_EXT_A * x + _EXT_B * x * x)


def pressure_flow_factor(H, smooth=False, width=0.05):
    """Patir–Cheng radial pressure flow factor for isotropic roughness.

    phi_r = 1 - 0.90 exp(-0.56 H) for H >= 0.5 (Patir & Cheng 1978, fitted for H > 0.5).
    Below H = 0.5 the fit would reach zero at H = -0.19 and turn negative, so it is continued
    by phi0 exp(a x + b x^2), x = H - 0.5, with value, slope and curvature matched at 0.5
    (a = 1.1911, b = -1.0429): the result is C2, positive for every H and tends to 0 as
    H -> -inf (0.136 at H = 0 where the fit gives 0.10).

    Parameters
    ----------
    H : float, array or CasADi symbol
        Film thickness ratio h / sigma [-].
    smooth : bool
        False (default): the two pieces are joined with min/max at H = 0.5 (already C2).
        True: min/max replaced by softplus of the given ``width``, giving a branch-free C-infinity
        expression; its error against the exact form is below 3e-6 relative for |H - 0.5| >= 0.5
        and below 3e-3 relative everywhere (width = 0.05; the largest error is at H = 0.5).
    width : float
        Smoothing width in H for ``smooth=True`` [-].

    Returns
    -------
    phi_r : same type as H
        Pressure flow factor [-], in (0, 1).
    """
    x = H - _H_FIT_MIN
    if smooth:
        x_lo = -softplus(-x, width)      # smooth min(x, 0)
        x_hi = softplus(x, width)        # smooth max(x, 0)
    else:
        x_lo = fmin(x, 0.0)
        x_hi = fmax(x, 0.0)
    # For x >= 0: phi0 * fit(H) / phi0 = fit(H); for x < 0: extension(x) * fit(H0) / phi0 = extension(x).
    return _pc_extension(x_lo) * _pc_fit(_H_FIT_MIN + x_hi) / _PHI0


def _check_radii(r1, r2):
    """Raise PhysicalRangeError for numeric radii with r1 <= 0 or r2 <= r1."""
    if is_symbolic(r1, r2):
        return
    if np.any(np.asarray(r1) <= 0) or np.any(np.asarray(r2) <= np.asarray(r1)):
        raise PhysicalRangeError(f"radii: need 0 < r1 < r2, got r1={r1!r}, r2={r2!r} [m]")


def squeeze_geometry(r1, r2):
    """Geometry factor of the annular squeeze film.

    G = r2^4 - r1^4 - (r2^2 - r1^2)^2 / ln(r2/r1), the bracket of the load integral
    (Liao 2021 Eq. 7, Bao 2020 Eq. 12 integrated). G > 0 for 0 < r1 < r2; G -> r2^4 (full disc)
    only logarithmically as r1 -> 0, G = r2^4 (1 - 1/ln(r2/r1)) + O(r1^2), because p = 0 is imposed
    at r1; G ~ (4/3) r (r2 - r1)^3 for a narrow annulus (a plane strip squeeze film);
    in the latter limit the subtraction loses about 3 (r1/(r2-r1))^2 ulps.

    Parameters
    ----------
    r1, r2 : float, array or CasADi symbol
        Inner and outer radius of the annulus [m].

    Returns
    -------
    G : same type as r1, r2
        Geometry factor [m^4].
    """
    _check_radii(r1, r2)
    return r2**4 - r1**4 - (r2**2 - r1**2) ** 2 / log(r2 / r1)


def _film_coefficients(h, dhT_dt, eta, phi_r, permeability, lining_thickness, rho, w1, w2):
    """E_s + E_c of Bao Eq. 11 with Zhang's permeable lining; (1/r)(r p')' = 4 E."""
    D = phi_r * (h**3 + 12.0 * permeability * lining_thickness)          # Zhang 2021 Eq. 1
    E_s = 3.0 * eta * dhT_dt / D                                           # Zhang Eq. 4 / Bao Eq. 11
    # Bao Eq. 7 -> 11: with h uniform, rho w1^2 [0.3 (1 - w2/w1)^2 + w2/w1] d/dr(r^2 h^3)/r
    # = 2 rho h^3 (3 w1^2 + 3 w2^2 + 4 w1 w2)/10, giving E_c below. With a permeable lining
    # E_c is kept as Bao's (not rescaled by h^3 / (h^3 + 12 Phi_p d)): this assumes the oil in
    # the lining is pumped like the film oil, exact when w1 = w2 (both then give dp/dr = rho w^2 r).
    E_c = rho * (3.0 * w1**2 + 3.0 * w2**2 + 4.0 * w1 * w2) / (20.0 * phi_r)  # Bao Eq. 11
    return E_s + E_c


def squeeze_pressure(r, h, dhT_dt, eta, r1, r2, *, phi_r=1.0, permeability=0.0,
                     lining_thickness=0.0, inlet_pressure=0.0, rho=0.0, w1=0.0, w2=0.0):
    """Radial pressure of the averaged squeeze film, p(r1) = inlet_pressure, p(r2) = 0.

    p(r) = E (r^2 - r2^2) + [E (r2^2 - r1^2) + P0] ln(r2/r) / ln(r2/r1) with
    E = 3 eta h_T' / (phi_r (h^3 + 12 Phi_p d)) + rho (3 w1^2 + 3 w2^2 + 4 w1 w2) / (20 phi_r)
    (Bao 2020 Eq. 11, Zhang 2021 Eq. 1 and 4 with its factor-2 erratum corrected).

    Parameters
    ----------
    r : float, array or CasADi symbol
        Radius, r1 <= r <= r2 [m].
    h : float, array or CasADi symbol
        Film thickness in the flow coefficient h^3 [m] (nominal h as in Zhang Eq. 1 and Bao
        Eq. 11; pass the average gap h_T to follow Bao Eq. 7).
    dhT_dt : float, array or CasADi symbol
        Rate of change of the average gap [m/s]; negative while squeezing.
    eta : float or symbol
        Dynamic viscosity [Pa s].
    r1, r2 : float or symbol
        Inner and outer radius [m].
    phi_r : float or symbol, keyword
        Pressure flow factor [-] (see ``pressure_flow_factor``); 1 for smooth plates.
    permeability : float or symbol, keyword
        Lining permeability Phi_p [m^2]; 0 for an impermeable lining.
    lining_thickness : float or symbol, keyword
        Lining thickness d [m].
    inlet_pressure : float or symbol, keyword
        Oil pressure P0 at the inner radius [Pa].
    rho : float or symbol, keyword
        Oil density [kg/m^3]; 0 switches the centrifugal term off.
    w1, w2 : float or symbol, keyword
        Angular speeds of the two plates [rad/s].

    Returns
    -------
    p : same type as r
        Film pressure [Pa].
    """
    _check_radii(r1, r2)
    E = _film_coefficients(h, dhT_dt, eta, phi_r, permeability, lining_thickness, rho, w1, w2)
    # Bao Eq. 8/11 with (ln r - ln r2)/(ln r1 - ln r2) = ln(r2/r)/ln(r2/r1)
    return E * (r**2 - r2**2) + (E * (r2**2 - r1**2) + inlet_pressure) * log(r2 / r) / log(r2 / r1)


def film_load(h, dhT_dt, eta, r1, r2, *, phi_r=1.0, permeability=0.0, lining_thickness=0.0,
              inlet_pressure=0.0, rho=0.0, w1=0.0, w2=0.0):
    """Load carried by the squeeze film over the full annulus; W > 0 pushes the plates apart.

    W = -(pi/2) (E_s + E_c) G + P0 [ (pi/2)(r2^2 - r1^2)/ln(r2/r1) - pi r1^2 ],
    the exact integral 2 pi int_{r1}^{r2} p(r) r dr of ``squeeze_pressure`` (Bao 2020 Eq. 12,
    Liao 2021 Eq. 3-7). Its three parts are:

    - squeeze: (3 pi eta (-h_T') / (2 phi_r (h^3 + 12 Phi_p d))) G; Liao's F3 (Eq. 7) lacks the 1/2;
    - inlet: P0 [...] equals Liao's F1 (Eq. 5);
    - centrifugal: -(pi/4) rho K G / phi_r, K = (3 w1^2 + 3 w2^2 + 4 w1 w2)/10
      = w1^2 - w1 dw + 0.3 dw^2 (dw = w1 - w2). Liao's F2 (Eq. 6) has the same K but the radial
      factor (pi/6)(r2^4 - r1^4) instead of (pi/4) G, so it is not the load of the Reynolds
      solution with p(r1) = p(r2) = 0; it is 2 (r2^4 - r1^4) / (3 G) times this term (-> 2/3 as
      r1 -> 0, 16.5 for r1/r2 = 0.7). This module follows the Reynolds solution (Bao Eq. 7).

    Multiply by (1 - A_c/A_n) to carry only the non-contact area as in Bao Eq. 12.

    Parameters
    ----------
    h, dhT_dt, eta, r1, r2 and keywords
        As in ``squeeze_pressure`` (SI units: m, m/s, Pa s, m, m; Pa, kg/m^3, rad/s, m^2, m).

    Returns
    -------
    W : same type as h
        Film load [N].
    """
    E = _film_coefficients(h, dhT_dt, eta, phi_r, permeability, lining_thickness, rho, w1, w2)
    G = squeeze_geometry(r1, r2)
    L = log(r2 / r1)
    inlet = inlet_pressure * (0.5 * np.pi * (r2**2 - r1**2) / L - np.pi * r1**2)  # Liao Eq. 5
    return -0.5 * np.pi * E * G + inlet
