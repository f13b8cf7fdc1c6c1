"""Initial guess of the collocation NLP from a simulated engagement (IDAS run of a profile)."""

import numpy as np

from ..errors import ModelError

SLIP_MODE = "pressing_slip_forward"
DISSIPATED = ("E_slip", "E_film", "E_seal", "E_spline", "E_impact")     # as in engagement.run.energy_balance


def slip_samples(run):
    """Samples of a run in forward slip up to lock-up: (times, their indices in the run, lock-up time)."""
    res = run.result
    t_lock = run.summary["engagement_time_s"]
    if t_lock is None:
        raise ModelError(f"scene '{run.model.scene.name}': the guess run does not lock up")
    mask = (np.asarray(res.mode) == SLIP_MODE) & (res.t <= t_lock)
    t, order = np.unique(res.t[mask], return_index=True)
    return t, np.nonzero(mask)[0][order], t_lock


def command_history(run, t):
    """Pressure command [Pa] that produced ``run``, at times t.

    The scene's own profile is evaluated directly; a run driven by a command input through the valve
    lag is inverted (u = p + tau dp/dt); without a valve the command is the pressure.
    """
    model = run.model
    act = model.actuation
    if act.control is None:
        return np.array([float(act.command(ti)) for ti in t])
    ts, idx, _ = slip_samples(run)
    p = run.result["pressure_Pa"][idx]
    if act.has_state:
        p = p + act.time_constant * np.gradient(p, ts)
    return np.interp(t, ts, p)


def guess_from_run(ocp, run, t_max=None):
    """NLP start vector of ``ocp`` from a simulated run: its slip phase stretched onto [0, T].

    Parameters
    ----------
    ocp : clutchocp.optimal.problem.EngagementOCP
    run : clutchocp.engagement.run.EngagementResult
        A run of the same scene that locks up (its own profile or a command).
    t_max : float, optional
        Engagement-time limit [s]: a slower run is compressed in time to end at t_max.

    Returns
    -------
    ndarray
        The scaled NLP vector.
    """
    t, idx, t_lock = slip_samples(run)
    T = min(t_lock, t_max) if t_max is not None else t_lock
    tr, nlp = ocp.transcription, ocp.nlp
    starts, points = tr.node_times(1.0)                 # normalised times s in [0, 1]
    res = run.result

    energy = sum(res[name][idx] for name in DISSIPATED if name in run.model.energy_terms)

    def states_at(s):
        cols = [np.interp(s * t_lock, t, res[name][idx]) / nominal
                for name, nominal in zip(ocp.state_names, ocp.nominal)]
        cols.append(np.interp(s * t_lock, t, energy) / ocp.scales.energy_J)
        return np.stack(cols, axis=-1)

    x = states_at(starts)
    xc = states_at(points)
    x[0] = np.append(ocp.x0 / ocp.nominal, 0.0)
    if tr.control == "constant":
        s_u = 0.5 * (starts[:-1] + starts[1:])
    else:
        s_u = starts
    u = command_history(run, s_u * t_lock) if ocp.has_valve else \
        np.interp(s_u * t_lock, t, res["pressure_Pa"][idx])
    u = np.clip(u, 0.0, ocp.p_max) / ocp.scales.pressure_Pa
    return nlp.pack(x, xc, u[:, None], T / ocp.scales.time_s)


def guess_from_optimum(ocp, opt, t_max=None):
    """NLP start vector of ``ocp`` from an optimum on another mesh (states and command interpolated)."""
    T = min(opt.t_f, t_max) if t_max is not None else opt.t_f
    tr, nlp = ocp.transcription, ocp.nlp
    starts, points = tr.node_times(1.0)
    t_old = opt.t / opt.t_f

    def states_at(s):
        cols = [np.interp(s, t_old, opt.states[name]) / nominal for name, nominal in zip(ocp.state_names, ocp.nominal)]
        cols.append(np.interp(s, t_old, opt.outputs["dissipated_energy_J"]) / ocp.scales.energy_J)
        return np.stack(cols, axis=-1)

    x, xc = states_at(starts), states_at(points)
    x[0] = np.append(ocp.x0 / ocp.nominal, 0.0)
    s_u = 0.5 * (starts[:-1] + starts[1:]) if tr.control == "constant" else starts
    old_times = opt.command_times / opt.t_f
    if opt.control == "constant":
        u = opt.command[np.clip(np.searchsorted(old_times, s_u, side="right") - 1, 0, opt.command.size - 1)]
    else:
        u = np.interp(s_u, old_times, opt.command)
    u = np.clip(u, 0.0, ocp.p_max) / ocp.scales.pressure_Pa
    return nlp.pack(x, xc, u[:, None], T / ocp.scales.time_s)
