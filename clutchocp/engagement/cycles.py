"""Repeated engagements (the classic abuse test): the same engagement again and again with a cooling
interval between, the plates keeping their heat, until a number of cycles or a limit is reached.

One cycle is the scene's engagement run (simulation.t_end, the locked clutch convecting heat to
the oil after lock-up) started from the plate temperatures the previous cycle left, followed by a
cooling interval with the clutch open: no heat input, the plate temperatures relaxing to the oil through the
lining's conduction chain (its linear system, solved exactly by the matrix exponential). The driveline
starts every cycle from the scene's speeds, as on an inertia test bench that re-accelerates the
flywheels between engagements.
"""

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from matplotlib.ticker import MaxNLocator

from ..errors import ModelError, SolverError
from ..output import new_figure, save_figure, write_csv, write_summary
from ..plotting import flat_value, overrides_of, scene_title
from .model import EngagementModel
from .run import simulate_engagement

# Per-cycle numbers (JSON and CSV keys, units in the names).
CYCLE_KEYS = ("cycle", "start_interface_temperature_C", "peak_interface_temperature_C",
              "end_interface_temperature_C", "engagement_time_s", "specific_energy_J_mm2",
              "peak_specific_power_W_mm2", "lockup_torque_jump_Nm", "energy_balance_rel_error")


@dataclass
class CyclesResult:
    """Repeated engagements: one dict per cycle (keys :data:`CYCLE_KEYS`) and why the run stopped."""

    scene: str
    cycles: list
    stop_reason: str
    cooling_time_s: float
    max_temperature_C: float | None
    run_time_s: float
    oil_temperature_C: float
    overrides: dict = field(default_factory=dict)       # the scene values that differ from its file (titles)

    def summary(self):
        """JSON-ready summary (units in the key names)."""
        times = [c["engagement_time_s"] for c in self.cycles if c["engagement_time_s"] is not None]
        return {
            "scene": self.scene,
            "cycles_run": len(self.cycles),
            "stop_reason": self.stop_reason,
            "cooling_time_s": self.cooling_time_s,
            "engagement_run_time_s": self.run_time_s,
            "oil_temperature_C": self.oil_temperature_C,
            "max_temperature_C": self.max_temperature_C,
            "peak_interface_temperature_C": max(c["peak_interface_temperature_C"] for c in self.cycles),
            "engagement_time_first_s": times[0] if times else None,
            "engagement_time_last_s": times[-1] if times else None,
            "engagement_time_drift_s": times[-1] - times[0] if times else None,
            "cycles": self.cycles,
        }


def run_cycles(scene, *, cycles=10, cooling_time=10.0, max_temperature_C=None, progress=None):
    """Engage ``cycles`` times in a row with ``cooling_time`` between, or until a limit is reached.

    Parameters
    ----------
    scene : clutchocp.scene.Scene
        An engagement scene with a ``[thermal]`` part.
    cycles : int
        Largest number of engagements (>= 1).
    cooling_time : float
        Open-clutch cooling interval after each engagement run [s] (>= 0).
    max_temperature_C : float, optional
        Stop after the cycle whose peak interface temperature reaches this limit [deg C].
    progress : callable, optional
        Called with each cycle's dict as it completes (e.g. to update a progress bar).

    Returns
    -------
    CyclesResult
        ``stop_reason`` is ``"cycles"`` (all done), ``"temperature limit"`` or ``"no lock-up"``
        (an engagement that did not lock within simulation.t_end; the run stops there).

    Raises
    ------
    ModelError
        No [thermal] part, or bad counts/times.
    """
    if not scene.has("thermal"):
        raise ModelError(f"scene '{scene.name}': repeated engagements need a [thermal] part (plate temperatures)")
    if isinstance(cycles, bool) or not isinstance(cycles, (int, np.integer)) or cycles < 1:
        raise ModelError(f"cycles = {cycles!r}: must be a whole number >= 1")
    if not (np.isfinite(cooling_time) and cooling_time >= 0):
        raise ModelError(f"cooling_time = {cooling_time!r}: must be a time >= 0 [s]")
    model = EngagementModel(scene)
    part = model.thermal
    if max_temperature_C is not None and not (np.isfinite(max_temperature_C) and max_temperature_C > part.T_start):
        raise ModelError(f"max_temperature_C = {max_temperature_C!r}: must be above the initial plate temperature "
                         f"{part.T_start:g} degC")
    plates = dict.fromkeys(part.names, part.T_start)
    rows, reason = [], "cycles"
    for k in range(1, cycles + 1):
        try:
            run = simulate_engagement(scene, model=model, initial_state=plates)
        except SolverError as err:
            raise SolverError(f"repeated engagements, cycle {k} (interface at {plates['T_interface']:.1f} degC, "
                              f"core at {plates['T_core']:.1f} degC): {err}") from None
        s = run.summary
        # Cooling with the clutch open: no heat, the chain relaxes to the oil (exact linear solution).
        plates = part.cooled(s["final_plate_temperatures_C"], cooling_time)
        row = {"cycle": k, "start_interface_temperature_C": float(run.result["interface_temperature_C"][0]),
               "peak_interface_temperature_C": s["peak_interface_temperature_C"],
               "end_interface_temperature_C": plates["T_interface"],
               **{key: s[key] for key in CYCLE_KEYS[4:]}}
        rows.append(row)
        if progress is not None:
            progress(row)
        if s["engagement_time_s"] is None:
            reason = "no lock-up"
            break
        if max_temperature_C is not None and s["peak_interface_temperature_C"] >= max_temperature_C:
            reason = "temperature limit"
            break
    return CyclesResult(scene.name, rows, reason, float(cooling_time), max_temperature_C,
                        scene.value("simulation.t_end"), part.T_oil, overrides_of(scene))


