"""Viscous shear torque of the oil film between rough plates (Patir–Cheng shear factors).

Cui 2019 Eq. 5-9: the average shear stress of the sliding film with the Patir & Cheng (1979) shear
stress factors phi_f (Eq. 6) and phi_fs (Eq. 7-8), integrated over the land area of the annulus;
Liao 2021 Eq. 2 for plates with radial grooves.

Two corrections to Cui Eq. 5 and 9 as printed (derivations in docs/physics.md, tests in
tests/physics/test_shear.py):

* **Which wall, which sign.** Patir-Cheng's mean stress eta U (phi_f -+ phi_fs) / h is the *viscous*
  shear on one wall. The torque the film transmits is the same on both plates (the film's momentum
  balance); on a rough wall it is the viscous shear plus the form drag of the pressure on its
  asperity flanks, on a smooth wall the viscous shear alone. Patir-Cheng's phi_fs lowers the rough
  wall's viscous shear by the form drag and raises the smooth wall's by as much, so a rough lining on
  smooth steel transmits (phi_f + Phi_fs): the transmitted factor is phi_f + |V_r1 - V_r2| Phi_fs
  (:func:`transmitted_shear_factor`). Zhang 2021 labels the separator w1 and the disc w2, so his
  phi_f - phi_fs with V_r1 = 0, V_r2 = 1 is the same plus sign; Cui's phi_f - phi_fs with his rougher
  friction plate as surface 1 is the viscous shear on that plate, not the transmitted stress.
* **h, not h_T, under phi_f.** phi_f is Patir-Cheng's E[h / h_loc], the mean of the local Couette
  stress eta U / h_loc written over the *nominal* film h (for H > 3, Cui Eq. 6 is exactly the
  quadrature of H / (H - s) over Patir's height density 35/32 (1 - s^2)^3, s in units of 3 sigma;
  phi_f -> 1 + 1/H^2 = h E[1/(h - delta)] for large H). Dividing by the average gap h_T (Cui Eq. 5, 9
  as printed) counts the roughness twice: h_T = 1.083 h at H = 1.

Units: SI throughout (m, Pa s, rad/s, N m).
"""

import casadi as ca
import numpy as np

from clutchocp.physics import transmitted_shear_table
from clutchocp.physics.backend import (apply_elementwise, declare_table, exp, fabs, fmax, fmin, if_else,
                                       is_symbolic, log, softplus, smooth_step)
from clutchocp.physics.roughness import average_gap, combined_sigma

EPS_STAR = 1.0 / 300.0          # Cui 2019 after Eq. 6: eps* = 0.00333 (cut-off film / 3 sigma)

# Patir & Cheng (1979) isotropic coefficients of Phi_fs (Cui 2019 Eq. 8)
A3 = 11.1
ALPHA4 = 2.31
ALPHA5 = 2.38
ALPHA6 = 0.11
H_CUT_FS = 7.0                  # Phi_fs = 0 above H = 7 (Cui Eq. 8)

# Far-field series of phi_f (H >= 6, z = H/3 >= 2, u = 1/z); derived from Cui Eq. 6, H > 3 branch:
# (1 - z^2)^3 ln((z+1)/(z-1)) = -2 z^6 (1 - u^2)^3 atanh(u); the powers z^5, z^3, z^1 cancel
# against the polynomial, leaving phi_f = 1 + 105 sum_{m>=1} u^(2m) / ((2m+1)(2m+3)(2m+5)(2m+7))
# = 1 + u^2/9 + u^4/33 + ... (phi_f ~ 1 + 1/H^2: E[h/h_T] of a Gaussian gap). The closed form
# loses ~z^5 / phi_f ulps to cancellation (1e-1 relative at H = 1000); the series does not.
_N_SERIES = 24
_SERIES = [105.0 / ((2 * m + 1) * (2 * m + 3) * (2 * m + 5) * (2 * m + 7))
           for m in range(1, _N_SERIES + 1)]
_Z_SERIES = 2.0


