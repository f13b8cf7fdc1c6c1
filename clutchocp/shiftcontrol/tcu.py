"""The TCU's slip controller with a Kalman filter: one CasADi function per sample, run in Python and generated as C.

At sample k (t_k = k Ts) the TCU reads y_k (speeds from its tooth wheels, the pressure sensor, the
engine-torque signal) and, with the tables of its calibration for that sample:

    y       = y_k + r_k (t_ref,k - y_time)                       readings moved to the times of the model
    nu      = (y - y_ref,k) - C_k xi_k^-                         innovation
    xi_k    = xi_k^- + M_k nu                                    Kalman update
    du_uns  = -K_k [xi_k; z_k]                                   LQR on the TCU's state and the slip-error integral z
    u_uns   = u_ff,k + du_uns
    u       = clip(u_uns, p_min, p_max), then within +-reach of the previous command (rate limit)
    u       = max(u, u_prev) while |w_in - w_out| (measured) <= lock_slip   (lock-up hold)
    du      = u - u_ff,k
    z_k+1   = z_k + dt_k (slip row) xi_k    (not while limited in the direction it would push: clamping)
    xi_k+1^- = A_k xi_k + B_k du + H_k (d (x) [xi_k; du])      d = the estimated parameters in xi_k
               + sum_s G_s (clip(u_s + c_s, p_min, p_max) - u_s - c_s)   c_s = du, or du_prev in the dead time

A tooth-wheel reading is the mean speed over its window, i.e. the speed at the window's middle, which
the TCU knows from its stamps (``y_time``); the model's reading stands for the nominal middle
(``t_ref``): the difference times the nominal acceleration (``rate_ref``) moves it there. The
prediction's bilinear term H_k (d (x) [xi_k; du]) (Kronecker product) is the change of the parameters' effect off the
nominal trajectory (:attr:`~clutchocp.shiftcontrol.observer.TCUModel.H`): a clutch whose friction is off and
whose films run thinner than the nominal ones feels its friction through another contact load. The
last sum is the command the TCU clipped between samples (sub-intervals s of the sample, feedforward u_s there,
columns G_s of :attr:`~clutchocp.shiftcontrol.observer.TCUModel.G_sub`): zero while nothing clips.
u_ff,k is the feedforward at t_k + D (D: the valve dead time the TCU assumes; it sends its command
that much early); between samples the TCU's output is clip(u_ff(t + D) + du_k, p_min, p_max) (the valve
cannot leave its range, :func:`clipped_command`). The lock-up counter counts
the samples in a row with the measured slip within ``lock_slip``; at ``lock_samples`` the TCU hands
over to the clamp ramp. :func:`step_function` is that law as one CasADi function of the sample's
table rows (:meth:`TCUFeedback.row`): :meth:`TCUFeedback.step` calls it, and
:mod:`clutchocp.shiftcontrol.export` generates it as C, so both compute the same arithmetic.
"""

import functools

import casadi as ca
import numpy as np

from ..errors import ModelError

STEP_INPUTS = ("y", "y_time", "y_ref", "t_ref", "rate_ref", "x_prior", "integral", "u_prev", "first", "lock_count",
               "M", "C", "K", "A", "B", "H", "G_sub", "u_sub", "held_sub", "slip_row", "dt", "u_ff", "limits")
STEP_OUTPUTS = ("u", "du", "u_unsat", "x_post", "x_next", "integral_next", "lock_count_next")
LIMITS = ("p_min", "p_max", "reach", "clamping", "lock_slip")


def clipped_command(times, values, p_min, p_max):
    """A piecewise-linear command clipped to [p_min, p_max], exactly: (times, values) [s], [Pa].

    Each segment that crosses a limit gets the crossing time as a new point, so the clipped command is
    again piecewise linear through its points (a crossing that falls on a point within round-off is dropped).
    """
    times, values = np.asarray(times, float), np.asarray(values, float)
    t_out, v_out = [times[0]], [values[0]]
    for t0, t1, v0, v1 in zip(times[:-1], times[1:], values[:-1], values[1:]):
        crossings = sorted((t0 + (level - v0) / (v1 - v0) * (t1 - t0), level) for level in (p_min, p_max)
                           if (v0 - level) * (v1 - level) < 0)      # the segment strictly crosses the level
        t_out += [t for t, _ in crossings] + [t1]
        v_out += [level for _, level in crossings] + [v1]
    t_out, v_out = np.asarray(t_out), np.clip(np.asarray(v_out), p_min, p_max)
    keep = np.concatenate([[True], np.diff(t_out) > 1e-12 * max(1.0, abs(t_out[-1]))])  # a crossing at a point
    return t_out[keep], v_out[keep]