def write_cycles(result, out_dir):
    """Write summary.json, cycles.csv and cycles.png of a repeated-engagement run; returns the paths."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    # An engagement that never locked has an empty cell (never NaN in a file).
    columns = {key: ["" if c[key] is None else c[key] for c in result.cycles] for key in CYCLE_KEYS}
    files = [write_summary(out / "summary.json", result.summary()), write_csv(out / "cycles.csv", columns)]
    files.append(plot_cycles(result, out / "cycles.png"))
    return files


def plot_cycles(result, path):
    """Interface temperatures per cycle (left) and the engagement time against the temperature the
    engagement started from (right, points labelled by cycle)."""
    n = [c["cycle"] for c in result.cycles]
    fig, (hot, slow) = new_figure(2)
    hot.plot(n, [c["peak_interface_temperature_C"] for c in result.cycles], "o-", color="C3", label="peak")
    hot.plot(n, [c["start_interface_temperature_C"] for c in result.cycles], "s-", color="C0",
             label="at the start of the engagement")
    hot.axhline(result.oil_temperature_C, color="C2", ls=":", label="oil")
    if result.max_temperature_C is not None:
        hot.axhline(result.max_temperature_C, color="k", ls="--", lw=0.8, label="limit")
    hot.xaxis.set_major_locator(MaxNLocator(integer=True))
    hot.set(xlabel="cycle", ylabel="interface temperature [degC]",
            title=f"each cycle: {result.run_time_s:g} s engagement run + {result.cooling_time_s:g} s open cooling")
    hot.legend(fontsize=8)
    locked = [c for c in result.cycles if c["engagement_time_s"] is not None]
    slow.plot([c["start_interface_temperature_C"] for c in locked], [c["engagement_time_s"] for c in locked],
              "o-", color="C1")
    for c in locked:
        slow.annotate(str(c["cycle"]), (c["start_interface_temperature_C"], c["engagement_time_s"]),
                      textcoords="offset points", xytext=(4, -10), fontsize=8)
    drift = result.summary()["engagement_time_drift_s"] or 0.0
    times = [c["engagement_time_s"] for c in locked]
    drift_text = (f"no drift beyond round-off ({drift:+.1e} s)" if flat_value(times) is not None or drift == 0.0
                  else f"engagement time drift {drift:+.4g} s")
    slow.set(xlabel="interface temperature at the start of the engagement [degC]",
             ylabel="engagement (lock-up) time [s]", title=f"{drift_text} (labels: cycle)")
    fig.suptitle(scene_title(result.scene, f"{len(n)} repeated engagements, stopped by: {result.stop_reason}",
                             result.overrides))
    return save_figure(fig, path)


def format_cycles(result):
    """A table for the terminal: one line per cycle."""
    lines = [f"scene {result.scene}: {len(result.cycles)} engagements, {result.cooling_time_s:g} s cooling between; "
             f"stopped by: {result.stop_reason}",
             f"  {'cycle':>5s} {'start [degC]':>13s} {'peak [degC]':>12s} {'lock-up [s]':>12s} {'J/mm^2':>8s}"]
    for c in result.cycles:
        t = "never" if c["engagement_time_s"] is None else f"{c['engagement_time_s']:.4f}"
        lines.append(f"  {c['cycle']:5d} {c['start_interface_temperature_C']:13.1f} "
                     f"{c['peak_interface_temperature_C']:12.1f} {t:>12s} {c['specific_energy_J_mm2']:8.4f}")
    return "\n".join(lines)
