"""Monte Carlo of shift-control strategies over a scene's uncertainty, on the exact model with IDAS.

A *strategy* is plain data: a name, a label and either a piecewise-linear command (open loop: the
scene's own profile as a constant command, an optimal curve continued by its clamp ramp) or a
feedback (:class:`~clutchocp.shiftcontrol.controller.SlipFeedback` with its feedforward). A *task*
is plain data too: the scene (name or path), the override dict of one sample and the strategies;
a worker rebuilds the scene and its model from it (:func:`run_sample`), so samples run in parallel
processes (:func:`parallel_map`).

Per run the numbers are those of every engagement run (:func:`clutchocp.optimal.verify.run_numbers`):
lock-up time, torque jump at lock-up, jerk integral int jerk^2 dt over the slip phase (on 1 ms output
samples), dissipated energy to lock-up; plus whether it locks within t_max (to 1 %, the lock-time
tolerance of :mod:`clutchocp.optimal.verify`) and the jump as a percentage of the torque the locked
clutch carries.
"""

import os
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field

import numpy as np

from ..optimal.replay import CommandModel
from ..optimal.verify import LOCK_TIME_TOLERANCE, run_numbers
from ..scene.loader import Scene
from .closed_loop import run_closed_loop, run_open_loop

HISTORY_STEP = 0.002          # [s] grid of the time histories kept for the envelope figures
HISTORY_SIGNALS = ("w_rel_rad_s", "total_torque_Nm", "pressure_Pa")


@dataclass
class Strategy:
    """A shift-control strategy as plain data.

    ``times``/``values``: the command [s], [Pa] (open loop, piecewise linear, last value held);
    ``feedback``: a :class:`~clutchocp.shiftcontrol.schedule.FeedbackSchedule` (closed loop: the slip
    feedback designed for the clutch's value of the scheduled field, its feedforward inside).
    """

    name: str
    label: str
    times: np.ndarray | None = None
    values: np.ndarray | None = None
    feedback: object = None
    notes: dict = field(default_factory=dict)


def _scene(task, overrides):
    """The scene of a task (its raw tables and file path: plain data) with overrides."""
    return Scene(task["scene_raw"], task["scene_path"]).with_overrides(dict(overrides))


def run_sample(task):
    """Run every strategy on one sample scene; returns a list of rows (one per strategy).

    Parameters
    ----------
    task : dict
        ``scene_raw`` and ``scene_path`` (the nominal scene's tables and file, :class:`clutchocp.scene.Scene`),
        ``overrides`` (the sample's draw), ``index``, ``strategies`` (list of Strategy), ``t_max``
        [s], ``t_end`` [s].
    """
    scene = _scene(task, task["overrides"])
    nominal = _scene(task, {})
    model = CommandModel(scene, "linear")
    grid = np.arange(0.0, task["t_end"] + 1e-12, HISTORY_STEP)
    rows = []
    for strategy in task["strategies"]:
        if strategy.notes.get("centre_only") and task["index"] >= 0:
            continue
        draws = {}
        if strategy.feedback is not None and strategy.feedback.sensors is not None:
            schedule = strategy.feedback
            sensors = realize_sensors(schedule, scene, model, task)
            reading = sensors.viscosity(scene.value("oil.viscosity")) if schedule.field == "oil.viscosity" else None
            feedback, _ = schedule.select(scene, reading)
            run, _ = run_closed_loop(scene, feedback, task["t_end"], model=model, sensors=sensors)
            draws = dict(sensors.draws, **({"viscosity_read_Pa_s": reading} if reading is not None else {}))
        elif strategy.feedback is not None:
            feedback, design = strategy.feedback.select(scene)
            run, _ = run_closed_loop(scene, feedback, task["t_end"], nominal_scene=_scene(task, design) if design
                                     else nominal, model=model)
        else:
            run = run_open_loop(scene, strategy.times, strategy.values, task["t_end"], model=model)
        rows.append(_row(task, strategy, run, grid, draws))
    return rows


