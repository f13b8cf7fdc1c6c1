"""Unequal oil films through a hydro-viscous clutch pack and the revised torque.

Liao, Yang, Hu & Gong 2021, Energies 14, 7884 ("Liao" below).

Each plate of an HVC pack floats between two films. In steady running the load of the
film in front of a plate equals the load of the film behind it plus the static
(spline) friction force on the plate (Liao Eq. 12). With equal inlet pressure and
speed everywhere only the groove (hydrodynamic) term F4 differs between films
(Eq. 3, 9), so, divided by K1,

    1 / g(delta_i) = 1 / g(delta_{i+1}) + (K3/K1) f(delta_j)                  (Liao Eq. 13)
    g(delta) = delta^3 + K2 (delta + h_a)^3,   f(delta) = K2 / delta + 1 / (delta + h_a),

K2 = theta2/theta1 (non-groove / groove angle), h_a the groove depth. Notes on the paper:

* Erratum, Eq. 13: the same film thickness is called delta_i (film load, Eq. 9) and
  sigma_i (friction force, Eq. 11) in one equation; both are the thickness of film i.
* Eq. 12 is not consistent with itself: its first line F_d1 = F_d2 + F_m1 puts the
  friction force at the leading film (j = i, as Eq. 13 prints), its general line
  F_d(i-1) = F_di + F_mi at the trailing film (j = i + 1). Only the trailing form
  reproduces Liao's Table 3: starting from the first film that Table 3 implies
  (below), it gives the tabulated modified coefficients alpha_i within 16 % (per-test
  median 8 %), the paper's "new formula" torques within 7 % and the bench torques within
  4 %, while the leading form grows the films much too
  fast (sigma_5/sigma_1 = 2.1 against 1.7 tabulated, up to 12 against 3.3 for K2 = 2.5).
  ``friction_film="trailing"`` is therefore the default; ``"leading"`` is Eq. 13 as printed.
* Units of K3/K1: it is a force ratio times a length^3 / length, i.e. 1/length^2. In SI
  (1/m^2) the paper's 0.05-0.15 would change the films by < 1e-5, in 1/cm^2 by ~1 %; in
  1/um^2 the films run away (a second film of tens of metres). In 1/mm^2 (the unit of the groove depths in Table 1 and 3) the films grow by
  15-50 % per film, the pattern of Table 3. So K3/K1 = 0.1 means 0.1 mm^-2 = 1e5 m^-2.
* First film: Liao does not state it. Table 3 gives, per test, the torque by the original
  formula (Eq. 2 with one film thickness sigma_bar for all n films) and alpha_i = sigma_bar /
  sigma_i; inverting Eq. 2 for sigma_bar and dividing by alpha_1 gives delta_1 = 0.105-0.165 mm
  (median 0.13 mm) over the nine tests (computed in clutchocp.analyses.liao2021).
  Note that Table 3's alpha_i do not satisfy sum(1/alpha_i) = n, as the definition
  alpha_i = mean(sigma) / sigma_i would require (sum 6.3-8.7 for n = 5): sigma_bar is the
  film of the original formula, not the mean of the unequal films.

The original torque formulas, Liao Eq. 2 (and Eq. 1 with h_a = 0) for n equal films, are
:func:`clutchocp.physics.shear.grooved_viscous_torque`; :func:`revised_torque` is Eq. 14.

The film recursion solves one scalar equation per film by Newton's method. Its residual
R(x) = 1/g(x) [+ k f(x)] - c is decreasing in x > 0, convex for K2 > 0.03 (Liao: 1.5-2.5;
a non-convergence is caught for numeric input) and positive at the
previous film, so Newton started there (or at a larger point where R is still >= 0)
increases monotonically to the root (no overshoot, no negative film); a fixed number of
steps makes the same code build CasADi expressions.
"""

import numpy as np

from clutchocp.errors import ModelError
from clutchocp.physics import backend as B

__all__ = [
    "groove_load_factor",
    "friction_load_factor",
    "film_balance_residual",
    "film_distribution",
    "modified_factors",
    "revised_torque",
]

_FRICTION_FILMS = ("trailing", "leading")


def groove_load_factor(delta, groove_depth, angle_ratio):
    """Groove film load divided by K1: F4 / K1 = 1 / (delta^3 + K2 (delta + h_a)^3) (Liao Eq. 9).

    Parameters
    ----------
    delta : float, array or CasADi
        Film thickness on the lands [m].
    groove_depth : float
        Groove depth h_a [m].
    angle_ratio : float
        K2 = theta2 / theta1, non-groove over groove angle [-].

    Returns
    -------
    F4/K1 [1/m^3].
    """
    return 1 / (delta**3 + angle_ratio * (delta + groove_depth) ** 3)  # Liao Eq. 9


