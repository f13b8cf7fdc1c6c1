"""CasADi functions of each mode, on scaled variables.

Every function takes ``(xs, zs, pu, t)`` with ``xs = x / x_nominal``, ``zs = z / z_nominal``,
``pu`` = parameters followed by inputs, in model order. Both integrator paths (IDAS and
scipy) use exactly these functions, so they integrate the same equations. Every expression is
passed through ``casadi.cse`` (common subexpressions evaluated once): a model assembled from
parts repeats many terms (e.g. a contact force feeds the film load, the torque, the capacity
and the energy rates), and the shared form halves the cost of the right-hand side.
"""

from collections.abc import Mapping
from dataclasses import dataclass

import casadi as ca
import numpy as np

from clutchocp.errors import ModelError, SolverError
from clutchocp.simulation.derivative import time_derivative
from clutchocp.simulation import vectorized
from clutchocp.simulation.diagnostics import solver_error
from clutchocp.simulation.native import compile_columns, native_dae
from clutchocp.simulation.vectorized import MIN_SAMPLES, numpy_function, padded_size


@dataclass(frozen=True)
class EventSpec:
    """Compiled description of one event of a mode."""

    index: int          # position in the mode's event list
    name: str
    direction: int
    target: str
    key: int            # index of the first event with the same function and scale (shared location)
    edge: str = ""      # non-empty: firing ends the run (Event.edge)


def _column(exprs):
    return ca.vertcat(*exprs) if len(exprs) else ca.SX(0, 1)


def _function(name, inputs, outputs, what, mode):
    try:
        return ca.Function(name, inputs, outputs)
    except RuntimeError:
        free = ca.Function(name, inputs, outputs, {"allow_free": True}).free_sx()
        raise ModelError(f"mode '{mode}': {what} uses symbols {[str(s) for s in free]} that are neither "
                         "its states, its algebraic variables, the model parameters, inputs nor time") from None


def _padded(a, rows, n, m):
    """Samples ``a`` (rows, n) as a C-ordered (m, rows) array, the last sample repeated to ``m >= n``."""
    a = np.reshape(np.asarray(a, float), (rows, n))
    out = np.empty((m, rows))
    out[:n] = a.T
    if m > n and rows:
        out[n:] = a[:, -1]
    return out


