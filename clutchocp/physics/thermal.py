"""Lumped temperatures of the two plate groups of a wet clutch (friction plates and separators).

The heat Q [W] released at the friction interfaces (slip and squeeze-film shear) divides between
the two bodies in contact in the ratio of their thermal effusivities e = sqrt(k rho c): for two
semi-infinite bodies brought into contact, the heat flux into each is proportional to its
effusivity and the contact temperature is the effusivity-weighted mean of the body temperatures
(Carslaw & Jaeger, Conduction of Heat in Solids, 2nd ed. 1959, Sec. 2.16; the classical partition
of frictional heat). Each group is one heat capacity C that also exchanges heat with the oil by
convection, G = h A:

    C_s dT_s/dt = a Q - G_s (T_s - T_oil),    C_f dT_f/dt = (1 - a) Q - G_f (T_f - T_oil),
    T_interface = a T_s + (1 - a) T_f,        a = e_s / (e_s + e_f).

Lumped means the bulk temperatures: the flash temperature at the asperities and the gradient
across a thick lining are not resolved, so the interface temperature is a lower bound of the
true surface temperature (see the assumptions of the scenes that use it).

``interface_temperature`` and ``plate_heating_rates`` take floats, numpy arrays or CasADi symbols
(they are the model's equations); the others take numbers. Temperatures in degC, SI otherwise.
"""

import math

import numpy as np

__all__ = ["effusivity", "heat_partition", "interface_temperature", "plate_heating_rates",
           "constant_heat_temperature"]


def effusivity(conductivity, density, specific_heat):
    """Thermal effusivity e = sqrt(k rho c) [W s^0.5 / (m^2 K)].

    Parameters
    ----------
    conductivity : thermal conductivity k [W/(m K)].
    density : density rho [kg/m^3].
    specific_heat : specific heat capacity c [J/(kg K)].
    """
    return math.sqrt(conductivity * density * specific_heat)


def heat_partition(e_separator, e_friction):
    """Share of the interface heat entering the separator, e_s / (e_s + e_f) [-] (Carslaw & Jaeger 2.16)."""
    return e_separator / (e_separator + e_friction)


def interface_temperature(T_separator, T_friction, partition):
    """Contact temperature of the two groups [degC]: the mean weighted by the heat partition."""
    return partition * T_separator + (1 - partition) * T_friction


def plate_heating_rates(heat, T_friction, T_separator, C_friction, C_separator, partition, conductance, T_oil):
    """Temperature rates of the two plate groups [K/s] and the heat convected to the oil [W].

    Parameters
    ----------
    heat : heat released at the interfaces Q [W].
    T_friction, T_separator : group temperatures [degC].
    C_friction, C_separator : group heat capacities [J/K].
    partition : share of Q into the separators a [-].
    conductance : convective conductance G = h A of each group to the oil [W/K].
    T_oil : oil temperature [degC].

    Returns
    -------
    (dT_friction/dt, dT_separator/dt, convected power [W])
    """
    q_f = conductance * (T_friction - T_oil)
    q_s = conductance * (T_separator - T_oil)
    return ((1 - partition) * heat - q_f) / C_friction, (partition * heat - q_s) / C_separator, q_f + q_s


def constant_heat_temperature(t, heat, capacity, conductance, T_start, T_oil):
    """Closed-form temperature [degC] of one heat capacity under a constant heat input with convection.

    Solves C dT/dt = Q - G (T - T_oil), T(0) = T_start:
    T = T_oil + Q/G + (T_start - T_oil - Q/G) exp(-G t / C), and T_start + Q t / C for G = 0.
    """
    t = np.asarray(t, dtype=float)
    if conductance == 0:
        return T_start + heat * t / capacity
    steady = T_oil + heat / conductance
    return steady + (T_start - steady) * np.exp(-conductance * t / capacity)
