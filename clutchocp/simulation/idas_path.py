"""Integration of one mode with CasADi IDAS or CVODES, events detected on the output grid and refined.

The integrator of a mode (:meth:`IdasPath.scheme_for`): IDAS for a mode with algebraic variables,
CasADi's CVODES (BDF, ``SimulationOptions.ode_integrator``) for a mode without (an ODE; every
engagement mode). CVODES needs no consistent initialisation and takes fewer steps (default_fill
at rtol 1e-8: 1 219 steps for the three pieces with IDAS, 960 with CVODES), but its error test
lets more global error through at the same tolerances: at the scenes' own tolerances its
outputs' median error against an rtol 1e-12 reference was 1.2-2.8 times IDAS's. The engine
therefore runs CVODES at ``CVODES_TOLERANCE_FACTOR`` (0.3) times rtol and atol, where on all six
built-in engagement scenes both the largest and the median output error are below IDAS's at
rtol (e.g. default_driveline: largest 4.3e-8 against 1.0e-7, median 1.20e-8 against 1.22e-8);
``method="cvodes"`` runs CVODES at the tolerances given. Adams (``ode_integrator="adams"``) takes
fewer steps on the non-stiff pieces (default_driveline slipping: 269 against 376) but more on
others (zhang2021 slipping: 524 against 436), fails on the stiff ones (CV_TOO_MUCH_WORK on
bao2020 slipping) and, approaching an event function asymptotically (a viscous coupling
closing on its input speed), overshoots it by ~atol and fires it; it is not chosen by default.

Within a piece (no mode switch, no input break) the mode is integrated by
``casadi.integrator(..., "idas", dae_tau, 0, taus, opts)`` on the scaled variables and on
normalised time ``tau`` (``t = t0 + tau * span``, ``t0`` and ``span`` are parameters), so one
integrator serves every call with the same relative output times: the integrators are built
once per mode and output pattern and cached on the compiled mode (a uniform chunk of ``n``
grid intervals has the pattern ``k / n``). IDACalcIC starts every call (it computes the
state derivatives, and for a DAE the algebraic variables); its first trial step is put at
``FIRST_TIME`` of the interval, so that its Newton matrix is dominated by the ``cj dF/dxdot``
term and converges on stiff modes (squeeze films, eigenvalues ~ -1e9 1/s), where the default
(the end of the interval) fails with IDA_CONV_FAIL. Measured on the seed scenes (starts all
along the runs, spans 1.5 ms - 3 s): IDACalcIC fails from 1e-2 up and works down to 1e-8;
below that its Newton test accepts an inexact derivative and the first step fails (a DAE with
a step input at rtol 1e-10 fails at 1e-9). If a call of a mode without algebraic variables
fails anyway, it is repeated once with a fresh integrator started from ``xdot = f(x0)``
(``init_xdot``, no IDACalcIC) before the failure counts.

How far each call goes (``chunk=None``): the scaled event functions, their first and second
time derivatives along the flow give a quadratic prediction of the next crossing; the call
ends on the first grid point beyond ``SAFETY`` times the predicted time (the rest of the piece
if no crossing is predicted). An event function at rest (zero slope) whose curvature points away
from zero hides its crossing from the quadratic (default_fill: the piston held back while the
fill pressure builds up, in the third derivative; the first call ran to 1.5 s, 9 092 steps of
them past the impact at 2.5 ms): such a piece is watched with calls of 1, 4, 16, ... grid
intervals (``BLIND_GROWTH``) until a crossing is predicted within one. A crossing predicted well
inside the next grid interval is approached by intermediate integrations (``PROBES``) that
produce no output sample. Each call is a restart of the integrator (order 1, small first
step), so fewer calls cost fewer steps; work integrated past an event is thrown away, so calls
that end shortly after it waste little.
After an event the first, partial grid interval is integrated on its own, and the rest of the
piece in uniform chunks (measured on bao2020: one call from the impact on takes 2300 steps,
a restart at the first grid point 2000). With ``chunk`` given, calls cover ``chunk`` grid
intervals, growing by ``chunk_growth``. Mode integrations use ``native_dae`` instead of
``dae_tau`` when ``native=True`` (see :mod:`clutchocp.simulation.native`).

The scaled event functions are evaluated on the outputs (with ``native=True``, in a mode whose
event functions call tables, together with the mode's outputs in one compiled function:
:meth:`~clutchocp.simulation.compiled.CompiledMode.native_events_outputs`; without, on a call
whose samples both take the numpy form, in one numpy function:
:meth:`~clutchocp.simulation.compiled.CompiledMode.events_outputs`; the outputs of the
grid samples kept go back to the driver in ``Advance.y``); at the first sign change the
crossing is located by short IDAS integrations started from the latest point known to lie
before it: a cubic Hermite interpolant of the grid values gives the first trial time, then
safeguarded secant steps (:func:`~clutchocp.simulation.events.locate`) until the bracket is
shorter than ``event_time_tol`` or ``|event| <= event_value_tol``.

A mode often stops making sense just past its event (a piston passing through a plate, a
gap below zero), so IDAS may fail there before the event has been seen. A failed call is
retried on the first half of its output times (an event before the failure is then found on
the grid); within a single interval the farthest reachable time is found by bisection and
checked for a crossing. Only if none crossed is a SolverError raised.

The same class drives CasADi's CVODES (``plugin="cvodes"``, ``method="cvodes"``) on the same
normalised-time ODE for modes without algebraic variables, and enforces
``SimulationOptions.max_wall_time`` before every call.
"""

