"""Spline friction and the axial attenuation of contact pressure through a plate pack.

Chen, Zhang, Feng, Wang & Wang 2021, Appl. Sci. 11, 814 ("Chen" below). Each plate is
held in its spline by teeth that rub axially while the pack closes; the spline friction
force takes part of the axial load, so every interface further from the piston carries
less pressure than the one before.

Derivation (Chen Eq. 1-8). A plate between interfaces k and k+1 transmits the torque
T = (2 pi / 3) mu (r2^3 - r1^3) (p_k + p_{k+1}) (Eq. 6); its spline teeth then carry the
friction force F_s = mu_s T / (R_p cos alpha) (Eq. 3), and the axial balance
p_{k+1} A = p_k A - F_s with A = pi (r2^2 - r1^2) (Eq. 4) gives
p_{k+1} = p_k (1 - zeta) / (1 + zeta) with zeta from Eq. 8. The plate next to the piston
rubs on one face only, so p_1 = p_0 / (1 + zeta).

Erratum (Chen Eq. 10): the total torque is written as a sum over i = 1, 3, 5, ... of
mu p_i, i.e. over every other interface. By Eq. 6 each friction disc transmits
mu (p_i + p_{i+1}), so summing over the discs counts every interface once:
T = (2 pi / 3)(r2^3 - r1^3) sum_{k=1}^{M-1} mu_k p_k. Only this all-interface sum
reproduces Chen's own Table 3 (to 0.05 %); the odd-only sum gives about half of it.
"""

import numpy as np

from clutchocp.errors import ModelError
from clutchocp.physics import backend as B

__all__ = [
    "attenuation_coefficient",
    "interface_pressures",
    "pack_torque",
    "pack_torque_uniform",
    "equivalent_cof",
]


def attenuation_coefficient(mu, mu_spline, r1, r2, pitch_radius, pressure_angle):
    """Attenuation coefficient zeta of one plate type (Chen Eq. 8).

    Parameters
    ----------
    mu : float, array or CasADi
        Interface friction coefficient of the friction pairs [-].
    mu_spline : float, array or CasADi
        Friction coefficient of the spline teeth of this plate [-].
    r1, r2 : float
        Inner and outer radius of the friction surface [m].
    pitch_radius : float
        Spline pitch radius R_p of this plate [m].
    pressure_angle : float
        Spline pressure angle alpha of this plate [rad].

    Returns
    -------
    zeta : same type as the inputs
        2 mu mu_s (r2^3 - r1^3) / (3 R_p (r2^2 - r1^2) cos alpha) [-].
    """
    # Chen Eq. 8
    return (2 * mu * mu_spline * (r2**3 - r1**3)
            / (3 * pitch_radius * (r2**2 - r1**2) * B.cos(pressure_angle)))


def interface_pressures(p0, zeta_first, zeta_second, n_interfaces):
    """Contact pressure on each friction interface of the pack (Chen Eq. 7).

    p_1 = p0 / (1 + zeta_first); then p_{k+1} = p_k (1 - zeta) / (1 + zeta) with zeta
    alternating zeta_second, zeta_first, zeta_second, ... (the plate between interface k
    and k+1 is of the second type when k is odd, since plates alternate).

    Parameters
    ----------
    p0 : float, array or CasADi
        Pressure applied by the piston [Pa].
    zeta_first : float, array or CasADi
        Attenuation coefficient of the plate next to the piston (for Chen's pack the
        separator plate) [-], from :func:`attenuation_coefficient`.
    zeta_second : float, array or CasADi
        Attenuation coefficient of the other plate type [-].
    n_interfaces : int
        Number of friction interfaces (friction pairs), M - 1 in Chen's notation.

    Returns
    -------
    pressures : numpy array of shape (n_interfaces, *shape(p0)) for numeric input, or a
        list of CasADi expressions for symbolic input [Pa].

    Raises
    ------
    ModelError
        If n_interfaces < 1, or a numeric zeta lies outside [0, 1) (then the pressure
        would not stay positive through the pack).
    """
    n = int(n_interfaces)
    if n < 1 or n != n_interfaces:
        raise ModelError(f"n_interfaces must be a positive integer, got {n_interfaces!r}")
    symbolic = B.is_symbolic(p0, zeta_first, zeta_second)
    if not symbolic:
        for name, z in (("zeta_first", zeta_first), ("zeta_second", zeta_second)):
            z = np.asarray(z, dtype=float)
            if np.any(z < 0) or np.any(z >= 1):
                raise ModelError(f"{name} must lie in [0, 1), got {z}")
    zetas = (zeta_first, zeta_second)
    pressures = [p0 / (1 + zeta_first)]  # Chen Eq. 7, i = 0 (one rubbing face)
    for k in range(1, n):
        z = zetas[k % 2]
        pressures.append(pressures[-1] * (1 - z) / (1 + z))  # Chen Eq. 7, i >= 1
    if symbolic:
        return pressures
    return np.asarray(np.broadcast_arrays(*pressures), dtype=float)


