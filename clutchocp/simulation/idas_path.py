"""Integration of one mode with CasADi IDAS, events detected on the output grid and refined.

Within a piece (no mode switch, no input break) the mode is integrated by
``casadi.integrator(..., "idas", dae, t0, times, opts)`` on the scaled variables. The
scaled event functions are evaluated on the outputs; at the first sign change the
crossing is located by short IDAS integrations (on normalised time, so one integrator per
mode serves every interval) started from the latest point known to lie before it: a cubic
Hermite interpolant of the grid values gives the first trial time, then safeguarded secant
steps (:func:`~clutchocp.simulation.events.locate`) until the bracket is shorter than
``event_time_tol`` or ``|event| <= event_value_tol``.

A mode often stops making sense just past its event (a piston passing through a plate, a
gap below zero), so IDAS may fail there before the event has been seen. A failed call is
retried on the first half of its output times (an event before the failure is then found on
the grid); within a single interval the farthest reachable time is found by bisection and
checked for a crossing. Only if none crossed is a SolverError raised.
"""

import casadi as ca
import numpy as np

from clutchocp.simulation.diagnostics import idas_flag, solver_error
from clutchocp.simulation.events import Advance, Crossing, locate

_COUNTERS = {"nsteps": "n_steps", "nfevals": "n_rhs_evals", "nlinsetups": "n_jacobian_evals",
             "netfails": "n_error_test_failures", "nniters": "n_newton_iters", "nncfails": "n_newton_failures"}


class _IdasFailure(Exception):
    def __init__(self, flag, message):
        super().__init__(message)
        self.flag = flag