def _phi_f_thin_per_z(z, eps):
    """Cui Eq. 6, H <= 3 branch divided by z = H/3 (finite at z = 0)."""
    poly = -55 + z * (132 + z * (345 + z * (-160 + z * (-405 + z * (60 + 147 * z)))))
    return 35.0 / 32.0 * ((1 - z * z) ** 3 * log((z + 1) / eps) + poly / 60.0)


def _phi_f_thin(z, eps):
    """Cui Eq. 6, H <= 3 branch (z = H/3 in [0, 1])."""
    return z * _phi_f_thin_per_z(z, eps)


def _phi_f_thick(z):
    """Cui Eq. 6, H > 3 branch (z = H/3 > 1), closed form."""
    # ln((z+1)/(z-1)) = ln(z+1) - ln(z-1); z - 1 floored so that the unselected branch stays
    # finite at z <= 1 (CasADi if_else evaluates both); (1 - z^2)^3 = 0 at z = 1 anyway.
    ln_ratio = log(z + 1) - log(fmax(z - 1, 1e-300))
    return 35.0 / 32.0 * z * ((1 - z * z) ** 3 * ln_ratio + z / 15.0 * (66 + z * z * (30 * z * z - 80)))


def _phi_f_far(z):
    """Cui Eq. 6, H > 3 branch as a series in u^2 = 1/z^2 (accurate to 1e-16 for z >= 2)."""
    u = 1.0 / z
    u2 = u * u
    acc = 0.0
    for c in reversed(_SERIES):          # Horner in u^2
        acc = (acc + c) * u2
    return 1.0 + acc


def shear_factor_phi_f(H, eps=EPS_STAR, smooth=False, width=0.05):
    """Patir–Cheng shear stress factor phi_f (Cui 2019 Eq. 6).

    With z = H/3: for H <= 3, phi_f = (35/32) z {(1 - z^2)^3 ln((z+1)/eps*) + (1/60)[-55 + z(132
    + z(345 + z(-160 + z(-405 + z(60 + 147 z)))))]}; for H > 3, phi_f = (35/32) z {(1 - z^2)^3
    ln((z+1)/(z-1)) + (z/15)[66 + z^2 (30 z^2 - 80)]}. The branches join C2 at H = 3 (value 7/6,
    slope -7/36, curvature 7/12 per unit H; not C3). For H >= 6 the H > 3 branch is evaluated
    by its exact series 1 + 105 sum u^(2m)/((2m+1)(2m+3)(2m+5)(2m+7)), u = 3/H, so
    phi_f -> 1 + 1/H^2 as H -> inf.
    phi_f(0) = 0 and phi_f = 0 for H < 0 (no fluid film to shear; z is clamped at 0).

    Parameters
    ----------
    H : float, array or CasADi symbol
        Film thickness ratio h / sigma [-].
    eps : float
        Cut-off film eps* (Cui: 1/300) [-].
    smooth : bool
        False (default): exact, with max(H, 0) (a kink at H = 0). True: softplus(H, width)
        instead of max(H, 0), which is C-infinity; relative error below 1e-5 for H >= 0.5.
    width : float
        Smoothing width in H for ``smooth=True`` [-].

    Returns
    -------
    phi_f : same type as H
        Shear stress factor [-].
    """
    Hp = softplus(H, width) if smooth else fmax(H, 0.0)
    z = Hp / 3.0
    # each branch gets z clamped to a range where it is finite (CasADi if_else evaluates both)
    thin = _phi_f_thin(fmin(z, 1.5), eps)
    thick = _phi_f_thick(fmin(fmax(z, 0.5), 3.0))
    far = _phi_f_far(fmax(z, 1.5))
    return if_else(z <= 1.0, thin, if_else(z <= _Z_SERIES, thick, far))


