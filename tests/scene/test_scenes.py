"""Built-in scenes: they load by name, trace their source, and hold the papers' values in SI."""

import math

import pytest

from clutchocp.scene import builtin_scene_dir, default_scene, list_scenes, load_scene


def test_at_least_six_builtin_scenes_one_per_seed_plus_default():
    names = {s.name for s in list_scenes()}
    assert {"bao2020", "chen2021", "cui2019", "zhang2021", "liao2021", "default_driveline"} <= names
    assert default_scene().name == "default_driveline"


def test_every_scene_names_its_source_and_file_name():
    for scene in list_scenes():
        assert scene.source.strip()
        assert scene.path.stem == scene.name


def test_default_scene_carries_torque_after_lockup():
    scene = default_scene()
    assert scene.value("driveline.input") == "inertia"
    assert scene.value("driveline.output") == "inertia"
    assert scene.variant("load") == "constant" and scene.value("load.torque") > 0


@pytest.mark.parametrize(
    "scene, key, expected",
    [
        ("bao2020", "driveline.input_speed", 6000 * 2 * math.pi / 60),  # Bao Table 1, 6000 r/min
        ("bao2020", "roughness.sigma", 8.4e-6),
        ("bao2020", "pack.initial_gap", 2e-4),
        ("zhang2021", "oil.viscosity", 0.0681),  # Zhang Table 1
        ("zhang2021", "plates.lining_permeability", 4e-12),
        ("cui2019", "roughness.sigma", math.hypot(5.975e-6, 2.85e-6)),  # Cui Table 2, combined
        ("cui2019", "plates.r_outer", 0.0615),
        ("chen2021", "spline.pressure_angle_separator", math.radians(27)),  # Chen Table 1
        ("liao2021", "groove.depth", 3e-4),
    ],
)
def test_seed_values_arrive_in_si(scene, key, expected):
    assert load_scene(scene).value(key) == pytest.approx(expected, rel=1e-12)


def test_scene_loads_by_path_as_well_as_by_name():
    path = builtin_scene_dir() / "zhang2021.toml"
    assert load_scene(path).value("plates.r_inner") == load_scene("zhang2021").value("plates.r_inner")


def test_absent_part_is_reported_absent():
    zhang = load_scene("zhang2021")
    assert not zhang.has("piston") and not zhang.has("spline")
    assert load_scene("bao2020").has("piston")
    assert not zhang.has("load")  # model = "none" counts as absent


def test_overrides_replace_values_and_revalidate():
    scene = load_scene("zhang2021", overrides={"oil.viscosity": "0.1 Pa s"})
    assert scene.value("oil.viscosity") == pytest.approx(0.1)
    assert load_scene("zhang2021").value("oil.viscosity") == pytest.approx(0.0681)
