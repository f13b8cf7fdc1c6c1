"""Stiffness of an engagement along its trajectory: the eigenvalues of the Jacobian of the ODE.

At every sample of a run the Jacobian of the mode's right-hand side with respect to its
physical states (energy accumulators left out: they are integrals of powers, feed nothing
back and only add zero eigenvalues) is evaluated exactly by CasADi; algebraic variables, where
a mode has them, are eliminated (A = f_x - f_z g_z^-1 g_x). The states are scaled by their
nominal values, which is a similarity transform and leaves the eigenvalues unchanged [1/s].

From the eigenvalues lambda at a sample:

* fastest time constant  tau_min = 1 / max |Re lambda|  [s];
* stiffness ratio        max |Re lambda| / min |Re lambda| over the decaying eigenvalues
  (Re lambda < 0) whose time constant is shorter than the run (|Re lambda| >= 1 / t_end):
  slower ones (integrators such as a piston position that is only a record, a speed without
  load) do not evolve over the run and would make the ratio meaningless;
* largest growth rate    max Re lambda  [1/s] (> 0: a locally unstable direction, e.g. a
  friction law whose coefficient falls with slip speed);
* stiffness index        t_end / tau_min: how many of the fastest time constants fit in the
  run, i.e. roughly the steps an explicit method would need.
"""

from dataclasses import dataclass

import casadi as ca
import numpy as np

from ..errors import ModelError
from ..output import new_figure, save_figure, write_csv
from ..simulation.compiled import ColumnFunction
from .model import ENERGY_TERMS


@dataclass
class StiffnessProfile:
    """Jacobian eigenvalue statistics at every sample of an engagement run.

    Attributes
    ----------
    scene : str
    t : numpy.ndarray
        Sample times [s] (repeated at events: before, after).
    mode : numpy.ndarray
        Mode at each sample.
    stiffness_ratio : numpy.ndarray
        max |Re lambda| / min |Re lambda| over the decaying eigenvalues faster than 1 / t_end
        [-] (1 if there is only one, NaN if none).
    fastest_time_constant_s : numpy.ndarray
        1 / max |Re lambda| [s] (inf if every eigenvalue is zero).
    max_growth_rate_1_s : numpy.ndarray
        Largest real part [1/s].
    t_end : float
        Simulated time [s].
    n_states : int
        Physical states of the model.
    """

    scene: str
    t: np.ndarray
    mode: np.ndarray
    stiffness_ratio: np.ndarray
    fastest_time_constant_s: np.ndarray
    max_growth_rate_1_s: np.ndarray
    t_end: float
    n_states: int

    def summary(self):
        """JSON-ready extremes along the run (units in the key names)."""
        ratio = self.stiffness_ratio
        finite = np.isfinite(ratio)
        k_ratio = int(np.argmax(np.where(finite, ratio, -np.inf))) if finite.any() else None
        tau = np.where(np.isnan(self.fastest_time_constant_s), np.inf, self.fastest_time_constant_s)
        k_tau = int(np.argmin(tau))
        return {
            "max_stiffness_ratio": float(ratio[k_ratio]) if k_ratio is not None else None,
            "max_stiffness_ratio_time_s": float(self.t[k_ratio]) if k_ratio is not None else None,
            "max_stiffness_ratio_mode": str(self.mode[k_ratio]) if k_ratio is not None else None,
            "median_stiffness_ratio": float(np.median(ratio[finite])) if finite.any() else None,
            "min_time_constant_s": float(tau[k_tau]) if np.isfinite(tau[k_tau]) else None,
            "min_time_constant_time_s": float(self.t[k_tau]),
            "min_time_constant_mode": str(self.mode[k_tau]),
            "stiffness_index": float(self.t_end / tau[k_tau]) if np.isfinite(tau[k_tau]) else None,
            "max_growth_rate_1_s": float(np.nanmax(self.max_growth_rate_1_s)),
            "n_samples": int(self.t.size),
            "n_states": int(self.n_states),
        }


def _jacobian_function(cm, keep):
    """Column function (xs, zs, pu, t) -> vec of the reduced Jacobian on the states ``keep``."""
    J = ca.jacobian(cm.ode_s, cm.xs)
    if cm.nz:
        g_z = ca.jacobian(cm.alg_s, cm.zs)
        J = J - ca.mtimes(ca.jacobian(cm.ode_s, cm.zs), ca.solve(g_z, ca.jacobian(cm.alg_s, cm.xs)))
    J = J[keep, keep]
    f = ca.Function(f"{cm.name}_stiffness_jacobian", [cm.xs, cm.zs, cm.pu, cm.t], [ca.densify(ca.vec(J))])
    return ColumnFunction(f)