class ColumnFunction:
    """A Function of ``(xs, zs, pu, t)`` evaluated on many samples at once.

    A CasADi ``map`` over the columns of ``xs, zs, t`` (``pu`` shared), called through the
    buffer interface: numpy arrays in and out, no DM conversions (which cost more than the
    evaluation for a few thousand samples of a small function). ``loop``, for a function compiled
    to machine code: its loop over samples (:func:`clutchocp.simulation.native.compile_columns`),
    used instead of the map (the same compiled function on every sample, without CasADi's calling
    machinery around each call). ``like``: a column function of which ``function`` computes some
    outputs (:meth:`CompiledMode.outputs_subset`); its choice between numpy and the map is taken
    on the same samples, so each value is bit for bit the one ``like`` gives.
    """

    def __init__(self, function, max_maps=32, loop=None, like=None):
        if not all(function.sparsity_in(i).is_dense() for i in range(4)) or not function.sparsity_out(0).is_dense():
            raise ModelError(f"{function.name()}: a column function needs dense inputs and output (densify them)")
        self.function = function
        self.sizes = [function.size1_in(i) for i in range(4)]
        self.n_out = function.size1_out(0)
        self._maps = {}
        self._max_maps = max_maps
        self._calls = like._calls if like is not None else vectorized.calls_unregistered(function)
        self._like = like
        self._translatable = None
        self._numpy_built = False
        self._numpy_fn = None
        self._loop = loop
        self._one = None            # (map entry, input arrays, output array) bound to the 1-sample map's buffer

    @property
    def _numpy(self):
        """The numpy translation (many samples: one numpy operation per instruction), made on first
        use: a run whose output pieces are all shorter than the threshold (MIN_SAMPLES, or
        MIN_SAMPLES_PLAIN without calls of tables) never pays for it."""
        if not self._numpy_built:
            mirrored = self._like is None or self._like.translatable()
            self._numpy_fn, self._numpy_built = numpy_function(self.function) if mirrored else None, True
        return self._numpy_fn

    def translatable(self):
        """Whether the function has a numpy form (found without building it)."""
        if self._translatable is None:
            self._translatable = self._numpy is not None if self._numpy_built else \
                vectorized.translatable(self.function)
        return self._translatable

    def _map(self, n):
        entry = self._maps.pop(n, None)
        if entry is None:
            mapped = self.function.map(f"{self.function.name()}_columns", "serial", n, [2], [])
            entry = (mapped, *mapped.buffer())
        self._maps[n] = entry                      # most recently used last
        if len(self._maps) > self._max_maps:
            self._maps.pop(next(iter(self._maps)))
        return entry

    def uses_numpy(self, n):
        """Whether a call on ``n`` samples is evaluated by the numpy form."""
        return self._loop is None and n >= (MIN_SAMPLES if self._calls else vectorized.MIN_SAMPLES_PLAIN) \
            and self._numpy is not None

    def on_numpy(self, xs, zs, pu, t):
        """The numpy form on the samples, whatever their number (each sample's values are those of a
        call on more samples that takes the numpy form: numpy evaluates element by element)."""
        t = np.atleast_1d(np.asarray(t, float)).ravel()
        n = t.size
        nx, nz = self.sizes[:2]
        out = np.empty((self.n_out, n))
        with np.errstate(all="ignore"):       # as CasADi: NaN/inf where the expression gives them
            self._numpy([np.reshape(np.asarray(xs, float), (nx, n)), np.reshape(np.asarray(zs, float), (nz, n)),
                         np.ravel(np.asarray(pu, float)), t[None, :]], [out])
        return out

    def __call__(self, xs, zs, pu, t):
        """Outputs on the samples: array (n_out, n) for ``t`` of length n."""
        t = np.atleast_1d(np.asarray(t, float)).ravel()
        n = t.size
        nx, nz = self.sizes[:2]
        if self._loop is not None and n:
            return self._looped(xs, zs, pu, t, n)
        if self.uses_numpy(n):
            return self.on_numpy(xs, zs, pu, t)
        if n == 0:
            return np.zeros((self.n_out, 0))
        if n == 1:
            return self._single(xs, zs, pu, t)
        m = padded_size(n)                         # a few cached maps serve every sample count
        _, buf, evaluate = self._map(m)
        args = [_padded(xs, nx, n, m), _padded(zs, nz, n, m), np.ascontiguousarray(np.ravel(np.asarray(pu, float))),
                _padded(t, 1, n, m)]
        out = np.zeros((m, self.n_out))           # CasADi leaves outputs that are constant zeros unwritten
        dummy = np.zeros(1)
        for i, a in enumerate(args):
            buf.set_arg(i, memoryview(a if a.size else dummy))
        buf.set_res(0, memoryview(out if out.size else dummy))
        evaluate()
        return out[:n].T

    def _single(self, xs, zs, pu, t):
        """One sample on the 1-sample map, through arrays bound to its buffer once (a run makes
        ~20 such calls: guards, resets, event values and slopes at one time, outputs at events)."""
        if self._one is None:                     # bound once: the map stays alive with it
            entry = self._map(1)
            _, buf, _ = entry
            args = [np.zeros(max(size, 1)) for size in self.sizes]     # an empty input gets a dummy
            out = np.zeros(max(self.n_out, 1))
            for i, a in enumerate(args):
                buf.set_arg(i, memoryview(a))
            buf.set_res(0, memoryview(out))
            self._one = (entry, args, out)
        entry, args, out = self._one
        for a, v, size in zip(args, (xs, zs, pu, t), self.sizes):
            if size:
                a[:] = np.ravel(v)
        out.fill(0.0)                             # CasADi leaves outputs that are constant zeros unwritten
        entry[2]()
        return out[:self.n_out, None].copy()

    def _looped(self, xs, zs, pu, t, n):
        """The compiled loop over the ``n`` samples (sample-major copies in, sample-major out)."""
        nx, nz, npu = self.sizes[:3]
        dummy = np.zeros(1)
        args = [np.ascontiguousarray(np.reshape(np.asarray(xs, float), (nx, n)).T) if nx else dummy,
                np.ascontiguousarray(np.reshape(np.asarray(zs, float), (nz, n)).T) if nz else dummy,
                np.ascontiguousarray(np.ravel(np.asarray(pu, float))) if npu else dummy, np.ascontiguousarray(t)]
        out = np.zeros((n, self.n_out)) if self.n_out else dummy
        if self._loop(args, (nx, nz, 0, 1), [out], (self.n_out,), n):
            raise SolverError(f"the compiled function {self.function.name()} failed on {n} samples "
                              f"(t = {t[0]:.6g} ... {t[-1]:.6g} s); try: run without native code")
        return out.T if self.n_out else np.zeros((0, n))


