"""The TCU's slip-feedback law: feedforward curve plus a time-varying LQI correction, sampled and held.

At sample k (t_k = k Ts) the TCU reads the speeds w_in, w_out (and the clutch pressure p if it
has a sensor), forms the slip w_rel = w_in - w_out and its rate by a backward difference
(w_rel[k] - w_rel[k-1]) / Ts, and compares them with the same signals of the nominal trajectory
(the reference: the optimal slip w_rel*(t) and its difference rate on the same sample grid, so
that both carry the same half-sample lag). With dy the deviations and xi the integral of the slip
error e = w_rel - w_rel*:

    du_unsat = -K_y[k] dy - k_xi[k] xi
    u        = clip(s_k (u_ff(t_k) + du_unsat) + d_k, p_min, p_max), then |u - u[k-1]| <= rate limit x Ts
    xi      <- xi + Ts e          (not while saturated in the direction e would push: clamping)

and the plant receives u_ff(t) + du[k] over [t_k, t_k + Ts) (du = u - u_ff(t_k) held; the
feedforward stays continuous so that with du = 0 the plant sees exactly the open-loop command; the
limits are enforced at the sample instants). s_k = 1, d_k = 0 without adaptation; with it, the
scale and shift of :class:`~clutchocp.shiftcontrol.estimator.FeedforwardAdaptation` (the clutch's
torque gain and load estimated from the last two samples). After the nominal lock-up time the reference is the
locked state (zero slip and slip rate) and the last gains hold.
"""

import numpy as np

from ..errors import ModelError