def friction_load_factor(delta, groove_depth, angle_ratio):
    """Static friction force on a plate divided by K3: K2 / delta + 1 / (delta + h_a) (Liao Eq. 11).

    Parameters
    ----------
    delta : float, array or CasADi
        Film thickness on the lands [m].
    groove_depth : float
        Groove depth h_a [m].
    angle_ratio : float
        K2 = theta2 / theta1 [-].

    Returns
    -------
    F_m/K3 [1/m].
    """
    return angle_ratio / delta + 1 / (delta + groove_depth)  # Liao Eq. 11


def film_balance_residual(delta_i, delta_next, groove_depth, angle_ratio, k3_over_k1, *,
                          friction_film="trailing"):
    """Residual of the plate balance between film i and film i+1, divided by K1 (Liao Eq. 12-13).

    F4(delta_i)/K1 - F4(delta_next)/K1 - (K3/K1) F_m(delta_j)/K3, j = i + 1 ("trailing",
    the general line of Eq. 12) or j = i ("leading", Eq. 13 as printed). Zero at balance.

    Parameters
    ----------
    delta_i, delta_next : float, array or CasADi
        Thickness of film i and film i+1 (counted from the piston) [m].
    groove_depth : float
        Groove depth h_a [m].
    angle_ratio : float
        K2 = theta2 / theta1 [-].
    k3_over_k1 : float, array or CasADi
        K3/K1 [1/m^2] (Liao's 0.1 is 0.1 mm^-2 = 1e5 m^-2, see the module note).
    friction_film : {"trailing", "leading"}
        Film whose torque sets the static friction force (module note).

    Returns
    -------
    residual [1/m^3].
    """
    _check_choice(friction_film)
    j = delta_next if friction_film == "trailing" else delta_i
    return (groove_load_factor(delta_i, groove_depth, angle_ratio)
            - groove_load_factor(delta_next, groove_depth, angle_ratio)
            - k3_over_k1 * friction_load_factor(j, groove_depth, angle_ratio))  # Liao Eq. 13


def film_distribution(first_film, n_films, groove_depth, angle_ratio, k3_over_k1, *,
                      friction_film="trailing", newton_steps=60, rtol=1e-12, max_film=0.01):
    """Thickness of every film of an HVC pack, from the piston side (Liao Eq. 13).

    Parameters
    ----------
    first_film : float, array or CasADi
        Thickness of the film next to the piston [m] (not given by Liao; see module note).
    n_films : int
        Number of films n [-].
    groove_depth : float
        Groove depth h_a [m].
    angle_ratio : float
        K2 = theta2 / theta1 [-].
    k3_over_k1 : float, array or CasADi
        K3/K1 [1/m^2] (>= 0).
    friction_film : {"trailing", "leading"}
        Where the static friction force is evaluated (module note); "trailing" reproduces
        Liao's Table 3.
    newton_steps : int
        Newton steps per film (fixed, so that symbolic input builds one expression).
    rtol : float
        For numeric input: required relative residual; a film that does not converge
        raises ModelError.
    max_film : float
        For numeric input: a film thicker than this [m] raises ModelError (the films run
        away: the static friction is more than the groove load can balance and the pack
        opens; each film then grows roughly as the cube of the one before).

    Returns
    -------
    films : numpy array of shape (n_films, *shape(first_film)) [m] for numeric input, or a
        list of CasADi expressions. Films grow along the pack when K3/K1 > 0 and are all
        equal to ``first_film`` when K3/K1 = 0.

    Raises
    ------
    ModelError
        If n_films < 1, or (numeric input) the balance has no positive solution — with
        ``friction_film="leading"`` the friction force can exceed the whole film load —
        a film exceeds ``max_film``, or Newton did not converge.
    """
    _check_choice(friction_film)
    n = int(n_films)
    if n < 1 or n != n_films:
        raise ModelError(f"n_films must be a positive integer, got {n_films!r}")
    symbolic = B.is_symbolic(first_film, k3_over_k1)
    h_a, k2, kap = groove_depth, angle_ratio, k3_over_k1
    trailing = friction_film == "trailing"
    films = [first_film]
    for i in range(1, n):
        prev = films[-1]
        # Liao Eq. 13 rearranged: 1/g(x) [+ kap f(x)] = c
        c = groove_load_factor(prev, h_a, k2)
        if not trailing:
            c = c - kap * friction_load_factor(prev, h_a, k2)
            if not symbolic and np.any(np.asarray(c) <= 0):
                raise ModelError(
                    f"film {i + 1}: the static friction force exceeds the film load (Liao Eq. 13 "
                    f"with friction_film='leading' has no solution); reduce hvc.friction_ratio or the first film"
                )
        # Start at the largest of three points where R >= 0 (so Newton stays left of the root):
        # the previous film, and the roots of the bounds g <= (1 + K2)(x + h_a)^3 and
        # f >= (1 + K2)/(x + h_a), which are close to the root when films run away.
        x = B.fmax(prev, (1 / ((1 + k2) * c)) ** (1 / 3) - h_a)
        if trailing:
            x = B.fmax(x, kap * (1 + k2) / c - h_a)
        if not symbolic and np.any(np.asarray(x) > max_film):  # x <= root: stop before overflow
            raise _runaway(i + 1, max_film)
        for _ in range(newton_steps):
            gx = x**3 + k2 * (x + h_a) ** 3
            dg = 3 * x**2 + 3 * k2 * (x + h_a) ** 2
            r = 1 / gx - c
            dr = -dg / gx**2
            if trailing:
                r = r + kap * friction_load_factor(x, h_a, k2)
                dr = dr - kap * (k2 / x**2 + 1 / (x + h_a) ** 2)
            x = x - r / dr
        if not symbolic:
            if np.any(np.asarray(x) > max_film):
                raise _runaway(i + 1, max_film)
            resid = np.abs(film_balance_residual(prev, x, h_a, k2, kap, friction_film=friction_film))
            if np.any(~np.isfinite(x)) or np.any(resid > rtol * np.asarray(c)):
                raise ModelError(f"film {i + 1}: Newton did not converge in {newton_steps} steps")
        films.append(x)
    if symbolic:
        return films
    return np.asarray(np.broadcast_arrays(*films), dtype=float)


