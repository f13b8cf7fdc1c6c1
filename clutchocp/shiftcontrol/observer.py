"""The TCU's model of the engagement per sample, and the Kalman filter designed on it.

Along the nominal trajectory of the feedforward the slip dynamics are linearised exactly
(:mod:`clutchocp.shiftcontrol.linearize`): d(dx)/dt = A dx + B du + F d, with d the relative
deviations of the scene fields the filter estimates (``[estimator.parameters]``: friction, load,
engine torque, valve lag ...; theta_i = theta_i,nom (1 + d_i)). The TCU's state per sample is

    xi = [dx (the model's physical states), s (pressure-sensor reading, with a sensor lag),
          a_in, a_out (the shafts' angles turned since the last sample, for a tooth wheel),
          d (estimated parameters), b (pressure-sensor offset), du_prev (the previous correction:
          it still acts over the valve dead time, and the LQR weighs the change of the correction)]

and one sample [t_k, t_k+1] maps it exactly for the frozen-midpoint pieces (matrix exponentials of
[[A_c, B_c, F_c], [0, 0, 0]] over sub-intervals, A_c with the sensor lag ds/dt = (dp - ds) / lag):
the correction du_k reaches the valve after the dead time D the TCU assumes, so du_prev acts over
[t_k, t_k + D] and du_k over [t_k + D, t_k+1] (the sample map is split there). The parameters, the
offset are constant. The TCU measures y = (w_in, w_out [, the pressure reading s + b] [, the
engine-torque signal T_in,nom (1 + d_Tin)]); a tooth wheel gives the mean speed over the last
sample, a / Ts + (e_k - e_k-1) / Ts (da/dt = dw, a set to zero at every sample: its column of A_k is
zero; e_k the angle error at the edge that ends window k and starts window k + 1: the tooth's
cumulative pitch error and the timer's, white from sample to sample, carried as the states ``edge:``
and ``edge_prev:`` so that the anticorrelation of consecutive readings is the filter's), an ideal
sensor the speed at t_k. The window of edge timing ends at the last edge, on average half a tooth
period before t_k: the reference reading is the nominal mean speed over the window shifted so, and
the spread of that age (uniform over a tooth period) times the nominal acceleration is white reading
noise.

Noise (the Kalman filter's covariances): readings from the sensor models' variances at the nominal
speeds (:meth:`~clutchocp.shiftcontrol.sensors.SpeedSensor.variance`), the pressure sensor's
noise; process noise: an unmodelled torque on each rotor (``torque_noise``, standard deviation
over a sample: Ts T / J of speed), unmodelled valve pressure (``pressure_noise``) and a drift of
each parameter (``parameter_drift``); the prior: the parameters' spreads (uniform half-width w:
variance w^2 / 3), the pressure offset's, the speeds' reading variance.
"""

from dataclasses import dataclass

import math

import numpy as np
from scipy.linalg import expm

from ..control.kalman import tvkf
from .linearize import DIFFERENCE_STEP

SUBSTEPS = 8            # sub-intervals per sample (per part of a sample split at the dead time)
ACCELERATION_SPREAD = 0.2   # a clutch's shaft acceleration may differ from the nominal by this fraction


