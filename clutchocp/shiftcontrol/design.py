"""Design of the slip feedback along the nominal trajectory of a feedforward command.

1. Replay the feedforward (piecewise linear) on the exact nominal model with IDAS: the nominal
   trajectory x*(t), its lock-up time t_lock and the reference signals at the TCU samples t_k.
2. Per sample [t_k, min(t_k + Ts, t_lock)]: the exact sample map (Phi_k, Gamma_k) of the slip
   dynamics (:class:`~clutchocp.shiftcontrol.linearize.SlipLinearization`) and the output rows
   C_w (slip) and C_a (slip rate) at t_k.
3. Augment with the slip-error integral xi_{k+1} = xi_k + Ts C_w dx_k and solve the finite-horizon
   time-varying LQR (:func:`~clutchocp.control.lqr.tvlqr`) with the weights of the spec on
   scaled deviations (Bryson's rule): slip error / w_rel(0), slip-rate error / (w_rel(0) / t_lock),
   integral / (w_rel(0) t_lock), correction / pressure range; the terminal weight at lock-up is
   ``terminal_weight`` times the state weight there (a slip rate held at its nominal value at
   lock-up means the slipping torque equals the locked one: no torque jump).
4. Realise the state feedback from what the TCU measures: speeds, the difference slip rate and (with
   ``measure_pressure``) the clutch pressure. The state deviation is reconstructed as the
   minimum-norm (in nominal-scaled units) deviation that explains the measured deviations,
   dx = S (C_y S)^+ dy, so the gains on the measurements are K_y = K_x S (C_y S)^+. With the speeds
   and the pressure measured, the only unmeasured direction of the default scene (the films, which
   stay equal in a massless pack) is read from the slip rate, which the clutch torque sets.
"""

from dataclasses import dataclass

import numpy as np

from ..control.lqr import tvlqr
from ..engagement.run import EngagementResult
from ..errors import ModelError
from ..optimal.guess import SLIP_MODE
from ..optimal.replay import CommandModel, simulate_command
from .controller import SlipFeedback
from .estimator import FeedforwardAdaptation, TorqueEstimator
from .linearize import SlipLinearization

SUBSTEPS = 8            # sub-intervals per sample for the sample maps


@dataclass
class SlipFeedbackDesign:
    """The designed feedback and what it was designed on."""

    feedback: SlipFeedback
    nominal: EngagementResult          # IDAS replay of the feedforward on the nominal scene
    t_lock: float                      # nominal lock-up time [s]
    sample_times: np.ndarray           # t_0 .. t_N [s]
    Phi: np.ndarray                    # (N, n, n)
    Gamma: np.ndarray                  # (N, n, 1)
    K: np.ndarray                      # (N, 1, n + 1) gains on [dx, xi]
    P: np.ndarray                      # (N + 1, n + 1, n + 1) cost-to-go
    state_names: tuple
    spec: object
    adaptation_off: str | None = None  # why the spec's adaptation cannot run on this scene (None: it runs or is off)



def feedforward_lock(scene, times, values, Ts, model):
    """The nominal lock-up of a feedforward and the TCU's samples before it.

    Parameters
    ----------
    scene : clutchocp.scene.Scene
    times, values : array
        The feedforward [s], [Pa] (piecewise linear, last value held).
    Ts : float
        TCU sample time [s].
    model : CommandModel

    Returns
    -------
    (float, float, array)
        The replay horizon [s] (1.5 x the feedforward's length + 2 samples), the lock-up time [s] and the
        sample starts before it [s].

    Raises
    ------
    ModelError
        The feedforward does not lock up on the nominal scene within the horizon.
    """
    horizon = 1.5 * max(times[-1], Ts) + 2 * Ts
    coarse = simulate_command(scene, times, values, horizon, model=model, control="linear", points=201)
    t_lock = coarse.summary["engagement_time_s"]
    if t_lock is None or not coarse.result.events:
        raise ModelError(f"slip feedback: the feedforward does not lock up on the nominal scene '{scene.name}' "
                         f"within {horizon:.3g} s; it cannot be a reference")
    return horizon, t_lock, np.arange(int(np.ceil(t_lock / Ts - 1e-9))) * Ts

def pressure_limits(scene, spec):
    """Command limits [Pa]: 0 .. actuation.max_pressure, narrowed by the spec."""
    p_max = scene.get("actuation.max_pressure")
    if p_max is None:
        raise ModelError("actuation.max_pressure: slip feedback needs an upper pressure limit; add e.g. "
                         "max_pressure = \"1.5 MPa\" to [actuation]")
    lo = 0.0 if spec.pressure_min is None else spec.pressure_min
    hi = p_max if spec.pressure_max is None else min(p_max, spec.pressure_max)
    if lo >= hi:
        raise ModelError(f"controller pressure limits {lo:g}..{hi:g} Pa leave no range below "
                         f"actuation.max_pressure = {p_max:g} Pa")
    return lo, hi


