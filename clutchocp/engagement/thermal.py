"""The thermal part of an engagement: lumped plate temperatures, or none.

``plate_thermal(scene)`` returns :class:`LumpedPlates` when the scene declares ``[thermal]`` and the
stand-in :class:`NoThermal` otherwise; both publish the same things (states, the interface
temperature the friction and viscosity laws read, state rates, outputs), so the model builder
needs no ``if``. The stand-in has no states and no equations.
"""

import math

import casadi as ca

from ..physics import thermal as heat

# Temperature states are carried in degC; their scale for the integrator and the NLP [K].
TEMPERATURE_SCALE = 100.0


class NoThermal:
    """Stand-in for an absent ``[thermal]`` part: no states, isothermal laws (their own fixed temperatures)."""

    present = False
    state_specs = ()
    symbols = {}

    def interface_temperature(self):
        """None: the viscosity and friction laws use the scene's fixed temperatures."""
        return None

    def rates(self, heat_power):
        return {}

    def outputs(self):
        return {}


class LumpedPlates:
    """Pack-average temperatures of the friction plates and the separators (``[thermal]`` part).

    Every interface of the pack is taken to release the same share of the heat (the pack's mean),
    so one pair of temperatures stands for the pack. See :mod:`clutchocp.physics.thermal`.

    Parameters
    ----------
    scene : clutchocp.scene.Scene
        An engagement scene with a ``[thermal]`` part.
    """

    present = True

    def __init__(self, scene):
        self.T_oil = scene.value("thermal.oil_temperature_C")
        self.T_start = scene.value("thermal.initial_temperature_C")
        self.C_friction = scene.value("thermal.friction_plate_heat_capacity")
        self.C_separator = scene.value("thermal.separator_heat_capacity")
        self.partition = scene.value("thermal.heat_partition")
        area = math.pi * (scene.value("plates.r_outer") ** 2 - scene.value("plates.r_inner") ** 2)
        # One face area per interface for each group (the friction-plate side and the separator side).
        self.conductance = scene.value("thermal.convection_coefficient") * area * scene.value("plates.n_interfaces")
        self.state_specs = (("T_friction", TEMPERATURE_SCALE, self.T_start),
                            ("T_separator", TEMPERATURE_SCALE, self.T_start))
        self.symbols = {name: ca.SX.sym(name) for name, _, _ in self.state_specs}

    def interface_temperature(self):
        """Interface (contact) temperature [degC] as a CasADi expression of the two states."""
        return heat.interface_temperature(self.symbols["T_separator"], self.symbols["T_friction"], self.partition)

    def stored_heat(self):
        """Heat stored in the plates since t = 0 [J]."""
        return (self.C_friction * (self.symbols["T_friction"] - self.T_start)
                + self.C_separator * (self.symbols["T_separator"] - self.T_start))

    def rates(self, heat_power):
        """Rates of the temperature states and of the convected-heat accumulator ``E_convection``.

        Parameters
        ----------
        heat_power : heat released at the interfaces [W] (slip and squeeze-film dissipation).
        """
        dT_f, dT_s, convected = heat.plate_heating_rates(
            heat_power, self.symbols["T_friction"], self.symbols["T_separator"], self.C_friction,
            self.C_separator, self.partition, self.conductance, self.T_oil)
        return {"T_friction": dT_f, "T_separator": dT_s, "E_convection": convected}

    def outputs(self):
        """Published outputs: the interface temperature [degC] and the stored heat [J]."""
        return {"interface_temperature_C": self.interface_temperature(), "stored_heat_J": self.stored_heat()}


def plate_thermal(scene):
    """The thermal part of a scene: :class:`LumpedPlates`, or the stand-in :class:`NoThermal`."""
    return LumpedPlates(scene) if scene.has("thermal") else NoThermal()
