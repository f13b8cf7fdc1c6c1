"""benchmarks/bench_run_overhead.py sweeps a key that one parametric model serves for all points: the
dynamic viscosity of a constant oil, the density of a Walther oil (whose dynamic viscosity is derived:
a point overriding it fails, and its datasheet viscosities cannot be parameters)."""


import pytest

from clutchocp.scene import load_scene
from clutchocp.study.tasks import Task, simulate_point
from repo_scripts import load_script


def _bench():
    return load_script("benchmarks/bench_run_overhead.py")


@pytest.mark.parametrize("scene, key", [("zhang2021", "oil.viscosity"),
                                        ("default_driveline_thermal", "oil.density")])
def test_swept_key_is_served_by_one_model_for_all_points(scene, key):
    swept = _bench().swept_key(load_scene(scene))
    assert swept == key
    nominal = load_scene(scene).value(swept)
    task = Task(scene, "simulate", options={"native": False})
    rows = [simulate_point(task, {swept: factor * nominal})[0] for factor in (0.98, 1.02)]
    assert all(row["status"] == "ok" for row in rows), rows
    assert rows[1]["model_reused"]