def pack_torque(pressures, mu, r1, r2):
    """Friction torque of a pack from its interface pressures (Chen Eq. 6 summed; Eq. 10 corrected).

    T = (2 pi / 3)(r2^3 - r1^3) sum_k mu_k p_k over every interface k (see the module
    note on Chen Eq. 10).

    Parameters
    ----------
    pressures : sequence of float/array/CasADi
        Interface pressures p_k [Pa], e.g. from :func:`interface_pressures`.
    mu : float, numpy array, CasADi, list/tuple, or callable
        Interface friction coefficient [-]. A float, array or CasADi value applies to
        every interface (an array broadcasts against each interface pressure, e.g. one
        COF per applied pressure); a list or tuple gives one value per interface; a
        function mu(p [Pa]) is evaluated at each interface pressure (Chen's mu(p_i),
        Eq. 10).
    r1, r2 : float
        Inner and outer radius of the friction surface [m].

    Returns
    -------
    torque : same type as the pressures [N m].
    """
    pressures = list(pressures)
    if callable(mu):
        mus = [mu(p) for p in pressures]
    elif isinstance(mu, (list, tuple)):
        mus = list(mu)
        if len(mus) != len(pressures):
            raise ModelError(f"mu has {len(mus)} values for {len(pressures)} interfaces")
    else:
        mus = [mu] * len(pressures)
    total = 0
    for m, p in zip(mus, pressures):
        total = total + m * p
    return 2 * np.pi / 3 * (r2**3 - r1**3) * total  # Chen Eq. 6 summed over all interfaces


def pack_torque_uniform(p0, mu, r1, r2, n_interfaces):
    """Torque of a pack without spline friction (Chen Eq. 9).

    Parameters
    ----------
    p0 : float, array or CasADi
        Applied pressure, equal on every interface [Pa].
    mu : float, array or CasADi
        Interface friction coefficient [-].
    r1, r2 : float
        Inner and outer radius [m].
    n_interfaces : int
        Number of friction interfaces (M - 1) [-].

    Returns
    -------
    torque : (2 pi / 3) n mu p0 (r2^3 - r1^3) [N m].
    """
    return 2 * np.pi / 3 * n_interfaces * mu * p0 * (r2**3 - r1**3)  # Chen Eq. 9


def equivalent_cof(torque, p0, r1, r2, n_interfaces):
    """Equivalent friction coefficient mu* of a measured pack torque (Chen Eq. 11).

    Parameters
    ----------
    torque : float, array or CasADi
        Total pack torque T* [N m].
    p0 : float, array or CasADi
        Applied pressure [Pa].
    r1, r2 : float
        Inner and outer radius [m].
    n_interfaces : int
        Number of friction interfaces (M - 1) [-].

    Returns
    -------
    mu_star : 3 T* / (2 pi p0 (r2^3 - r1^3) n) [-], the inverse of :func:`pack_torque_uniform`.
    """
    return 3 * torque / (2 * np.pi * p0 * (r2**3 - r1**3) * n_interfaces)  # Chen Eq. 11
