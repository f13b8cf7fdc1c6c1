"""What a worker does with one unit of work: plain data in (scene, overrides, options), rows out.

A unit is ``(task, points)``: ``task`` a :class:`Task` (scene name or path, ``"simulate"`` or
``"optimize"``, options), ``points`` a list of override dictionaries. Nothing CasADi crosses a
process boundary; each worker loads the scene once and builds the models of its points itself.
An optimize unit is a chain of neighbouring grid points solved in order, each starting from the
optimum of the previous one (``EngagementOCP.solve(guess=...)``).

Every point gives a row ``{field: value, ..., "point_id", "status", "reason", <numbers>}``; a point
that fails gives ``status = "failed"`` and the one-line reason, and the unit goes on.
"""

import functools
import time
from dataclasses import asdict, dataclass, field

from ..errors import ClutchocpError
from .points import point_id

TASKS = ("simulate", "optimize")

# Result columns per task, with units in the names (the CSV header and summary.json use them).
SIMULATE_COLUMNS = ("engagement_time_s", "lockup_torque_jump_Nm", "peak_torque_Nm", "peak_jerk_rad_s3",
                    "dissipated_energy_J", "energy_balance_rel_error", "torque_response_time_s",
                    "pressure_response_time_s", "final_mode", "n_steps", "run_time_s")
OPTIMIZE_COLUMNS = ("engagement_time_s", "t_max_s", "jerk_integral", "dissipated_energy_J", "lockup_torque_jump_Nm",
                    "peak_jerk_rad_s3", "peak_torque_Nm", "objective", "ipopt_iterations", "solve_time_s",
                    "build_time_s", "warm_start", "idas_lock_time_rel_diff", "run_time_s")
STATUS_COLUMNS = ("point_id", "status", "reason")


@dataclass(frozen=True)
class Task:
    """What to do at every point of a study (plain data: picklable, cheap to send).

    Parameters
    ----------
    scene : str
        Built-in scene name or path of a scene file.
    kind : {"simulate", "optimize"}
    base_overrides : dict
        ``{"part.key": value}`` applied to the scene before each point's own overrides (``--set``).
    options : dict
        simulate: ``output_points`` (int, output grid of a run; None: the scene's), ``rtol``,
        ``atol``, ``native`` (bool). optimize: ``intervals``, ``degree``, ``t_max`` [s] (None: each
        point's own baseline lock time), ``weights``, ``warm_start`` (bool, default True),
        ``verify`` (bool, default True: replay each optimum with IDAS).
    """

    scene: str
    kind: str = "simulate"
    base_overrides: dict = field(default_factory=dict)
    options: dict = field(default_factory=dict)

    def columns(self):
        """Result columns of this task (without the parameter and status columns)."""
        return SIMULATE_COLUMNS if self.kind == "simulate" else OPTIMIZE_COLUMNS

    def as_dict(self):
        return asdict(self)


@functools.lru_cache(maxsize=8)
def _base_scene(scene, overrides_items):
    from ..scene import load_scene
    return load_scene(scene, overrides=dict(overrides_items) or None)


def point_scene(task, point):
    """The scene of one point: the task's scene with its base overrides, then the point's."""
    base = _base_scene(task.scene, tuple(sorted(task.base_overrides.items(), key=lambda kv: kv[0])))
    return base.with_overrides(point) if point else base


def reason_of(exc):
    """One line saying why a point failed (the message of a clutchocp error; else the type too)."""
    text = str(exc).replace("\n", " ").strip()
    return text if isinstance(exc, ClutchocpError) else f"{type(exc).__name__}: {text}"


def _row(point, status, reason, numbers):
    return {**point, "point_id": point_id(point), "status": status, "reason": reason, **numbers}


def run_unit(task, points):
    """Run one unit of work in this process.

    Returns
    -------
    list of (dict, dict or None)
        Per point its row and, for a solved optimize point, its command curve
        ``{"time_s": [...], "pressure_Pa": [...]}`` (else None).
    """
    if task.kind == "simulate":
        return [simulate_point(task, point) for point in points]
    return optimize_chain(task, points)


def simulate_point(task, point):
    """Simulate one point; returns ``(row, None)``."""
    from ..engagement.run import simulate_engagement

    opts = task.options
    start = time.perf_counter()
    try:
        scene = point_scene(task, point)
        run = simulate_engagement(scene, rtol=opts.get("rtol"), atol=opts.get("atol"),
                                  output_points=opts.get("output_points"), native=bool(opts.get("native", False)))
    except Exception as exc:                  # a failed point is recorded, never stops the sweep
        return _row(point, "failed", reason_of(exc), {"run_time_s": time.perf_counter() - start}), None
    s = run.summary
    numbers = {key: s[key] for key in SIMULATE_COLUMNS if key in s}
    numbers["n_steps"] = int(s["solver"]["statistics"]["n_steps"])
    numbers["run_time_s"] = time.perf_counter() - start
    return _row(point, "ok", "", numbers), None


def optimize_chain(task, points):
    """Solve the optimal engagement at consecutive points, each warm-started from the previous optimum."""
    previous = None
    out = []
    for point in points:
        row, curve, optimum = optimize_point(task, point, guess=previous)
        out.append((row, curve))
        if task.options.get("warm_start", True):
            previous = optimum if optimum is not None else previous
    return out


def optimize_point(task, point, guess=None):
    """Solve one point; returns ``(row, curve, optimum)`` (``curve`` and ``optimum`` None on failure)."""
    from ..optimal.problem import EngagementOCP
    from ..optimal.verify import verify

    opts = task.options
    start = time.perf_counter()
    try:
        scene = point_scene(task, point)
        ocp = EngagementOCP(scene, intervals=opts.get("intervals", 40), degree=opts.get("degree", 3))
        built = time.perf_counter()
        optimum = ocp.solve(t_max=opts.get("t_max"), weights=opts.get("weights"), guess=guess)
        numbers = {key: optimum.terms[key] for key in ("engagement_time_s", "jerk_integral", "dissipated_energy_J",
                                                       "lockup_torque_jump_Nm", "peak_jerk_rad_s3", "peak_torque_Nm",
                                                       "objective")}
        numbers.update(t_max_s=float(optimum.t_max), ipopt_iterations=int(optimum.stats["iterations"]),
                       solve_time_s=float(optimum.stats["wall_time_s"]), build_time_s=built - start,
                       warm_start=bool(optimum.stats["warm_start"]))
        if opts.get("verify", True):
            check, _ = verify(ocp.exact if ocp.polish else ocp, optimum)
            numbers["idas_lock_time_rel_diff"] = check["lock_time_rel_diff"]
    except Exception as exc:                  # a failed point is recorded, never stops the sweep
        return _row(point, "failed", reason_of(exc), {"run_time_s": time.perf_counter() - start}), None, None
    numbers["run_time_s"] = time.perf_counter() - start
    curve = {"time_s": [float(t) for t in optimum.command_times], "pressure_Pa": [float(p) for p in optimum.command]}
    return _row(point, "ok", "", numbers), curve, optimum
