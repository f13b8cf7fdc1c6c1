"""Exact linearisation of the engagement slip phase along a trajectory, continuous and per TCU sample.

In the forward-slip mode of the exact engagement model (:class:`~clutchocp.engagement.model.EngagementModel`,
``smooth=False``) with the pressure command u as input, dx/dt = f(x, z, u), 0 = g(x, z, u). At a
point of a trajectory CasADi gives the Jacobians exactly and the algebraic variables (the hub speed
of a compliant shaft) are eliminated (:mod:`clutchocp.control.linearize`):

    d(dx)/dt = A(t) dx + B(t) du,    dy = C(t) dx + D(t) du

for the physical states (energy accumulators left out: nothing depends on them) and the signals
y = (w_rel, dw_rel/dt, w_in, w_out, p_valve) a transmission control unit (TCU) sees or estimates.

Over one TCU sample [t_k, t_k + Ts] with the feedback correction du held (zero-order hold) on top
of the feedforward, the deviation obeys dx_{k+1} = Phi_k dx_k + Gamma_k du_k with Phi_k, Gamma_k the
solution of the variational equations dPhi/dt = A(t) Phi, dGamma/dt = A(t) Gamma + B(t). They are
computed as a product over m sub-intervals of the exact exponential of A, B frozen at each
sub-interval's midpoint (exp([[A, B], [0, 0]] dt) = [[Phi_j, Gamma_j], [0, 1]]): second order in
Ts / m, and exact for each frozen piece however stiff.
"""

import casadi as ca
import numpy as np
from scipy.linalg import expm

from ..control.linearize import jacobian_function, linear_model
from ..errors import ModelError
from ..optimal.guess import SLIP_MODE

#: Signals of the slip phase that the linearisation gives output rows for.
SIGNALS = ("w_rel", "slip_rate", "w_in", "w_out", "p_valve")


class SlipLinearization:
    """Exact Jacobians of the forward-slip mode of an engagement model with a pressure-command input.

    Parameters
    ----------
    engagement : clutchocp.engagement.model.EngagementModel
        Built with ``pressure_command`` (e.g. ``CommandModel(scene).engagement``), exact forms.

    Attributes
    ----------
    state_names : tuple of str
        The physical states (the rows of A), in model order.
    signals : tuple of str
        The output rows of C and D: ``w_rel`` [rad/s], ``slip_rate`` [rad/s^2] and those of
        ``w_in``, ``w_out`` [rad/s], ``p_valve`` [Pa] that are states of the model.
    """

    def __init__(self, engagement):
        inputs = engagement.hybrid.u
        if "pressure_command" not in inputs:
            raise ModelError("slip linearisation: the engagement model needs a pressure-command input")
        u = inputs["pressure_command"]
        mode = engagement.modes[SLIP_MODE]
        self.engagement = engagement
        self.all_states = tuple(mode.x)
        self.state_names = tuple(n for n in self.all_states if not n.startswith("E_"))
        self.z_names = tuple(mode.z)
        rows = [self.all_states.index(n) for n in self.state_names]
        x_all = ca.vertcat(*mode.x.values())
        x = ca.vertcat(*[mode.x[n] for n in self.state_names])
        z = ca.vertcat(*mode.z.values()) if mode.z else ca.SX(0, 1)
        f = ca.vertcat(*mode.ode)[rows]
        g = ca.vertcat(*mode.alg) if mode.alg else ca.SX(0, 1)
        out = mode.outputs
        w_rel = out["w_in_rad_s"] - out.get("w_hub_rad_s", out["w_out_rad_s"])
        signals = {"w_rel": w_rel, "slip_rate": mode.time_derivative(w_rel, t=engagement.t)}
        for name in ("w_in", "w_out", "p_valve"):
            if name in self.state_names:
                signals[name] = mode.x[name]
        self.signals = tuple(signals)
        c = ca.vertcat(*signals.values())
        if ca.depends_on(ca.vertcat(f, g, c), engagement.t):
            raise ModelError("slip linearisation: the slip mode depends on time explicitly (a pressure profile, "
                             "not a command)")
        self._jacobians = jacobian_function("slip_jacobians", [x_all, z, u], x, z, u, f, g, c)
        self._signals = ca.Function("slip_signals", [x_all, z, u], [c])
        self.nominal = np.array([mode.x_nominal[list(mode.x).index(n)] for n in self.state_names])

    @property
    def n(self):
        """Number of physical states."""
        return len(self.state_names)

    def _point(self, x, z):
        x = np.asarray(x, float).ravel()
        if x.size != len(self.all_states):
            raise ModelError(f"slip linearisation: a state needs {len(self.all_states)} values "
                             f"({', '.join(self.all_states)}), got {x.size}")
        z = np.zeros(0) if z is None else np.asarray(z, float).ravel()
        return x, z

    def continuous(self, x, u, z=None):
        """(A, B, C, D) at the state x (all model states, SI), command u [Pa] and algebraic values z.

        A is (n, n), B (n, 1), C (len(signals), n), D (len(signals), 1); algebraic variables eliminated.
        """
        x, z = self._point(x, z)
        return linear_model(self._jacobians, x, z, u)

    def signal_values(self, x, u, z=None):
        """The signals (w_rel, slip_rate, ...) at a point, SI (dict)."""
        x, z = self._point(x, z)
        values = np.array(self._signals(x, z, u), float).ravel()
        return dict(zip(self.signals, values))

    def sample_map(self, points, u_points, dt, z_points=None):
        """(Phi, Gamma) of one sample from the trajectory at the midpoints of its m sub-intervals.

        Parameters
        ----------
        points : array (m, n_all)
            Model states (all, SI) at the midpoints of m equal sub-intervals of the sample.
        u_points : array (m,)
            Feedforward command at those midpoints [Pa].
        dt : float
            Sub-interval length [s] (the sample is m dt long).
        z_points : array (m, n_z), optional
            Algebraic variables at the midpoints.

        Returns
        -------
        (Phi (n, n), Gamma (n, 1))
        """
        n = self.n
        Phi, Gamma = np.eye(n), np.zeros((n, 1))
        M = np.zeros((n + 1, n + 1))
        for j, x in enumerate(np.atleast_2d(points)):
            z = None if z_points is None else z_points[j]
            A, B, _, _ = self.continuous(x, u_points[j], z)
            M[:n, :n], M[:n, n:] = A * dt, B * dt
            E = expm(M)
            Phi, Gamma = E[:n, :n] @ Phi, E[:n, :n] @ Gamma + E[:n, n:]
        return Phi, Gamma
