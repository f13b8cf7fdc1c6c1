"""Viscous shear torque of the oil film between rough plates (Patir–Cheng shear factors).

Cui 2019 Eq. 5-9: the average shear stress tau = eta (w1 - w2) r (phi_f - phi_fs) / h_T with
the Patir & Cheng (1979) shear stress factors phi_f (Eq. 6) and phi_fs (Eq. 7-8), integrated
over the land area of the annulus; Liao 2021 Eq. 2 for plates with radial grooves.

Which wall, which sign. (phi_f - phi_fs), phi_fs = (V_r1 - V_r2) Phi_fs, is the mean *viscous*
shear on surface 1. The torque the film transmits is the same on both plates (its momentum
balance); on a rough wall it is the viscous shear plus the form drag of the pressure on the
asperity flanks, on a smooth wall the viscous shear alone. With surface 1 smooth (V_r1 = 0,
V_r2 = 1) Cui's factor is phi_f + Phi_fs, the transmitted one; with surface 1 rough it is
phi_f - Phi_fs, the rough wall's viscous shear, short of the transmitted torque by the form
drag 2 Phi_fs. Patir-Cheng's factors, linear in V_r, give phi_f + Phi_fs for any split of the
roughness (wall i: viscous (V_rj - V_ri) Phi_fs plus form drag 2 V_ri Phi_fs, V_r1 + V_r2 = 1).
Zhang 2021 (Sect. 2.1: w1 the separator, w2 the friction disc; Eq. 10: phi_f - phi_fs) with the
smooth separator as surface 1 gets the plus sign. :func:`transmitted_shear_factor` gives the
transmitted factor, by Patir-Cheng or by a deterministic-flow table (physics/rough_wall_flow.py);
``viscous_torque(..., factors=...)`` uses it.

Units: SI throughout (m, Pa s, rad/s, N m).
"""

import casadi as ca
import numpy as np

from clutchocp.physics import transmitted_shear_table
from clutchocp.physics.backend import (apply_elementwise, exp, fmax, fmin, if_else, is_symbolic, log,
                                       softplus, smooth_step)
from clutchocp.physics.roughness import average_gap, combined_sigma
from clutchocp.simulation.vectorized import register_table

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


def _phi_f_thin(z, eps):
    """Cui Eq. 6, H <= 3 branch (z = H/3 in [0, 1])."""
    poly = -55 + z * (132 + z * (345 + z * (-160 + z * (-405 + z * (60 + 147 * z)))))
    return 35.0 / 32.0 * z * ((1 - z * z) ** 3 * log((z + 1) / eps) + poly / 60.0)


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


def _variance_ratio_difference(sigma_1, sigma_2):
    """V_r1 - V_r2 = (sigma_1^2 - sigma_2^2) / sigma^2 (Cui Eq. 7)."""
    return (sigma_1**2 - sigma_2**2) / (sigma_1**2 + sigma_2**2)


def _both_zero(sigma_1, sigma_2):
    return (not is_symbolic(sigma_1, sigma_2)
            and np.all(np.asarray(sigma_1) == 0) and np.all(np.asarray(sigma_2) == 0))


