"""The piston of an engagement: a piston on springs, or none.

``piston_part(scene, pack_area)`` returns :class:`Piston` when the scene declares ``[piston]`` and the
stand-in :class:`NoPiston` otherwise. Both give, once per mode, a drive (:class:`PistonDrive`,
:class:`PressureOnPack`) that answers the pack's questions the same way: how plate 1 moves, the force
on the pack face, the hydraulic power, the seal power, the spring energy, extra outputs; so the
model builder needs no ``if``. The stand-in has no states and no equations: the oil pressure acts
on the pack face and the drive publishes that plate-pack force ``p A``.
"""

import math

from ..simulation.model import Event


class NoPiston:
    """Stand-in for an absent ``[piston]``: the pressure presses the pack face directly (no states).

    Parameters
    ----------
    pack_area : float
        Area the pressure acts on [m^2] (``actuation.area``, else the plate area).
    """

    present = False
    spring_applied = False
    travel = 0.0
    axial_phases = ("pressing",)
    energy_terms = ()
    force_output = ("pack_force_N", "pressure force on the pack")     # (output, label) of the figures

    def __init__(self, pack_area):
        self.pack_area = pack_area

    def state_specs(self, gap_scale, v_scale):
        return []

    def drive(self, state, axial, p, n, H0):
        """The pressure on the pack face in one mode."""
        return PressureOnPack(p * self.pack_area)

    def kinetic_energy_terms(self, state):
        return []


class PressureOnPack:
    """The stand-in's drive: a known force ``face_force`` = p A on the pack face [N]."""

    rates = {}
    seal_power = 0.0
    spring_energy = 0.0

    def __init__(self, face_force):
        self.face_force = face_force

    def first_plate_velocity(self, v_1):
        """Velocity of plate 1 [m/s]: its own state."""
        return v_1

    def push_first_plate(self, W_1, m_1):
        """Plate 1 (mass ``m_1``) under the face force and the load ``W_1`` of film 1 (Bao Eq. 23):
        (face force [N], {state: rate})."""
        return self.face_force, {"v_1": (self.face_force - W_1) / m_1}

    def press_massless(self, d, S, K):
        """Force on the face of a massless pack [N] and the rates it sets ({}): the pressure force."""
        return self.face_force, {}

    def hydraulic_power(self, face_force, face_speed):
        """Work rate of the pressure on the pack face [W]."""
        return face_force * face_speed

    def outputs(self):
        return {}


class Piston:
    """The piston: a mass on springs pushed by the oil and held back by its viscous seal (Bao Eq. 16,
    21); it travels ``piston.travel_to_pack`` freely before it meets plate 1 (the approach phase).

    Parameters
    ----------
    scene : clutchocp.scene.Scene
        An engagement scene with a ``[piston]`` part.
    """

    present = True
    energy_terms = ("E_seal",)
    force_output = ("piston_force_N", "piston drive (springs and pressure)")

    def __init__(self, scene):
        self.scene = scene
        self.spring_applied = scene.variant("piston") == "spring_applied"
        self.travel = scene.get("piston.travel_to_pack", 0.0)
        self.axial_phases = ("approach", "pressing") if self.travel > 0 else ("pressing",)

    def state_specs(self, gap_scale, v_scale):
        """(name, nominal, initial) of the piston position x0 [m] and velocity v0 [m/s]."""
        return [("x0", max(self.travel, gap_scale), 0.0), ("v0", v_scale, 0.0)]

    def position(self, state, axial, n, H0):
        """Piston travel [m]: the state x0 while approaching; once it presses the pack, the free
        travel plus the closure of the films (x0 = travel + sum (H0 - h_i), Bao Eq. 13), so the
        integrated x0 is a record, not a second (drifting) copy of the pack geometry."""
        if axial == "approach":
            return state("x0")
        return self.travel + sum(H0 - state(f"h_{i + 1}") for i in range(n))

    def drive_force(self, p, x0):
        """Net axial force on the piston from oil pressure and springs [N] (before pack and seal)."""
        s = self.scene
        k = s.value("piston.spring_stiffness") * s.value("piston.spring_count")
        area = s.value("piston.area")
        if self.spring_applied:
            return k * (s.value("piston.spring_preload") - x0) - p * area   # Bao Eq. 21
        return p * area - k * (s.value("piston.spring_preload") + x0)

    def spring_energy(self, x0):
        """Energy stored in the piston springs [J] at travel ``x0``."""
        s = self.scene
        k = s.value("piston.spring_stiffness") * s.value("piston.spring_count")
        if self.spring_applied:
            return 0.5 * k * (s.value("piston.spring_preload") - x0) ** 2
        return 0.5 * k * (s.value("piston.spring_preload") + x0) ** 2

    def seal_coefficient(self):
        """Viscous seal friction coefficient eta L pi D / psi [N s/m] (Bao Eq. 16)."""
        s = self.scene
        return (s.value("oil.viscosity") * s.value("piston.seal_length") * math.pi * s.value("piston.seal_diameter")
                / s.value("piston.seal_clearance"))

    def drive(self, state, axial, p, n, H0):
        """The piston in one mode (axial phase ``axial``, pressure ``p`` [Pa])."""
        return PistonDrive(self, state, axial, p, n, H0)

    def kinetic_energy_terms(self, state):
        return [0.5 * self.scene.value("piston.mass") * state("v0") ** 2]

    def impact_event(self, state, rotation, pack, gap_scale):
        """The piston meeting plate 1 at the end of its free travel: approach -> pressing, with the
        pack's impact reset (:meth:`~clutchocp.engagement.pack.PlateMasses.impact_reset`)."""
        reset = pack.impact_reset(state, self.scene.value("piston.mass"))
        return Event("impact", self.travel - state("x0"), f"pressing_{rotation}", direction=-1, reset=reset,
                     scale=max(self.travel, gap_scale))


