"""The hybrid simulation loop: pieces between input breaks, events, resets, restarts."""

import time

import numpy as np

from clutchocp import interrupt
from clutchocp.errors import ModelError, SolverError
from clutchocp.simulation.diagnostics import edge_error, solver_error
from clutchocp.simulation.events import ARMED, PASSED, EventMonitor
from clutchocp.simulation.idas_path import IdasPath
from clutchocp.simulation.model import PiecewiseConstant
from clutchocp.simulation.options import METHODS, SimulationOptions
from clutchocp.simulation.result import EventRecord, LazyOutputs, Segment, SimulationResult
from clutchocp.simulation.scipy_path import ScipyPath


def simulate(model, x0, grid, *, mode=None, p=None, u=None, z_guess=None, method="idas", options=None):
    """Simulate a hybrid DAE over an output grid.

    Parameters
    ----------
    model : HybridModel
        The modes, parameters, inputs and time symbol.
    x0 : mapping of str to float
        Initial value of every state of the initial mode (unscaled units).
    grid : array_like of float
        Increasing output times [s]; the run goes from ``grid[0]`` to ``grid[-1]``. Events
        are detected between consecutive grid points, so the grid must resolve the events
        (two crossings of one function within one interval cancel).
    mode : str, optional
        Initial mode (default: the model's first mode).
    p : mapping of str to float, optional
        Value of every parameter.
    u : mapping of str to float or PiecewiseConstant, optional
        Value or schedule of every input.
    z_guess : mapping of str to float, optional
        Starting guess for the initial algebraic variables (default: the mode's z_guess).
    method : {"idas", "cvodes", "Radau", "BDF", "LSODA"}
        "idas" integrates the DAE with CasADi IDAS; "cvodes" the same equations with CasADi
        CVODES (modes without algebraic variables only); the others integrate the ODE obtained
        by eliminating z with scipy's ``solve_ivp`` (a cross-check path).
    options : SimulationOptions, optional
        Tolerances and limits.

    Returns
    -------
    SimulationResult

    Raises
    ------
    ModelError
        Missing or unknown initial values, parameters or inputs; a bad grid.
    SolverError
        The integrator, the consistent initialisation or the event location failed, or the
        modes chatter; the message says when, in which mode, why and what to try.
    """
    wall_start = time.perf_counter()
    opts = options or SimulationOptions()
    if method not in METHODS:
        raise ModelError(f"method must be one of {METHODS}, got {method!r}")
    compile_start = time.perf_counter()
    compiled = model.compiled()                     # built once per model, then cached
    compile_time = time.perf_counter() - compile_start
    grid = np.asarray(grid, dtype=float).ravel()
    if grid.size < 2 or not np.all(np.isfinite(grid)) or np.any(np.diff(grid) <= 0):
        raise ModelError("grid must hold at least two finite, strictly increasing times")
    mode = model.initial_mode if mode is None else mode
    if mode not in compiled:
        raise ModelError(f"unknown initial mode '{mode}'; modes: {list(compiled)}")
    deadline = wall_start + opts.max_wall_time if opts.max_wall_time is not None else None
    run = _Run(compiled, grid, opts, _make_path(method, opts, deadline), _inputs(model, p, u, grid))
    cm = compiled[mode]
    xs0 = _initial_state(cm, x0)
    guess = None
    if z_guess is not None:
        unknown = sorted(set(z_guess) - set(cm.z_names))
        if unknown:
            raise ModelError(f"z_guess names {unknown} are not algebraic variables of mode '{cm.name}'")
        guess = np.array([z_guess[n] / s if n in z_guess else g
                          for n, s, g in zip(cm.z_names, cm.z_nominal, cm.z_guess_scaled)], dtype=float)
    run.start(cm, xs0, guess)
    run.loop()
    stats = run.path.stats()
    stats.update(method=method, n_switches=len(run.events), n_event_iterations=run.event_iterations,
                 wall_time_s=time.perf_counter() - wall_start, compile_time_s=compile_time, options=opts.as_dict())
    return SimulationResult.from_segments(run.segments(), run.events, stats)


