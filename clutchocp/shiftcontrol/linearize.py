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

from ..control.linearize import eliminate_algebraic, jacobian_function, linear_model
from ..engagement.model import EngagementModel
from ..errors import ModelError
from ..optimal.guess import SLIP_MODE
from ..optimal.replay import COMMAND
from ..scene.symbolic import SymbolicScene

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

    def __init__(self, engagement, parameters=None, differences=(), order=None):
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
        parameters = dict(parameters or {})
        self.parameter_names = self._symbols = tuple(parameters)
        p = ca.vertcat(*[symbol for symbol, _ in parameters.values()]) if parameters else ca.SX(0, 1)
        self._p0 = np.array([value for _, value in parameters.values()], float)
        self._jacobians = jacobian_function("slip_jacobians", [x_all, z, u, p], x, z, u, f, g, c)
        self._signals = ca.Function("slip_signals", [x_all, z, u, p], [c])
        self._by_parameters = ca.Function("slip_parameter_jacobians", [x_all, z, u, p],
                                          [ca.jacobian(e, p) for e in (f, g, c)])
        self._values = ca.Function("slip_values", [x_all, z, u, p], [f, g, c])
        self._differences = list(differences)
        names = self.parameter_names + tuple(d.name for d in self._differences)
        self._order = [names.index(n) for n in (order or names)]
        self.parameter_names = tuple(order or names)
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
        return linear_model(self._jacobians, x, z, u, self._p0)

    def signal_values(self, x, u, z=None):
        """The signals (w_rel, slip_rate, ...) at a point, SI (dict)."""
        x, z = self._point(x, z)
        values = np.array(self._signals(x, z, u, self._p0), float).ravel()
        return dict(zip(self.signals, values))

    def parameter_columns(self, x, u, z=None):
        """(F, G) at a point: the response of the state rates (n, m) and of the signals (len(signals), m) to a
        relative change of each parameter, theta_i = theta_i,nom (1 + d_i): columns theta_i,nom d(f, c)/d theta_i,
        algebraic variables eliminated (empty with no parameters)."""
        x, z = self._point(x, z)
        if not self.parameter_names:
            return np.zeros((self.n, 0)), np.zeros((len(self.signals), 0))
        point = (x, z, u, self._p0)
        # relative columns: theta_nom d/d theta (symbols: the Jacobian times theta_nom; differences: already so)
        f_p, g_p, c_p = (np.array(m, float) * self._p0 for m in self._by_parameters(*point))
        blocks = [[m] for m in (f_p, g_p, c_p)]
        for d in self._differences:
            for block, column in zip(blocks, d.blocks(x, z, u)):
                block.append(column.reshape(-1, 1))
        f_p, g_p, c_p = (np.hstack(block)[:, self._order] for block in blocks)
        fx, fz, _, gx, gz, _, cx, cz, _ = (np.array(m, float) for m in self._jacobians(*point))
        (_, F), (_, G) = eliminate_algebraic(gx, gz, g_p, (fx, fz, f_p), (cx, cz, c_p))
        return F, G

    def values(self, x, u, z=None, relative=None):
        """(f, g, c) at a point: state rates (n,), algebraic residuals, signals (numpy arrays); ``relative``, optional:
        {field: d} relative changes of parameters the model takes as symbols, theta = theta_nom (1 + d)."""
        x, z = self._point(x, z)
        p = self._p0.copy()
        for name, change in (relative or {}).items():
            if name not in self._symbols:
                raise ModelError(f"slip linearisation: {name} is not a symbol of the model ({', '.join(self._symbols)})")
            p[self._symbols.index(name)] *= 1.0 + change
        return [np.array(v, float).ravel() for v in self._values(x, z, u, p)]

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


DIFFERENCE_STEP = 1e-3      # relative step of the central differences for a field the model cannot take as a symbol


class _Difference:
    """Central differences of the slip mode's (f, g, c) in one scene field, from two models built at
    theta_nom (1 +- h): the column of a field the engagement model cannot take as a CasADi symbol (one
    that also sets a scale, e.g. ``driveline.input_torque`` the lock-up event's). O(h^2) accurate."""

    def __init__(self, scene, name, h=DIFFERENCE_STEP):
        self.name, self.h = name, h
        self.nominal = float(scene.value(name))
        self._sides = [SlipLinearization(EngagementModel(scene.with_overrides({name: self.nominal * (1 + s * h)}),
                                                          smooth=False, pressure_command=ca.SX.sym(COMMAND)))
                       for s in (1.0, -1.0)]

    def blocks(self, x, z, u):
        """theta_nom d(f, g, c)/d theta at fixed (x, z, u): three column vectors."""
        plus, minus = (side.values(x, u, z) for side in self._sides)
        return [(a - b) / (2 * self.h) for a, b in zip(plus, minus)]


def _symbolic_model(scene, names):
    symbolic = SymbolicScene(scene, names)
    command = ca.SX.sym(COMMAND)
    model = EngagementModel(symbolic, smooth=False, pressure_command=command)
    return model, symbolic.symbols


_SYMBOLIC_FIELDS = {}       # (scene structure, names) -> the fields the model takes as symbols


def parametric_linearization(scene, names):
    """The slip linearisation of ``scene`` with relative-change columns for the scene fields ``names``.

    Fields the engagement model can take as CasADi symbols get exact Jacobians; the others central
    differences (:class:`_Difference`). Returns a :class:`SlipLinearization` whose
    :meth:`~SlipLinearization.parameter_columns` are in the order of ``names``.
    """
    names = tuple(names)
    key = (scene.path, scene.name, names)
    symbolic = _SYMBOLIC_FIELDS.get(key)
    if symbolic is None:
        try:
            _symbolic_model(scene, names)
            symbolic = names
        except Exception:            # some field cannot be a symbol: find which, one at a time
            symbolic = []
            for name in names:
                try:
                    _symbolic_model(scene, (name,))
                    symbolic.append(name)
                except Exception:
                    pass
            symbolic = tuple(symbolic)
        _SYMBOLIC_FIELDS[key] = symbolic
    model, symbols = _symbolic_model(scene, symbolic)
    parameters = {name: (symbols[name], float(scene.value(name))) for name in symbolic}
    differences = [_Difference(scene, name) for name in names if name not in symbolic]
    return SlipLinearization(model, parameters, differences=differences, order=names)