class CompiledMode:
    """The scaled DAE, events, guards, resets and outputs of one mode as CasADi Functions."""

    def __init__(self, mode, model):
        self.name = mode.name
        self.x_names = list(mode.x)
        self.z_names = list(mode.z)
        self.output_names = list(mode.outputs)
        self.output_index = {name: i for i, name in enumerate(self.output_names)}
        self.x_nominal = mode.x_nominal
        self.z_nominal = mode.z_nominal
        self.z_guess_scaled = mode.z_guess / mode.z_nominal if mode.z else np.zeros(0)
        self.nx, self.nz = len(self.x_names), len(self.z_names)

        self.xs = ca.SX.sym(f"{mode.name}_xs", self.nx)
        self.zs = ca.SX.sym(f"{mode.name}_zs", self.nz)
        self.pu = _column(list(model.p.values()) + list(model.u.values()))
        self.t = model.t
        args = [self.xs, self.zs, self.pu, self.t]
        old = _column(list(mode.x.values()) + list(mode.z.values()))
        new = ca.vertcat(self.xs * ca.DM(mode.x_nominal), self.zs * ca.DM(mode.z_nominal)) \
            if self.nz else self.xs * ca.DM(mode.x_nominal)

        def scaled(exprs):
            return ca.cse(ca.substitute(_column(exprs), old, new))

        self.ode_s = ca.cse(scaled(mode.ode) / ca.DM(mode.x_nominal))
        self.alg_s = ca.cse(scaled(mode.alg) / ca.DM(mode.alg_nominal)) if self.nz else ca.SX(0, 1)
        self.f_ode = _function(f"{self.name}_ode", args, [self.ode_s], "the ode", self.name)
        self.f_alg = _function(f"{self.name}_alg", args, [self.alg_s], "the algebraic equations", self.name)
        self._outputs_s = ca.densify(scaled(list(mode.outputs.values())))
        self.f_outputs = _function(f"{self.name}_outputs", args, [self._outputs_s], "an output", self.name)
        self.outputs_on = ColumnFunction(self.f_outputs)
        self._output_subsets = {}

        # events: scaled functions, guards (>= 0 lets the event fire), shared-location keys
        self.events = []
        functions = []
        for i, ev in enumerate(mode.events):
            fun = ca.SX(ev.function)
            key = next((j for j, e in enumerate(mode.events[:i])
                        if e.scale == ev.scale and ca.is_equal(ca.SX(e.function), fun, 16)), i)
            self.events.append(EventSpec(i, ev.name, ev.direction, ev.target, key, ev.edge))
            functions.append(fun / ev.scale)
        self.f_events = _function(f"{self.name}_events", args, [ca.densify(scaled(functions))], "an event function",
                                  self.name)
        self.events_on = ColumnFunction(self.f_events)
        guards = [ca.SX(1.0) if ev.guard is None else ca.SX(ev.guard) for ev in mode.events]
        self.f_guards = _function(f"{self.name}_guards", args, [scaled(guards)], "an event guard", self.name)
        self._mode = mode

        # the same DAE on normalised time tau in [0, 1], t = t0 + tau dt (event location)
        tau, t0, dt = ca.SX.sym("tau"), ca.SX.sym("t0"), ca.SX.sym("dt")
        at = lambda e: ca.substitute(e, self.t, t0 + tau * dt)
        self.dae = {"x": self.xs, "z": self.zs, "p": self.pu, "t": self.t, "ode": self.ode_s, "alg": self.alg_s}
        self.dae_tau = {"x": self.xs, "z": self.zs, "p": ca.vertcat(self.pu, t0, dt), "t": tau,
                        "ode": dt * at(self.ode_s), "alg": at(self.alg_s)}

        self._event_functions = scaled(functions)
        self._rootfinder = None
        self._z_explicit = None
        self._event_rates = None
        self._event_slopes = None
        self._native_dae = None
        self._native_outputs_on = None
        self._native_events_on = None
        self._native_events_outputs = None
        self._events_outputs = None
        self._on_samples = {}
        self.integrators = {}       # cached casadi integrators of this mode (see idas_path)

    def build_resets(self, modes):
        """Reset maps x+ (scaled for the target mode) of every event.

        Parameters
        ----------
        modes : dict
            All :class:`~clutchocp.simulation.model.Mode` objects of the model by name.
        """
        mode = self._mode
        self.resets = []
        for ev in mode.events:
            target = modes[ev.target]
            exprs = reset_expressions(mode, ev, target)
            old = _column(list(mode.x.values()) + list(mode.z.values()))
            new = ca.vertcat(self.xs * ca.DM(mode.x_nominal), self.zs * ca.DM(mode.z_nominal)) \
                if self.nz else self.xs * ca.DM(mode.x_nominal)
            expr = ca.substitute(_column(exprs), old, new) / ca.DM(target.x_nominal)
            self.resets.append(_function(f"{mode.name}_reset_{ev.name}", [self.xs, self.zs, self.pu, self.t],
                                         [expr], f"the reset of event '{ev.name}'", mode.name))

    def event_rates(self):
        """The scaled event functions and their first and second time derivatives along the flow, as
        SX expressions of ``(xs, zs, pu, t)`` (built on first use and kept)."""
        if self._event_rates is None:
            x, ode = ca.vertsplit(self.xs), ca.vertsplit(self.ode_s)
            z, alg = (ca.vertsplit(self.zs), ca.vertsplit(self.alg_s)) if self.nz else (None, None)
            s = self._event_functions
            s1 = time_derivative(s, x, ode, z=z, alg=alg, t=self.t) if s.numel() else s
            s2 = time_derivative(s1, x, ode, z=z, alg=alg, t=self.t) if s.numel() else s
            self._event_rates = (s, s1, s2)
        return self._event_rates

    def event_slopes(self):
        """Column function ``(xs, zs, pu, t) -> (3 n_events, n)``: the scaled event functions, then
        their first, then their second time derivatives along the flow (to predict crossings)."""
        if self._event_slopes is None:
            self._event_slopes = ColumnFunction(ca.Function(
                f"{self.name}_event_slopes", [self.xs, self.zs, self.pu, self.t],
                [ca.densify(ca.cse(ca.vertcat(*self.event_rates())))]))
        return self._event_slopes

    def outputs_subset(self, indices):
        """Column function of the outputs at ``indices`` (increasing positions in
        :attr:`output_names`): :attr:`outputs_on` itself for all of them, else a Function of the
        same expressions restricted to those outputs (built on first use and kept), evaluated the way
        :attr:`outputs_on` would be on the same samples (numpy or CasADi's map), so each value is
        bit for bit the one :attr:`outputs_on` gives, at the cost of the instructions those outputs
        need (a summary reads ~15 of an engagement model's ~42 outputs)."""
        key = tuple(int(i) for i in indices)
        if key == tuple(range(len(self.output_names))):
            return self.outputs_on
        function = self._output_subsets.get(key)
        if function is None:
            subset = ca.Function(f"{self.name}_outputs_{len(key)}", [self.xs, self.zs, self.pu, self.t],
                                 [self._outputs_s[list(key)] if key else ca.SX(0, 1)])
            function = self._output_subsets[key] = ColumnFunction(subset, like=self.outputs_on)
        return function

    def native_dae(self):
        """``dae_tau`` compiled to machine code (see :mod:`clutchocp.simulation.native`), or None."""
        if self._native_dae is None:
            self._native_dae = native_dae(self) or False
        return self._native_dae or None

    def on_samples(self, what):
        """Column function (numpy in and out, no DM conversions: a few us a call instead of ~20 us)
        of ``"ode"``, ``"guards"`` or ``("reset", i)``: the same Function as ``f_ode``, ``f_guards``
        and ``resets[i]`` with its output densified, built on first use."""
        function = self._on_samples.get(what)
        if function is None:
            source = self.resets[what[1]] if isinstance(what, tuple) else {"ode": self.f_ode, "guards": self.f_guards}[what]
            dense = ca.Function(f"{source.name()}_dense", [self.xs, self.zs, self.pu, self.t],
                                [ca.densify(source(self.xs, self.zs, self.pu, self.t))])
            function = self._on_samples[what] = ColumnFunction(dense)
        return function

    def at(self, what, xs, zs, pu, t):
        """:meth:`on_samples` ``what`` at one sample: a 1-D array."""
        return self.on_samples(what)(xs, zs, pu, t)[:, 0]

    def event_values(self, native=False):
        """The column function of the scaled event functions a run uses: :attr:`events_on`, or with
        ``native`` and event functions that call tables (interpolants) the same compiled to machine
        code. The numpy translation evaluates such calls sample by sample through CasADi
        (default_driveline, locked: 3.2 ms on 1 622 samples), compiled code inlines them (1.3 ms);
        without calls numpy is the faster (zhang2021, slipping: 6 us against 0.27 ms), measured."""
        if not native:
            return self.events_on
        if self._native_events_on is None:
            f = self.f_events
            calls = any(f.instruction_id(k) == ca.OP_CALL for k in range(f.n_instructions()))
            compiled = None
            if calls:
                compiled = compile_columns(f)
            self._native_events_on = ColumnFunction(compiled[0], loop=compiled[1]) if compiled is not None \
                else self.events_on
        return self._native_events_on

    def native_events_outputs(self):
        """Column function of the scaled event functions followed by the outputs, compiled to machine
        code as one function (shared subexpressions evaluated once), or None.

        Only for a mode whose event functions call tables, where :meth:`event_values` and
        :meth:`native_outputs_on` are both compiled: the compiled code performs the same operations
        on the same numbers as the two separate functions, so each value is bit for bit theirs
        (tested). Elsewhere the events are evaluated by numpy or CasADi and a merged compiled
        function would change them by rounding. A locked mode's events (static capacity against
        the torque to hold) repeat much of its outputs: bao2020, 159 and 373 instructions, 377
        together.
        """
        if self._native_events_outputs is None:
            merged = None
            if self.events and self.event_values(True) is not self.events_on:
                args = [self.xs, self.zs, self.pu, self.t]
                both = ca.Function(f"{self.name}_events_outputs", args,
                                   [ca.densify(ca.cse(ca.vertcat(self.f_events(*args), self.f_outputs(*args))))])
                compiled = compile_columns(both)
                merged = ColumnFunction(compiled[0], loop=compiled[1]) if compiled is not None else None
            self._native_events_outputs = merged or False
        return self._native_events_outputs or None

    def events_outputs(self, n):
        """Column function of the scaled event functions followed by the outputs as one function (shared
        subexpressions evaluated once) for ``n`` samples, or None: only where :attr:`events_on` and
        :attr:`outputs_on` both take their numpy form on ``n`` samples, and it is then evaluated by its
        numpy form too (:meth:`ColumnFunction.on_numpy`), the same operations on the same numbers, so
        each value is bit for bit theirs (tested). A locked mode's events (static capacity against the
        torque to hold) are almost all in its outputs: default_driveline, 299 and 942 instructions,
        951 together, on 1 821 samples 0.56 + 1.32 ms apart and 1.32 ms together (measured). Only for
        a mode whose events and outputs share at least a tenth of the outputs' instructions: a
        slipping mode's events (17 instructions against 1 810) would save nothing, and the outputs of
        the samples past a crossing are thrown away."""
        if not self.events or not (self.events_on.uses_numpy(n) and self.outputs_on.uses_numpy(n)):
            return None
        if self._events_outputs is None:
            args = [self.xs, self.zs, self.pu, self.t]
            both = ca.Function(f"{self.name}_events_outputs", args,
                               [ca.densify(ca.cse(ca.vertcat(self.f_events(*args), self.f_outputs(*args))))])
            n_outputs = self.f_outputs.n_instructions()
            shared = self.f_events.n_instructions() + n_outputs - both.n_instructions()
            merged = ColumnFunction(both) if shared >= 0.1 * n_outputs else None
            self._events_outputs = merged if merged is not None and merged.translatable() else False
        return self._events_outputs or None

    def native_outputs_on(self):
        """:attr:`outputs_on` with the outputs compiled to machine code (itself if that fails)."""
        if self._native_outputs_on is None:
            compiled = compile_columns(self.f_outputs)
            self._native_outputs_on = ColumnFunction(compiled[0], loop=compiled[1]) if compiled is not None \
                else self.outputs_on
        return self._native_outputs_on

    # ----------------------------------------------------------------- algebraic variables
    def rootfinder(self):
        """``rf(zs_guess, xs, pu, t) -> zs`` solving the algebraic equations (CasADi Newton)."""
        if self._rootfinder is None:
            g = ca.Function(f"{self.name}_g", [self.zs, self.xs, self.pu, self.t], [self.alg_s])
            self._rootfinder = ca.rootfinder(f"{self.name}_rf", "newton", g,
                                             {"abstol": 1e-13, "abstolStep": 1e-14, "max_iter": 100,
                                              "error_on_fail": False})
        return self._rootfinder

    def consistent_z(self, xs, pu, t, guess=None):
        """Scaled algebraic variables solving ``alg = 0`` at ``(xs, pu, t)`` (Newton from ``guess``)."""
        if not self.nz:
            return np.zeros(0)
        guess = self.z_guess_scaled if guess is None else np.asarray(guess, float)
        rf = self.rootfinder()
        zs = np.array(rf(guess, xs, pu, t), dtype=float).ravel()
        if not (rf.stats()["success"] and np.all(np.isfinite(zs))):
            residual = np.array(self.f_alg(xs, zs, pu, t), dtype=float).ravel()
            raise solver_error("the consistent-initialisation Newton solve", "no_convergence", t, self,
                               xs, zs, detail=f"; largest scaled residual {np.max(np.abs(residual)):.3g}")
        return zs

    def z_explicit(self):
        """``zs(xs, pu, t)`` when the residuals are linear in z (solved symbolically), else None."""
        if self._z_explicit is None:
            if self.nz and ca.is_linear(self.alg_s, self.zs):
                a = ca.jacobian(self.alg_s, self.zs)
                b = ca.substitute(self.alg_s, self.zs, ca.DM.zeros(self.nz))
                zs = -ca.solve(a, b)
                self._z_explicit = ca.Function(f"{self.name}_z", [self.xs, self.pu, self.t], [zs])
            else:
                self._z_explicit = False
        return self._z_explicit or None

    # ----------------------------------------------------------------- conversions
    def x_dict(self, xs):
        """Unscaled state values by name."""
        xs = np.asarray(xs, float).reshape(self.nx)
        return dict(zip(self.x_names, xs * self.x_nominal))

    def z_dict(self, zs):
        """Unscaled algebraic values by name."""
        zs = np.asarray(zs, float).reshape(self.nz)
        return dict(zip(self.z_names, zs * self.z_nominal))


