"""Plate temperatures of a wet clutch: heat conduction through the friction lining between lumped steel.

The heat Q [W] released at the friction interfaces (slip and squeeze-film shear) enters the interface,
where the separator touches the friction lining. Over an engagement (0.1-1 s) heat penetrates about
sqrt(alpha t) into a body: 0.1-0.4 mm of a paper lining (alpha ~ 1.3e-7 m^2/s), the whole 1 mm half
thickness of a steel separator (alpha ~ 1.4e-5 m^2/s; Fourier number ~4, Biot number of the convection
~0.02). So the steel is lumped (one temperature each: the separator, the friction plate's core) and the
lining is resolved by a chain of nodes across its thickness d (Carslaw & Jaeger, Conduction of Heat in
Solids, 2nd ed. 1959; the vertex-centred finite-volume form of the heat equation):

    node 0       the interface: lining surface and separator (in perfect contact), capacity C_sep + half cell
    node j       inside the lining at depth x_j, capacity n A rho c (dx_{j-1} + dx_j) / 2
    node N       the lining's back face bonded to the core, capacity half cell + C_core
    C_j dT_j/dt = g_{j-1} (T_{j-1} - T_j) + g_j (T_{j+1} - T_j) [+ Q at node 0] - G_j (T_j - T_oil),

with conductances g_j = n A k / dx_j between neighbours and the convective conductances G_0 (separator) and
G_N (friction-plate core) to the oil. The cells grow by :data:`GRID_RATIO` from the surface (finest where
the gradient is steepest). Stored heat sum C_j (T_j - T_0) plus the heat convected is the heat put in,
exactly: conduction only moves heat between nodes.

Closed forms the chain is tested against: a semi-infinite solid under a constant surface flux q has the
surface temperature rise 2 q sqrt(t / (pi k rho c)) (Carslaw & Jaeger Sec. 2.9); the steady state under
a constant Q with convection is the resistor chain of :meth:`ConductionChain.steady_state`.

``ConductionChain.rates`` takes floats, numpy arrays or CasADi symbols (they are the model's equations);
the rest takes numbers. Temperatures in degC, SI otherwise.
"""

import math
from dataclasses import dataclass

import numpy as np
from scipy.linalg import expm

__all__ = ["GRID_RATIO", "effusivity", "semi_infinite_surface_rise", "lining_cells", "ConductionChain",
           "lining_chain", "constant_heat_temperature"]

GRID_RATIO = 1.5        # each lining cell 1.5 x the one nearer the surface


def effusivity(conductivity, density, specific_heat):
    """Thermal effusivity e = sqrt(k rho c) [W s^0.5 / (m^2 K)].

    Parameters
    ----------
    conductivity : thermal conductivity k [W/(m K)].
    density : density rho [kg/m^3].
    specific_heat : specific heat capacity c [J/(kg K)].
    """
    return math.sqrt(conductivity * density * specific_heat)


def semi_infinite_surface_rise(flux, t, conductivity, density, specific_heat):
    """Surface temperature rise [K] of a semi-infinite solid under a constant surface heat flux.

    Delta T = 2 q sqrt(t / (pi k rho c)) (Carslaw & Jaeger Sec. 2.9, Eq. 2.9(5) at x = 0).

    Parameters
    ----------
    flux : heat flux into the surface q [W/m^2].
    t : time since the flux started [s] (number or array).
    conductivity, density, specific_heat : k [W/(m K)], rho [kg/m^3], c [J/(kg K)].
    """
    return 2 * flux * np.sqrt(np.asarray(t, dtype=float) / math.pi) / effusivity(conductivity, density, specific_heat)


def lining_cells(thickness, cells, ratio=GRID_RATIO):
    """Widths of the conduction cells across a lining [m], surface first, each ``ratio`` x the previous.

    Parameters
    ----------
    thickness : lining thickness d [m].
    cells : number of cells N (>= 1).
    ratio : growth of the cell width from the surface inwards.
    """
    widths = ratio ** np.arange(cells, dtype=float)
    return thickness * widths / widths.sum()