def _slip_trajectory(run, names, z_names=()):
    """Slip-phase samples of a run: times, states (len, len(names)), algebraic values (len, len(z_names))."""
    res = run.result
    mask = np.asarray(res.mode) == SLIP_MODE
    t, order = np.unique(res.t[mask], return_index=True)
    idx = np.nonzero(mask)[0][order]
    x = np.column_stack([res[n][idx] for n in names])
    z = np.column_stack([res[n][idx] for n in z_names]) if z_names else np.zeros((t.size, 0))
    return t, x, z


def design_slip_feedback(scene, command_times, command, spec, *, model=None):
    """Slip feedback for a feedforward command on a scene (see the module docstring).

    Parameters
    ----------
    scene : clutchocp.scene.Scene
        The nominal engagement scene.
    command_times, command : array
        The feedforward: piecewise-linear command [Pa] through these times [s] (last value held).
    spec : clutchocp.shiftcontrol.spec.SlipControlSpec
    model : clutchocp.optimal.replay.CommandModel, optional
        A linear command model of the scene already built.

    Returns
    -------
    SlipFeedbackDesign

    Raises
    ------
    ModelError
        The feedforward does not lock up on the nominal scene, or no pressure range is left.
    """
    model = model or CommandModel(scene, "linear")
    eng = model.engagement
    lin = SlipLinearization(eng)
    Ts = spec.sample_time
    times, values = np.asarray(command_times, float), np.asarray(command, float)
    p_lo, p_hi = pressure_limits(scene, spec)
    horizon, t_lock, starts = feedforward_lock(scene, times, values, Ts, model)
    N = len(starts)
    ends = np.minimum(starts + Ts, t_lock)
    mids = starts[:, None] + (ends - starts)[:, None] * (np.arange(SUBSTEPS) + 0.5) / SUBSTEPS
    grid = np.concatenate([starts, mids.ravel(), [t_lock]])
    nominal = simulate_command(scene, times, values, min(horizon, t_lock + 2 * Ts), model=model, control="linear",
                               points=101, extra_times=grid[grid < t_lock])
    t_slip, x_slip, z_slip = _slip_trajectory(nominal, lin.all_states, lin.z_names)

    def state_at(t):
        return np.array([np.interp(t, t_slip, x_slip[:, j]) for j in range(x_slip.shape[1])])

    def alg_at(t):
        return np.array([np.interp(t, t_slip, z_slip[:, j]) for j in range(z_slip.shape[1])])

    def ff(t):
        return np.interp(t, times, values)

    n = lin.n
    Phi, Gamma, rows = np.zeros((N, n, n)), np.zeros((N, n, 1)), []
    for k in range(N):
        points = np.array([state_at(t) for t in mids[k]])
        Phi[k], Gamma[k] = lin.sample_map(points, ff(mids[k]), (ends[k] - starts[k]) / SUBSTEPS,
                                          np.array([alg_at(t) for t in mids[k]]))
        rows.append(lin.continuous(state_at(starts[k]), ff(starts[k]), alg_at(starts[k]))[2])
    C_end = lin.continuous(x_slip[-1], ff(t_slip[-1]), z_slip[-1])[2]
    sig = {name: j for j, name in enumerate(lin.signals)}

    w_rel0 = lin.signal_values(state_at(0.0), ff(0.0), alg_at(0.0))["w_rel"]
    K, P = _slip_lqr(spec.lqi, sig, Phi, Gamma, rows, C_end, ends - starts, w_rel0, t_lock, p_hi - p_lo)

    # realisation from the measured signals
    measured = ["slip_rate"] + [s for s in ("w_in", "w_out") if s in sig]
    if spec.measure_pressure and "p_valve" in sig:
        measured.append("p_valve")
    S = np.diag(lin.nominal)
    gains = np.zeros((N, len(measured)))
    for k in range(N):
        Cy = rows[k][[sig[m] for m in measured]]
        gains[k] = K[k, 0, :n] @ S @ np.linalg.pinv(Cy @ S)
    sample_times = np.arange(N + 1) * Ts
    ref, slip_ref = _references(lin, measured, sample_times, Ts, t_lock, t_slip[-1], state_at, alg_at, ff,
                                 nominal)
    path = None
    if spec.progress == "slip":
        w_slip = np.array([lin.signal_values(x, ff(t), z)["w_rel"] for t, x, z in zip(t_slip, x_slip, z_slip)])
        peak = int(np.argmax(w_slip))
        fall = slice(peak, None)
        path = (np.append(t_slip[fall], t_lock), np.append(w_slip[fall], 0.0))
    adaptation, adaptation_off = None, None
    if spec.estimator["enabled"]:
        adaptation_off = _adaptation_unavailable(scene, lin.all_states)
        if adaptation_off is None:
            adaptation = _adaptation(scene, spec, sample_times[:N], state_at, lin.all_states)
    feedback = SlipFeedback(Ts, gains, K[:, 0, n], ref, slip_ref, measured, (times, values), p_lo, p_hi,
                            (p_hi - p_lo) / spec.rate_limit_time, spec.anti_windup, path=path,
                            max_delay=spec.max_delay, adaptation=adaptation)
    return SlipFeedbackDesign(feedback, nominal, t_lock, sample_times, Phi, Gamma, K, P, lin.state_names, spec,
                              adaptation_off)