class IdasPath:
    """Integrates modes with IDAS; see the module docstring."""

    name = "idas"

    def __init__(self, options):
        self.options = options
        self.counters = {v: 0 for v in _COUNTERS.values()}
        self.counters.update(n_integrator_calls=0, n_location_integrations=0)
        self._location_integrators = {}

    # ------------------------------------------------------------------ IDAS calls
    def _idas_options(self, with_max_step=True):
        o = self.options
        opts = {"abstol": o.atol, "reltol": o.rtol, "max_num_steps": o.max_num_steps,
                "suppress_algebraic": o.suppress_algebraic, "calc_ic": True}
        if o.max_step is not None and with_max_step:
            opts["max_step_size"] = o.max_step
        opts.update(o.idas_options)
        return opts

    def _run(self, integrator, x0, z0, p):
        self.counters["n_integrator_calls"] += 1
        try:
            r = integrator(x0=x0, z0=z0, p=p)
        except RuntimeError as err:
            self._count(integrator.stats())
            raise _IdasFailure(idas_flag(err), str(err)) from None
        self._count(integrator.stats())
        return np.array(r["xf"], dtype=float), np.array(r["zf"], dtype=float)

    def _count(self, stats):
        for key, name in _COUNTERS.items():
            self.counters[name] += int(stats.get(key, 0))

    def _ode_start(self, cm, t0, xs0, pu, dt=1.0):
        """IDAS options that start a mode without algebraic variables from xdot = f(x0).

        IDACalcIC solves for xdot with IDAS's combined Jacobian dF/dx + cj dF/dxdot; on very stiff
        ODEs (squeeze films, eigenvalues ~ -1e9) its Newton iteration fails (IDA_CONV_FAIL) although
        the answer is explicit. With no algebraic variables the consistent xdot is simply f(x0).
        """
        if cm.nz:
            return {}
        xdot = np.array(cm.f_ode(xs0, np.zeros(0), pu, t0), dtype=float).ravel() * dt
        return {"calc_ic": False, "init_xdot": xdot.tolist()}

    def _integrate(self, cm, t0, xs0, zs0, pu, times):
        opts = {**self._idas_options(), **self._ode_start(cm, t0, xs0, pu)}
        integrator = ca.integrator(f"idas_{cm.name}", "idas", cm.dae, float(t0), [float(t) for t in times], opts)
        return self._run(integrator, xs0, zs0, pu)

    def _integrate_to(self, cm, t0, xs0, zs0, pu, t1):
        """Single interval [t0, t1] on normalised time (one cached integrator per DAE mode)."""
        integrator = self._location_integrators.get(cm.name)
        if cm.nz == 0:      # the start derivative depends on x0: a fresh integrator each time
            opts = {**self._idas_options(with_max_step=False), **self._ode_start(cm, t0, xs0, pu, t1 - t0)}
            integrator = ca.integrator(f"idas_{cm.name}_tau", "idas", cm.dae_tau, 0.0, [1.0], opts)
        elif integrator is None:
            integrator = ca.integrator(f"idas_{cm.name}_tau", "idas", cm.dae_tau, 0.0, [1.0],
                                       self._idas_options(with_max_step=False))
            self._location_integrators[cm.name] = integrator
        self.counters["n_location_integrations"] += 1
        xs, zs = self._run(integrator, xs0, zs0, np.concatenate([np.ravel(pu), [t0, t1 - t0]]))
        return xs[:, -1], zs[:, -1]

    # ------------------------------------------------------------------ one piece
    def advance(self, cm, t_a, xs_a, zs_a, pu, times, monitor):
        """Integrate mode ``cm`` from ``t_a`` over ``times`` until the first event crossing.

        Returns an :class:`~clutchocp.simulation.events.Advance` with the samples strictly
        before the crossing (all of ``times`` if none) and the located crossing.
        """
        times = np.asarray(times, float)
        size = self.options.chunk or times.size
        left = (t_a, np.asarray(xs_a, float), np.asarray(zs_a, float), self._events(cm, xs_a, zs_a, pu, t_a)[:, 0])
        out_t, out_x, out_z = [], [], []
        start = 0
        while start < times.size:
            chunk_times = times[start:start + size]
            failure, n_grid = None, chunk_times.size
            try:
                xs, zs = self._integrate(cm, left[0], left[1], left[2], pu, chunk_times)
                if self.options.chunk_growth:
                    size = max(1, int(size * self.options.chunk_growth))
            except _IdasFailure as fail:
                if chunk_times.size > 1:        # retry the first half: an event may come before the failure
                    size = chunk_times.size // 2
                    continue
                failure, n_grid = fail, 0       # one interval: go as far as IDAS can, look for an event there
                chunk_times, xs, zs = self._reach(cm, left, pu, chunk_times[0], fail, monitor)
            s = self._events(cm, xs, zs, pu, chunk_times)
            for j in range(chunk_times.size):
                right = (chunk_times[j], xs[:, j], zs[:, j], s[:, j])
                crossings, new_state = monitor.scan(left[3], right[3])
                if crossings:
                    crossing = self._locate(cm, pu, left, right, crossings)
                    return _advance(out_t, out_x, out_z, cm, crossing)
                monitor.commit(new_state)
                if j < n_grid:
                    out_t.append(right[0]), out_x.append(right[1]), out_z.append(right[2])
                left = right
            if failure is not None:
                raise solver_error("IDAS", failure.flag, left[0], cm, left[1], left[2])
            start += chunk_times.size
        return _advance(out_t, out_x, out_z, cm, None)

    def _reach(self, cm, left, pu, t_fail, fail, monitor, rel_tol=1e-7):
        """Farthest time in (left, t_fail) IDAS reaches, by bisection; stops early at an event crossing.

        Returns that time and the state there as a one-sample (times, xs, zs).
        """
        lo, hi, best = left[0], t_fail, None
        while hi - lo > rel_tol * (t_fail - left[0]):
            mid = 0.5 * (lo + hi)
            try:
                xs, zs = self._integrate_to(cm, left[0], left[1], left[2], pu, mid)
            except _IdasFailure:
                hi = mid
                continue
            lo, best = mid, (mid, xs, zs)
            if monitor.scan(left[3], self._events(cm, xs, zs, pu, mid)[:, 0])[0]:
                break
        if best is None:
            raise solver_error("IDAS", fail.flag, left[0], cm, left[1], left[2])
        return np.array([best[0]]), best[1].reshape(cm.nx, 1), best[2].reshape(cm.nz, 1)

    @staticmethod
    def _events(cm, xs, zs, pu, t):
        t = np.atleast_1d(np.asarray(t, float))
        values = np.array(cm.f_events(np.reshape(xs, (cm.nx, t.size)), np.reshape(zs, (cm.nz, t.size)), pu,
                                      t.reshape(1, -1)), dtype=float)
        return values.reshape(len(cm.events), t.size)

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
                xs, zs = self._integrate_to(cm, start[0], start[1], start[2], pu, t)
                return self._events(cm, xs, zs, pu, t)[i, 0] - offset, (t, xs, zs)

            guess = self._hermite_guess(cm, pu, left, right, i, offset)
            t, payload, iterations = locate(
                phi_at, left[0], left[3][i] - offset, left[:3], right[0], right[3][i] - offset, right[:3],
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
        ta, xa, za = left[:3]
        tb, xb, zb = right[:3]
        h = tb - ta
        da = np.array(cm.f_ode(xa, za, pu, ta), dtype=float).ravel()
        db = np.array(cm.f_ode(xb, zb, pu, tb), dtype=float).ravel()
        th = np.linspace(0.0, 1.0, n)
        h00, h10 = 2 * th**3 - 3 * th**2 + 1, th**3 - 2 * th**2 + th
        h01, h11 = -2 * th**3 + 3 * th**2, th**3 - th**2
        x = np.outer(xa, h00) + np.outer(h * da, h10) + np.outer(xb, h01) + np.outer(h * db, h11)
        z = np.outer(za, 1 - th) + np.outer(zb, th)
        phi = self._events(cm, x, z, pu, ta + th * h)[i] - offset
        sign_a = np.sign(phi[0]) or np.sign(left[3][i] - offset)
        change = np.nonzero(np.sign(phi[1:]) != sign_a)[0]
        if not np.all(np.isfinite(phi)) or change.size == 0:
            return None
        k = change[0]
        f0, f1 = phi[k], phi[k + 1]
        theta = th[k] + (th[k + 1] - th[k]) * (f0 / (f0 - f1) if f0 != f1 else 0.5)
        return ta + theta * h

    def stats(self):
        return dict(self.counters)


def _advance(out_t, out_x, out_z, cm, crossing):
    n = len(out_t)
    return Advance(np.array(out_t, float),
                   np.array(out_x, float).T.reshape(cm.nx, n),
                   np.array(out_z, float).T.reshape(cm.nz, n), crossing)