def eigenvalue_statistics(eigenvalues, t_end):
    """(stiffness ratio, fastest time constant [s], largest real part [1/s]) of one spectrum.

    Parameters
    ----------
    eigenvalues : array_like of complex
        Eigenvalues of the Jacobian [1/s].
    t_end : float
        Length of the run [s]: decaying eigenvalues slower than 1 / t_end are left out of the ratio.
    """
    re = np.real(np.asarray(eigenvalues))
    if not np.all(np.isfinite(re)):
        return np.nan, np.nan, np.nan
    fastest = np.max(np.abs(re)) if re.size else 0.0
    tau = 1.0 / fastest if fastest > 0 else np.inf
    decaying = -re[(re < 0) & (-re >= 1.0 / t_end)]
    ratio = decaying.max() / decaying.min() if decaying.size else np.nan
    return ratio, tau, (re.max() if re.size else 0.0)


def jacobian_eigenvalues(run):
    """Eigenvalues of the Jacobian (physical states, algebraic variables eliminated) at every sample.

    Parameters
    ----------
    run : clutchocp.engagement.run.EngagementResult
        A run of an engagement scene (its model must have no inputs: a scene's own pressure profile).

    Returns
    -------
    t : numpy.ndarray
        Sample times [s].
    mode : numpy.ndarray
        Mode at each sample.
    eigenvalues : list of numpy.ndarray
        Complex eigenvalues at each sample [1/s] (as many as the mode has physical states).
    """
    model, result = run.model, run.result
    if model.hybrid.p or model.hybrid.u:
        raise ModelError("stiffness: the model has parameters or inputs (a pressure command); "
                         "analyse a run of the scene's own pressure profile")
    compiled = model.hybrid.compiled()
    physical = [n for n in model.state_names if n not in ENERGY_TERMS]
    times, modes, eigenvalues = [], [], []
    for seg in result.segments:
        if seg.t.size == 0:
            continue
        cm = compiled[seg.mode]
        keep = [cm.x_names.index(n) for n in physical if n in cm.x_names]
        n = len(keep)
        xs = np.array([seg.x[name] / nom for name, nom in zip(cm.x_names, cm.x_nominal)]).reshape(cm.nx, seg.t.size)
        zs = np.array([seg.z[name] / nom for name, nom in zip(cm.z_names, cm.z_nominal)]).reshape(cm.nz, seg.t.size)
        columns = _jacobian_function(cm, keep)(xs, zs, np.zeros(0), seg.t)
        for k in range(seg.t.size):
            J = columns[:, k].reshape(n, n, order="F")
            eigenvalues.append(np.linalg.eigvals(J) if np.all(np.isfinite(J)) else np.full(n, np.nan))
        times.append(seg.t)
        modes.append(np.full(seg.t.size, seg.mode, dtype=object))
    return np.concatenate(times), np.concatenate(modes), eigenvalues


def stiffness_profile(run):
    """Stiffness along an engagement run (see the module docstring for the measures).

    Parameters
    ----------
    run : clutchocp.engagement.run.EngagementResult

    Returns
    -------
    StiffnessProfile
    """
    t, mode, eigenvalues = jacobian_eigenvalues(run)
    t_end = float(t[-1] - t[0]) or 1.0
    stats = np.array([eigenvalue_statistics(ev, t_end) for ev in eigenvalues], dtype=float).reshape(-1, 3)
    return StiffnessProfile(run.model.scene.name, t, mode, stats[:, 0], stats[:, 1], stats[:, 2], t_end,
                            run.model.n_states)


def write_stiffness(profile, out_dir, stem=None):
    """Write ``stiffness_<scene>.csv`` and ``stiffness_<scene>.png`` (ratio and fastest time constant).

    Returns
    -------
    list of pathlib.Path
    """
    from pathlib import Path

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    stem = stem or f"stiffness_{profile.scene}"
    def column(values):          # empty cell where a measure is undefined (no decaying eigenvalue)
        return ["" if not np.isfinite(v) else float(v) for v in values]

    csv = write_csv(out / f"{stem}.csv", {
        "time_s": profile.t, "mode": [str(m) for m in profile.mode],
        "stiffness_ratio": column(profile.stiffness_ratio),
        "fastest_time_constant_s": column(profile.fastest_time_constant_s),
        "max_growth_rate_1_s": column(profile.max_growth_rate_1_s)})
    fig, (ax1, ax2) = new_figure(2, width=5.0, height=3.8)
    for mode in dict.fromkeys(profile.mode):
        sel = profile.mode == mode
        ratio = sel & np.isfinite(profile.stiffness_ratio)
        tau = sel & np.isfinite(profile.fastest_time_constant_s)
        ax1.semilogy(profile.t[ratio], profile.stiffness_ratio[ratio], ".", ms=2.5, label=str(mode))
        ax2.semilogy(profile.t[tau], profile.fastest_time_constant_s[tau], ".", ms=2.5, label=str(mode))
    ax1.set(xlabel="time [s]", ylabel="stiffness ratio max|Re l| / min|Re l| [-]",
            title=f"{profile.scene}: Jacobian eigenvalue spread")
    ax2.set(xlabel="time [s]", ylabel="fastest time constant 1/max|Re l| [s]",
            title=f"{profile.scene}: smallest time constant")
    ax1.legend(fontsize=7)
    png = save_figure(fig, out / f"{stem}.png")
    return [csv, png]