def _make_path(method, opts, deadline=None):
    path = IdasPath(opts, plugin=method) if method in ("idas", "cvodes") else ScipyPath(method, opts)
    path.deadline = deadline
    return path


def _initial_state(cm, x0):
    x0 = dict(x0)
    missing = [n for n in cm.x_names if n not in x0]
    unknown = sorted(set(x0) - set(cm.x_names))
    if missing or unknown:
        raise ModelError(f"x0 of mode '{cm.name}' must give exactly {cm.x_names}; missing {missing}, unknown {unknown}")
    xs0 = np.array([float(x0[n]) for n in cm.x_names]) / cm.x_nominal
    if not np.all(np.isfinite(xs0)):
        raise ModelError(f"x0 must be finite, got {x0}")
    return xs0


class _Inputs:
    """Parameter + input vector as a function of time, and the input break times."""

    def __init__(self, fixed, schedules, breaks):
        self.fixed, self.schedules, self.breaks = fixed, schedules, breaks

    def at(self, t):
        return np.array(self.fixed + [s(t) if isinstance(s, PiecewiseConstant) else s for s in self.schedules])


def _inputs(model, p, u, grid):
    p, u = dict(p or {}), dict(u or {})
    for kind, given, declared in (("parameter", p, model.p), ("input", u, model.u)):
        missing = [n for n in declared if n not in given]
        unknown = sorted(set(given) - set(declared))
        if missing or unknown:
            raise ModelError(f"{kind} values must give exactly {list(declared)}; missing {missing}, unknown {unknown}")
    fixed = [float(p[n]) for n in model.p]
    schedules = [u[n] if isinstance(u[n], PiecewiseConstant) else float(u[n]) for n in model.u]
    tiny = 1e-12 * max(1.0, abs(grid[-1]))
    breaks = sorted({float(b) for s in schedules if isinstance(s, PiecewiseConstant) for b in s.breaks
                     if grid[0] + tiny < b < grid[-1] - tiny})
    values = fixed + [v for s in schedules for v in np.ravel(s.values if isinstance(s, PiecewiseConstant) else s)]
    if not np.all(np.isfinite(values)):
        raise ModelError("parameter and input values must be finite")
    return _Inputs(fixed, schedules, breaks)


def _same_inputs(a, b):
    """Whether two parameter + input vectors are equal (the same array, as a piece's samples share it,
    or equal values; the values are finite)."""
    return a is b or np.array_equal(a, b)


def _outputs_on(evaluate, xs, zs, blocks_pu, t):
    """Outputs (``evaluate``: a mode's ColumnFunction) on all samples of a segment, one call per run
    of equal inputs."""
    y = np.zeros((evaluate.n_out, t.size))
    start = 0
    for pu, count in blocks_pu:
        if count:
            y[:, start:start + count] = evaluate(xs[:, start:start + count], zs[:, start:start + count], pu,
                                                 t[start:start + count])
        start += count
    return y


def _outputs_completed(evaluate, n_out, blocks, rows=None):
    """Outputs on all samples of a segment whose grid blocks carry them already (evaluated with the
    events, :meth:`~clutchocp.simulation.compiled.CompiledMode.native_events_outputs` or
    :meth:`~clutchocp.simulation.compiled.CompiledMode.events_outputs`): the other blocks (single
    samples at events and input breaks) by ``evaluate`` in one call per run of equal inputs; ``rows``:
    the outputs ``evaluate`` gives, as positions in the blocks' outputs (default: all). ``evaluate``
    must give each sample the same value whatever the samples evaluated with it: compiled code, or
    the numpy form (:meth:`~clutchocp.simulation.compiled.ColumnFunction.on_numpy`)."""
    parts, missing = [], []
    for b in blocks:
        if b[4] is None:
            if missing and _same_inputs(missing[-1][0], b[3]):
                missing[-1][1].append(len(parts))
            else:
                missing.append([b[3], [len(parts)]])
            parts.append(None)
        else:
            parts.append(b[4] if rows is None else b[4][rows])
    for pu, idx in missing:
        group = [blocks[i] for i in idx]
        y = evaluate(np.concatenate([b[1] for b in group], axis=1), np.concatenate([b[2] for b in group], axis=1), pu,
                     np.concatenate([b[0] for b in group]))
        start = 0
        for i in idx:
            size = blocks[i][0].size
            parts[i] = y[:, start:start + size]
            start += size
    return np.concatenate(parts, axis=1) if parts else np.zeros((n_out, 0))