class SlipFeedback:
    """Discrete time-varying slip feedback (see the module docstring).

    Parameters
    ----------
    sample_time : float
        Ts [s].
    gains : array (N, n_y)
        K_y[k] on the deviations of the measured signals ``measured``.
    integral_gains : array (N,)
        k_xi[k] [Pa/(rad)].
    reference : array (N + 1, n_y)
        The measured signals of the nominal trajectory at t_0 .. t_N (``slip_rate`` as the
        backward difference of the nominal slip).
    slip_reference : array (N + 1,)
        Nominal slip w_rel*(t_k) [rad/s].
    measured : tuple of str
        Names of the measured signals (``slip_rate``, ``w_in``, ``w_out``, ``p_valve``).
    feedforward : (array, array)
        Command times [s] and values [Pa] of the feedforward (piecewise linear, last value held).
    p_min, p_max : float
        Command limits [Pa].
    rate_limit : float
        Largest command rate [Pa/s].
    anti_windup : {"clamping", "none"}
    path : (array, array), optional
        The falling branch of the nominal slip: times [s] and slip [rad/s]. Given, the reference time
        tau of a sample on that branch is the time at which the nominal slip equals the measured one
        (slip progress), not the clock: the clutch follows the optimal slip path at its own pace, so a
        clutch that is a little slow or fast still approaches lock-up as the optimum does (slip rate
        falling to zero with the slip: no torque jump). Before the branch tau = t.
    max_delay : float
        The reference time never lags the clock by more than this [s]: a slow clutch is then pushed
        along in time (the slip error and its integral act).
    adaptation : clutchocp.shiftcontrol.estimator.FeedforwardAdaptation, optional
        Given, the command before the limits is scale (u_ff + du) + shift, with the scale and shift
        that make the clutch met give the nominal slip path (its torque gain and load estimated from
        the speeds and pressure of the last two samples).
    """

    def __init__(self, sample_time, gains, integral_gains, reference, slip_reference, measured, feedforward,
                 p_min, p_max, rate_limit, anti_windup="clamping", path=None, max_delay=np.inf, adaptation=None):
        self.Ts = float(sample_time)
        self.gains = np.atleast_2d(np.asarray(gains, float))
        self.integral_gains = np.asarray(integral_gains, float).ravel()
        self.reference = np.atleast_2d(np.asarray(reference, float))
        self.slip_reference = np.asarray(slip_reference, float).ravel()
        self.measured = tuple(measured)
        N = self.integral_gains.size
        if self.gains.shape != (N, len(self.measured)) or self.reference.shape != (N + 1, len(self.measured)) \
                or self.slip_reference.size != N + 1:
            raise ModelError("SlipFeedback: gains (N, n_y), integral gains (N,), references (N + 1, n_y) and "
                             "(N + 1,) do not fit together")
        self.ff_times, self.ff_values = (np.asarray(a, float) for a in feedforward)
        self.p_min, self.p_max = float(p_min), float(p_max)
        self.rate_limit = float(rate_limit)
        if anti_windup not in ("clamping", "none"):
            raise ModelError(f"anti_windup = {anti_windup!r}: allowed values are clamping, none")
        self.anti_windup = anti_windup
        self.enabled = True
        self.path = None if path is None else tuple(np.asarray(a, float) for a in path)
        self.max_delay = float(max_delay)
        self.adaptation = adaptation
        self.reset()

    @property
    def horizon(self):
        """Number of designed samples N (the nominal lock-up lies in the last one)."""
        return self.integral_gains.size

    def blended(self, other, weight):
        """The feedback whose tables are (1 - weight) x this one's + weight x ``other``'s, or None.

        A TCU interpolates its calibration between two designs (e.g. made at two oil viscosities): gains,
        references, the feedforward (on the union of both command grids, where both are linear) and the
        adaptation's nominal estimates are blended. None when the two do not share their horizon,
        measured signals and settings, or read their reference by slip progress.
        """
        same = (self.horizon == other.horizon and self.measured == other.measured and self.path is None
                and other.path is None and (self.Ts, self.p_min, self.p_max, self.rate_limit, self.anti_windup)
                == (other.Ts, other.p_min, other.p_max, other.rate_limit, other.anti_windup)
                and (self.adaptation is None) == (other.adaptation is None))
        if not same:
            return None
        w = float(weight)

        def mix(a, b):
            return (1.0 - w) * a + w * b

        times = np.union1d(self.ff_times, other.ff_times)
        adaptation = None if self.adaptation is None else self.adaptation.blended(other.adaptation, w)
        return SlipFeedback(self.Ts, mix(self.gains, other.gains), mix(self.integral_gains, other.integral_gains),
                            mix(self.reference, other.reference), mix(self.slip_reference, other.slip_reference),
                            self.measured, (times, mix(np.interp(times, self.ff_times, self.ff_values),
                                                       np.interp(times, other.ff_times, other.ff_values))),
                            self.p_min, self.p_max, self.rate_limit, self.anti_windup, max_delay=self.max_delay,
                            adaptation=adaptation)

    def reset(self):
        """Before a run: zero integral, no previous sample."""
        self.integral = 0.0
        self.progress = 0.0
        self._last_t = 0.0
        self._previous_slip = None
        self._previous_signals = None
        self._previous_command = None
        self.scale, self.shift_Pa = 1.0, 0.0

    def feedforward(self, t):
        """Feedforward command at time t [Pa] (piecewise linear, the last value held)."""
        return float(np.interp(t, self.ff_times, self.ff_values))

    def _progress(self, k, w_rel):
        """Reference time tau [s] of sample k: t_k, or on the falling branch of the nominal slip the time
        at which the nominal slip equals the measured one (never going back)."""
        t = k * self.Ts
        if self.path is None:
            return t
        t_path, w_path = self.path            # the falling branch: times increasing, slip decreasing
        if t < t_path[0]:
            return t
        tau = float(np.interp(-w_rel, -w_path, t_path)) if w_rel < w_path[0] else t_path[0]
        return max(tau, self.progress, t - self.max_delay)

    @property
    def finished(self):
        """True once the reference has run out (its time past the nominal lock-up): time to clamp."""
        return self.progress >= self.horizon * self.Ts

    def _at(self, table, tau):
        """Row of a per-sample table at reference time tau (linear between samples, ends held)."""
        pos = min(max(tau / self.Ts, 0.0), table.shape[0] - 1.0)
        j = min(int(pos), table.shape[0] - 2) if table.shape[0] > 1 else 0
        if table.shape[0] == 1:
            return table[0]
        f = pos - j
        return (1 - f) * table[j] + f * table[j + 1]

    def _reference(self, tau):
        ref = self._at(self.reference, tau)
        slip = float(self._at(self.slip_reference[:, None], tau)[0])
        return ref, slip

    def step(self, k, signals):
        """The correction du[k] [Pa] for the measured ``signals`` (dict: w_in, w_out, p_valve); updates the state.

        Returns
        -------
        (du, u, u_unsat) : the held correction, the command at t_k and the command before the limits [Pa].
        """
        t = k * self.Ts
        self._last_t = t
        w_rel = signals["w_in"] - signals["w_out"]
        tau = self._progress(k, w_rel)
        self.progress = tau
        u_ff = self.feedforward(tau)
        ref, slip_ref = self._reference(tau)
        rate = (w_rel - self._previous_slip) / self.Ts if self._previous_slip is not None else None
        if self.adaptation is not None and self.enabled:
            row = self._at(self.adaptation.nominal, tau)
            estimate = self.adaptation.correction(row, self._previous_signals, signals)
            if estimate != (1.0, 0.0):      # outside the adapted stretch the last estimate is held
                self.scale, self.shift_Pa = estimate
        y = []
        for j, name in enumerate(self.measured):
            if name == "slip_rate":
                y.append(ref[j] if rate is None else rate)        # first sample: no difference yet
            elif name == "p_valve":
                # the pressure the nominal clutch would need for the same torque: the LQI acts on the
                # adapted clutch as on the nominal one
                y.append((signals[name] - self.shift_Pa) / self.scale)
            else:
                y.append(signals[name])
        dy = np.asarray(y) - ref
        e = w_rel - slip_ref
        gain = self._at(self.gains, min(tau, (self.horizon - 1) * self.Ts))
        k_xi = float(self._at(self.integral_gains[:, None], min(tau, (self.horizon - 1) * self.Ts))[0])
        du_unsat = -float(gain @ dy) - k_xi * self.integral if self.enabled else 0.0
        u_unsat = self.scale * (u_ff + du_unsat) + self.shift_Pa
        u = min(max(u_unsat, self.p_min), self.p_max)
        if self._previous_command is not None:
            reach = self.rate_limit * self.Ts
            u = min(max(u, self._previous_command - reach), self._previous_command + reach)
        increment = self.Ts * e
        limited = abs(u - u_unsat) > 1e-9 * max(abs(u_unsat), 1.0)
        if self.anti_windup == "clamping" and limited and np.sign(-k_xi * increment) == np.sign(u_unsat - u):
            increment = 0.0
        self.integral += increment
        self._previous_slip = w_rel
        self._previous_signals = dict(signals)
        self._previous_command = u
        return u - u_ff, u, u_unsat

    @property
    def shift(self):
        """How far the feedforward is delayed at the last sample, t_k - tau_k [s] (0 without a path)."""
        return self._last_t - self.progress