def realize_sensors(schedule, scene, model, task):
    """The sensors of one sample's transmission, drawn from the sample's own seed (the Monte Carlo seed and the
    sample's index: the same sensors whatever the order or process the samples run in). The nominal clutch
    (index -1) has nominal sensors: no unit errors, only the reading noise and the timer's quantisation."""
    eng = model.engagement
    x0 = dict(zip(eng.state_names, eng.initial_state))
    rng = np.random.default_rng([task.get("seed", 0), task["index"] + 1])
    sensors = schedule.sensors.nominal() if task["index"] < 0 else schedule.sensors
    return sensors.realize(rng, {name: x0[name] for name in ("w_in", "w_out", "p_valve") if name in x0},
                                    schedule.feedbacks[0].Ts)


def _row(task, strategy, run, grid, draws=None):
    numbers = run_numbers(run)
    t_lock = numbers["engagement_time_s"]
    row = {"sample": task["index"], "strategy": strategy.name, **{k: float(v) if not isinstance(v, str) else v
                                                                 for k, v in task["overrides"].items()}}
    row["sensor_draws"] = dict(draws or {})
    row.update(numbers)
    row["locked"] = t_lock is not None
    # an optimum ends exactly at t_max; IDAS locates its (tangential) lock-up within the verification's
    # lock-time tolerance of the collocation time, so "within t_max" allows that much
    row["locked_within_t_max"] = t_lock is not None and t_lock <= task["t_max"] * (1 + LOCK_TIME_TOLERANCE)
    jump, locked = numbers["lockup_torque_jump_Nm"], numbers["locked_torque_Nm"]
    row["jump_pct"] = 100.0 * abs(jump) / abs(locked) if t_lock is not None and locked else None
    res = run.result
    t, order = np.unique(res.t, return_index=True)
    row["history"] = {name: np.interp(grid, t, res[name][order]) for name in HISTORY_SIGNALS
                      if name != "w_rel_rad_s"}
    row["history"]["w_rel_rad_s"] = np.interp(grid, t, (res["w_in_rad_s"] - res["w_out_rad_s"])[order])
    return row


def parallel_map(function, tasks, *, workers=None, progress=None):
    """``[function(task) for task in tasks]`` on local processes, in order; ``progress(done, total)`` after each.

    ``workers`` = 1 runs in this process (no pickling). The sweeps engine of the project is meant to
    take this job over; this is the one place that would change.
    """
    workers = workers or os.cpu_count() or 1
    results = [None] * len(tasks)
    if workers == 1 or len(tasks) <= 1:
        for i, task in enumerate(tasks):
            results[i] = function(task)
            if progress:
                progress(i + 1, len(tasks))
        return results
    with ProcessPoolExecutor(max_workers=workers) as pool:
        futures = {pool.submit(function, task): i for i, task in enumerate(tasks)}
        from concurrent.futures import as_completed
        for done, future in enumerate(as_completed(futures), start=1):
            results[futures[future]] = future.result()
            if progress:
                progress(done, len(tasks))
    return results


def _quantiles(values):
    v = np.asarray([x for x in values if x is not None], float)
    if v.size == 0:
        return {"median": None, "p95": None, "worst": None}
    return {"median": float(np.median(v)), "p95": float(np.percentile(v, 95)), "worst": float(np.max(v))}


def strategy_statistics(rows):
    """Per-strategy numbers over the samples (JSON-ready; None where no sample locked).

    Returns
    -------
    dict: ``samples``, ``lock_share`` (locked at all), ``lock_within_t_max_share``, ``jump_pct``,
    ``jerk_integral``, ``engagement_time_s``, ``dissipated_energy_J`` (each: median, p95, worst =
    largest), over the samples that lock.
    """
    out = {}
    for name in dict.fromkeys(r["strategy"] for r in rows):
        mine = [r for r in rows if r["strategy"] == name]
        out[name] = {
            "samples": len(mine),
            "lock_share": sum(r["locked"] for r in mine) / len(mine),
            "lock_within_t_max_share": sum(r["locked_within_t_max"] for r in mine) / len(mine),
            "jump_pct": _quantiles(r["jump_pct"] for r in mine),
            "jerk_integral": _quantiles(r["jerk_integral"] for r in mine),
            "engagement_time_s": _quantiles(r["engagement_time_s"] for r in mine),
            "dissipated_energy_J": _quantiles(r["dissipated_energy_J"] for r in mine),
        }
    return out