import functools
import math
import time
import warnings
from collections import OrderedDict

import casadi as ca
import numpy as np

from clutchocp import interrupt
from clutchocp.errors import ModelError
from clutchocp.simulation.diagnostics import idas_flag, solver_error
from clutchocp.simulation.events import ARMED, ENTRY, Advance, Crossing, locate

_COUNTERS = {"nsteps": "n_steps", "nfevals": "n_rhs_evals", "nlinsetups": "n_jacobian_evals",
             "netfails": "n_error_test_failures", "nniters": "n_newton_iters", "nncfails": "n_newton_failures"}

FIRST_TIME = 1e-6       # IDACalcIC's trial step, as a fraction of the call's interval
SAFETY = 1.5            # a call ends beyond SAFETY x the predicted time to the next crossing
PROBES = (0.9, 2.0)     # intermediate integrations inside a grid interval end at these multiples
                        # of the predicted time (first just before the crossing, then past it)
CVODES_TOLERANCE_FACTOR = 0.3   # the engine's CVODES tolerances: this x rtol, atol (see the module docstring)
BLIND_GROWTH = 4        # a piece started with an unseen crossing: calls of 1, 4, 16, ... grid intervals
SCHEMES = ("idas", "bdf", "adams")
CACHE_SIZE = 64         # integrators kept per mode for irregular output patterns


class _IdasFailure(Exception):
    def __init__(self, flag, message):
        super().__init__(message)
        self.flag = flag


class _Point:
    """A sample: time, scaled states, scaled algebraic variables, scaled event values."""

    __slots__ = ("s", "t", "xs", "zs")

    def __init__(self, t, xs, zs, s):
        self.t, self.xs, self.zs, self.s = float(t), xs, zs, s

    def payload(self):
        return (self.t, self.xs, self.zs)


def first_positive_root(a, b, c):
    """Smallest tau > 0 with ``a + b tau + c tau^2 / 2 = 0`` (inf if none or not finite)."""
    if not (math.isfinite(a) and math.isfinite(b) and math.isfinite(c)):
        return math.inf
    if a == 0:
        return 0.0
    q2 = 0.5 * c
    if q2 == 0 or abs(q2 * a) <= 1e-14 * b * b:
        tau = -a / b if b != 0 else math.inf
        return tau if tau > 0 else math.inf
    disc = b * b - 4 * q2 * a
    if disc < 0:
        return math.inf
    q = -0.5 * (b + math.copysign(math.sqrt(disc), b))
    roots = [q / q2, a / q if q != 0 else math.inf]
    positive = [r for r in roots if r > 0]
    return min(positive) if positive else math.inf


