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
import multiprocessing
import threading
import time
from dataclasses import asdict, dataclass, field

from ..engagement.model import EngagementModel
from ..engagement.run import simulate_engagement
from ..errors import ClutchocpError, ModelError, SolverError
from ..interrupt import ignore_sigint, sigint_held
from ..optimal.problem import EngagementOCP
from ..optimal.verify import verify
from ..scene import load_scene
from ..simulation.native import compiler
from . import parametric, parametric_ocp
from .points import point_id

TASKS = ("simulate", "optimize")

# Result columns per task, with units in the names (the CSV header and summary.json use them).
SIMULATE_RESULTS = ("engagement_time_s", "lockup_torque_jump_Nm", "peak_torque_Nm", "peak_jerk_rad_s3",
                    "dissipated_energy_J", "energy_balance_rel_error", "torque_response_time_s",
                    "pressure_response_time_s", "final_mode")
SIMULATE_COLUMNS = SIMULATE_RESULTS + ("n_steps", "model_reused", "native_code", "build_time_s", "integration_time_s",
                                       "run_time_s")
OPTIMIZE_COLUMNS = ("engagement_time_s", "t_max_s", "jerk_integral", "dissipated_energy_J", "lockup_torque_jump_Nm",
                    "peak_jerk_rad_s3", "peak_torque_Nm", "objective", "ipopt_iterations", "solve_time_s",
                    "build_time_s", "warm_start", "problem_reused", "idas_lock_time_rel_diff", "run_time_s")
STATUS_COLUMNS = ("point_id", "status", "reason")
# Options of each task with their defaults (see Task).
DEFAULT_OPTIONS = {
    "simulate": {"output_points": None, "rtol": None, "atol": None, "native": "auto", "reuse_model": True},
    "optimize": {"intervals": 40, "degree": 3, "t_max": None, "weights": None, "warm_start": True, "verify": True,
                 "reuse_problem": True},
}