class _SegmentOutputs:
    """The outputs of one segment, evaluated when first read (:class:`~clutchocp.simulation.result.LazyOutputs`).

    Keeps the segment's scaled samples and its grid blocks, and gives the values that evaluating
    every output at the end of the run gives: the mode's output function on each run of samples with
    equal inputs (:func:`_outputs_on`); on CasADi's virtual machine and numpy restricted to the
    outputs asked for (:meth:`~clutchocp.simulation.compiled.CompiledMode.outputs_subset`, the same
    operations). Blocks that carry their outputs already (evaluated with the events) keep them where
    the run would have been evaluated the same way: always with compiled code (each sample's values
    whatever the others), with numpy where the run's samples take the numpy form (the other samples
    of the run then by numpy too).
    """

    def __init__(self, cm, blocks, t, xs, zs, native):
        self.cm, self.t, self.xs, self.zs, self.native = cm, t, xs, zs, native
        self.runs = []                        # [inputs, samples, blocks] of consecutive blocks with the same inputs
        for b in blocks:
            if self.runs and _same_inputs(self.runs[-1][0], b[3]):
                self.runs[-1][1] += b[0].size
                self.runs[-1][2].append(b)
            else:
                self.runs.append([b[3], b[0].size, [b]])

    def __call__(self, names):
        cm = self.cm
        if self.native:
            evaluate = cm.native_outputs_on()
            index, rows, on_each = list(range(len(cm.output_names))), None, evaluate
        else:
            index = sorted(cm.output_index[n] for n in names)
            evaluate = cm.outputs_subset(index)
            rows, on_each = index, evaluate.on_numpy
        parts, start = [], 0
        for pu, count, blocks in self.runs:
            if any(b[4] is not None for b in blocks) and (self.native or cm.outputs_on.uses_numpy(count)):
                parts.append(_outputs_completed(on_each, len(index), blocks, rows))
            else:
                parts.append(_outputs_on(evaluate, self.xs[:, start:start + count], self.zs[:, start:start + count],
                                         [(pu, count)], self.t[start:start + count]))
            start += count
        y = np.concatenate(parts, axis=1) if parts else np.zeros((len(index), 0))
        return {cm.output_names[i]: row for i, row in zip(index, y)}


