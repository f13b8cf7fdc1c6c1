"""Definition of a hybrid (multi-mode) semi-explicit index-1 DAE.

A :class:`HybridModel` is a set of :class:`Mode` objects sharing parameters ``p``,
piecewise-constant inputs ``u`` and time ``t`` (CasADi SX scalars). Each mode is

    dx/dt = f(x, z, p, u, t),   0 = g(x, z, p, u, t)      (dg/dz non-singular)

with its own named differential states ``x`` and algebraic variables ``z`` (each with a
nominal scale), named outputs, and :class:`Event` objects that switch to another mode
through a reset map ``x+ = R(x-, z-, p, u, t)``. Modes may have different state vectors.
This module describes the model; :mod:`clutchocp.simulation.compiled` turns it into
CasADi functions and :func:`clutchocp.simulation.simulate` integrates it.
"""

from collections.abc import Mapping, Sequence
import re
from dataclasses import dataclass

import casadi as ca
import numpy as np

from clutchocp.errors import ModelError
from clutchocp.simulation.compiled import compile_model
from clutchocp.simulation.derivative import time_derivative

DIRECTIONS = {-1: "falling (+ to -)", 0: "either way", 1: "rising (- to +)"}


@dataclass(frozen=True, eq=False)
class Event:
    """A switch out of a mode when ``function`` crosses zero.

    Parameters
    ----------
    name : str
        Name of the event (e.g. ``"lockup"``), used in results and messages.
    function : casadi.SX
        Scalar event function of the source mode's ``x, z`` and the model's ``p, u, t``.
    target : str
        Name of the mode entered when the event fires (may be the source mode itself).
    direction : int
        -1: fires when the function falls from > 0 to <= 0; +1: rises from < 0 to >= 0;
        0: either.
    reset : mapping of str to casadi.SX, optional
        Values of the target mode's states just after the event, as expressions of the
        source mode's ``x-, z-`` (and ``p, u, t``). Target states not listed keep the value of
        the source state of the same name (which must then exist).
    guard : casadi.SX, optional
        The event fires only if ``guard >= 0`` at the crossing (e.g. "needed torque within
        static capacity"); otherwise the crossing is passed through. Several events may share
        one function with different guards and targets; the first (in mode order) whose
        guard holds fires.
    scale : float
        Nominal size of the function: tolerances and the hysteresis band apply to
        ``function / scale``.
    edge : str
        Non-empty: the crossing is an edge of the model's validity (e.g. "film 2 closed"), not a switch.
        When it fires the run ends with a :class:`~clutchocp.errors.ModelEdgeError` carrying this text,
        the time, the mode, the states and the outputs there; ``target`` and ``reset`` are not used.
        Such an event does not shorten the integrator's calls (its crossing is found on the samples,
        then located), so a run that never reaches the edge costs no more than without it.
    """

    name: str
    function: ca.SX
    target: str
    direction: int = 0
    reset: Mapping[str, ca.SX] | None = None
    guard: ca.SX | None = None
    scale: float = 1.0
    edge: str = ""

    def __post_init__(self):
        if self.direction not in DIRECTIONS:
            raise ModelError(f"event '{self.name}': direction must be -1, 0 or 1, got {self.direction!r}")
        if not (np.isfinite(self.scale) and self.scale > 0):
            raise ModelError(f"event '{self.name}': scale must be a positive number, got {self.scale!r}")


def _as_symbol_dict(kind, mode_name, mapping):
    out = dict(mapping or {})
    for name, sym in out.items():
        if not (isinstance(sym, ca.SX) and sym.is_scalar() and sym.is_symbolic()):
            raise ModelError(f"mode '{mode_name}': {kind} '{name}' must be a scalar casadi.SX symbol")
    return out


def _nominals(kind, mode_name, names, given):
    given = dict(given or {})
    unknown = sorted(set(given) - set(names))
    if unknown:
        raise ModelError(f"mode '{mode_name}': {kind} nominal given for unknown names {unknown}; known: {list(names)}")
    values = np.array([float(given.get(n, 1.0)) for n in names])
    if not np.all(np.isfinite(values) & (values > 0)):
        raise ModelError(f"mode '{mode_name}': every {kind} nominal must be a positive number, got {given}")
    return values


