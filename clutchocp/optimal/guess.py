"""Initial guess of the collocation NLP from a simulated engagement (IDAS run of a profile) or an optimum.

Each phase of the problem (:mod:`clutchocp.optimal.phases`) is seeded from the samples of the run in
that phase's mode, between the events that bound it (impact, lock-up), stretched onto the phase's mesh.
"""

import numpy as np

from ..errors import ModelError

SLIP_MODE = "pressing_slip_forward"
DISSIPATED = ("E_slip", "E_film", "E_seal", "E_spline", "E_impact")     # as in engagement.run.energy_balance


def phase_windows(run):
    """Start and end time [s] of each axial phase of a run that locks up: {mode: (t_start, t_end)}.

    The fill (``approach_slip_forward``) ends at the impact; the slip phase ends at lock-up.
    """
    t_lock = run.summary["engagement_time_s"]
    if t_lock is None:
        raise ModelError(f"scene '{run.model.scene.name}': the guess run does not lock up")
    impact = [e.t for e in run.result.events if e.name == "impact"]
    if impact:
        return {"approach_slip_forward": (0.0, impact[0]), SLIP_MODE: (impact[0], t_lock)}
    return {SLIP_MODE: (0.0, t_lock)}


def mode_samples(run, mode, t_start, t_end):
    """Samples of a run in ``mode`` within [t_start, t_end]: (times, their indices in the run)."""
    res = run.result
    mask = (np.asarray(res.mode) == mode) & (res.t >= t_start) & (res.t <= t_end)
    t, order = np.unique(res.t[mask], return_index=True)
    return t, np.nonzero(mask)[0][order]


def engagement_samples(run):
    """Samples of a run from t = 0 up to lock-up, fill and slip (times, their indices in the run)."""
    t_lock = phase_windows(run)[SLIP_MODE][1]
    res = run.result
    mask = np.isin(np.asarray(res.mode), ("approach_slip_forward", SLIP_MODE)) & (res.t <= t_lock)
    t, order = np.unique(res.t[mask], return_index=True)
    return t, np.nonzero(mask)[0][order]


def command_history(run, t):
    """Pressure command [Pa] that produced ``run``, at times t.

    The scene's own profile is evaluated directly; a run driven by a command input through the valve
    lag is inverted (u = p + tau dp/dt); without a valve the command is the pressure.
    """
    model = run.model
    act = model.actuation
    if act.control is None:
        return np.array([float(act.command(ti)) for ti in t])
    res = run.result
    t_lock = run.summary["engagement_time_s"]
    ts, idx = np.unique(res.t[res.t <= t_lock], return_index=True)
    p = res["pressure_Pa"][idx]
    if act.has_state:
        p = p + act.time_constant * np.gradient(p, ts)
    return np.interp(t, ts, p)


def guess_from_run(ocp, run, t_max=None):
    """NLP start vector of ``ocp`` from a simulated run: each phase stretched onto its mesh.

    Parameters
    ----------
    ocp : clutchocp.optimal.problem.EngagementOCP
    run : clutchocp.engagement.run.EngagementResult
        A run of the same scene that locks up (its own profile or a command), through the same phases.
    t_max : float, optional
        Engagement-time limit [s]: a slower run is compressed in time to end at t_max.

    Returns
    -------
    ndarray
        The scaled NLP vector.
    """
    pieces = []
    for k, part in enumerate(ocp.phased.parts):
        x, xc, u, T = phase_guess(ocp, run, k, part.transcription, t_max)
        pieces.append(part.pack(x, xc, u[:, None], T))
    return np.concatenate(pieces)


def phase_guess(ocp, run, k, tr, t_max=None):
    """The guess of phase k of ``ocp`` from a run, on the mesh of transcription ``tr`` (see
    :func:`guess_from_run`): scaled node states (N + 1, n_x), collocation states (N, d, n_x), command
    values (n_controls,) and duration."""
    windows = phase_windows(run)
    t_lock = run.summary["engagement_time_s"]
    squeeze = min(1.0, t_max / t_lock) if t_max is not None else 1.0
    res = run.result
    energy_all = sum(res[name] for name in DISSIPATED if name in run.model.energy_terms)
    name, mode = ocp.phase_modes[k]
    if mode not in windows:
        raise ModelError(f"scene '{ocp.scene.name}': the guess run never enters mode '{mode}' of the {name} phase")
    t0, t1 = windows[mode]
    t, idx = mode_samples(run, mode, t0, t1)
    x, xc, tau_u = _phase_nodes(ocp, tr, k, t0, t1, t, {nm: res[nm][idx] for nm in ocp.state_names},
                                energy_all[idx])
    u = command_history(run, tau_u) if ocp.has_valve else np.interp(tau_u, t, res["pressure_Pa"][idx])
    u = np.clip(u, 0.0, ocp.p_max) / ocp.scales.pressure_Pa
    return x, xc, u, squeeze * (t1 - t0) / ocp.scales.time_s


def guess_from_optimum(ocp, opt, t_max=None):
    """NLP start vector of ``ocp`` from an optimum on another mesh (states and command interpolated per phase)."""
    if [p["name"] for p in opt.phases] != [name for name, _ in ocp.phase_modes]:
        raise ModelError("a guess optimum must have the same phases as the problem")
    squeeze = min(1.0, t_max / opt.t_f) if t_max is not None else 1.0
    pieces = []
    for k, phase in enumerate(opt.phases):
        part = ocp.phased.parts[k]
        tr = part.transcription
        a, b = phase["nodes"]
        t0, t1 = phase["t_start_s"], phase["t_end_s"]
        states = {nm: opt.states[nm][a:b] for nm in ocp.state_names}
        x, xc, tau_u = _phase_nodes(ocp, tr, k, t0, t1, opt.t[a:b], states, opt.outputs["dissipated_energy_J"][a:b])
        if opt.control == "constant":
            u = opt.command[np.clip(np.searchsorted(opt.command_times, tau_u, side="right") - 1, 0,
                                    opt.command.size - 1)]
        else:
            u = np.interp(tau_u, opt.command_times, opt.command)
        u = np.clip(u, 0.0, ocp.p_max) / ocp.scales.pressure_Pa
        pieces.append(part.pack(x, xc, u[:, None], squeeze * (t1 - t0) / ocp.scales.time_s))
    return np.concatenate(pieces)


def _phase_nodes(ocp, tr, k, t0, t1, t, states, energy):
    """Scaled node states (N + 1, n_x + 1) and collocation states (N, d, n_x + 1) of phase k on the
    mesh of ``tr``, interpolated from samples ``states`` {name: values} and dissipated ``energy`` [J]
    at times ``t`` [s] over the phase [t0, t1]; and the command times [s] of the phase."""
    starts, points = tr.node_times(1.0)                 # normalised times s in [0, 1]

    def states_at(s):
        tau = t0 + s * (t1 - t0)
        cols = [np.interp(tau, t, states[nm]) / nominal for nm, nominal in zip(ocp.state_names, ocp.nominal)]
        cols.append(np.interp(tau, t, energy) / ocp.scales.energy_J)
        return np.stack(cols, axis=-1)

    x, xc = states_at(starts), states_at(points)
    if k == 0:
        x[0] = np.append(ocp.x0 / ocp.nominal, 0.0)
    s_u = 0.5 * (starts[:-1] + starts[1:]) if tr.control == "constant" else starts
    return x, xc, t0 + s_u * (t1 - t0)