def _slip_lqr(w, sig, Phi, Gamma, rows, C_end, durations, w_rel0, t_lock, p_range):
    """Gains and cost-to-go of the time-varying LQR on the sample maps augmented with the slip-error integral.

    Weights on scaled deviations (Bryson's rule, see the module docstring): ``w`` the spec's [lqi] table,
    ``sig`` the row of each signal in the output matrices ``rows`` (per sample) and ``C_end`` (at lock-up),
    ``durations`` the sample lengths [s], ``w_rel0`` the initial slip [rad/s], ``p_range`` [Pa].
    """
    n = Phi.shape[1]
    e_s, r_s, xi_s, p_s = abs(w_rel0), abs(w_rel0) / t_lock, abs(w_rel0) * t_lock, p_range

    def state_weight(C):
        Cw, Ca = C[sig["w_rel"]][None, :], C[sig["slip_rate"]][None, :]
        Q = np.zeros((n + 1, n + 1))
        Q[:n, :n] = (Cw.T @ Cw / (w["slip_tolerance"] * e_s) ** 2
                     + Ca.T @ Ca / (w["slip_rate_tolerance"] * r_s) ** 2)
        Q[n, n] = 1.0 / (w["integral_tolerance"] * xi_s) ** 2
        return Q

    A_aug, B_aug, Q = [], [], []
    for k in range(len(Phi)):
        A = np.eye(n + 1)
        A[:n, :n] = Phi[k]
        A[n, :n] = durations[k] * rows[k][sig["w_rel"]]
        A_aug.append(A)
        B_aug.append(np.vstack([Gamma[k], [[0.0]]]))
        Q.append(state_weight(rows[k]))
    R = [np.array([[1.0 / (w["correction_tolerance"] * p_s) ** 2]])] * len(Phi)
    return tvlqr(A_aug, B_aug, Q, R, w["terminal_weight"] * state_weight(C_end))


def _references(lin, measured, sample_times, Ts, t_lock, t_last, state_at, alg_at, ff, nominal):
    """The measured signals' and the slip's values on the nominal trajectory at the TCU samples.

    ``sample_times`` are t_0 .. t_N, ``Ts`` apart [s]; ``t_last`` is the last slipping time of the nominal
    run; ``state_at``, ``alg_at`` and ``ff`` give its states, algebraic values and the feedforward at a time.
    Returns (ref (N + 1, len(measured)), slip_ref (N + 1)).
    """
    N = len(sample_times) - 1
    ref = np.zeros((N + 1, len(measured)))
    slip_ref = np.zeros(N + 1)
    for k, t in enumerate(sample_times):
        t_in = min(t, t_last)
        values_k = lin.signal_values(state_at(t_in), ff(t), alg_at(t_in))
        slip_ref[k] = values_k["w_rel"] if t < t_lock else 0.0
        for j, name in enumerate(measured):
            ref[k, j] = values_k[name] if name != "slip_rate" else 0.0
    ref[0, 0] = lin.signal_values(state_at(0.0), ff(0.0), alg_at(0.0))["slip_rate"]
    ref[1:, 0] = np.diff(slip_ref) / Ts            # the TCU's difference rate of the nominal slip
    if N >= 1:
        # at t_N the nominal clutch is locked: both speeds at the common speed just after lock-up
        lock = next(e for e in nominal.result.events if e.name == "lockup")
        for j, name in enumerate(measured):
            if name in ("w_in", "w_out"):
                ref[N, j] = lock.x_after[name]
    return ref, slip_ref


def _adaptation_unavailable(scene, state_names):
    """Why the feedforward adaptation cannot run on a scene's model (one line), or None."""
    missing = [name for name in ("w_in", "w_out", "p_valve") if name not in state_names]
    if missing:
        return (f"the model has no {', '.join(missing)} state (the estimator needs both rotor speeds and the valve "
                "pressure: actuation.model = \"valve_lag\")")
    return TorqueEstimator.unavailable(scene)


def _adaptation(scene, spec, sample_times, state_at, state_names):
    """The feedforward adaptation: the estimator's values on the nominal trajectory at the TCU samples before lock-up.

    Row k of the table is the estimate over the sample ending at t_k, as the TCU computes it on the nominal
    clutch (rows 0 and N repeat their neighbours: no estimate exists before t_1, and the TCU hands over at the
    first sample after lock-up).
    """
    estimator = TorqueEstimator.from_scene(scene, spec.sample_time)
    states = np.array([state_at(t) for t in sample_times])
    columns = [states[:, state_names.index(name)] for name in ("w_in", "w_out", "p_valve")]
    rows = np.column_stack(estimator.along(*columns)) if len(sample_times) > 1 else np.zeros((0, 3))
    if rows.shape[0] == 0:
        raise ModelError("estimator.enabled = true: the nominal engagement locks within one TCU sample; nothing to adapt")
    table = np.vstack([rows[:1], rows, rows[-1:]])
    activation = spec.estimator["activation"] * float(np.max(rows[:, 0]))
    return FeedforwardAdaptation(estimator, table, activation, spec.estimator["gain_limit"])