def _phi_f_per_H(H, smooth, width=0.05):
    """phi_f / H [-], finite at H = 0: the mean Couette stress is eta U (phi_f / H) / sigma.

    For H <= 0 (exact form) it keeps its value at H = 0, (35/96)(ln(1/eps*) - 11/12) = 1.7448:
    Patir-Cheng's E[sigma / h_loc] over the area still wetted, continued flat past the model's edge
    (no jump; the real value falls to 0 at H = -3, where the contact area multiplies it by ~0).
    The smooth form uses softplus(H) for max(H, 0) as :func:`shear_factor_phi_f` does.
    """
    Hp = softplus(H, width) if smooth else fmax(H, 0.0)
    z = Hp / 3.0
    thin = _phi_f_thin_per_z(fmin(z, 1.5), EPS_STAR) / 3.0
    thick = _phi_f_thick(fmin(fmax(z, 0.5), 3.0)) / fmax(Hp, 1.5)       # selected for Hp > 3
    far = _phi_f_far(fmax(z, 1.5)) / fmax(Hp, 4.5)                       # selected for Hp > 6
    return if_else(z <= 1.0, thin, if_else(z <= _Z_SERIES, thick, far))


def _variance_ratio_difference(sigma_1, sigma_2):
    """V_r1 - V_r2 = (sigma_1^2 - sigma_2^2) / sigma^2 (Cui Eq. 7)."""
    return (sigma_1**2 - sigma_2**2) / (sigma_1**2 + sigma_2**2)


def _both_zero(sigma_1, sigma_2):
    return (not is_symbolic(sigma_1, sigma_2)
            and np.all(np.asarray(sigma_1) == 0) and np.all(np.asarray(sigma_2) == 0))


def _Phi_fs(H, smooth, width, power=ALPHA4):
    """Patir-Cheng's unsigned Phi_fs(H) >= 0 (Cui Eq. 8), exact or smoothly cut off at H = 7.

    ``power = ALPHA4 - 1`` gives Phi_fs / H (0 for H <= 0).
    """
    Hp = fmax(H, 0.0)
    if smooth:
        Hc = 9.0 - softplus(9.0 - Hp, 0.1)            # ~ min(H, 9): keeps exp(a6 H^2) finite
        cut = 1.0 - smooth_step(Hp - H_CUT_FS, width)
    else:
        Hc = fmin(Hp, H_CUT_FS)                       # finite in the unselected branch
        cut = if_else(Hp <= H_CUT_FS, 1.0, 0.0)
    # the base of H^a4 is capped at 10 only to avoid overflow for huge H, where cut is 0
    # (exact) or below exp(-60) (smooth), so the cap changes nothing visible
    return A3 * fmin(Hp, 10.0)**power * exp(-ALPHA5 * Hc + ALPHA6 * Hc * Hc) * cut     # Cui Eq. 8


def shear_factor_phi_fs(H, sigma_1, sigma_2, smooth=False, width=0.1):
    """Patir–Cheng shear stress factor phi_fs (Cui 2019 Eq. 7-8).

    phi_fs = (V_r1 - V_r2) Phi_fs(H), V_ri = (sigma_i / sigma)^2,
    Phi_fs = A3 H^a4 exp(-a5 H + a6 H^2) for 0 <= H <= 7 and 0 for H > 7 (A3 = 11.1, a4 = 2.31,
    a5 = 2.38, a6 = 0.11; Patir & Cheng 1979 isotropic). The cut-off at H = 7 is a jump of
    Phi_fs(7) = 0.0127; Phi_fs = 0 for H <= 0. Equal roughness (or both zero) gives phi_fs = 0.
    The viscous shear on surface 1 is eta U (phi_f - phi_fs) / h, on surface 2 eta U (phi_f + phi_fs)
    / h; the transmitted torque is :func:`transmitted_shear_factor`.

    Parameters
    ----------
    H : float, array or CasADi symbol
        Film thickness ratio h / sigma [-].
    sigma_1, sigma_2 : float or symbol
        RMS roughness of surface 1 (speed w1) and surface 2 (speed w2) [m].
    smooth : bool
        False (default): exact cut-off. True: Phi_fs multiplied by 1 - smooth_step(H - 7, width)
        and H in the exponent capped smoothly near 9, which is C2 (H^2.31 at 0 is C2); error below
        5e-5 relative for H <= 6.5 and below 1e-6 absolute for H >= 7.5 (width = 0.1).
    width : float
        Width of the smooth cut-off [-].

    Returns
    -------
    phi_fs : same type as H
        Shear stress factor [-].
    """
    if _both_zero(sigma_1, sigma_2):
        return 0.0 * H
    return _variance_ratio_difference(sigma_1, sigma_2) * _Phi_fs(H, smooth, width)      # Cui Eq. 7