class _Run:
    """State of one hybrid simulation."""

    def __init__(self, compiled, grid, opts, path, inputs):
        self.compiled, self.grid, self.opts, self.path, self.inputs = compiled, grid, opts, path, inputs
        self.tiny = 1e-12 * max(1.0, abs(grid[-1]))
        self.events, self.event_iterations = [], 0
        self._segments = []        # [cm, [t], [xs], [zs], [pu]]
        self._instant = (None, 0)  # (time of the last switch, switches at that time)

    # ------------------------------------------------------------- samples
    def _begin(self, cm):
        # blocks of (t (n,), xs (nx, n), zs (nz, n), pu (npu,), outputs (n_out, n) or None if not yet evaluated)
        self._segments.append([cm, []])

    def _add(self, t, xs, zs, pu):
        self._add_block(np.array([float(t)]), xs, zs, pu)

    def _add_block(self, t, xs, zs, pu, y=None):
        n = np.size(t)
        if n:
            cm = self._segments[-1][0]
            self._segments[-1][1].append((np.asarray(t, float).reshape(n), np.asarray(xs, float).reshape(cm.nx, n),
                                          np.asarray(zs, float).reshape(cm.nz, n), np.asarray(pu, float), y))

    def _start_outputs(self, y):
        """Outputs ``y`` at the start of the last advance (self.t, self.xs, self.zs, self.pu) given to the
        segment's last sample if it is that start (it is unless the advance followed a passed event)."""
        blocks = self._segments[-1][1]
        b = blocks[-1] if blocks else None
        if b is not None and b[4] is None and b[0].size == 1 and b[0][0] == self.t \
                and np.array_equal(b[1][:, 0], self.xs) and np.array_equal(b[2][:, 0], self.zs) \
                and _same_inputs(b[3], self.pu):
            blocks[-1] = (*b[:4], y.reshape(-1, 1))

    def segments(self):
        out = []
        for cm, blocks in self._segments:
            t = np.concatenate([b[0] for b in blocks]) if blocks else np.zeros(0)
            xs = np.concatenate([b[1] for b in blocks], axis=1) if blocks else np.zeros((cm.nx, 0))
            zs = np.concatenate([b[2] for b in blocks], axis=1) if blocks else np.zeros((cm.nz, 0))
            outputs = LazyOutputs(cm.output_names, _SegmentOutputs(cm, blocks, t, xs, zs, self.opts.native))
            x, z = xs * cm.x_nominal[:, None], zs * cm.z_nominal[:, None]     # unscaled, row by row
            out.append(Segment(cm.name, t, dict(zip(cm.x_names, x)), dict(zip(cm.z_names, z)), outputs))
        return out

    # ------------------------------------------------------------- mode entry and switches
    def start(self, cm, xs, z_guess):
        self.t, self.pu = float(self.grid[0]), self.inputs.at(self.grid[0])
        self.cm, self.xs = cm, xs
        self.zs = cm.consistent_z(xs, self.pu, self.t, z_guess)
        self._begin(cm)
        self._add(self.t, self.xs, self.zs, self.pu)
        self._enter()

    def _enter(self):
        """Arm the current mode's events; switch at once while one is already past its zero."""
        while True:
            cm = self.cm
            self.monitor = EventMonitor(cm.events, self.opts.event_band)
            if not cm.events:
                return
            s = cm.event_values(self.opts.native)(self.xs, self.zs, self.pu, self.t).ravel()
            ok = cm.at("guards", self.xs, self.zs, self.pu, self.t) >= 0
            fire = self.monitor.enter(s, ok)
            if fire is None:
                return
            self._switch(fire, iterations=0)

    def _switch(self, i, iterations):
        cm, spec, t = self.cm, self.cm.events[i], self.t
        if spec.edge:                   # the model's edge: the run ends here, no result beyond it
            raise edge_error(spec, t, cm, self.xs, self.zs, self._outputs(cm, self.xs, self.zs))
        last, count = self._instant
        count = count + 1 if last is not None and abs(t - last) <= self.opts.event_time_tol else 1
        self._instant = (t, count)
        if count > self.opts.max_instant_switches:
            modes = " -> ".join(e.source for e in self.events[-count + 1:]) + f" -> {spec.target}"
            raise SolverError(f"mode chatter at t = {t:.12g} s: {count} switches without time passing ({modes}). "
                              "The events of these modes contradict each other at this state. Try: give the events "
                              "guards that exclude each other (e.g. lock only when the needed torque is within the "
                              "static capacity), or a larger event_band.")
        if len(self.events) >= self.opts.max_switches:
            raise SolverError(f"more than max_switches = {self.opts.max_switches} mode switches by t = {t:.12g} s "
                              f"(last: '{spec.name}' from '{cm.name}' to '{spec.target}'). Try: check the events "
                              "for chatter, or raise max_switches.")
        target = self.compiled[spec.target]
        xs_new = cm.at(("reset", i), self.xs, self.zs, self.pu, t)
        known = cm.z_dict(self.zs)
        guess = np.array([known[n] / s if n in known else g
                          for n, s, g in zip(target.z_names, target.z_nominal, target.z_guess_scaled)])
        zs_new = target.consistent_z(xs_new, self.pu, t, guess)
        self.events.append(EventRecord(spec.name, t, cm.name, target.name, cm.x_dict(self.xs), target.x_dict(xs_new),
                                       cm.z_dict(self.zs), target.z_dict(zs_new), self._outputs(cm, self.xs, self.zs),
                                       self._outputs(target, xs_new, zs_new), iterations))
        self.cm, self.xs, self.zs = target, xs_new, zs_new
        self._begin(target)
        self._add(t, xs_new, zs_new, self.pu)

    def _outputs(self, cm, xs, zs):
        values = cm.outputs_on(xs, zs, self.pu, self.t)[:, 0]
        return dict(zip(cm.output_names, values))

    # ------------------------------------------------------------- main loop
    def loop(self):
        t_final = self.grid[-1]
        while self.t < t_final - self.tiny:
            interrupt.check(f"{self.path.name} at t = {self.t:.6g} s")
            if self.path.deadline is not None and time.perf_counter() > self.path.deadline:
                raise solver_error(self.path.name, "wall_time", self.t, self.cm, self.xs, self.zs,
                                   detail=f" ({self.opts.max_wall_time:g} s)")
            t_end = next((b for b in self.inputs.breaks if b > self.t + self.tiny), t_final)
            # grid points in (t + tiny, t_end - tiny): the grid is strictly increasing
            inner = self.grid[np.searchsorted(self.grid, self.t + self.tiny, side="right"):
                              np.searchsorted(self.grid, t_end - self.tiny, side="left")]
            times = np.append(inner, t_end)
            adv = self.path.advance(self.cm, self.t, self.xs, self.zs, self.pu, times, self.monitor)
            if adv.y_start is not None:
                self._start_outputs(adv.y_start)
            if adv.y_blocks is None:
                self._add_block(adv.t, adv.xs, adv.zs, self.pu, adv.y)
            else:                               # block by block, each with its outputs or without
                start = 0
                for size, y in adv.y_blocks:
                    self._add_block(adv.t[start:start + size], adv.xs[:, start:start + size],
                                    adv.zs[:, start:start + size], self.pu, y)
                    start += size
            crossing = adv.crossing
            if crossing is None:
                self.t, self.xs, self.zs = t_end, adv.xs[:, -1], adv.zs[:, -1]
                if t_end < t_final:
                    self._input_break()
                continue
            self.t, self.xs, self.zs = crossing.t, np.asarray(crossing.xs, float), np.asarray(crossing.zs, float)
            self.event_iterations += crossing.iterations
            if crossing.kind == "rearm":
                for i in crossing.events:
                    self.monitor.state[i] = ARMED
                continue
            guards = self.cm.at("guards", self.xs, self.zs, self.pu, self.t)
            fired = next((i for i in crossing.events if guards[i] >= 0), None)
            if fired is None:
                for i in crossing.events:
                    self.monitor.state[i] = PASSED
                continue
            self._add(self.t, self.xs, self.zs, self.pu)
            self._switch(fired, crossing.iterations)
            self._enter()
            self._break_at_event()

    def _input_break(self, at=None):
        """Inputs jump at self.t (their values taken at ``at``, default self.t): new consistent z,
        a sample on each side, events re-armed."""
        self.pu = self.inputs.at(self.t if at is None else at)
        self.zs = self.cm.consistent_z(self.xs, self.pu, self.t, self.zs)
        self._add(self.t, self.xs, self.zs, self.pu)
        self._enter()

    def _break_at_event(self):
        """An event located within ``tiny`` of an input break: the next piece starts past that
        break, so apply it here (else the old input values would stay in force)."""
        for b in self.inputs.breaks:
            if abs(b - self.t) <= self.tiny and not np.array_equal(self.inputs.at(b), self.pu):
                self._input_break(at=b)