@functools.lru_cache(maxsize=16)
def step_function(n, p, parameters=(), subs=0):
    """The per-sample law as a CasADi function for a TCU state of ``n`` and ``p`` readings (see the module docstring).

    ``parameters``: the positions in the state of the m estimated parameters d (a tuple of int) the bilinear term
    multiplies the state with; ``subs``: the sub-intervals S of a sample. The previous correction du_prev is the
    state's last entry.

    Inputs (:data:`STEP_INPUTS`): y, y_time [s], y_ref, t_ref [s], rate_ref (p), x_prior (n), integral, u_prev,
    first (1 at the first sample: no previous command), lock_count, M (n x p), C (p x n), K (1 x n+1), A (n x n), B (n),
    H (n x m (n + 1)), G_sub (n x S), u_sub (S) [Pa], held_sub (S), slip_row (1 x n),
    dt [s], u_ff [Pa], limits (p_min [Pa], p_max [Pa], reach [Pa], clamping (0/1), lock_slip [rad/s]).
    Outputs (:data:`STEP_OUTPUTS`): u, du, u_unsat [Pa], x_post, x_next (n), integral_next, lock_count_next.
    """
    sx = ca.SX.sym
    y, y_time, y_ref, x_prior = sx("y", p), sx("y_time", p), sx("y_ref", p), sx("x_prior", n)
    t_ref, rate_ref = sx("t_ref", p), sx("rate_ref", p)
    integral, u_prev, first, lock_count = sx("integral"), sx("u_prev"), sx("first"), sx("lock_count")
    M, C, K, A, B = sx("M", n, p), sx("C", p, n), sx("K", 1, n + 1), sx("A", n, n), sx("B", n)
    H = sx("H", n, len(parameters) * (n + 1))
    G_sub, u_sub, held_sub = sx("G_sub", n, subs), sx("u_sub", subs), sx("held_sub", subs)
    slip_row, dt, u_ff, limits = sx("slip_row", 1, n), sx("dt"), sx("u_ff"), sx("limits", len(LIMITS))
    p_min, p_max, reach, clamping, lock_slip = (limits[i] for i in range(len(LIMITS)))

    y_model = y + rate_ref * (t_ref - y_time)
    x_post = x_prior + ca.mtimes(M, (y_model - y_ref) - ca.mtimes(C, x_prior))
    k_xi = K[0, n]
    u_unsat = u_ff - ca.mtimes(K[0, :n], x_post) - k_xi * integral
    u = ca.fmin(ca.fmax(u_unsat, p_min), p_max)
    u = ca.if_else(first, u, ca.fmin(ca.fmax(u, u_prev - reach), u_prev + reach))
    near = ca.fabs(y[0] - y[1]) <= lock_slip
    u = ca.if_else(ca.logic_and(near, 1 - first), ca.fmax(u, u_prev), u)
    du = u - u_ff
    increment = dt * ca.mtimes(slip_row, x_post)
    limited = ca.fabs(u - u_unsat) > 1e-9 * ca.fmax(ca.fabs(u_unsat), 1.0)
    pushes = (-k_xi * increment) * (u_unsat - u) > 0          # integrating would push further into the limit
    increment = ca.if_else(ca.logic_and(ca.logic_and(clamping, limited), pushes), 0.0, increment)
    bilinear = ca.vertcat(*[x_post[i] * ca.vertcat(x_post, du) for i in parameters]) if parameters else ca.SX(0, 1)
    held = held_sub * du + (1 - held_sub) * x_post[n - 1]      # the correction acting in each sub-interval
    clipped = ca.fmin(ca.fmax(u_sub + held, p_min), p_max) - u_sub - held
    x_next = ca.mtimes(A, x_post) + B * du + ca.mtimes(H, bilinear) + ca.mtimes(G_sub, clipped)
    outputs = [u, du, u_unsat, x_post, x_next, integral + increment,
               ca.if_else(near, lock_count + 1, 0.0)]
    inputs = [y, y_time, y_ref, t_ref, rate_ref, x_prior, integral, u_prev, first, lock_count, M, C, K, A, B, H,
              G_sub, u_sub, held_sub, slip_row, dt, u_ff, limits]
    return ca.Function("tcu_step", inputs, outputs, list(STEP_INPUTS), list(STEP_OUTPUTS))