@dataclass
class TCUModel:
    """The TCU's linear model per sample k = 0 .. N-1 (plain arrays) and its noise.

    Attributes
    ----------
    names : tuple of str
        The TCU's state xi: model states, then ``p_sensor``, ``d:<field>``, ``p_offset``, ``du_prev`` as present.
    measured : tuple of str
        The readings: ``w_in``, ``w_out`` [rad/s], ``p_sensor`` [Pa], ``engine_torque`` [N m].
    A : (N, n, n), B : (N, n)
        xi_k+1 = A_k xi_k + B_k du_k (+ the bilinear term of H).
    H : (N, n, m (n + 1))
        The bilinear term of the prediction: xi_k+1 += H_k (d (x) [xi_k; du_k]), d the m estimated parameters (the
        states ``d:``) and (x) the Kronecker product: column j (n + 1) + i is d(Psi_j)/d(v_i), the change of
        parameter j's column with the model state, previous or current correction v_i
        (:meth:`TCUModelBuilder.column_derivative`; zero for the other states).
    G_sub : (N, n, S), u_sub : (N, S), held_sub : (N, S)
        Per sample, the states at its end per Pa of correction over sub-interval s alone (zero-padded; the
        columns of ``held_sub`` 1 sum to B_k, those of 0 to the previous correction's column of A_k), the
        feedforward there [Pa] and which correction acts there (1: the current, 0: the previous): the command
        clipped between samples, clip(u_ff + du) - u_ff, acts through them.
    C : (N, p, n)
        Readings' deviations from their nominal values: dy_k = C_k xi_k + noise.
    y_ref : (N, p)
        The readings on the nominal trajectory (noise-free sensors).
    slip_row, slip_rate_row : (N, n)
        Slip [rad/s] and slip rate [rad/s^2] deviations at t_k: rows over xi.
    slip_rate_end : (n,)
        The slip-rate row at the nominal lock-up.
    slip_row_end : (n,)
    durations : (N,)
        Sample lengths [s] (the last one ends at the nominal lock-up).
    Q : (N, n, n), R : (N, p, p), P0 : (n, n)
    t_ref : (N, p)
        The time each reading stands for on the nominal trajectory [s].
    rate_ref : (N, p)
        The nominal rate of change of each reading's reference there [unit/s].
    """

    names: tuple
    measured: tuple
    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    y_ref: np.ndarray
    slip_row: np.ndarray
    slip_rate_row: np.ndarray
    slip_row_end: np.ndarray
    slip_rate_end: np.ndarray
    durations: np.ndarray
    Q: np.ndarray
    R: np.ndarray
    P0: np.ndarray
    t_ref: np.ndarray
    rate_ref: np.ndarray
    H: np.ndarray
    G_sub: np.ndarray
    u_sub: np.ndarray
    held_sub: np.ndarray

    def kalman(self):
        """Gains and covariances of the time-varying Kalman filter (:func:`clutchocp.control.kalman.tvkf`)."""
        return tvkf(list(self.A), list(self.C), list(self.Q), list(self.R), self.P0)


def _pieces(start, end, dead_time):
    """The parts of a sample [start, end]: (t0, t1, held) with held "previous" before the dead time, "current" after."""
    split = min(start + dead_time, end)
    parts = []
    if split > start:
        parts.append((start, split, "previous"))
    if end > split:
        parts.append((split, end, "current"))
    return parts


def midpoints(t0, t1, sample_time):
    """Midpoints of the sub-intervals of [t0, t1] (SUBSTEPS per whole sample, at least one)."""
    m = max(int(np.ceil(SUBSTEPS * (t1 - t0) / sample_time - 1e-9)), 1)
    return t0 + (t1 - t0) * (np.arange(m) + 0.5) / m


def sample_grid(sample_times, t_lock, sample_time, dead_time):
    """Every time the design evaluates the nominal trajectory at: the samples, the dead-time splits, the midpoints."""
    times = []
    for start in sample_times:
        end = min(start + sample_time, t_lock)
        times.append([start])
        for t0, t1, _ in _pieces(start, end, dead_time):
            times.append([t0, t1])
            times.append(midpoints(t0, t1, sample_time))
    return np.unique(np.concatenate(times))


def _padded(subs, n_a):
    """(G_sub (N, n_a, S), u_sub (N, S), held_sub (N, S)) from each sample's sub-interval columns, feedforward at
    their midpoints and flags (:meth:`TCUModelBuilder.sub_interval_columns`), zero-padded to the most sub-intervals."""
    S = max(columns.shape[1] for columns, _, _ in subs)
    G, u, held = np.zeros((len(subs), n_a, S)), np.zeros((len(subs), S)), np.zeros((len(subs), S))
    for k, (columns, values, flags) in enumerate(subs):
        G[k, :columns.shape[0], :columns.shape[1]] = columns
        u[k, :values.size], held[k, :flags.size] = values, flags
    return G, u, held