# Transmitted factor by deterministic flow: phi_T = 1 + u^2 y(u), u = 1 / (1 + H), y a C2 cubic
# B-spline through the table (physics/transmitted_shear_table.py) and the far-field value y(0) = 2.5:
# phi_T -> 1 + 2.5 / H^2, the Couette part E[h / h_loc] = 1 + 1/H^2 plus half the form drag,
# 6 E[k_x^2 / k^2] (sigma / h)^2 = 3 / H^2 for an isotropic wall (second order in sigma / h).
FAR_FIELD_TRANSMITTED = 2.5
_TABLE_U = np.concatenate([[0.0], 1.0 / (1.0 + np.asarray(transmitted_shear_table.H)[::-1])])
_TABLE_Y = np.concatenate([[FAR_FIELD_TRANSMITTED],
                           ((np.asarray(transmitted_shear_table.PHI_T) - 1.0)
                            * (1.0 + np.asarray(transmitted_shear_table.H)) ** 2)[::-1]])
_TRANSMITTED_SPLINE = ca.interpolant("transmitted_y", "bspline", [_TABLE_U.tolist()], _TABLE_Y.tolist())
declare_table(_TRANSMITTED_SPLINE, _TABLE_U)    # numpy-translated models evaluate it with numpy


def table_shear_factor(H, smooth=False, width=0.05):
    """The deterministic-flow transmitted factor phi_T(H) of one rough wall on a smooth one [-].

    The mean transmitted stress is eta U phi_T / h_T (h_T the average gap, Bao Eq. 10): the table's
    own definition (:mod:`clutchocp.physics.transmitted_shear_table`), interpolated as
    1 + u^2 y(u), u = 1 / (1 + H), y a C2 cubic B-spline through the table with y(0) = 2.5, so
    phi_T -> 1 + 2.5 / H^2. H <= 0 takes the value at H = 0 (``smooth``: softplus(H, width) for
    max(H, 0)). :func:`transmitted_shear_factor` gives it over the nominal film.

    Parameters
    ----------
    H : float, array or CasADi symbol
        Film thickness ratio h / sigma [-].
    smooth : bool
        Softplus instead of max(H, 0).
    width : float
        Softplus width in H [-].

    Returns
    -------
    phi_T : same type as H
    """
    Hp = softplus(H, width) if smooth else fmax(H, 0.0)
    u = 1.0 / (1.0 + Hp)
    return 1.0 + u * u * apply_elementwise(_TRANSMITTED_SPLINE, u)


def _table_per_H(H, smooth, width=0.05):
    """phi_T / (h_T / sigma) [-]: the table's transmitted stress over the nominal film, divided by H
    (finite at H = 0, where h_T / sigma = phi(0) = 0.399; held flat below H = 0 like phi_f / H)."""
    Hp = softplus(H, width) if smooth else fmax(H, 0.0)
    return table_shear_factor(Hp, False, width) / average_gap(Hp, 1.0)


SHEAR_FACTOR_METHODS = ("patir_cheng", "table")


def _check_method(method):
    if method not in SHEAR_FACTOR_METHODS:
        raise ValueError(f"method must be one of {', '.join(SHEAR_FACTOR_METHODS)}, got {method!r}")


def _transmitted_per_H(H, sigma_1, sigma_2, method, smooth, smooth_cutoff, width=0.1):
    """Transmitted factor over the nominal film, divided by H [-] (finite at H = 0)."""
    phi_f = _phi_f_per_H(H, smooth)
    if _both_zero(sigma_1, sigma_2):
        return phi_f
    asymmetry = fabs(_variance_ratio_difference(sigma_1, sigma_2))                  # |V_r1 - V_r2|
    if method == "patir_cheng":
        excess = _Phi_fs(H, smooth or smooth_cutoff, width, power=ALPHA4 - 1.0)
    else:
        excess = _table_per_H(H, smooth) - phi_f
    return phi_f + asymmetry * excess


