"""The points of a study: a full grid over scene fields, or samples of the scene's uncertainty.

A point is a plain ``{"part.key": value}`` dictionary (SI floats or choice strings) ready for
``Scene.with_overrides``; :func:`point_id` names it by its content, so a resumed study matches
finished points by their parameters, not by their position.
"""

import hashlib
import json
import math

import numpy as np

from ..errors import SceneError


class StudySpecError(SceneError):
    """A sweep specification (``--grid``, ``--samples``) that cannot be used."""


def parse_grid(text, scene):
    """``"part.key=start:stop:n"`` -> ``("part.key", [n SI values])``.

    Parameters
    ----------
    text : str
        Field, then start and stop (plain SI numbers or quantities such as ``"100 N m"``) and the
        number of values (>= 1; 1 gives ``start``).
    scene : clutchocp.scene.Scene
        The scene swept: it checks the field name and converts the quantities to SI.

    Returns
    -------
    tuple (str, list of float)
    """
    name, eq, spec = text.partition("=")
    name = name.strip()
    parts = spec.split(":")
    if not eq or not name or len(parts) != 3:
        raise StudySpecError(f"--grid {text}: write part.key=start:stop:count, e.g. load.torque=50:150:5")
    try:
        count = int(parts[2])
    except ValueError:
        count = 0
    if count < 1:
        raise StudySpecError(f"--grid {text}: the count '{parts[2].strip()}' must be a whole number >= 1")
    start, stop = (_si_value(scene, name, raw.strip(), text) for raw in parts[:2])
    values = [float(v) for v in np.linspace(start, stop, count)]
    for value in {values[0], values[-1]}:
        scene.with_overrides({name: value})        # the scene's own range checks, e.g. a negative viscosity
    return name, values


def _si_value(scene, name, raw, text):
    """SI value of a grid end ``raw`` (a number or a quantity with units) for field ``name``."""
    try:
        return float(raw)
    except ValueError:
        pass
    value = scene.with_overrides({name: raw}).value(name)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise StudySpecError(f"--grid {text}: {name} is not a numeric field (got {value!r})")
    return float(value)


def grid_points(axes):
    """All combinations of the axes' values, ordered so that consecutive points are neighbours.

    Parameters
    ----------
    axes : list of (str, list)
        ``(field, values)`` per swept field; the first field varies slowest.

    Returns
    -------
    list of dict
        One ``{field: value}`` per grid point, in serpentine (boustrophedon) order: each
        faster axis runs forwards, then backwards, so two consecutive points differ in one
        field by one step (what a warm start needs).
    """
    names = [name for name, _ in axes]
    if len(set(names)) != len(names):
        raise StudySpecError(f"--grid: a field is given twice ({', '.join(names)})")
    points = [{}]
    for name, values in axes:
        grown = []
        for k, point in enumerate(points):
            run = values if k % 2 == 0 else values[::-1]
            grown.extend({**point, name: value} for value in run)
        points = grown
    return points


def chains(points, n_chains):
    """Split points (in :func:`grid_points` order) into ``n_chains`` contiguous runs of near-equal length.

    Consecutive grid points are neighbours, so every run is a path through the grid: the unit of
    work of an optimize sweep, solved in order on one worker so that each point warm-starts the
    next. Only the first point of each run starts cold (give one run per worker).
    """
    n = max(1, min(int(n_chains), len(points)))
    bounds = [round(k * len(points) / n) for k in range(n + 1)]
    return [points[a:b] for a, b in zip(bounds, bounds[1:]) if b > a]


def point_id(point):
    """A stable 12-character name of a point's parameters (same parameters, same name)."""
    text = json.dumps({k: _canonical(v) for k, v in sorted(point.items())}, sort_keys=True)
    return hashlib.sha1(text.encode()).hexdigest()[:12]


def _canonical(value):
    if isinstance(value, (float, np.floating)):
        return float(value).hex()
    if isinstance(value, (np.integer,)):
        return int(value)
    return value