class TCUFeedback:
    """The calibrated slip controller of one design: its tables per sample and the law of :func:`step_function`.

    Parameters
    ----------
    sample_time : float
        Ts [s].
    names, measured : tuple of str
        The TCU's state and its readings (:class:`~clutchocp.shiftcontrol.observer.TCUModel`).
    tables : dict of arrays
        Per sample k = 0 .. N-1: ``A`` (N, n, n), ``B`` (N, n), ``H`` (N, n, m (n + 1)) the prediction's bilinear term
        (m: the states ``d:``), ``G_sub`` (N, n, S), ``u_sub`` (N, S) [Pa], ``held_sub`` (N, S) the command clipped
        between samples (:class:`~clutchocp.shiftcontrol.observer.TCUModel`), ``C`` (N, p, n), ``M`` (N, n, p) Kalman gains,
        ``K`` (N, n + 1) LQR gains on [xi; z], ``y_ref`` (N, p), ``slip_row`` (N, n), ``dt`` (N,) [s],
        ``u_ff`` (N,) the feedforward at t_k + D [Pa], ``t_ref`` (N, p) the time each reading stands for
        on the nominal trajectory [s], ``rate_ref`` (N, p) the nominal rate of each reading there.
    feedforward : (array, array)
        The feedforward curve [s], [Pa] as the plant should receive it (piecewise linear, last value held).
    advance : float
        D, the valve dead time the TCU assumes [s]: its output at t is u_ff(t + D) + du.
    p_min, p_max, rate_limit : float
        Command limits [Pa] and largest rate [Pa/s].
    anti_windup : {"clamping", "none"}
    lock_slip : float
        |measured slip| at or below which the TCU counts a sample towards lock-up [rad/s].
    lock_samples : int
        Samples in a row that confirm lock-up (then the clamp ramp).
    clamp_pressure : float
        Holding pressure the clamp ramp goes to [Pa].
    nominal_torque : float
        The engine torque of the design [N m] (the reading of the torque channel is compared with it).
    """

    kind = "kalman"

    def __init__(self, sample_time, names, measured, tables, feedforward, advance, p_min, p_max, rate_limit,
                 anti_windup, lock_slip, lock_samples, clamp_pressure, nominal_torque):
        self.Ts = float(sample_time)
        self.names, self.measured = tuple(names), tuple(measured)
        self.tables = {key: np.asarray(value, float) for key, value in tables.items()}
        N, n, p = self.tables["A"].shape[0], len(self.names), len(self.measured)
        self.parameters = tuple(i for i, name in enumerate(self.names) if name.startswith("d:"))
        if self.names[-1] != "du_prev":
            raise ModelError("TCUFeedback: the state's last entry must be du_prev")
        S = self.subs = self.tables["u_sub"].shape[-1] if "u_sub" in self.tables else 0
        shapes = {"A": (N, n, n), "B": (N, n), "H": (N, n, len(self.parameters) * (n + 1)), "C": (N, p, n),
                  "G_sub": (N, n, S), "u_sub": (N, S), "held_sub": (N, S),
                  "M": (N, n, p), "K": (N, n + 1), "y_ref": (N, p), "slip_row": (N, n), "dt": (N,), "u_ff": (N,), "t_ref": (N, p), "rate_ref": (N, p)}
        for key, shape in shapes.items():
            if self.tables.get(key) is None or self.tables[key].shape != shape:
                raise ModelError(f"TCUFeedback: table {key} must be {shape}")
        self.ff_times, self.ff_values = (np.asarray(a, float) for a in feedforward)
        self.advance = float(advance)
        self.p_min, self.p_max, self.rate_limit = float(p_min), float(p_max), float(rate_limit)
        if anti_windup not in ("clamping", "none"):
            raise ModelError(f"anti_windup = {anti_windup!r}: allowed values are clamping, none")
        self.anti_windup = anti_windup
        self.lock_slip, self.lock_samples = float(lock_slip), int(lock_samples)
        self.clamp_pressure, self.nominal_torque = float(clamp_pressure), float(nominal_torque)
        self._step = step_function(n, p, self.parameters, S)
        self.reset()

    @property
    def horizon(self):
        """Designed samples N (the nominal lock-up lies in the last one)."""
        return self.tables["A"].shape[0]

    def reset(self):
        """Before a run: the filter at the nominal trajectory, no integral, no previous command."""
        self.x_prior = np.zeros(len(self.names))
        self.x_post = self.x_prior.copy()
        self.integral = 0.0
        self.lock_count = 0
        self._u_prev = None

    @property
    def locked(self):
        """True once the measured slip has stayed within ``lock_slip`` for ``lock_samples`` samples."""
        return self.lock_count >= self.lock_samples

    def feedforward(self, t):
        """The feedforward the TCU sends at ``t`` [Pa]: u_ff(t + D)."""
        return float(np.interp(t + self.advance, self.ff_times, self.ff_values))

    def limits(self):
        return np.array([self.p_min, self.p_max, self.rate_limit * self.Ts, float(self.anti_windup == "clamping"),
                         self.lock_slip])

    def row(self, k):
        """The table inputs of :func:`step_function` for sample k (a dict by input name)."""
        t = self.tables
        return {"M": t["M"][k], "C": t["C"][k], "K": t["K"][k][None, :], "A": t["A"][k], "B": t["B"][k], "H": t["H"][k],
                "G_sub": t["G_sub"][k], "u_sub": t["u_sub"][k], "held_sub": t["held_sub"][k],
                "slip_row": t["slip_row"][k][None, :], "dt": t["dt"][k], "u_ff": t["u_ff"][k],
                "y_ref": t["y_ref"][k], "t_ref": t["t_ref"][k], "rate_ref": t["rate_ref"][k], "limits": self.limits()}

    def readings_vector(self, readings):
        """The readings in the order of ``measured`` (``p_sensor`` is the pressure reading ``p_valve``)."""
        key = {"p_sensor": "p_valve"}
        return np.array([readings[key.get(name, name)] for name in self.measured], float)

    def reading_times(self, k, readings):
        """The times the readings stand for (``time:<name>`` in ``readings``; else the model's own)."""
        return np.array([readings.get(f"time:{name}", self.tables["t_ref"][k][j])
                         for j, name in enumerate(self.measured)], float)

    def inputs(self, k, readings):
        """Every input of :func:`step_function` at sample k for the readings (dict), from the current state."""
        first = self._u_prev is None
        return {"y": self.readings_vector(readings), "y_time": self.reading_times(k, readings),
                "x_prior": self.x_prior, "integral": self.integral,
                "u_prev": 0.0 if first else self._u_prev, "first": float(first), "lock_count": float(self.lock_count),
                **self.row(k)}

    def step(self, k, readings):
        """The correction at sample k (k < N) for the TCU's ``readings``; updates the state.

        Returns
        -------
        (du, u, u_unsat) : the held correction, the command at t_k and the command before the limits [Pa].
        """
        if not 0 <= k < self.horizon:
            raise ModelError(f"TCUFeedback.step: sample {k} outside the design's 0 .. {self.horizon - 1}")
        inputs = self.inputs(k, readings)
        # the innovation, kept for diagnostics (the filter's consistency): y - y_ref - C x_prior
        y = inputs["y"] + inputs["rate_ref"] * (inputs["t_ref"] - inputs["y_time"])
        self.innovation = y - inputs["y_ref"] - inputs["C"] @ self.x_prior
        out = self._step.call(inputs)
        u, du, u_unsat = (float(out[key]) for key in ("u", "du", "u_unsat"))
        self.x_post = np.array(out["x_post"], float).ravel()
        self.x_prior = np.array(out["x_next"], float).ravel()
        self.integral = float(out["integral_next"])
        self.lock_count = int(round(float(out["lock_count_next"])))
        self._u_prev = u
        return du, u, u_unsat

    def estimate(self, name):
        """The TCU's current estimate of a state deviation (after the last update), e.g. ``d:friction.mu``."""
        return float(self.x_post[self.names.index(name)])

    def blended(self, other, weight):
        """The controller whose tables are (1 - weight) x this one's + weight x ``other``'s, or None when the two
        do not share their horizon, state, readings and settings (a TCU interpolating its calibration)."""
        same = (self.horizon == other.horizon and self.names == other.names and self.measured == other.measured
                and (self.Ts, self.advance, self.p_min, self.p_max, self.rate_limit, self.anti_windup,
                     self.lock_samples) == (other.Ts, other.advance, other.p_min, other.p_max, other.rate_limit,
                                            other.anti_windup, other.lock_samples))
        if not same:
            return None
        w = float(weight)

        def mix(a, b):
            return (1.0 - w) * a + w * b

        times = np.union1d(self.ff_times, other.ff_times)
        return TCUFeedback(self.Ts, self.names, self.measured,
                           {key: mix(value, other.tables[key]) for key, value in self.tables.items()},
                           (times, mix(np.interp(times, self.ff_times, self.ff_values),
                                       np.interp(times, other.ff_times, other.ff_values))),
                           self.advance, self.p_min, self.p_max, self.rate_limit, self.anti_windup,
                           mix(self.lock_slip, other.lock_slip), self.lock_samples,
                           mix(self.clamp_pressure, other.clamp_pressure),
                           mix(self.nominal_torque, other.nominal_torque))
