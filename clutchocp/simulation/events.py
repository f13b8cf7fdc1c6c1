"""Event arming (hysteresis against chatter) and event location, shared by both paths.

Rules (all on the scaled event function ``s = function / scale``, band ``b``):

* ARMED: the event fires on a crossing of ``s = 0`` in its direction.
* On entering a mode (start, switch, input break) every event is re-classified:
  ``|s| <= b`` -> ENTRY (disarmed); ``s`` beyond the band on the firing side (direction
  -1: ``s < -b``; +1: ``s > b``) -> fires at once if its guard holds, else PASSED;
  otherwise ARMED.
* ENTRY: re-arms when ``s`` leaves the band on the pre-crossing side; fires if ``s`` leaves
  the band on the firing side (located at ``s = -b`` resp. ``s = b``). Direction-0 events
  re-arm on leaving the band either way and do not fire from ENTRY.
* PASSED (a crossing whose guards all failed): re-arms when ``s`` is back beyond the band on
  the pre-crossing side; never fires before.

So a lock-up that sets the slip speed to zero cannot be undone (or redone) by the same
zero it started from: the slip must first grow beyond the band.
"""

from dataclasses import dataclass

import numpy as np

from clutchocp.errors import SolverError

ARMED, ENTRY, PASSED = "armed", "entry", "passed"


@dataclass
class Crossing:
    """A located event crossing: time, scaled state there, the events involved."""

    t: float
    xs: np.ndarray
    zs: np.ndarray
    events: list        # indices into the mode's events, in mode order
    kind: str           # "fire" or "rearm"
    iterations: int = 0


@dataclass
class Advance:
    """What an integrator path returns: samples on the requested times, and a crossing if one stopped it."""

    t: np.ndarray       # (n,)
    xs: np.ndarray      # (nx, n)
    zs: np.ndarray      # (nz, n)
    crossing: Crossing | None = None
    y: np.ndarray | None = None     # (n_outputs, n): the mode's outputs on the samples, if already evaluated
    y_blocks: list | None = None    # or block by block: [(samples, outputs or None)] in order
    y_start: np.ndarray | None = None   # (n_outputs,): the outputs at the start of the call, if evaluated


class EventMonitor:
    """Arming state of the events of one mode (see the module docstring)."""

    def __init__(self, specs, band):
        self.specs = list(specs)
        self.band = float(band)
        self.state = [ARMED] * len(self.specs)

    def _pre_beyond(self, d, s):
        return abs(s) > self.band if d == 0 else d * s < -self.band

    def enter(self, s, guard_ok):
        """Classify every event at mode entry; return the index of one that fires at once, or None."""
        fire = None
        for i, spec in enumerate(self.specs):
            d = spec.direction
            if abs(s[i]) <= self.band:
                self.state[i] = ENTRY
            elif d != 0 and d * s[i] > self.band:
                self.state[i] = PASSED
                if guard_ok[i] and fire is None:
                    fire = i
            else:
                self.state[i] = ARMED
        return fire

    def scan(self, s0, s1):
        """Crossings between two consecutive samples of the scaled event values.

        Returns ``(crossings, new_state)``: ``crossings`` is a list of ``(index, offset)``
        (the event fires where ``s = offset``); ``new_state`` is the arming after the
        second sample, to be applied (by :meth:`commit`) only when nothing crossed.
        """
        crossings, new_state = [], list(self.state)
        for i, spec in enumerate(self.specs):
            d, a, b = spec.direction, s0[i], s1[i]
            if self.state[i] == ARMED:
                crossed = ((a > 0 >= b) or (a < 0 <= b)) if d == 0 else (d * a < 0 <= d * b)
                if crossed:
                    crossings.append((i, 0.0))
            elif self.state[i] == ENTRY and d != 0 and d * b > self.band:
                crossings.append((i, d * self.band))
            elif self._pre_beyond(d, b):
                new_state[i] = ARMED
        return crossings, new_state

    def commit(self, new_state):
        self.state = list(new_state)

    def scan_block(self, s0, S):
        """:meth:`scan` over consecutive samples: ``s0`` then the columns of ``S``.

        Arming changes are committed as the samples are passed. Returns ``(j, crossings)``
        for the first sample ``j`` whose step from the previous one crosses, else ``(None, [])``.
        Only the samples at which some event changes state are examined one by one.
        """
        if not self.specs:
            return None, []
        S = np.asarray(S, float).reshape(len(self.specs), -1)
        if S.shape[1] == 1:                         # one sample: the scan itself
            crossings, new_state = self.scan(np.asarray(s0, float).ravel(), S[:, 0])
            if crossings:
                return 0, crossings
            self.commit(new_state)
            return None, []
        V = np.column_stack([np.asarray(s0, float).reshape(-1, 1), S])     # s0, then the samples
        j = 0
        while j < S.shape[1]:
            k = self._first_change(V[:, j:-1], V[:, j + 1:])
            if k is None:
                return None, []
            j += k
            crossings, new_state = self.scan(V[:, j], S[:, j])
            if crossings:
                return j, crossings
            self.commit(new_state)
            j += 1
        return None, []

    def _first_change(self, A, B):
        """Index of the first step (A[:, k] -> B[:, k]) at which :meth:`scan` would report a
        crossing or change an arming state (None if there is none).

        The events of one arming state and direction are tested together, as rows of one array
        (usually every event of the mode: all armed, the same direction)."""
        groups = {}
        for i, spec in enumerate(self.specs):
            groups.setdefault((self.state[i], spec.direction), []).append(i)
        first = None
        for (st, d), rows in groups.items():
            a, b = (A, B) if len(rows) == len(self.specs) else (A[rows], B[rows])
            if st == ARMED and d in (1, -1):      # d a < 0 <= d b without the products (the same for NaN)
                hit = (a < 0) & (b >= 0) if d == 1 else (a > 0) & (b <= 0)
            elif st == ARMED:
                hit = ((a > 0) & (b <= 0)) | ((a < 0) & (b >= 0)) if d == 0 else (d * a < 0) & (d * b >= 0)
            else:
                pre = np.abs(b) > self.band if d == 0 else d * b < -self.band
                hit = pre | (d * b > self.band) if (st == ENTRY and d != 0) else pre
            any_row = hit.any(axis=0)
            k = int(any_row.argmax()) if any_row.size else 0
            if any_row.size and any_row[k] and (first is None or k < first):
                first = k
        return first

    def scipy_events(self):
        """Terminal scipy event specs ``(index, kind, offset, scipy_direction)``.

        ``kind`` is "fire" or "rearm"; the event function is ``s - offset``.
        """
        out = []
        for i, spec in enumerate(self.specs):
            d, st, b = spec.direction, self.state[i], self.band
            if st == ARMED:
                out.append((i, "fire", 0.0, d))
            elif d == 0:
                out += [(i, "rearm", b, 1), (i, "rearm", -b, -1)]
            else:
                if st == ENTRY:
                    out.append((i, "fire", d * b, d))
                out.append((i, "rearm", -d * b, -d))
        return out