def transmitted_shear_factor(H, sigma_1, sigma_2, method="patir_cheng", smooth=False, smooth_cutoff=False,
                             width=0.1):
    """Shear factor of the torque the film transmits, over the nominal film h [-].

    The film's momentum balance makes the transmitted stress the same on both plates: the viscous
    shear plus the pressure's form drag on the asperity flanks of a rough wall, the viscous shear
    alone on a smooth wall. The mean transmitted stress is eta U factor / h.

    * ``"patir_cheng"``: phi_f + |V_r1 - V_r2| Phi_fs (Cui Eq. 6-8 with the transmitted sign).
      Patir-Cheng's phi_fs lowers the rougher wall's viscous shear by the form drag and raises the
      smoother wall's by as much, so with one smooth wall this is the transmitted factor (a rough
      lining on smooth steel: phi_f + Phi_fs).
    * ``"table"``: the deterministic Reynolds flow over an isotropic Gaussian rough wall sliding on a
      smooth one (:mod:`clutchocp.physics.rough_wall_flow`, table in
      :mod:`clutchocp.physics.transmitted_shear_table`): phi_T h / h_T, phi_T the mean transmitted
      stress x h_T / (eta U). It agrees with Patir-Cheng's phi_f + Phi_fs within its scatter at
      H = 3.5-5 and is 6-48 % above it for H = 0.5-3 (the form drag near contact spots).

    With two rough walls the excess over Patir-Cheng's phi_f is scaled by |V_r1 - V_r2| in both
    methods (Patir-Cheng's own form; the deterministic flow was computed for one rough wall only), so
    an equal split gives phi_f: the smoother wall's viscous shear, a lower bound of the transmitted
    stress.

    Parameters
    ----------
    H : float, array or CasADi symbol
        Film thickness ratio h / sigma [-].
    sigma_1, sigma_2 : float or symbol
        RMS roughness of the two surfaces [m] (the order does not matter).
    method : {"patir_cheng", "table"}
        Source of the factor.
    smooth : bool
        Smooth forms of phi_f, of the cut-off of Phi_fs and of the table's clamp at H = 0.
    smooth_cutoff : bool
        The smooth cut-off of Phi_fs even with ``smooth=False``.
    width : float
        Width of the smooth cut-off of Phi_fs [-].

    Returns
    -------
    factor : same type as H
        Transmitted shear factor [-].
    """
    _check_method(method)
    return H * _transmitted_per_H(H, sigma_1, sigma_2, method, smooth, smooth_cutoff, width)