class Mode:
    """One mode (e.g. "slipping", "locked") of a hybrid DAE.

    Parameters
    ----------
    name : str
        Unique mode name.
    x : mapping of str to casadi.SX
        Differential states, name -> scalar SX symbol (order defines the state vector).
    ode : mapping of str to casadi.SX or sequence of casadi.SX
        Time derivative of each state (keys as in ``x``, or a sequence in ``x`` order).
    z : mapping of str to casadi.SX, optional
        Algebraic variables, name -> scalar SX symbol.
    alg : sequence of casadi.SX, optional
        Algebraic residuals, as many as ``z``; ``d alg / d z`` must be non-singular (index 1).
    outputs : mapping of str to casadi.SX, optional
        Named quantities evaluated on the result (torques, powers, pieces of the jerk ...).
    events : sequence of Event, optional
        Switches out of this mode.
    x_nominal, z_nominal : mapping of str to float, optional
        Typical magnitude of each state / algebraic variable (default 1). The integrators
        work on ``x / x_nominal`` and ``z / z_nominal``, so absolute tolerances are relative
        to these scales.
    alg_nominal : sequence of float, optional
        Typical magnitude of each residual (default 1); the residuals are divided by it.
    z_guess : mapping of str to float, optional
        Starting guess for the algebraic variables when the mode is entered and no variable
        of the same name was known before (default 0).
    """

    def __init__(self, name, x, ode, *, z=None, alg=None, outputs=None, events=(),
                 x_nominal=None, z_nominal=None, alg_nominal=None, z_guess=None):
        self.name = str(name)
        if not re.fullmatch(r"[A-Za-z](?:_?[A-Za-z0-9])*", self.name):
            raise ModelError(f"mode name {self.name!r}: use letters, digits and single underscores, "
                             "starting with a letter (it names CasADi functions)")
        self.x = _as_symbol_dict("state", self.name, x)
        self.z = _as_symbol_dict("algebraic variable", self.name, z)
        if not self.x:
            raise ModelError(f"mode '{self.name}': needs at least one differential state")
        if isinstance(ode, Mapping):
            missing = [n for n in self.x if n not in ode]
            extra = [n for n in ode if n not in self.x]
            if missing or extra:
                raise ModelError(f"mode '{self.name}': ode keys must match the states; "
                                 f"missing {missing}, unknown {extra}")
            ode = [ode[n] for n in self.x]
        self.ode = [ca.SX(e) for e in ode]
        if len(self.ode) != len(self.x):
            raise ModelError(f"mode '{self.name}': {len(self.ode)} ode expressions for {len(self.x)} states")
        self.alg = [ca.SX(e) for e in (alg or [])]
        if len(self.alg) != len(self.z):
            raise ModelError(f"mode '{self.name}': {len(self.alg)} algebraic residuals for {len(self.z)} "
                             "algebraic variables (they must be equal)")
        self.outputs = {str(k): ca.SX(v) for k, v in (outputs or {}).items()}
        for k, expr in [(f"ode of {n}", e) for n, e in zip(self.x, self.ode)] + \
                       [(f"alg[{i}]", e) for i, e in enumerate(self.alg)] + \
                       [(f"output {n}", e) for n, e in self.outputs.items()]:
            if not expr.is_scalar():
                raise ModelError(f"mode '{self.name}': {k} must be a scalar expression, got shape {expr.shape}")
        self.events = list(events)
        for ev in self.events:
            if not isinstance(ev, Event):
                raise ModelError(f"mode '{self.name}': events must be Event objects, got {type(ev).__name__}")
        names = list(self.x) + list(self.z) + list(self.outputs)
        clashes = sorted({n for n in names if names.count(n) > 1})
        if clashes:
            raise ModelError(f"mode '{self.name}': names used twice among states, algebraic variables "
                             f"and outputs: {clashes}")
        self.x_nominal = _nominals("state", self.name, list(self.x), x_nominal)
        self.z_nominal = _nominals("algebraic", self.name, list(self.z), z_nominal)
        alg_nominal = np.ones(len(self.alg)) if alg_nominal is None else np.asarray(alg_nominal, float)
        if alg_nominal.shape != (len(self.alg),) or not np.all(np.isfinite(alg_nominal) & (alg_nominal > 0)):
            raise ModelError(f"mode '{self.name}': alg_nominal must be {len(self.alg)} positive numbers")
        self.alg_nominal = alg_nominal
        z_guess = dict(z_guess or {})
        unknown = sorted(set(z_guess) - set(self.z))
        if unknown:
            raise ModelError(f"mode '{self.name}': z_guess for unknown algebraic variables {unknown}")
        self.z_guess = np.array([float(z_guess.get(n, 0.0)) for n in self.z])

    def time_derivative(self, expr, t=None):
        """Total time derivative of ``expr`` along this mode's flow (see :func:`time_derivative`)."""
        return time_derivative(expr, self.x, self.ode, z=self.z, alg=self.alg, t=t)

    def __repr__(self):
        return (f"Mode({self.name!r}, x={list(self.x)}, z={list(self.z)}, "
                f"events={[e.name for e in self.events]})")