def reset_expressions(mode, ev, target):
    """The target mode's states after event ``ev`` of ``mode`` (expressions in the source
    variables): the reset's own, else the source state of the same name; ModelError if neither."""
    reset = dict(ev.reset or {})
    unknown = sorted(set(reset) - set(target.x))
    if unknown:
        raise ModelError(f"mode '{mode.name}', event '{ev.name}': reset names {unknown} are not states "
                         f"of target mode '{target.name}' ({list(target.x)})")
    exprs = []
    for name in target.x:
        if name in reset:
            exprs.append(ca.SX(reset[name]))
        elif name in mode.x:
            exprs.append(mode.x[name])
        else:
            raise ModelError(f"mode '{mode.name}', event '{ev.name}': target mode '{target.name}' has "
                             f"state '{name}' that the source mode lacks; give it in reset=")
    return exprs


def check_mode(mode, model):
    """Raise ModelError if a mode uses symbols that are not its variables, the model's parameters,
    inputs or time, or if a reset leaves a target state undefined (what compiling it would find,
    without compiling it)."""
    args = [_column(list(mode.x.values())), _column(list(mode.z.values())),
            _column(list(model.p.values()) + list(model.u.values())), model.t]
    groups = {"the ode": mode.ode, "the algebraic equations": mode.alg, "an output": list(mode.outputs.values()),
              "an event function": [ev.function for ev in mode.events],
              "an event guard": [ev.guard for ev in mode.events if ev.guard is not None]}
    for ev in mode.events:
        groups[f"the reset of event '{ev.name}'"] = reset_expressions(mode, ev, model.modes[ev.target])
    for what, exprs in groups.items():
        _function(f"{mode.name}_check", args, [_column([ca.SX(e) for e in exprs])], what, mode.name)


class CompiledModes(Mapping):
    """The compiled modes of a model by name, each compiled when a run first enters it.

    A run visits few of the modes an engagement model declares (bao2020: 3 of 6), and compiling a
    mode (common subexpressions, scaling, functions) costs as much as a warm run, so a sweep
    whose every point is a new model pays only for the modes its runs enter. The compiled mode
    is kept, so later runs of the same model reuse it (and its integrators).
    """

    def __init__(self, model):
        self._model = model
        self._done = {}

    def __getitem__(self, name):
        cm = self._done.get(name)
        if cm is None:
            mode = self._model.modes[name]            # KeyError for an unknown mode, as a dict
            cm = CompiledMode(mode, self._model)
            cm.build_resets(self._model.modes)
            self._done[name] = cm
        return cm

    def __iter__(self):
        return iter(self._model.modes)

    def __len__(self):
        return len(self._model.modes)

    def __contains__(self, name):
        return name in self._model.modes


def compile_model(model):
    """The modes of a :class:`~clutchocp.simulation.model.HybridModel`, checked now (:func:`check_mode`)
    and compiled on first use (:class:`CompiledModes`)."""
    for mode in model.modes.values():
        check_mode(mode, model)
    return CompiledModes(model)