@functools.lru_cache(maxsize=4)
def _hermite_basis(n):
    """The ``n`` equally spaced points ``th`` of [0, 1] and the cubic Hermite basis functions there
    (h00, h10, h01, h11), computed once per ``n`` (read-only arrays)."""
    th = np.linspace(0.0, 1.0, n)
    h00, h10 = 2 * th**3 - 3 * th**2 + 1, th**3 - 2 * th**2 + th
    h01, h11 = -2 * th**3 + 3 * th**2, th**3 - th**2
    for a in (th, h00, h10, h01, h11):
        a.flags.writeable = False
    return th, h00, h10, h01, h11


def _uniform_count(t0, times, tol=1e-8):
    """How many leading ``times`` are equally spaced from ``t0`` (spacing times[0] - t0)."""
    step = times[0] - t0
    k = _counting(times.size)
    ok = np.abs((times - t0) - k * step) <= tol * step
    first_bad = int(ok.argmin())
    return int(times.size) if ok[first_bad] else first_bad


def _counting(n):
    """1.0, 2.0, ..., n as a read-only float array (a view of one kept array, grown when too short)."""
    count = _COUNT[0]
    if count.size < n:
        count = np.arange(1, max(n, 2 * count.size) + 1, dtype=float)
        count.flags.writeable = False
        _COUNT[0] = count
    return count[:n]


_COUNT = [np.zeros(0)]


class _Integrator:
    """A casadi IDAS integrator called through the buffer interface (numpy in and out)."""

    def __init__(self, integrator, nx, nz, n):
        # buffers carry structural nonzeros only: the outputs read here must be dense
        assert integrator.sparsity_out("xf").is_dense() and integrator.sparsity_out("zf").is_dense()
        self.integrator, self.nx, self.nz, self.n = integrator, nx, nz, n
        self.buffer, self.evaluate = integrator.buffer()

    def __call__(self, x0, z0, p):
        """Scaled states (nx, n) and algebraic variables (nz, n) at the output times."""
        dummy = np.zeros(1)
        args = [np.ascontiguousarray(x0, float).ravel(), np.ascontiguousarray(z0, float).ravel(),
                np.ascontiguousarray(p, float).ravel()]
        xf, zf = np.zeros((self.n, self.nx)), np.zeros((self.n, self.nz))
        for i, a in enumerate(args):
            self.buffer.set_arg(i, memoryview(a if a.size else dummy))
        self.buffer.set_res(0, memoryview(xf if xf.size else dummy))
        self.buffer.set_res(1, memoryview(zf if zf.size else dummy))
        self.evaluate()
        if self.buffer.ret():
            raise RuntimeError(f"integrator returned flag {self.buffer.ret()}")
        return xf.T, zf.T

    def stats(self):
        try:
            return self.buffer.stats()
        except RuntimeError:
            return {}


