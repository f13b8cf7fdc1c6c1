"""The thermal part of an engagement: plate temperatures with conduction through the lining, or none.

``plate_thermal(scene)`` returns :class:`LiningConduction` when the scene declares ``[thermal]`` and the
stand-in :class:`NoThermal` otherwise; both publish the same things (states, the interface temperature
the friction and viscosity laws read, state rates, outputs), so the model builder needs no ``if``. The
stand-in has no states and no equations.
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


class LiningConduction:
    """Pack-mean plate temperatures (``[thermal]`` part): the interface, the lining across its thickness,
    the friction plate's core (see :mod:`clutchocp.physics.thermal`).

    Every interface of the pack is taken to release the same share of the heat (the pack's mean), so one
    chain of nodes stands for the pack. The states, surface first: ``T_interface`` (the lining's surface
    and the lumped separator steel in perfect contact with it), ``T_lining_1`` .. ``T_lining_{N-1}``
    inside the lining, ``T_core`` (the lining's back face and the lumped steel core of the friction
    plate). The separator convects to the oil at the interface temperature, the friction plate at its
    core temperature.

    Parameters
    ----------
    scene : clutchocp.scene.Scene
        An engagement scene with a ``[thermal]`` part (validated: a lining thickness > 0, a friction-plate
        heat capacity that holds the linings).
    """

    present = True

    def __init__(self, scene):
        self.T_oil = scene.value("thermal.oil_temperature_C")
        self.T_start = scene.value("thermal.initial_temperature_C")
        n = scene.value("plates.n_interfaces")
        area = n * math.pi * (scene.value("plates.r_outer") ** 2 - scene.value("plates.r_inner") ** 2)
        thickness = scene.value("plates.lining_thickness")
        k, rho, c = (scene.value(f"thermal.lining_{key}") for key in ("conductivity", "density", "specific_heat"))
        self.cells = scene.value("thermal.lining_cells")
        self.C_separator = scene.value("thermal.separator_heat_capacity")
        self.C_friction = scene.value("thermal.friction_plate_heat_capacity")
        self.C_lining = area * thickness * rho * c
        # One face area per interface for each group (the separator side and the friction-plate side).
        self.conductance = scene.value("thermal.convection_coefficient") * area
        self.chain = heat.lining_chain(thickness, self.cells, k, rho, c, area, surface_capacity=self.C_separator,
                                       back_capacity=self.C_friction - self.C_lining,
                                       surface_loss=self.conductance, back_loss=self.conductance)
        names = ["T_interface"] + [f"T_lining_{j}" for j in range(1, self.cells)] + ["T_core"]
        self.state_specs = tuple((name, TEMPERATURE_SCALE, self.T_start) for name in names)
        self.symbols = {name: ca.SX.sym(name) for name in names}
        self.names = tuple(names)

    def temperatures(self):
        """The node temperatures [degC] as CasADi symbols, surface first."""
        return [self.symbols[name] for name in self.names]

    def interface_temperature(self):
        """Interface (lining surface) temperature [degC] as a CasADi expression of the states."""
        return self.symbols["T_interface"]

    def friction_plate_temperature(self, T=None):
        """Mean (bulk) temperature of the friction plates [degC]: lining and core, weighted by heat capacity.

        ``T``: node temperatures (default: the state symbols)."""
        T = self.temperatures() if T is None else T
        own = list(self.chain.capacity)
        own[0] -= self.C_separator                  # node 0's share of the lining (the rest is the separator)
        return sum(C * Tj for C, Tj in zip(own, T)) / self.C_friction

    def stored_heat(self):
        """Heat stored in the plates since t = 0 [J] (every node)."""
        return self.chain.stored_heat(self.temperatures(), self.T_start)

    def rates(self, heat_power):
        """Rates of the temperature states and of the convected-heat accumulator ``E_convection``.

        Parameters
        ----------
        heat_power : heat released at the interfaces [W] (slip and squeeze-film dissipation).
        """
        dT, convected = self.chain.rates(self.temperatures(), heat_power, self.T_oil)
        return {**dict(zip(self.names, dT)), "E_convection": convected}

    def outputs(self):
        """Published outputs: the interface (lining surface) temperature, the friction plates' bulk
        temperature [degC] and the stored heat [J]."""
        return {"interface_temperature_C": self.interface_temperature(),
                "friction_plate_temperature_C": self.friction_plate_temperature(),
                "stored_heat_J": self.stored_heat()}

    def cooled(self, temperatures, time):
        """Node temperatures {state: degC} after ``time`` [s] of the open clutch (no heat) from
        ``temperatures`` {state: degC} (the chain's linear system, solved exactly)."""
        T = self.chain.relax([temperatures[name] for name in self.names], time, self.T_oil)
        return dict(zip(self.names, (float(v) for v in T)))


def plate_thermal(scene):
    """The thermal part of a scene: :class:`LiningConduction`, or the stand-in :class:`NoThermal`."""
    return LiningConduction(scene) if scene.has("thermal") else NoThermal()