def locate(phi_at, a, fa, pa, b, fb, pb, *, guess=None, time_tol, value_tol, max_iter=100, where=""):
    """Find the crossing of a scalar function in the bracket ``[a, b]``.

    Safeguarded secant: secant steps through the two latest iterates while they stay inside
    the bracket and keep reducing |phi| (by half every two iterations), bisection otherwise.

    Parameters
    ----------
    phi_at : callable
        ``phi_at(t, left_payload) -> (phi, payload)``: the function at ``t`` obtained from the
        left bracket point (the IDAS path integrates from there).
    a, fa, pa : float, float, object
        Left end [s], its value (strictly on the pre-crossing side) and payload.
    b, fb, pb : float, float, object
        Right end, its value (on the other side or zero) and payload.
    guess : float, optional
        First trial time (e.g. from an interpolant).
    time_tol, value_tol : float
        Stop when ``b - a <= time_tol`` (returns the right end) or ``|phi| <= value_tol``.

    Returns
    -------
    t : float
    payload : object
    iterations : int
    """
    if fa == 0:
        return a, pa, 0
    if abs(fb) <= value_tol:
        return b, pb, 0
    t_try = guess if (guess is not None and a < guess < b) else a + (b - a) * fa / (fa - fb)
    if not a < t_try < b:
        t_try = 0.5 * (a + b)
    prev_t, prev_f = b, fb
    history = []
    for iteration in range(1, max_iter + 1):
        if b - a <= time_tol:
            return b, pb, iteration - 1
        f, payload = phi_at(t_try, pa)
        if abs(f) <= value_tol:
            return t_try, payload, iteration
        if np.sign(f) == np.sign(fa):
            a, fa, pa = t_try, f, payload
        else:
            b, fb, pb = t_try, f, payload
        if b - a <= time_tol:
            return b, pb, iteration
        history.append(abs(f))
        stalled = len(history) >= 3 and history[-1] > 0.5 * history[-3]
        t_next = t_try - f * (t_try - prev_t) / (f - prev_f) if f != prev_f else np.nan
        prev_t, prev_f = t_try, f
        if stalled or not (a < t_next < b):
            t_next = 0.5 * (a + b)
            history.clear()
        t_try = t_next
    raise SolverError(f"event location did not converge {where} within {max_iter} iterations "
                      f"(bracket [{a:.12g}, {b:.12g}] s). Try: loosen event_value_tol/event_time_tol, or check "
                      "that the event function is continuous in this mode.")
