"""clutchocp: wet-clutch and hydro-viscous-drive simulation, optimal engagement pressure and control.

Python API first; the ``clutchocp`` command is a thin layer over it::

    import clutchocp
    run = clutchocp.simulate("zhang2021", overrides={"oil.viscosity": "40 mPa s"})
    run                      # EngagementResult(scene='zhang2021', lock-up ... s, ...)
    run.summary["engagement_time_s"]
    run.table()["total_torque_Nm"]
    run.plot("zhang.png")
    best = clutchocp.optimize(t_max=0.25, intervals=60)
    best.table(), best.plot()
"""

from . import errors
from .scene import Scene, default_scene, list_scenes, load_scene

__version__ = "0.1.0"
__all__ = ["Scene", "default_scene", "errors", "list_scenes", "load_scene", "optimize", "simulate", "__version__"]


def _scene(scene, overrides):
    if isinstance(scene, Scene):
        return scene.with_overrides(overrides) if overrides else scene
    return load_scene(scene, overrides=overrides)


def simulate(scene, *, overrides=None, rtol=None, atol=None, t_end=None, output_points=None, method="idas"):
    """Simulate an engagement scene through impact, slip and lock-up (IDAS).

    Parameters
    ----------
    scene : Scene, str or pathlib.Path
        A scene, a built-in scene name (``clutchocp.list_scenes()``) or a TOML file.
    overrides : dict, optional
        ``{"part.key": value}`` replacing scene values, e.g. ``{"oil.viscosity": "40 mPa s"}``.
    rtol, atol : float, optional
        Integration tolerances, 1e-14 ... 1e-2 (default: the scene's ``simulation.rtol``/``atol``).
    t_end : float, optional
        End time [s] (default: ``simulation.t_end``).
    output_points : int, optional
        Output times, 2 ... 200 000 (default: ``simulation.output_points``).
    method : str
        ``"idas"`` or a scipy method (``"Radau"``, ``"BDF"``, ``"LSODA"``) as a cross-check.

    Returns
    -------
    clutchocp.engagement.run.EngagementResult
        ``summary`` (the numbers of summary.json), ``table()`` (time series with units),
        ``plot(path=None)`` (overview figure).
    """
    # imported here: at the top every clutchocp import (the CLI's too) loads SciPy's integrators
    from .engagement.run import simulate_engagement
    return simulate_engagement(_scene(scene, overrides), rtol=rtol, atol=atol, t_end=t_end,
                               output_points=output_points, method=method)


def optimize(scene=None, *, overrides=None, t_max=None, weights=None, intervals=100, degree=3, progress=False):
    """Optimal engagement pressure (direct collocation + IPOPT), verified with IDAS, beside the baselines.

    Parameters
    ----------
    scene : Scene, str or pathlib.Path, optional
        Engagement scene (default: the default scene).
    overrides : dict, optional
        ``{"part.key": value}`` replacing scene values.
    t_max : float, optional
        Largest engagement time [s] (default: the scene's ``actuation.engagement_time_limit``, else the
        lock-up time of the scene's own profile).
    weights : dict, optional
        Objective weights ``jerk``, ``energy``, ``time``, ``jump``, ``smooth`` (see the README;
        defaults jerk = 1, smooth = 0.1 x jerk, the others 0).
    intervals, degree : int
        Collocation intervals (2 ... 2000) and points per interval (1 ... 9).
    progress : bool
        Print the stages.

    Returns
    -------
    clutchocp.optimal.outcome.OptimizationResult
        ``summary``, ``optimum``, ``replay``; ``table()`` (pressure profile), ``plot(path=None)``.
    """
    # imported here: as simulate (the optimiser's modules only when asked for)
    from .optimal.report import optimize_scene
    scene = default_scene() if scene is None and not overrides else _scene(scene or default_scene(), overrides)
    return optimize_scene(scene, t_max=t_max, weights=weights, intervals=intervals, degree=degree, progress=progress)