def viscous_torque(w_rel, h, eta, r1, r2, *, sigma_1=0.0, sigma_2=0.0, area_ratio=0.0,
                   land_fraction=1.0, smooth=False, smooth_cutoff=False, method="patir_cheng"):
    """Viscous torque the film between rough annular plates transmits (Cui 2019 Eq. 9, corrected).

    T = (1 - A_c/A_n) psi factor pi eta w_rel (r2^4 - r1^4) / (2 h), with H = h/sigma,
    sigma = sqrt(sigma_1^2 + sigma_2^2), h the nominal film (the distance of the mean planes) and
    the factor of :func:`transmitted_shear_factor` (Patir-Cheng: phi_f + |V_r1 - V_r2| Phi_fs). The
    factor over h is evaluated as (factor / H) / sigma, finite at H = 0; below H = 0 (the model's
    edge: the mean planes cross) it keeps its value at H = 0. Cui Eq. 9 as printed has phi_f - phi_fs
    (the viscous shear on his surface 1, the rougher friction plate) and the average gap h_T; see the
    module docstring for both corrections. Bao 2020 Eq. 25 writes phi_f + phi_fs and h, as here.
    With sigma_1 = sigma_2 = 0 (numbers) it is the Newtonian torque pi eta w (r2^4 - r1^4)/(2h).

    Parameters
    ----------
    w_rel : float, array or CasADi symbol
        Relative angular speed w1 - w2 [rad/s].
    h : float, array or CasADi symbol
        Nominal film thickness [m].
    eta : float or symbol
        Dynamic viscosity [Pa s].
    r1, r2 : float or symbol
        Inner and outer radius [m].
    sigma_1, sigma_2 : float or symbol, keyword
        RMS roughness of the two surfaces [m]; sigma_1 = sigma_2 = 0 (as numbers) means smooth
        plates; symbols must not both evaluate to 0 (H = h / sigma).
    area_ratio : float or symbol, keyword
        Real contact area ratio A_c / A_n [-] (area not sheared by the oil).
    land_fraction : float or symbol, keyword
        Non-grooved fraction psi of the nominal area [-].
    smooth : bool, keyword
        Use the smooth forms of the factors.
    smooth_cutoff : bool, keyword
        Use the smooth (C2) cut-off of Phi_fs at H = 7 even with ``smooth=False``. With unequal
        roughness the exact cut (Cui Eq. 8) is a jump of the torque by Phi_fs(7) = 0.0127 of
        phi_f ~ 1.02, which an integrator has to step across (a stiff compliant-shaft DAE cannot);
        the smooth cut differs by < 5e-5 relative for H <= 6.5 and < 1e-6 absolute for H >= 7.5.
    method : {"patir_cheng", "table"}, keyword
        Source of the transmitted factor (:func:`transmitted_shear_factor`).

    Returns
    -------
    T : same type as w_rel
        Viscous torque [N m], same sign as w_rel.
    """
    _check_method(method)
    if _both_zero(sigma_1, sigma_2):
        per_film = 1.0 / h                                                   # Newtonian: 1 / h
    else:
        # factor / h = (factor / H) / sigma, written so that it stays finite at H = 0
        sigma = combined_sigma(sigma_1, sigma_2)
        per_film = _transmitted_per_H(h / sigma, sigma_1, sigma_2, method, smooth, smooth_cutoff) / sigma
    # Cui 2019 Eq. 9 with the transmitted factor over the nominal film h
    return (1.0 - area_ratio) * land_fraction * np.pi * eta * w_rel * (r2**4 - r1**4) / 2.0 * per_film


def grooved_viscous_torque(w_rel, h, eta, r1, r2, groove_depth, angle_ratio, n_films=1):
    """Viscous torque of plates with radial grooves (Liao 2021 Eq. 2).

    T = n pi eta w_rel (r2^4 - r1^4) / (2 (th1 + th2)) (th1 / (h + h_a) + th2 / h), written with
    K2 = th2 / th1 (non-groove / groove angle): the land (gap h) covers K2 / (1 + K2) of each
    period and the groove (gap h + h_a) 1 / (1 + K2). With h_a = 0 it is Liao Eq. 1.

    Parameters
    ----------
    w_rel : float, array or CasADi symbol
        Relative angular speed [rad/s].
    h : float, array or CasADi symbol
        Film thickness on the lands [m].
    eta : float or symbol
        Dynamic viscosity [Pa s].
    r1, r2 : float or symbol
        Inner and outer radius [m].
    groove_depth : float or symbol
        Groove depth h_a [m].
    angle_ratio : float or symbol
        K2 = theta2 / theta1, land angle over groove angle [-].
    n_films : int or symbol
        Number of sheared films n [-].

    Returns
    -------
    T : same type as w_rel
        Viscous torque [N m].
    """
    groove_share = 1.0 / (1.0 + angle_ratio)               # th1 / (th1 + th2)
    land_share = angle_ratio / (1.0 + angle_ratio)          # th2 / (th1 + th2)
    # Liao 2021 Eq. 2
    return (n_films * np.pi * eta * w_rel * (r2**4 - r1**4) / 2.0
            * (groove_share / (h + groove_depth) + land_share / h))