class PiecewiseConstant:
    """A piecewise-constant input schedule.

    ``values[0]`` holds before ``breaks[0]``, ``values[k]`` on ``[breaks[k-1], breaks[k])`` and
    ``values[-1]`` from ``breaks[-1]`` on. The simulation restarts at every break (with new
    consistent algebraic variables), so a jump never falls inside an integration step.
    Piecewise-polynomial inputs (ramps, tables) are written in the model as polynomials in
    ``t`` whose coefficients are piecewise-constant inputs.

    Parameters
    ----------
    breaks : sequence of float
        Strictly increasing switching times [s].
    values : sequence of float
        ``len(breaks) + 1`` values (unit of the input).
    """

    def __init__(self, breaks, values):
        self.breaks = np.atleast_1d(np.asarray(breaks, dtype=float))
        self.values = np.atleast_1d(np.asarray(values, dtype=float))
        if self.breaks.ndim != 1 or self.values.shape != (self.breaks.size + 1,):
            raise ModelError(f"PiecewiseConstant needs len(values) == len(breaks) + 1, got "
                             f"{self.values.size} values for {self.breaks.size} breaks")
        if np.any(np.diff(self.breaks) <= 0) or not np.all(np.isfinite(self.breaks)):
            raise ModelError("PiecewiseConstant breaks must be finite and strictly increasing")

    def __call__(self, t):
        """Value holding at time ``t`` (right-continuous)."""
        return float(self.values[np.searchsorted(self.breaks, t, side="right")])


class HybridModel:
    """A set of modes with shared parameters, inputs and time.

    Parameters
    ----------
    modes : sequence of Mode
        The modes; the first one is the default initial mode.
    p : mapping of str to casadi.SX, optional
        Parameters (constant over a simulation), name -> scalar SX symbol.
    u : mapping of str to casadi.SX, optional
        Piecewise-constant inputs, name -> scalar SX symbol (values given as numbers or
        :class:`PiecewiseConstant` when simulating).
    t : casadi.SX, optional
        Time symbol used by the expressions (if any).
    """

    def __init__(self, modes: Sequence[Mode], *, p=None, u=None, t=None):
        self.modes = {}
        for m in modes:
            if not isinstance(m, Mode):
                raise ModelError(f"HybridModel needs Mode objects, got {type(m).__name__}")
            if m.name in self.modes:
                raise ModelError(f"two modes are named '{m.name}'")
            self.modes[m.name] = m
        if not self.modes:
            raise ModelError("HybridModel needs at least one mode")
        self.p = _as_symbol_dict("parameter", "<model>", p)
        self.u = _as_symbol_dict("input", "<model>", u)
        clash = sorted(set(self.p) & set(self.u))
        if clash:
            raise ModelError(f"names used both as parameter and input: {clash}")
        self.t = ca.SX.sym("t") if t is None else t
        if not (isinstance(self.t, ca.SX) and self.t.is_scalar() and self.t.is_symbolic()):
            raise ModelError("t must be a scalar casadi.SX symbol")
        for m in self.modes.values():
            for ev in m.events:
                if ev.target not in self.modes:
                    raise ModelError(f"mode '{m.name}', event '{ev.name}': unknown target mode "
                                     f"'{ev.target}'; modes: {list(self.modes)}")
        self._compiled = None

    @property
    def initial_mode(self):
        """Name of the first mode."""
        return next(iter(self.modes))

    def compiled(self):
        """The CasADi functions of every mode (built once, then cached)."""
        if self._compiled is None:
            self._compiled = compile_model(self)
        return self._compiled