class PistonDrive:
    """The piston in one mode: its rates, powers and how it moves plate 1 or a massless pack."""

    def __init__(self, piston, state, axial, p, n, H0):
        s = piston.scene
        self.mass = s.value("piston.mass")
        self.v0 = v0 = state("v0")
        c_seal = piston.seal_coefficient()
        x0 = piston.position(state, axial, n, H0)
        self.F_drive = piston.drive_force(p, x0)
        self.net_force = self.F_drive - c_seal * v0        # drive less seal friction [N]
        self.rates = {"x0": v0}
        self.seal_power = c_seal * v0**2
        sign = -1.0 if piston.spring_applied else 1.0
        self._hydraulic_power = sign * p * s.value("piston.area") * v0
        self.spring_energy = piston.spring_energy(x0)

    def free_travel(self):
        """Rates while the piston travels freely, plates at rest (the approach phase)."""
        return {"v0": self.net_force / self.mass}

    def first_plate_velocity(self, v_1):
        """Velocity of plate 1 [m/s]: the piston's (v_1 is its copy)."""
        return self.v0

    def push_first_plate(self, W_1, m_1):
        """Piston and plate 1 moving together (Bao Eq. 23) against the load ``W_1`` of film 1:
        (face force [N]: 0, the pair is one body; {state: rate})."""
        m_front = self.mass + m_1
        front = self.net_force - W_1
        rate = front / m_front
        return 0.0, {"v0": rate, "v_1": rate}

    def press_massless(self, d, S, K):
        """Massless plates: the piston speed fixes the sum of film rates, which sets the force on the
        pack face: v0 = sum (F_face - d_k - S_k) / K_k. (face force [N], {state: rate})."""
        face_force = (self.v0 + sum((dk + Sk) / Kk for dk, Sk, Kk in zip(d, S, K))) / sum(1 / Kk for Kk in K)
        return face_force, {"v0": (self.net_force - face_force) / self.mass}

    def hydraulic_power(self, face_force, face_speed):
        """Work rate of the oil on the piston [W] (its sign: the pressure releases a spring-applied piston)."""
        return self._hydraulic_power

    def outputs(self):
        return {"piston_force_N": self.F_drive}        # springs and pressure on the piston (net drive)


def piston_part(scene, pack_area):
    """The piston part of a scene: :class:`Piston`, or the stand-in :class:`NoPiston`."""
    return Piston(scene) if scene.has("piston") else NoPiston(pack_area)