def shear_factor_phi_fs(H, sigma_1, sigma_2, smooth=False, width=0.1):
    """Patir–Cheng shear stress factor phi_fs (Cui 2019 Eq. 7-8).

    phi_fs = (V_r1 - V_r2) Phi_fs(H), V_ri = (sigma_i / sigma)^2,
    Phi_fs = A3 H^a4 exp(-a5 H + a6 H^2) for 0 <= H <= 7 and 0 for H > 7 (A3 = 11.1, a4 = 2.31,
    a5 = 2.38, a6 = 0.11; Patir & Cheng 1979 isotropic). The cut-off at H = 7 is a jump of
    Phi_fs(7) = 0.0127; Phi_fs = 0 for H <= 0. Equal roughness (or both zero) gives phi_fs = 0.

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
    Hp = fmax(H, 0.0)
    if smooth:
        Hc = 9.0 - softplus(9.0 - Hp, 0.1)            # ~ min(H, 9): keeps exp(a6 H^2) finite
        cut = 1.0 - smooth_step(Hp - H_CUT_FS, width)
    else:
        Hc = fmin(Hp, H_CUT_FS)                       # finite in the unselected branch
        cut = if_else(Hp <= H_CUT_FS, 1.0, 0.0)
    # the base of H^a4 is capped at 10 only to avoid overflow for huge H, where cut is 0
    # (exact) or below exp(-60) (smooth), so the cap changes nothing visible
    Phi_fs = A3 * fmin(Hp, 10.0)**ALPHA4 * exp(-ALPHA5 * Hc + ALPHA6 * Hc * Hc)   # Cui Eq. 8
    return _variance_ratio_difference(sigma_1, sigma_2) * Phi_fs * cut           # Cui Eq. 7


def viscous_torque(w_rel, h, eta, r1, r2, *, sigma_1=0.0, sigma_2=0.0, area_ratio=0.0,
                   land_fraction=1.0, smooth=False, smooth_cutoff=False, factors="cui"):
    """Viscous shear torque of one film between rough annular plates (Cui 2019 Eq. 9).

    T = (1 - A_c/A_n) psi (phi_f - phi_fs) pi eta w_rel (r2^4 - r1^4) / (2 h_T), with H = h/sigma,
    sigma = sqrt(sigma_1^2 + sigma_2^2) and h_T = h Phi(H) + sigma phi(H) the average gap.
    With sigma_1 = sigma_2 = 0 (numbers) it is the Newtonian torque pi eta w (r2^4 - r1^4)/(2h).
    Bao 2020 Eq. 25 writes phi_f + phi_fs and h instead of h_T; this follows Cui.

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
        Use the smooth forms of phi_f and phi_fs.
    smooth_cutoff : bool, keyword
        Use the smooth (C2) cut-off of phi_fs at H = 7 even with ``smooth=False``. With unequal
        roughness the exact cut (Cui Eq. 8) is a jump of the torque by Phi_fs(7) = 0.0127 of
        phi_f ~ 1.02, which an integrator has to step across (a stiff compliant-shaft DAE cannot);
        the smooth cut differs by < 5e-5 relative for H <= 6.5 and < 1e-6 absolute for H >= 7.5.
    factors : {"cui", "patir_cheng", "table"}, keyword
        "cui" (default): Cui's phi_f - phi_fs, the viscous shear on surface 1. "patir_cheng" and
        "table": the transmitted factor of :func:`transmitted_shear_factor` (the torque both
        plates feel), which does not depend on how the roughness is split.

    Returns
    -------
    T : same type as w_rel
        Viscous torque [N m], same sign as w_rel.
    """
    if factors not in ("cui", "patir_cheng", "table"):
        raise ValueError(f"factors must be 'cui', 'patir_cheng' or 'table', got {factors!r}")
    if _both_zero(sigma_1, sigma_2):
        factor, h_T = 1.0, h
    else:
        sigma = combined_sigma(sigma_1, sigma_2)
        H = h / sigma
        if factors == "cui":
            factor = (shear_factor_phi_f(H, smooth=smooth)
                      - shear_factor_phi_fs(H, sigma_1, sigma_2, smooth=smooth or smooth_cutoff))
        else:
            factor = transmitted_shear_factor(H, method=factors, smooth=smooth,
                                              smooth_cutoff=smooth_cutoff)
        h_T = average_gap(h, sigma)                                    # Bao Eq. 10
    # Cui 2019 Eq. 9
    return (1.0 - area_ratio) * land_fraction * factor * np.pi * eta * w_rel * (r2**4 - r1**4) / (2.0 * h_T)


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
register_table(_TRANSMITTED_SPLINE, _TABLE_U)   # numpy-translated models evaluate it with numpy


def transmitted_shear_factor(H, method="patir_cheng", smooth=False, smooth_cutoff=False, width=0.05):
    """Shear factor of the torque a film between a rough and a smooth wall transmits.

    Replaces (phi_f - phi_fs) of Cui 2019 Eq. 9 (mean stress = eta (w1 - w2) r factor / h_T).

    "patir_cheng": phi_f + Phi_fs (Cui Eq. 6 and 8): the viscous shear on the smooth wall, equal to
    the rough wall's viscous shear phi_f - Phi_fs plus its form drag 2 Phi_fs (see the module
    docstring for the sign). Jumps by Phi_fs(7) = 0.0127 at H = 7 unless smoothed.

    "table": phi_T from the deterministic Reynolds flow over isotropic Gaussian rough walls
    (physics/rough_wall_flow.py; no flow and no shear below the gap 3 eps* sigma = 0.01 sigma),
    tabulated for 0 <= H <= 12 (standard error 1-4 % in the mixed range, see the table module) and
    interpolated as 1 + u^2 y(u), u = 1 / (1 + H), with a C2 cubic B-spline y through the table and
    y(0) = 2.5, so phi_T -> 1 + 2.5 / H^2 as H grows. H <= 0 uses the value at H = 0 (a kink there,
    as phi_f's max(H, 0); ``smooth`` replaces max(H, 0) by softplus(H, width)).

    Parameters
    ----------
    H : float, array or CasADi symbol
        Film thickness ratio h / sigma [-].
    method : {"patir_cheng", "table"}
        Source of the factor.
    smooth : bool
        Smooth forms (phi_f, phi_fs as in :func:`shear_factor_phi_f`, :func:`shear_factor_phi_fs`;
        the table's H <= 0 clamp by softplus).
    smooth_cutoff : bool
        Smooth cut-off of Phi_fs at H = 7 even with ``smooth=False`` ("patir_cheng" only).
    width : float
        Softplus width in H of the table's clamp with ``smooth=True`` [-].

    Returns
    -------
    factor : same type as H
        Transmitted shear factor [-].
    """
    if method == "patir_cheng":
        return (shear_factor_phi_f(H, smooth=smooth)
                + shear_factor_phi_fs(H, 1.0, 0.0, smooth=smooth or smooth_cutoff))
    if method == "table":
        Hp = softplus(H, width) if smooth else fmax(H, 0.0)
        u = 1.0 / (1.0 + Hp)
        return 1.0 + u * u * apply_elementwise(_TRANSMITTED_SPLINE, u)
    raise ValueError(f"method must be 'patir_cheng' or 'table', got {method!r}")


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