class IdasPath:
    """Integrates modes with IDAS; see the module docstring.

    ``plugin="cvodes"`` integrates the same normalised-time equations with CasADi's CVODES
    (BDF, the ODE counterpart of IDAS) instead: for modes without algebraic variables only,
    with no consistent initialisation needed; everything else (events, restarts, caching) is
    shared. ``deadline`` (a ``time.perf_counter()`` value, set by the driver from
    ``max_wall_time``) is checked before every integrator call.
    """

    def __init__(self, options, plugin="idas"):
        if plugin not in ("idas", "cvodes"):
            raise ModelError(f"IdasPath plugin must be 'idas' or 'cvodes', got {plugin!r}")
        self.options = options
        self.plugin = self.name = plugin
        self.deadline = None
        self.counters = {v: 0 for v in _COUNTERS.values()}
        self.counters.update(n_integrator_calls=0, n_location_integrations=0, n_probe_integrations=0,
                             n_integrators_built=0, integration_time_s=0.0)
        self.counters.update({f"n_pieces_{k}": 0 for k in SCHEMES}, n_adams_redone_bdf=0)
        self._options_key = {}      # scheme -> the cache key of its options (_options_key_of), on first use
        self._schemes = {}          # mode name -> scheme of its current piece (begin_piece)
        self._stiff = set()         # modes whose Adams integration failed in this run: BDF from then on

    # ------------------------------------------------------------------ the integrator of a mode
    def scheme_for(self, cm):
        """The integrator of mode ``cm``: ``"idas"``, ``"bdf"`` (CVODES BDF) or ``"adams"`` (CVODES
        Adams-Moulton); see the module docstring."""
        if self.plugin == "cvodes":
            return "bdf"
        choice = self.options.ode_integrator
        if cm.nz or choice == "idas":
            return "idas"
        return "bdf" if cm.name in self._stiff else choice

    def _solver(self, cm):
        """Name of the integrator of the current piece of ``cm`` (for messages)."""
        return "IDAS" if self._schemes.get(cm.name, "idas") == "idas" else "CVODES"

    def begin_piece(self, cm):
        """Choose the integrator of mode ``cm`` for the piece that starts now (every integration of
        ``cm`` until the next call uses it), count the piece and return the integrator."""
        scheme = self._schemes[cm.name] = self.scheme_for(cm)
        self.counters[f"n_pieces_{scheme}"] += 1
        return scheme

    # ------------------------------------------------------------------ IDAS calls
    def _idas_options(self, span, scheme):
        o = self.options
        # NaN/Inf in an evaluation is reported by the integrator's flag (IDA_RES_FAIL, ...) and
        # turned into a SolverError; CasADi's own per-evaluation warnings would flood stderr.
        factor = CVODES_TOLERANCE_FACTOR if scheme != "idas" and self.plugin == "idas" else 1.0
        opts = {"abstol": factor * o.atol, "reltol": factor * o.rtol, "max_num_steps": o.max_num_steps,
                "show_eval_warnings": False}
        if scheme == "idas":
            opts.update(suppress_algebraic=o.suppress_algebraic, calc_ic=True, first_time=FIRST_TIME)
        elif scheme == "adams":
            opts["linear_multistep_method"] = "adams"
        if o.max_step is not None:
            opts["max_step_size"] = o.max_step / span          # normalised time
        if scheme == "idas":
            opts.update(o.idas_options)
        return opts

    def _options_key_of(self, scheme):
        """The part of an integrator's cache key that stands for its options (computed once per run
        and scheme: most runs use one scheme of three)."""
        key = self._options_key.get(scheme)
        if key is None:
            key = self._options_key[scheme] = (repr(sorted(self._idas_options(1.0, scheme).items()))
                                               + f"native={self.options.native}")
        return key

    def _integrator(self, cm, taus, span, scheme):
        """The cached integrator (``scheme``) of ``cm`` with outputs at normalised times ``taus``."""
        n = len(taus)
        uniform = float(np.max(np.abs(taus - _counting(n) / n))) <= 1e-9
        pattern = n if uniform else tuple(np.round(taus, 12))
        key = (self._options_key_of(scheme), pattern, span if self.options.max_step is not None else None)
        cache = cm.integrators.setdefault(scheme, OrderedDict())
        entry = cache.get(key)
        if entry is None:
            if self.plugin == "cvodes" and cm.nz:
                raise ModelError(f"method 'cvodes' integrates ODEs only: mode '{cm.name}' has algebraic variables "
                                 f"{cm.z_names}; use method='idas'")
            plugin = "idas" if scheme == "idas" else "cvodes"
            grid = [k / n for k in range(1, n + 1)] if uniform else [float(x) for x in taus]
            entry = _Integrator(ca.integrator(f"{plugin}_{cm.name}", plugin, self._dae(cm), 0.0, grid,
                                              self._idas_options(span, scheme)), cm.nx, cm.nz, n)
            self.counters["n_integrators_built"] += 1
            cache[key] = entry
            if len(cache) > CACHE_SIZE:
                cache.popitem(last=False)
        else:
            cache.move_to_end(key)
        return entry

    def _dae(self, cm):
        """The DAE IDAS integrates: compiled to machine code with ``native=True`` (if it can be)."""
        if self.options.native:
            dae = cm.native_dae()
            if dae is not None:
                return dae
            warnings.warn("SimulationOptions(native=True): no working C compiler found ($CC, cc, gcc); "
                          "the equations are evaluated by CasADi instead", RuntimeWarning, stacklevel=2)
        return cm.dae_tau

    def _run(self, entry, x0, z0, p):
        self.counters["n_integrator_calls"] += 1
        start = time.perf_counter()
        try:
            with interrupt.in_solver():
                xs, zs = entry(x0, z0, p)
        except RuntimeError as err:
            self._count(entry, start)
            # a Ctrl-C inside IDAS surfaces as a failed step ("psetup failed: KeyboardInterrupt")
            interrupt.check(f"{self.name.upper()} at t = {p[-2]:.6g} s")
            raise _IdasFailure(idas_flag(err), str(err)) from None
        self._count(entry, start)
        interrupt.check(f"{self.name.upper()} at t = {p[-2]:.6g} s")
        return xs, zs

    def _count(self, entry, start):
        """Add the time since ``start`` (the integrator call alone) and the call's statistics."""
        self.counters["integration_time_s"] += time.perf_counter() - start
        stats = entry.stats()
        for key, name in _COUNTERS.items():
            self.counters[name] += int(stats.get(key, 0))

    def _integrate(self, cm, t0, xs0, zs0, pu, times):
        """From ``t0`` over the output ``times``: scaled states (nx, n) and algebraic variables (nz, n)."""
        if self.deadline is not None and time.perf_counter() > self.deadline:
            raise solver_error(self.name.upper(), "wall_time", t0, cm, xs0, zs0,
                               detail=f" ({self.options.max_wall_time:g} s)")
        times = np.asarray(times, float)
        span = float(times[-1] - t0)
        taus = (times - t0) / span
        p = np.concatenate([np.ravel(pu), [t0, span]])
        scheme = self._schemes.get(cm.name) or self.begin_piece(cm)
        try:
            return self._run(self._integrator(cm, taus, span, scheme), xs0, zs0, p)
        except _IdasFailure:
            if scheme == "adams":       # stiff after all: BDF for this mode from here on
                self._stiff.add(cm.name)
                self._schemes[cm.name] = "bdf"
                self.counters["n_adams_redone_bdf"] += 1
                return self._run(self._integrator(cm, taus, span, "bdf"), xs0, zs0, p)
            if cm.nz or scheme != "idas":
                raise
        # an ODE mode: the consistent start derivative is f(x0); IDAS without IDACalcIC
        xdot = np.array(cm.f_ode(xs0, np.zeros(0), pu, t0), dtype=float).ravel() * span
        opts = {**self._idas_options(span, "idas"), "calc_ic": False, "init_xdot": xdot.tolist()}
        self.counters["n_integrators_built"] += 1
        integrator = ca.integrator(f"idas_{cm.name}_fresh", "idas", self._dae(cm), 0.0, taus.tolist(), opts)
        return self._run(_Integrator(integrator, cm.nx, cm.nz, taus.size), xs0, zs0, p)

    def _integrate_to(self, cm, t0, xs0, zs0, pu, t1):
        """Single interval [t0, t1]: the state at t1 (scaled x, z)."""
        xs, zs = self._integrate(cm, t0, xs0, zs0, pu, [t1])
        return xs[:, -1], zs[:, -1]

    # ------------------------------------------------------------------ one piece
    def advance(self, cm, t_a, xs_a, zs_a, pu, times, monitor):
        """Integrate mode ``cm`` from ``t_a`` over ``times`` until the first event crossing.

        Returns an :class:`~clutchocp.simulation.events.Advance` with the samples strictly
        before the crossing (all of ``times`` if none) and the located crossing.

        Where the events are evaluated with the outputs by numpy
        (:meth:`~clutchocp.simulation.compiled.CompiledMode.events_outputs`), on the call that ends
        the piece, the samples before it (the start, ``t_a``, and the earlier calls) are evaluated in
        the same call: a numpy call costs about the same for one sample as for two thousand, so one
        call a piece.
        """
        o = self.options
        times = np.asarray(times, float)
        xs_a, zs_a = np.asarray(xs_a, float), np.asarray(zs_a, float)
        self.begin_piece(cm)
        left = _Point(t_a, xs_a, zs_a, self._events(cm, xs_a, zs_a, pu, t_a)[:, 0])
        blocks = []
        pending = [None]        # samples without outputs, to evaluate with the next merged call: None is the start
        y_start = None
        start, size, cap, probes, horizon = 0, o.chunk, None, 0, None
        while start < times.size:
            if o.chunk is None:
                n, t_probe, horizon = self._plan(cm, left, pu, times[start:], monitor, probes, horizon, start == 0)
            else:
                n, t_probe = min(size, times.size - start), None
            if cap is not None:
                n = min(n, cap)
            n = self._regular(left.t, times[start:], n)
            targets = np.array([t_probe]) if t_probe is not None else times[start:start + n]
            failure = None
            try:
                if t_probe is not None:
                    self.counters["n_probe_integrations"] += 1
                xs, zs = self._integrate(cm, left.t, left.xs, left.zs, pu, targets)
                if o.chunk is not None and o.chunk_growth:
                    size = max(1, int(size * o.chunk_growth))
                if cap is not None:
                    cap *= 2
            except _IdasFailure as fail:
                if targets.size > 1:            # retry the first half: an event may come before the failure
                    cap = targets.size // 2
                    continue
                failure = fail                  # one interval: go as far as IDAS can, look for an event there
                targets, xs, zs = self._reach(cm, left, pu, targets[0], fail, monitor)
            y = None
            merged = None
            if t_probe is None and failure is None:
                # numpy: only on the call that ends the piece, with every sample before it (one call a piece)
                merged = cm.native_events_outputs() if o.native else \
                    cm.events_outputs(targets.size) if start + targets.size == times.size else None
            if merged is not None and o.native:     # grid samples: their outputs with the events, in one call
                both = merged(xs, zs, pu, targets)
                s, y = both[:len(cm.events)], both[len(cm.events):]
            elif merged is not None:
                earlier = [(t_a, xs_a.reshape(cm.nx, 1), zs_a.reshape(cm.nz, 1)) if k is None else blocks[k][:3]
                           for k in pending]
                both = merged.on_numpy(np.concatenate([e[1] for e in earlier] + [xs], axis=1),
                                       np.concatenate([e[2] for e in earlier] + [zs], axis=1), pu,
                                       np.concatenate([np.atleast_1d(e[0]) for e in earlier] + [targets]))
                first = 0
                for k, e in zip(pending, earlier):
                    size_k = np.size(e[0])
                    y_k = both[len(cm.events):, first:first + size_k]
                    if k is None:
                        y_start = y_k[:, 0]
                    else:
                        blocks[k] = (*blocks[k][:3], y_k)
                    first += size_k
                pending = []
                s, y = both[:len(cm.events), first:], both[len(cm.events):, first:]
            else:
                s = self._events(cm, xs, zs, pu, targets)
            j, crossings = monitor.scan_block(left.s, s)
            if j is not None:
                right = _Point(targets[j], xs[:, j], zs[:, j], s[:, j])
                if j > 0 and t_probe is None and failure is None:
                    blocks.append((targets[:j], xs[:, :j], zs[:, :j], y[:, :j] if y is not None else None))
                if j > 0:
                    left = _Point(targets[j - 1], xs[:, j - 1], zs[:, j - 1], s[:, j - 1])
                crossing = self._locate(cm, pu, left, right, crossings)
                return _advance(blocks, cm, crossing, y_start)
            if failure is not None:
                raise solver_error(self._solver(cm), failure.flag, targets[-1], cm, xs[:, -1], zs[:, -1])
            left = _Point(targets[-1], xs[:, -1], zs[:, -1], s[:, -1])
            if t_probe is not None:
                probes += 1
                continue
            if y is None:
                pending.append(len(blocks))
            blocks.append((targets, xs, zs, y))
            start += targets.size
            probes = 0
        return _advance(blocks, cm, None, y_start)

    def _plan(self, cm, left, pu, times, monitor, probes, horizon=None, first=False):
        """Grid intervals for the next call, or a probe time inside the next interval, and the
        horizon of the call after it.

        A piece whose first call (``first``) sees an event function at rest curving away from zero
        (:meth:`_time_to_event`) is watched with calls of 1, BLIND_GROWTH, BLIND_GROWTH^2, ... grid
        intervals (``horizon``) until a crossing is predicted within one of them; other pieces are
        planned by the prediction alone.
        """
        tau, unknown = self._time_to_event(cm, left, pu, monitor, times[-1] - left.t)
        gap = times[0] - left.t
        if probes < len(PROBES) and PROBES[probes] * tau < 0.5 * gap:
            return 1, left.t + max(PROBES[probes] * tau, 1e-3 * gap), horizon
        if first and unknown:
            return 1, None, BLIND_GROWTH
        span = SAFETY * tau
        n = int(np.searchsorted(times, left.t + span, side="left")) + 1 if math.isfinite(span) else times.size
        n = min(n, times.size)
        if horizon is not None:
            if n > horizon:
                return horizon, None, horizon * BLIND_GROWTH
            horizon = None                  # a crossing predicted within reach: predictions from here on
        return n, None, horizon

    @staticmethod
    def _regular(t0, times, n):
        """Shorten ``n`` to a run of equally spaced outputs (one cached integrator per length).

        After an event the first interval is partial: it is integrated on its own. A grid that
        is irregular throughout is taken as it comes (one integrator per pattern).
        """
        k = _uniform_count(t0, times[:n])
        if k >= 2 or n == 1:
            return k
        if n >= 3 and _uniform_count(times[0], times[1:n]) >= 2:
            return 1
        return n

    def _time_to_event(self, cm, left, pu, monitor, span=math.inf):
        """Predicted time until an event can fire (quadratic in its time derivatives; inf if none)
        and whether an event's crossing is unknown: a function at rest (zero first derivative)
        whose curvature points away from zero and would move it by more than its distance from
        zero within ``span`` [s] (e.g. a piston held against its stop while the fill pressure,
        which will move it, builds up from zero; in the third derivative). A locked mode's
        nearly constant function (curvature ~1e-10 of its value) is not unknown."""
        if not cm.events:
            return math.inf, False
        unknown = False
        slopes = cm.event_slopes()(left.xs, left.zs, pu, left.t).reshape(3, len(cm.events)).T.tolist()   # floats
        best = math.inf
        for i, spec in enumerate(cm.events):
            state = monitor.state[i]
            if spec.edge:               # an edge of the model ends the run: found on the samples, never planned for
                continue
            if state == ARMED:
                offset = 0.0
            elif state == ENTRY and spec.direction != 0:
                offset = spec.direction * monitor.band
            else:
                continue
            s, s1, s2 = slopes[i]
            root = first_positive_root(s - offset, s1, s2)
            unknown = unknown or (s1 == 0 and root == math.inf and 0.5 * abs(s2) * span * span > abs(s - offset))
            best = min(best, root)
        return best, unknown

    def _reach(self, cm, left, pu, t_fail, fail, monitor, rel_tol=1e-7):
        """Farthest time in (left, t_fail) IDAS reaches, by bisection; stops early at an event crossing.

        Returns that time and the state there as a one-sample (times, xs, zs).
        """
        lo, hi, best = left.t, t_fail, None
        while hi - lo > rel_tol * (t_fail - left.t):
            mid = 0.5 * (lo + hi)
            try:
                xs, zs = self._integrate_to(cm, left.t, left.xs, left.zs, pu, mid)
            except _IdasFailure:
                hi = mid
                continue
            lo, best = mid, (mid, xs, zs)
            if monitor.scan(left.s, self._events(cm, xs, zs, pu, mid)[:, 0])[0]:
                break
        if best is None:
            raise solver_error(self._solver(cm), fail.flag, left.t, cm, left.xs, left.zs)
        return np.array([best[0]]), best[1].reshape(cm.nx, 1), best[2].reshape(cm.nz, 1)

    def _events(self, cm, xs, zs, pu, t):
        t = np.atleast_1d(np.asarray(t, float))
        return cm.event_values(self.options.native)(xs, zs, pu, t).reshape(len(cm.events), t.size)

    # ------------------------------------------------------------------ event location
    def _locate(self, cm, pu, left, right, crossings):
        o = self.options
        located = {}
        for i, offset in crossings:
            key = (cm.events[i].key, offset)
            if key in located:
                located[key][2].append(i)
                continue

            def phi_at(t, start, i=i, offset=offset):
                self.counters["n_location_integrations"] += 1
                xs, zs = self._integrate_to(cm, start[0], start[1], start[2], pu, t)
                return self._events(cm, xs, zs, pu, t)[i, 0] - offset, (t, xs, zs)

            guess = self._hermite_guess(cm, pu, left, right, i, offset)
            t, payload, iterations = locate(
                phi_at, left.t, left.s[i] - offset, left.payload(), right.t, right.s[i] - offset, right.payload(),
                guess=guess, time_tol=o.event_time_tol, value_tol=o.event_value_tol,
                where=f"for event '{cm.events[i].name}' in mode '{cm.name}'")
            located[key] = (t, payload, [i], iterations)
        t_first = min(v[0] for v in located.values())
        members, payload, iterations = [], None, 0
        for t, pl, idx, it in located.values():
            iterations += it
            if t <= t_first + o.event_time_tol:
                members += idx
                if t == t_first:
                    payload = pl
        return Crossing(t_first, payload[1], payload[2], sorted(members), "fire", iterations)

    def _hermite_guess(self, cm, pu, left, right, i, offset, n=65):
        """Root of the event function along a cubic Hermite interpolant of the state."""
        ta, xa, za = left.payload()
        tb, xb, zb = right.payload()
        h = tb - ta
        da = cm.at("ode", xa, za, pu, ta)
        db = cm.at("ode", xb, zb, pu, tb)
        th, h00, h10, h01, h11 = _hermite_basis(n)
        x = np.outer(xa, h00) + np.outer(h * da, h10) + np.outer(xb, h01) + np.outer(h * db, h11)
        z = np.outer(za, 1 - th) + np.outer(zb, th)
        phi = self._events(cm, x, z, pu, ta + th * h)[i] - offset
        sign_a = np.sign(phi[0]) or np.sign(left.s[i] - offset)
        change = np.nonzero(np.sign(phi[1:]) != sign_a)[0]
        if not np.all(np.isfinite(phi)) or change.size == 0:
            return None
        k = change[0]
        f0, f1 = phi[k], phi[k + 1]
        theta = th[k] + (th[k + 1] - th[k]) * (f0 / (f0 - f1) if f0 != f1 else 0.5)
        return ta + theta * h

    def stats(self):
        return dict(self.counters)


def _advance(blocks, cm, crossing, y_start=None):
    if not blocks:
        return Advance(np.zeros(0), np.zeros((cm.nx, 0)), np.zeros((cm.nz, 0)), crossing, y_start=y_start)
    t = np.concatenate([b[0] for b in blocks])
    # outputs of one block as they are; of several, block by block (the driver keeps blocks: no copy)
    y = blocks[0][3] if len(blocks) == 1 else None
    y_blocks = [(b[0].size, b[3]) for b in blocks] if len(blocks) > 1 and any(b[3] is not None for b in blocks) \
        else None
    return Advance(t, np.concatenate([np.reshape(b[1], (cm.nx, b[0].size)) for b in blocks], axis=1),
                   np.concatenate([np.reshape(b[2], (cm.nz, b[0].size)) for b in blocks], axis=1), crossing, y,
                   y_blocks, y_start)