def modified_factors(films):
    """Mean film and Liao's modified factors alpha_i = mean / sigma_i (Liao, text above Eq. 14).

    Parameters
    ----------
    films : sequence of float/array/CasADi, or numpy array (films along axis 0)
        Film thicknesses sigma_i [m].

    Returns
    -------
    alpha : list (symbolic) or numpy array (numeric) of the factors [-]
    sigma_bar : mean film sum(sigma_i) / n [m]
    """
    films = list(films)
    n = len(films)
    total = 0
    for s in films:
        total = total + s
    sigma_bar = total / n
    alpha = [sigma_bar / s for s in films]
    if not B.is_symbolic(*films):
        alpha = np.asarray(alpha, dtype=float)
    return alpha, sigma_bar


def revised_torque(w_rel, films, eta, r1, r2, groove_depth, angle_ratio):
    """Viscous torque of an HVC pack with unequal films (Liao Eq. 14).

    T_r = pi eta w (r2^4 - r1^4) / (2 (theta1 + theta2)) *
          [sum alpha_i theta1 / (sigma_bar + alpha_i h_a) + sum alpha_i theta2 / sigma_bar],
    evaluated in this alpha form (Eq. 14, second line); it equals the sum over films of the
    grooved single-film torque (Liao Eq. 2 with n = 1, ``shear.grooved_viscous_torque``), and
    with equal films n times that torque.

    Parameters
    ----------
    w_rel : float, array or CasADi
        Relative angular speed omega1 - omega2 [rad/s].
    films : sequence of float/array/CasADi, or numpy array (films along axis 0)
        Film thicknesses sigma_i on the lands [m].
    eta : float
        Dynamic viscosity [Pa s].
    r1, r2 : float
        Inner and outer radius [m].
    groove_depth : float
        Groove depth h_a [m] (0 for plain plates, Liao Eq. 1).
    angle_ratio : float
        K2 = theta2 / theta1 [-].

    Returns
    -------
    torque [N m].
    """
    alpha, sigma_bar = modified_factors(films)
    groove_share = 1 / (1 + angle_ratio)  # theta1 / (theta1 + theta2)
    land_share = angle_ratio / (1 + angle_ratio)  # theta2 / (theta1 + theta2)
    total = 0
    for a in alpha:
        total = total + a * groove_share / (sigma_bar + a * groove_depth) + a * land_share / sigma_bar
    return np.pi * eta * w_rel * (r2**4 - r1**4) / 2 * total  # Liao Eq. 14


def _runaway(film, max_film):
    return ModelError(
        f"film {film}: the films run away (thicker than {max_film:g} m): the static friction exceeds "
        f"what the groove load can balance; reduce hvc.friction_ratio or the first film"
    )


def _check_choice(friction_film):
    if friction_film not in _FRICTION_FILMS:
        raise ModelError(f"friction_film = {friction_film!r}: allowed values are {', '.join(_FRICTION_FILMS)}")