def task_options(kind, options):
    """``options`` completed with the defaults of task ``kind`` (ModelError for an unknown option)."""
    defaults = DEFAULT_OPTIONS[kind]
    unknown = sorted(set(options or {}) - set(defaults))
    if unknown:
        raise ModelError(f"{kind} sweep: unknown option(s) {', '.join(unknown)} (allowed: {', '.join(defaults)})")
    return {**defaults, **(options or {})}


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
        ``atol``, ``reuse_model`` (bool, default True: one model per worker with the swept fields
        as parameters, :mod:`clutchocp.study.parametric`, where the model allows it; False: a new
        model per point, bit for bit the single-run results), ``native`` (``"auto"``, default:
        compiled C for a reused model where a C compiler exists; True: for every model; False: never). optimize: ``intervals``, ``degree``, ``t_max`` [s] (None: the scene's
        ``actuation.engagement_time_limit``, else each point's own baseline lock time), ``weights``, ``warm_start`` (bool, default True),
        ``verify`` (bool, default True: replay each optimum with IDAS), ``reuse_problem`` (bool,
        default True: one collocation problem per worker with the swept fields as parameters,
        :mod:`clutchocp.study.parametric_ocp`, where the problem allows it; False: a new problem
        per point). Missing options take the
        defaults of :data:`DEFAULT_OPTIONS`.
    """

    scene: str
    kind: str = "simulate"
    base_overrides: dict = field(default_factory=dict)
    options: dict = field(default_factory=dict)

    def __post_init__(self):
        if self.kind not in TASKS:
            raise ModelError(f"--task {self.kind!r}: allowed values are {', '.join(TASKS)}")
        object.__setattr__(self, "options", task_options(self.kind, self.options))

    def columns(self):
        """Result columns of this task (without the parameter and status columns)."""
        return SIMULATE_COLUMNS if self.kind == "simulate" else OPTIMIZE_COLUMNS

    def as_dict(self):
        return asdict(self)


@functools.lru_cache(maxsize=8)
def _base_scene(scene, overrides_items):
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


# One unit at a time in a process. A worker's reused models and problems, their integrators and the
# numpy form's maps are called through buffers bound once (CasADi's buffer interface), which two
# threads must not use at once: a Dask worker started with several threads (``dask worker
# --nthreads 4``) gave 15 of 36 zhang2021 rows different from the serial sweep's, one locked
# where it slips. The units of such a worker's threads wait for each other here; CasADi's calls
# hold the GIL, so threads would not have run them side by side anyway (two 0.45 s evaluations of
# a mapped function: 0.92 s one after the other, 0.95 s in two threads).
_ONE_UNIT_AT_A_TIME = threading.Lock()


def run_unit(task, points):
    """Run one unit of work in this process (one unit at a time, whatever the thread).

    Returns
    -------
    list of (dict, dict or None)
        Per point its row and, for a solved optimize point, its command curve
        ``{"time_s": [...], "pressure_Pa": [...]}`` (else None).
    """
    with _ONE_UNIT_AT_A_TIME:
        if task.kind == "simulate":
            return [simulate_point(task, point) for point in points]
        return optimize_chain(task, points)


def warm_up(task, units):
    """Prepare this process to hand its state to forked workers: run the first point of a simulate
    study here (it builds the reused model, checks it and compiles its code, see
    :func:`simulate_point`); an optimize study is left as it is.

    Returns
    -------
    done : list of (dict, dict or None)
        The results of the points run here.
    units : list of list of dict
        The units still to run.
    """
    if task.kind != "simulate" or not units:
        return [], units
    first, rest = units[0][:1], [units[0][1:]] + list(units[1:])
    _reference_beside(task, first[0])
    try:
        done = run_unit(task, first)
    finally:
        _drop_references()
    return done, [u for u in rest if u]


def _run_settings(task):
    """The integration settings of a simulate task's runs."""
    opts = task.options
    return {"rtol": opts["rtol"], "atol": opts["atol"], "output_points": opts["output_points"]}


def simulate_point(task, point):
    """Simulate one point; returns ``(row, None)``."""
    opts = task.options
    has_compiler = compiler() is not None                       # no compiler: the VM, silently
    settings = _run_settings(task)
    start = time.perf_counter()
    try:
        scene = point_scene(task, point)
        native = has_compiler and opts["native"] in (True, "auto")
        run = _simulate_reusing(task, point, scene, dict(settings, native=native)) if opts["reuse_model"] else None
        reused = run is not None
        built = start
        if run is None:
            native = has_compiler and opts["native"] is True
            model = EngagementModel(scene)
            built = time.perf_counter()
            run = simulate_engagement(scene, model=model, native=native, **settings)
    except Exception as exc:                  # a failed point is recorded, never stops the sweep
        return _row(point, "failed", reason_of(exc), {"run_time_s": time.perf_counter() - start}), None
    s = run.summary
    numbers = {key: s[key] for key in SIMULATE_RESULTS}
    numbers.update(n_steps=int(s["solver"]["statistics"]["n_steps"]), model_reused=reused, native_code=native,
                   build_time_s=built - start,
                   integration_time_s=float(s["solver"]["statistics"]["integration_time_s"]),
                   run_time_s=time.perf_counter() - start)
    return _row(point, "ok", "", numbers), None


_PARAMETRIC = {}        # this worker's parametric models: key -> [ParametricModel or None, checked]
_REFERENCES = {}        # point_id -> (process, connection): a usual run computed beside the warm-up


def _parametric_key(task, point):
    """Key of the parametric model that serves ``point`` (its scene, base overrides, swept names)."""
    return (task.scene, tuple(sorted(task.base_overrides.items(), key=lambda kv: kv[0])), tuple(sorted(point)))


def _reference_numbers(task, point, settings):
    """What the usual run of ``point`` (a model of its own, CasADi's virtual machine) gives for the
    numbers a parametric run is checked against (:func:`clutchocp.study.parametric.agrees`)."""
    summary = simulate_engagement(point_scene(task, point), **dict(settings, native=False)).summary
    return {key: summary[key] for key in (*parametric.COMPARED, "final_mode")}


def _send_reference(connection, task, point, settings):
    """Body of the process that runs the usual run beside the warm-up."""
    ignore_sigint()                          # Ctrl-C is the parent's, which stops this process
    try:
        connection.send(("ok", _reference_numbers(task, point, settings)))
    except Exception:                        # the warm-up runs it again itself and meets the error there
        connection.send(("failed", None))
    finally:
        connection.close()


def _reference_beside(task, point):
    """Start the usual run of the warm-up's first point in a forked process, beside this one.

    The warm-up builds the parametric model and runs the point on it (~0.06 s for zhang2021), then
    checks it against the usual run (~0.05 s); with the usual run in a second process the two
    share the cores instead of following each other (the other core is idle while the sweep's
    first point runs). Started only where the point will be checked (a reused model not yet built
    in this process) and where processes are forked."""
    if not (task.options["reuse_model"] and all(isinstance(v, float) for v in point.values())) \
            or _parametric_key(task, point) in _PARAMETRIC or "fork" not in multiprocessing.get_all_start_methods():
        return
    context = multiprocessing.get_context("fork")
    receive, send = context.Pipe(duplex=False)
    process = context.Process(target=_send_reference, args=(send, task, point, _run_settings(task)), daemon=True)
    with sigint_held():                      # held until the child ignores it
        process.start()
    send.close()
    _REFERENCES[point_id(point)] = (process, receive)


def _reference(task, point, settings):
    """The usual run's numbers of ``point``: from the process started beside the warm-up, else run here."""
    pending = _REFERENCES.pop(point_id(point), None)
    if pending is not None:
        process, connection = pending
        try:
            status, numbers = connection.recv()
        except EOFError:                     # the process died
            status = "failed"
        finally:
            connection.close()
            process.join()
        if status == "ok":
            return numbers
    return _reference_numbers(task, point, settings)


def _drop_references():
    """Stop the processes started beside the warm-up whose result was not needed."""
    while _REFERENCES:
        process, connection = _REFERENCES.popitem()[1]
        connection.close()
        process.terminate()
        process.join()


def _simulate_reusing(task, point, scene, settings):
    """The run of ``point`` on this worker's parametric model, or None where it cannot be used
    (a choice field, a field the model cannot take as a symbol, a run that fails: the usual run
    then gives the result or the failure and its reason)."""
    names = tuple(sorted(point))
    if not all(isinstance(point[n], float) for n in names):
        return None
    key = _parametric_key(task, point)
    entry = _PARAMETRIC.get(key)
    if entry is None:
        entry = _PARAMETRIC[key] = [parametric.build(point_scene(task, {}), names), False]
    if entry[0] is None:
        return None
    view, values = entry[0].for_point(scene)
    try:
        run = simulate_engagement(scene, model=view, parameters=values, **settings)
    except Exception:
        return None
    if not entry[1]:                          # the first point: check against the usual run once
        if not parametric.agrees(run.summary, _reference(task, point, settings)):
            entry[0] = None
            return None
        entry[1] = True
    return run


def optimize_chain(task, points):
    """Solve the optimal engagement at consecutive points, each warm-started from the previous optimum."""
    previous = None
    out = []
    for point in points:
        row, curve, optimum = optimize_point(task, point, guess=previous)
        out.append((row, curve))
        if task.options["warm_start"]:
            previous = optimum if optimum is not None else previous
    return out


_PROBLEMS = {}          # this worker's reused optimize problems: key -> SweepOCP or None


def clear_caches():
    """Forget this process's reused models and problems and loaded scenes (a benchmark times
    their build this way)."""
    _PARAMETRIC.clear()
    _PROBLEMS.clear()
    _base_scene.cache_clear()


def _problem(task, point, scene):
    """The problem of ``point``: this worker's reused problem set to the point, or a new one.

    Returns ``(ocp, reused)``."""
    opts = task.options
    settings = {"intervals": opts["intervals"], "degree": opts["degree"]}
    names = tuple(sorted(point))
    if opts["reuse_problem"] and names and all(isinstance(point[n], float) for n in names):
        key = (task.scene, tuple(sorted(task.base_overrides.items(), key=lambda kv: kv[0])), names)
        if key not in _PROBLEMS:                  # built at its first point: ready for it
            _PROBLEMS[key] = parametric_ocp.build(scene, names, **settings)
            if _PROBLEMS[key] is not None:
                return _PROBLEMS[key], True
        ocp = _PROBLEMS[key]
        if ocp is not None:
            try:
                ocp.set_point(scene)
                return ocp, True
            except parametric_ocp.NotReusable:
                pass
    return EngagementOCP(scene, **settings), False


def optimize_point(task, point, guess=None):
    """Solve one point; returns ``(row, curve, optimum)`` (``curve`` and ``optimum`` None on failure)."""
    opts = task.options
    start = time.perf_counter()
    try:
        scene = point_scene(task, point)
        ocp, reused = _problem(task, point, scene)
        built = time.perf_counter()
        try:
            optimum = ocp.solve(t_max=opts["t_max"], weights=opts["weights"], guess=guess)
        except SolverError:
            if guess is None:
                raise
            # a neighbour's optimum too far off to start from: solve this point cold
            optimum = ocp.solve(t_max=opts["t_max"], weights=opts["weights"])
        numbers = {key: optimum.terms[key] for key in ("engagement_time_s", "jerk_integral", "dissipated_energy_J",
                                                       "lockup_torque_jump_Nm", "peak_jerk_rad_s3", "peak_torque_Nm",
                                                       "objective")}
        numbers.update(t_max_s=float(optimum.t_max), ipopt_iterations=int(optimum.stats["iterations"]),
                       solve_time_s=float(optimum.stats["wall_time_s"]), build_time_s=built - start,
                       warm_start=bool(optimum.stats["warm_start"]), problem_reused=reused)
        if opts["verify"]:
            check, _ = verify(ocp.exact if ocp.polish else ocp, optimum)
            numbers["idas_lock_time_rel_diff"] = check["lock_time_rel_diff"]
    except Exception as exc:                  # a failed point is recorded, never stops the sweep
        return _row(point, "failed", reason_of(exc), {"run_time_s": time.perf_counter() - start}), None, None
    numbers["run_time_s"] = time.perf_counter() - start
    curve = {"time_s": [float(t) for t in optimum.command_times], "pressure_Pa": [float(p) for p in optimum.command]}
    return _row(point, "ok", "", numbers), curve, optimum