class TCUModelBuilder:
    """Builds :class:`TCUModel` from a parametric slip linearisation and the nominal trajectory.

    Parameters
    ----------
    lin : clutchocp.shiftcontrol.linearize.SlipLinearization
        With the estimated parameters' columns (:func:`~clutchocp.shiftcontrol.linearize.parametric_linearization`).
    trajectory : callable
        ``trajectory(t) -> (x_all, z, u_ff)``: the nominal states, algebraic values and feedforward at t.
    sensors : clutchocp.shiftcontrol.sensors.Sensors
    spec : SlipControlSpec
    inertias : (float, float)
        J_in, J_out [kg m^2] (for the torque process noise).
    nominal_torque : float
        The engine torque the TCU is told [N m].
    pressure_reference : callable, optional
        ``pressure_reference(t)``: the noise-free pressure reading on the nominal trajectory [Pa] (the
        valve pressure through the sensor's lag; default: the valve pressure).
    """

    def __init__(self, lin, trajectory, sensors, spec, inertias, nominal_torque, pressure_reference=None):
        self.lin, self.trajectory, self.sensors, self.spec = lin, trajectory, sensors, spec
        self._sensor_nominal = pressure_reference or (
            lambda t: float(dict(zip(lin.all_states, trajectory(t)[0]))["p_valve"]))
        self.inertias, self.nominal_torque = inertias, nominal_torque
        self.n = lin.n
        self.m = len(lin.parameter_names)
        pressure = sensors.pressure
        self.has_p = pressure is not None and "p_valve" in lin.state_names
        self.lag = pressure.lag if self.has_p else 0.0
        self.offset = pressure.offset if self.has_p else 0.0
        self.dead_time = sensors.valve.assumed_dead_time
        names = list(lin.state_names)
        if self.lag > 0:
            names.append("p_sensor")
        speed_sensors = {"w_in": sensors.input_speed, "w_out": sensors.output_speed}
        self.averaged = tuple(name for name in ("w_in", "w_out") if speed_sensors[name].averages)
        names += [f"mean:{name}" for name in self.averaged]
        self.n_c = self.n + (1 if self.lag > 0 else 0) + len(self.averaged)       # states with dynamics
        self.speed_sensors = speed_sensors
        for name in self.averaged:
            names += [f"edge:{name}", f"edge_prev:{name}"]
        names += [f"d:{name}" for name in lin.parameter_names]
        if self.offset > 0:
            names.append("p_offset")
        names.append("du_prev")              # the correction applied at the last sample
        self.names = tuple(names)
        measured = ["w_in", "w_out"] + (["p_sensor"] if self.has_p else [])
        self.torque_channel = (sensors.engine_torque.source == "plant"
                               and "driveline.input_torque" in lin.parameter_names)
        if self.torque_channel:
            measured.append("engine_torque")
        self.measured = tuple(measured)

    def index(self, name):
        return self.names.index(name)

    def _continuous(self, t, shift=None, correction=0.0):
        """(A_c, B_c, F_c, C signals (over the model's states), G) at time t: the model with the sensor lag.

        ``shift(t)``, optional: a deviation of all the model's states from the nominal trajectory (SI), and
        ``correction`` one of the command [Pa], at which to linearise instead."""
        x, z, u = self.trajectory(t)
        if shift is not None:
            x = x + shift(t)
        u = u + correction
        A, B, C, _ = self.lin.continuous(x, u, z)
        F, G = self.lin.parameter_columns(x, u, z)
        n, extra = self.n, self.n_c - self.n
        if extra:
            A = np.block([[A, np.zeros((n, extra))], [np.zeros((extra, n + extra))]])
            B = np.vstack([B, np.zeros((extra, 1))])
            F = np.vstack([F, np.zeros((extra, self.m))])
        row = n
        if self.lag > 0:                          # ds/dt = (dp - ds) / lag
            A[row, self.lin.state_names.index("p_valve")] = 1.0 / self.lag
            A[row, row] = -1.0 / self.lag
            row += 1
        for name in self.averaged:                # da/dt = dw
            A[row, self.lin.state_names.index(name)] = 1.0
            row += 1
        return A, B, F, C, G

    def _part_map(self, t0, t1, Ts, shift=None, correction=0.0):
        """(Phi, Gamma, Psi) of the dynamic states over [t0, t1] with a constant correction and parameters
        (along the nominal trajectory, or the one moved by ``shift``, see :meth:`_continuous`)."""
        mids = midpoints(t0, t1, Ts)
        dt = (t1 - t0) / mids.size
        n_c = self.n_c
        Phi, Gamma, Psi = np.eye(n_c), np.zeros((n_c, 1)), np.zeros((n_c, self.m))
        M = np.zeros((n_c + 1 + self.m, n_c + 1 + self.m))
        for t in mids:
            A, B, F, _, _ = self._continuous(t, shift, correction)
            M[:n_c, :n_c], M[:n_c, n_c:n_c + 1], M[:n_c, n_c + 1:] = A * dt, B * dt, F * dt
            E = expm(M)
            step = E[:n_c, :n_c]
            Phi, Gamma, Psi = step @ Phi, step @ Gamma + E[:n_c, n_c:n_c + 1], step @ Psi + E[:n_c, n_c + 1:]
        return Phi, Gamma, Psi

    def sample_map(self, start, end, Ts, shift=None, corrections=(0.0, 0.0)):
        """(Phi, Gamma_prev, Gamma_cur, Psi) of the dynamic states over the sample [start, end]: the pieces split at
        the dead time composed (Gamma_prev: the previous correction's column, Gamma_cur: the current one's);
        linearised along the trajectory moved by ``shift`` and ``corrections`` (previous, current) [Pa], see
        :meth:`_continuous`."""
        n_c = self.n_c
        Phi, G_prev, G_cur, Psi = np.eye(n_c), np.zeros((n_c, 1)), np.zeros((n_c, 1)), np.zeros((n_c, self.m))
        for t0, t1, held in _pieces(start, end, self.dead_time):
            P_, Gm, Ps = self._part_map(t0, t1, Ts, shift, corrections[0 if held == "previous" else 1])
            Phi, Psi = P_ @ Phi, P_ @ Psi + Ps
            G_prev, G_cur = P_ @ G_prev, P_ @ G_cur
            if held == "previous":
                G_prev = G_prev + Gm
            else:
                G_cur = G_cur + Gm
        return Phi, G_prev, G_cur, Psi

    def sub_interval_columns(self, start, end, Ts):
        """(columns (n_c, S), midpoints (S,), held (S,)) of the sample's sub-intervals: the dynamic states at the
        sample's end per Pa of correction held over sub-interval s alone (frozen pieces, as :meth:`_part_map`: they
        sum to Gamma_prev and Gamma_cur), its midpoint [s] and whether the current correction (1) or the previous
        one (0) acts there. The TCU knows the command it clips between samples from them."""
        n_c = self.n_c
        columns, times, held_flags = [], [], []
        for t0, t1, held in _pieces(start, end, self.dead_time):
            mids = midpoints(t0, t1, Ts)
            dt = (t1 - t0) / mids.size
            M = np.zeros((n_c + 1, n_c + 1))
            for t in mids:
                A, B, _, _, _ = self._continuous(t)
                M[:n_c, :n_c], M[:n_c, n_c:] = A * dt, B * dt
                E = expm(M)
                columns = [E[:n_c, :n_c] @ c for c in columns] + [E[:n_c, n_c]]
                times.append(float(t))
                held_flags.append(1.0 if held == "current" else 0.0)
        return np.array(columns).T, np.array(times), np.array(held_flags)

    def responses_at_midpoints(self, start, end, Ts):
        """{t: S(t)} at every midpoint of the sample: the model states' response (n, n + 2) to a deviation of each
        model state at the sample's start, the previous correction and the current one [SI/Pa] (nominal flow,
        frozen pieces as :meth:`_part_map`)."""
        n = self.n
        S, out = np.hstack([np.eye(n), np.zeros((n, 2))]), {}
        M = np.zeros((n + 1, n + 1))
        for t0, t1, held in _pieces(start, end, self.dead_time):
            mids = midpoints(t0, t1, Ts)
            dt = (t1 - t0) / mids.size
            column = n if held == "previous" else n + 1
            for t in mids:
                A, B = self.lin.continuous(*self._point(t))[:2]
                M[:n, :n], M[:n, n:] = A * 0.5 * dt, B * 0.5 * dt
                half = expm(M)
                S = half[:n, :n] @ S
                S[:, column] += half[:n, n]
                out[float(t)] = S.copy()
                S = half[:n, :n] @ S
                S[:, column] += half[:n, n]
        return out

    def _point(self, t):
        x, z, u = self.trajectory(t)
        return x, u, z

    def column_derivative(self, start, end, Ts):
        """H = d Psi / d v of the sample [start, end]: (n_c, m, n + 2), the change of each parameter's column Psi_j
        (its effect on the states at the sample's end) per deviation v of each model state at the sample's start,
        of the previous correction and of the current one (the last two columns, per Pa).

        The clutch met runs off the nominal trajectory, and there the parameters act with other columns (friction
        times a contact load that is not the nominal one): x_k+1 = ... + sum_j d_j H_j v is the bilinear term of
        the sample map. Central differences of Psi along the trajectory moved by +-eps S(t) e_i (the deviation e_i
        carried by the nominal linear flow, :meth:`responses_at_midpoints`; for a correction the command moved
        too), eps = DIFFERENCE_STEP of the state's size (of the nominal valve pressure for the corrections)."""
        n, n_c = self.n, self.n_c
        H = np.zeros((n_c, self.m, n + 2))
        flow = self.responses_at_midpoints(start, end, Ts)
        x0 = self.trajectory(start)[0]
        rows = [self.lin.all_states.index(name) for name in self.lin.state_names]
        pressure = self.lin.nominal[self.lin.state_names.index("p_valve")] if "p_valve" in self.lin.state_names \
            else 1.0
        for i in range(n + 2):
            if i < n:
                eps = DIFFERENCE_STEP * max(abs(x0[rows[i]]), DIFFERENCE_STEP * abs(self.lin.nominal[i]))
            else:
                eps = DIFFERENCE_STEP * abs(pressure)
            columns = []
            for sign in (1.0, -1.0):
                def shift(t, sign=sign):
                    moved = np.zeros(x0.size)
                    moved[rows] = sign * eps * flow[float(t)][:, i]
                    return moved
                corrections = tuple(sign * eps * (i == n + c) for c in (0, 1))
                columns.append(self.sample_map(start, end, Ts, shift, corrections)[3])
            H[:, :, i] = (columns[0] - columns[1]) / (2 * eps)
        return H

    def build(self, sample_times, t_lock, Ts):
        """The :class:`TCUModel` over the samples t_0 .. t_N-1 (the last one ends at t_lock)."""
        N, n_a, n_c = len(sample_times), len(self.names), self.n_c
        p = len(self.measured)
        A, B, C = np.zeros((N, n_a, n_a)), np.zeros((N, n_a)), np.zeros((N, p, n_a))
        H = np.zeros((N, n_a, self.m * (n_a + 1)))
        subs = []
        slip, rate, y_ref = np.zeros((N, n_a)), np.zeros((N, n_a)), np.zeros((N, p))
        durations = np.minimum(np.asarray(sample_times) + Ts, t_lock) - np.asarray(sample_times)
        params = [self.index(f"d:{name}") for name in self.lin.parameter_names]
        sig = {name: j for j, name in enumerate(self.lin.signals)}
        for k, start in enumerate(sample_times):
            end = start + durations[k]
            Phi, G_prev, G_cur, Psi = self.sample_map(start, end, Ts)
            for j, column in enumerate(self.column_derivative(start, end, Ts).transpose(1, 0, 2)):
                at = j * (n_a + 1)               # acts on d_j [xi; du]: the model states, du_prev and du
                H[k][:n_c, at:at + self.n] = column[:, :self.n]
                H[k][:n_c, at + self.index("du_prev")] = column[:, self.n]
                H[k][:n_c, at + n_a] = column[:, self.n + 1]
            columns, mids, held = self.sub_interval_columns(start, end, Ts)
            subs.append((columns, np.array([self.trajectory(t)[2] for t in mids]), held))
            A[k] = np.eye(n_a)
            A[k][:n_c, :n_c] = Phi
            A[k][:n_c, params] = Psi
            for name in self.averaged:            # the angle counts from zero again at every sample
                A[k][:, self.index(f"mean:{name}")] = 0.0
                edge, previous = self.index(f"edge:{name}"), self.index(f"edge_prev:{name}")
                A[k][edge, edge] = 0.0                # a new boundary error each sample (process noise)
                A[k][previous, previous] = 0.0
                A[k][previous, edge] = 1.0
            j = self.index("du_prev")
            A[k][:n_c, j] = G_prev[:, 0]          # zero without a dead time
            A[k][j, j] = 0.0
            B[k][j] = 1.0
            B[k][:n_c] = G_cur[:, 0]
            _, _, _, Cs, Gs = self._continuous(start)
            slip[k, :self.n] = Cs[sig["w_rel"]]
            rate[k, :self.n] = Cs[sig["slip_rate"]]
            rate[k, params] = Gs[sig["slip_rate"]]
            C[k], y_ref[k] = self._readings(start, Ts)
        end_state = self._continuous(t_lock * (1 - 1e-9))
        slip_end, rate_end = np.zeros(n_a), np.zeros(n_a)
        slip_end[:self.n], rate_end[:self.n] = end_state[3][sig["w_rel"]], end_state[3][sig["slip_rate"]]
        rate_end[params] = end_state[4][sig["slip_rate"]]
        Q = np.array([self._process_noise(Ts, t) for t in sample_times])
        R = np.array([self._reading_noise(y_ref[k], Ts, t) for k, t in enumerate(sample_times)])
        times = np.array([self.reading_times(t, Ts)[0] for t in sample_times])
        rates = np.array([self.reading_times(t, Ts)[1] for t in sample_times])
        return TCUModel(self.names, self.measured, A, B, C, y_ref, slip, rate, slip_end, rate_end, durations, Q, R,
                        self._prior(y_ref[0], Ts), times, rates, H, *_padded(subs, n_a))

    def _readings(self, t, Ts):
        """(C rows, nominal readings) at time t."""
        n_a = len(self.names)
        x, _, _ = self.trajectory(t)
        states = dict(zip(self.lin.all_states, x))
        rows, values = [], []
        for name in self.measured:
            row = np.zeros(n_a)
            if name in self.averaged:             # the mean speed over the window, on average
                row[self.index(f"mean:{name}")] = 1.0 / Ts
                row[self.index(f"edge:{name}")] = 1.0 / Ts
                row[self.index(f"edge_prev:{name}")] = -1.0 / Ts
                middle = self.speed_sensors[name].reading_time(t, Ts, states[name])
                values.append(self.mean_speed(name, middle - 0.5 * Ts, middle + 0.5 * Ts))
            elif name in ("w_in", "w_out"):
                row[self.index(name)] = 1.0
                values.append(states[name])
            elif name == "p_sensor":
                row[self.index("p_sensor" if self.lag > 0 else "p_valve")] = 1.0
                if self.offset > 0:
                    row[self.index("p_offset")] = 1.0
                values.append(self.pressure_reference(t))
            else:                                   # the engine-torque signal: T_nom (1 + d_Tin)
                row[self.index("d:driveline.input_torque")] = self.nominal_torque
                values.append(self.nominal_torque)
            rows.append(row)
        return np.array(rows), np.array(values)

    def mean_speed(self, name, t0, t1, points=41):
        """Mean of the nominal speed ``name`` over [t0, t1] [rad/s] (before t = 0: the initial speed); Simpson."""
        j = self.lin.all_states.index(name)
        t = np.linspace(t0, t1, points)
        w = np.array([self.trajectory(max(ti, 0.0))[0][j] for ti in t])
        h = (t1 - t0) / (points - 1)
        return float(h / 3 * (w[0] + w[-1] + 4 * w[1:-1:2].sum() + 2 * w[2:-1:2].sum()) / (t1 - t0))

    def pressure_reference(self, t):
        """The noise-free pressure reading on the nominal trajectory at t [Pa] (the lagged valve pressure)."""
        return self._sensor_nominal(t)

    def _process_noise(self, Ts, t):
        n_a = len(self.names)
        q = np.zeros(n_a)
        x, _, _ = self.trajectory(t + Ts)
        states = dict(zip(self.lin.all_states, x))
        for name in self.averaged:
            q[self.index(f"edge:{name}")] = self.speed_sensors[name].boundary_variance(states[name])
        J_in, J_out = self.inertias
        T = self.spec.estimator["torque_noise"]
        q[self.index("w_in")] = (Ts * T / J_in) ** 2
        q[self.index("w_out")] = (Ts * T / J_out) ** 2
        if "p_valve" in self.names:
            q[self.index("p_valve")] = self.spec.estimator["pressure_noise"] ** 2
        for name in self.lin.parameter_names:
            q[self.index(f"d:{name}")] = self.spec.estimator["parameter_drift"] ** 2
        return np.diag(q)

    def reading_times(self, t, Ts):
        """(times, rates) of the readings at sample time t: the time each stands for on average [s] and the
        nominal rate of change of its reference there (per s; the TCU moves a reading that stands for another
        time by the rate times the difference)."""
        x, _, _ = self.trajectory(t)
        states = dict(zip(self.lin.all_states, x))
        times, rates = [], []
        for name in self.measured:
            if name in self.averaged:
                middle = self.speed_sensors[name].reading_time(t, Ts, states[name])
                h = 0.25 * Ts
                times.append(middle)
                rates.append((self.mean_speed(name, middle - 0.5 * Ts + h, middle + 0.5 * Ts + h)
                              - self.mean_speed(name, middle - 0.5 * Ts - h, middle + 0.5 * Ts - h)) / (2 * h))
            else:
                times.append(t)
                rates.append(0.0)
        return np.array(times), np.array(rates)

    def _reading_noise(self, y_nominal, Ts, t):
        variances = []
        _, rates = self.reading_times(t, Ts)
        for name, value, rate in zip(self.measured, y_nominal, rates):
            if name in self.averaged:
                # white: the sensor's noise; and the window's middle, spread uniformly over a tooth period,
                # moved with the nominal acceleration: the clutch's may be off by ACCELERATION_SPREAD of it
                sensor = self.speed_sensors[name]
                period = 2 * math.pi / (sensor.teeth * max(abs(value), 1e-6)) if sensor.method == "edge_timing" else 0.0
                v = sensor.noise ** 2 + (ACCELERATION_SPREAD * rate * period) ** 2 / 12
            elif name in ("w_in", "w_out"):
                v = self.speed_sensors[name].variance(value, Ts)
            elif name == "p_sensor":
                v = self.sensors.pressure.noise ** 2
            else:
                v = (self.nominal_torque * self.sensors.engine_torque.error) ** 2 / 3.0
            # a floor: the exact readings of an ideal sensor still carry the integration's round-off
            floor = (1e-6 * max(abs(value), 1.0)) ** 2
            variances.append(max(v, floor))
        return np.diag(variances)

    def _prior(self, y0, Ts):
        n_a = len(self.names)
        p0 = np.zeros(n_a)
        for j, name in enumerate(self.measured):
            if name in ("w_in", "w_out"):          # the speeds before the shift, as read
                sensor = self.speed_sensors[name]
                p0[self.index(name)] = sensor.variance(y0[j], Ts)
                if name in self.averaged:
                    p0[self.index(f"mean:{name}")] = Ts ** 2 * p0[self.index(name)]
                    p0[self.index(f"edge:{name}")] = p0[self.index(f"edge_prev:{name}")] = \
                        sensor.boundary_variance(y0[j])
        for name, width in self.spec.estimated_parameters.items():
            p0[self.index(f"d:{name}")] = width ** 2 / 3.0
        if self.offset > 0:
            p0[self.index("p_offset")] = self.offset ** 2 / 3.0
        return np.diag(p0)
