"""The plate pack of an engagement: plates with masses, or a massless pack.

``pack_part(scene, n, plate_masses)`` returns :class:`PlateMasses` for ``pack.model = "masses"`` and
:class:`MasslessPack` otherwise. Both turn the film load coefficients and the drive of the piston
part (:mod:`clutchocp.engagement.piston`) into the film rates of one pressing mode
(:meth:`press`), and publish their states, kinetic energy and impact reset the same way, so the
model builder needs no ``if``. The massless pack has no states: its plates are in force balance.
"""

import math
from dataclasses import dataclass

import casadi as ca

from ..errors import ModelError


@dataclass
class Pressing:
    """The axial dynamics of the pack in one mode.

    dh : film rates dh_i/dt [m/s]; rates : {state: rate}; face_force : force on the pack face [N];
    hydraulic_power, spline_power : [W].
    """

    dh: list
    rates: dict
    face_force: object
    hydraulic_power: object
    spline_power: object = 0.0


class PlateMasses:
    """Plates with masses (``pack.model = "masses"``): each plate a state v_i, driven by the film loads
    on its faces (Bao Eq. 13, 23).

    Parameters
    ----------
    scene : clutchocp.scene.Scene
    n : int
        Number of films (interfaces).
    plate_masses : numpy.ndarray
        Mass of each moving plate, piston side first [kg].
    """

    has_masses = True

    def __init__(self, scene, n, plate_masses):
        if scene.has("spline"):
            raise ModelError("spline: spline friction is modelled for the massless pack (pack.model = 'massless')")
        self.n = n
        self.plate_masses = plate_masses

    def state_specs(self, v_scale):
        """(name, nominal, initial) of the plate velocities v_1 .. v_n [m/s]."""
        return [(f"v_{i + 1}", v_scale, 0.0) for i in range(self.n)]

    def press(self, state, drive, K, S, T_film):
        """Plate accelerations from the film loads W = K (-dh/dt) + S (Bao Eq. 12-13, 23)."""
        n, m = self.n, self.plate_masses
        v = [state(f"v_{i + 1}") for i in range(n)]
        v[0] = drive.first_plate_velocity(v[0])
        v_next = v[1:] + [0.0]
        dh = [vn - vi for vi, vn in zip(v, v_next)]                      # Bao Eq. 13
        W = [Ki * (-dhi) + Si for Ki, dhi, Si in zip(K, dh, S)]
        face_force, rates = drive.push_first_plate(W[0], m[0])
        for i in range(1, n):
            rates[f"v_{i + 1}"] = (W[i - 1] - W[i]) / m[i]                   # Bao Eq. 23
        return Pressing(dh, rates, face_force, drive.hydraulic_power(face_force, v[0]))

    def kinetic_energy_terms(self, state):
        return [0.5 * self.plate_masses[i] * state(f"v_{i + 1}") ** 2 for i in range(self.n)]

    def impact_reset(self, state, piston_mass):
        """The piston meeting plate 1: a plastic impact conserving momentum (Bao Eq. 22); its loss
        goes to E_impact."""
        m0, m1 = piston_mass, self.plate_masses[0]
        v0 = state("v0")
        v_after = m0 * v0 / (m0 + m1)                                 # Bao Eq. 22
        loss = 0.5 * m0 * v0**2 - 0.5 * (m0 + m1) * v_after**2
        return {"v0": v_after, "v_1": v_after, "E_impact": state("E_impact") + loss}


class MasslessPack:
    """A massless pack (``pack.model = "massless"``): no states; every plate is in force balance, so
    each film carries the face force less the spline friction before it (Chen 2021 Eq. 1-4)."""

    has_masses = False

    def __init__(self, scene, n, plate_masses):
        self.scene = scene
        self.n = n
        self.plate_masses = plate_masses

    def state_specs(self, v_scale):
        return []

    def spline_deductions(self, torques):
        """Cumulative spline-friction forces d_k taken from the pack force before film k [N].

        A plate carrying torque T in its spline feels an axial friction mu_s T / (R_p cos alpha)
        against its motion (Chen 2021 Eq. 1-4); the first plate has one friction face, the others two.
        """
        s = self.scene
        if not s.has("spline"):
            return [0.0] * self.n
        mu_s = float(s.value("spline.friction_coefficients")[0])
        kinds = ("separator", "friction") if s.value("spline.first") == "separator" else ("friction", "separator")
        radius = {k: s.value(f"spline.pitch_radius_{k}") for k in kinds}
        angle = {k: s.value(f"spline.pressure_angle_{k}") for k in kinds}
        coeff = [mu_s / (radius[kinds[i % 2]] * math.cos(angle[kinds[i % 2]])) for i in range(self.n)]
        deductions = [coeff[0] * ca.fabs(torques[0])]
        for k in range(1, self.n):
            deductions.append(deductions[-1] + coeff[k] * (ca.fabs(torques[k - 1]) + ca.fabs(torques[k])))
        return deductions

    def press(self, state, drive, K, S, T_film):
        """Film rates of the force balance: F_k = F_face - d_k = K_k (-dh_k/dt) + S_k (Bao Eq. 12)."""
        d = self.spline_deductions(T_film)
        face_force, rates = drive.press_massless(d, S, K)
        force = [face_force - dk for dk in d]
        dh = [-(Fk - Sk) / Kk for Fk, Sk, Kk in zip(force, S, K)]
        # Work of the face force not passed on to the films is lost in the splines.
        spline_power = sum((face_force - Fk) * (-dhi) for Fk, dhi in zip(force, dh))
        hydraulic_power = drive.hydraulic_power(face_force, sum(-dhi for dhi in dh))
        return Pressing(dh, rates, face_force, hydraulic_power, spline_power)

    def kinetic_energy_terms(self, state):
        return []

    def impact_reset(self, state, piston_mass):
        """None: massless plates take no momentum, the piston keeps its speed."""
        return None


def pack_part(scene, n, plate_masses):
    """The pack part of a scene: :class:`PlateMasses`, or :class:`MasslessPack`."""
    return (PlateMasses if scene.variant("pack") == "masses" else MasslessPack)(scene, n, plate_masses)