@dataclass(frozen=True)
class ConductionChain:
    """A chain of heat capacities joined by conductances, convecting to the oil at both ends.

    Attributes
    ----------
    capacity : numpy.ndarray
        Heat capacity of each node [J/K], node 0 (where the heat enters) first.
    conductance : numpy.ndarray
        Conductance between node j and j + 1 [W/K] (one fewer than the nodes).
    surface_loss, back_loss : float
        Convective conductance of node 0 and of the last node to the oil [W/K].
    """

    capacity: np.ndarray
    conductance: np.ndarray
    surface_loss: float
    back_loss: float

    @property
    def size(self):
        """Number of nodes."""
        return len(self.capacity)

    def flows(self, T, T_oil):
        """Heat flows [W]: into each node from its neighbours, and to the oil from node 0 and the last node."""
        n = self.size
        net = [0.0] * n
        for j, g in enumerate(self.conductance):
            flow = g * (T[j] - T[j + 1])             # from node j to node j + 1
            net[j] = net[j] - flow
            net[j + 1] = net[j + 1] + flow
        return net, self.surface_loss * (T[0] - T_oil), self.back_loss * (T[n - 1] - T_oil)

    def rates(self, T, heat, T_oil):
        """Temperature rates of the nodes [K/s] and the heat convected to the oil [W].

        Parameters
        ----------
        T : sequence of temperatures [degC] (floats or CasADi symbols), node 0 first.
        heat : heat entering node 0 [W].
        T_oil : oil temperature [degC].
        """
        net, surface, back = self.flows(T, T_oil)
        net[0] = net[0] + heat - surface
        net[-1] = net[-1] - back
        return [q / C for q, C in zip(net, self.capacity)], surface + back

    def stored_heat(self, T, T_ref):
        """Heat stored in the chain since every node was at ``T_ref`` [J]."""
        return sum(C * (Tj - T_ref) for C, Tj in zip(self.capacity, T))

    def matrix(self):
        """(A, b): dT/dt = A (T - T_oil) + b Q, the chain as a linear system (numbers)."""
        n = self.size
        G = np.zeros((n, n))
        for j, g in enumerate(self.conductance):
            G[j, j] -= g
            G[j + 1, j + 1] -= g
            G[j, j + 1] += g
            G[j + 1, j] += g
        G[0, 0] -= self.surface_loss
        G[-1, -1] -= self.back_loss
        b = np.zeros(n)
        b[0] = 1.0
        return G / self.capacity[:, None], b / self.capacity

    def relax(self, T, time, T_oil, heat=0.0):
        """Node temperatures [degC] after ``time`` [s] from ``T`` under a constant ``heat`` [W] (matrix exponential)."""
        A, b = self.matrix()
        n = self.size
        M = np.zeros((n + 1, n + 1))
        M[:n, :n], M[:n, n] = A, b * heat
        E = expm(M * float(time))
        return T_oil + E[:n, :n] @ (np.asarray(T, float) - T_oil) + E[:n, n]

    def steady_state(self, heat, T_oil):
        """Node temperatures [degC] of the steady state under a constant ``heat`` [W] into node 0, in closed form.

        The heat leaves through node 0's convection and through the chain's series resistance
        R = sum 1/g_j into the last node's convection: f = Q / (1 + G_0 (R + 1/G_N)) flows through the
        chain, T_N = T_oil + f / G_N, and each node is lower than the one before by f / g_j.
        Without convection at either end the chain heats without end: returned as inf.
        """
        if self.surface_loss == 0 and self.back_loss == 0:
            return np.full(self.size, np.inf)
        if self.back_loss == 0:
            return np.full(self.size, T_oil + heat / self.surface_loss)
        resistance = float(np.sum(1.0 / self.conductance))
        through = heat / (1.0 + self.surface_loss * (resistance + 1.0 / self.back_loss))
        drops = np.concatenate([[0.0], np.cumsum(through / self.conductance)])
        return T_oil + through / self.back_loss + (drops[-1] - drops)


def lining_chain(thickness, cells, conductivity, density, specific_heat, area, surface_capacity, back_capacity,
                 surface_loss, back_loss, ratio=GRID_RATIO):
    """The conduction chain through a friction lining between two lumped capacities.

    Parameters
    ----------
    thickness : lining thickness d [m].
    cells : number of conduction cells N across it (N + 1 nodes).
    conductivity, density, specific_heat : the lining's k [W/(m K)], rho [kg/m^3], c [J/(kg K)].
    area : total lining area the heat crosses [m^2] (n_interfaces x the friction annulus).
    surface_capacity : lumped capacity at the surface node [J/K] (the separator; 0 for the lining alone).
    back_capacity : lumped capacity at the back node [J/K] (the friction plate's steel core).
    surface_loss, back_loss : convective conductances of the surface and back nodes to the oil [W/K].
    ratio : growth of the cell width from the surface inwards (:data:`GRID_RATIO`).

    Returns
    -------
    ConductionChain
    """
    dx = lining_cells(thickness, cells, ratio)
    half = density * specific_heat * area * dx / 2            # each cell's capacity, half to each of its nodes
    capacity = np.zeros(cells + 1)
    capacity[:-1] += half
    capacity[1:] += half
    capacity[0] += surface_capacity
    capacity[-1] += back_capacity
    return ConductionChain(capacity, conductivity * area / dx, float(surface_loss), float(back_loss))


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
