"""Every kind of user mistake in a scene gives one clean line naming the field, and exit code 2."""

import copy
import subprocess
import sys
import tomllib

import pytest

from clutchocp import errors
from clutchocp.cli import main
from clutchocp.scene import Scene, builtin_scene_dir


def raw_scene(name):
    return tomllib.loads((builtin_scene_dir() / f"{name}.toml").read_text())


def edit(name, change):
    raw = copy.deepcopy(raw_scene(name))
    change(raw)
    return raw


def set_(part, key, value):
    return lambda raw: raw.setdefault(part, {}).__setitem__(key, value)


def drop(part, key=None):
    return lambda raw: raw[part].pop(key) if key else raw.pop(part)


# (scene, edit, expected error class, text the one-line message must contain)
MISTAKES = {
    "unknown key": ("zhang2021", set_("oil", "viscosty", 0.1), errors.UnknownKeyError, "did you mean 'viscosity'"),
    "unknown part": ("zhang2021", lambda r: r.__setitem__("pistn", {"mass": 1}), errors.UnknownKeyError, "did you mean 'piston'"),
    "key of another variant": ("zhang2021", set_("contact", "fit", "exact"), errors.UnknownKeyError, "contact.fit"),
    "missing parameter": ("zhang2021", drop("oil", "viscosity"), errors.MissingParameterError, "oil.viscosity"),
    "missing part": ("zhang2021", drop("actuation"), errors.MissingParameterError, "[actuation]"),
    "missing scene table": ("zhang2021", drop("scene"), errors.MissingParameterError, "[scene]"),
    "missing source": ("zhang2021", drop("scene", "source"), errors.MissingParameterError, "scene.source"),
    "wrong type, text for number": ("zhang2021", set_("plates", "n_interfaces", "four"), errors.ParameterTypeError, "plates.n_interfaces"),
    "wrong type, float for integer": ("zhang2021", set_("plates", "n_interfaces", 2.5), errors.ParameterTypeError, "plates.n_interfaces"),
    "wrong type, list for number": ("zhang2021", set_("oil", "viscosity", [0.1]), errors.ParameterTypeError, "oil.viscosity"),
    "wrong type, number for bool": ("zhang2021", set_("film", "centrifugal", 1), errors.ParameterTypeError, "film.centrifugal"),
    "wrong type, part not a table": ("zhang2021", lambda r: r.__setitem__("oil", 0.1), errors.ParameterTypeError, "[oil]"),
    "negative radius": ("zhang2021", set_("plates", "r_inner", "-0.064 m"), errors.PhysicalRangeError, "plates.r_inner"),
    "inner radius >= outer": ("zhang2021", set_("plates", "r_inner", "0.09 m"), errors.PhysicalRangeError, "plates.r_inner"),
    "zero viscosity": ("zhang2021", set_("oil", "viscosity", 0), errors.PhysicalRangeError, "oil.viscosity"),
    "negative viscosity": ("zhang2021", set_("oil", "viscosity", "-0.05 Pa s"), errors.PhysicalRangeError, "oil.viscosity"),
    "negative roughness": ("bao2020", set_("roughness", "sigma", "-1 um"), errors.PhysicalRangeError, "roughness.sigma"),
    "zero roughness with contact": ("bao2020", set_("roughness", "sigma", 0), errors.PhysicalRangeError, "roughness.sigma"),
    "sigma twice": ("bao2020", set_("roughness", "sigma_1", "1 um"), errors.SceneError, "roughness.sigma"),
    "not finite": ("zhang2021", set_("oil", "density", float("nan")), errors.PhysicalRangeError, "oil.density"),
    "friction coefficient out of range": ("zhang2021", set_("friction", "mu", 3.0), errors.PhysicalRangeError, "friction.mu"),
    "fraction out of range": ("zhang2021", set_("plates", "land_fraction", 1.5), errors.PhysicalRangeError, "plates.land_fraction"),
    "unknown part variant": ("zhang2021", set_("contact", "model", "hertz"), errors.UnknownVariantError, "contact.model"),
    "unknown choice": ("zhang2021", set_("driveline", "input", "engine"), errors.UnknownVariantError, "driveline.input"),
    "unknown scene kind": ("zhang2021", set_("scene", "kind", "dynamic"), errors.UnknownVariantError, "scene.kind"),
    "unit that does not parse": ("zhang2021", set_("plates", "r_inner", "64 mmm"), errors.UnitError, "plates.r_inner"),
    "unit of the wrong dimension": ("zhang2021", set_("oil", "viscosity", "0.07 Pa"), errors.UnitError, "oil.viscosity"),
    "number without a unit shape": ("zhang2021", set_("oil", "viscosity", "thick"), errors.UnitError, "oil.viscosity"),
    "masses do not match films": ("bao2020", set_("pack", "plate_masses", ["0.3 kg"]), errors.SceneError, "pack.plate_masses"),
    "negative plate mass": ("bao2020", set_("pack", "plate_masses", ["0.3 kg", "-1 kg"]), errors.PhysicalRangeError, "pack.plate_masses[1]"),
    "spring-applied without spring": ("bao2020", set_("piston", "spring_stiffness", 0), errors.PhysicalRangeError, "piston.spring_stiffness"),
    "pressure above its limit": ("default_driveline", set_("actuation", "pressure", "2 MPa"), errors.PhysicalRangeError, "actuation.pressure"),
    "inertia input without inertia": ("zhang2021", drop("driveline", "input_inertia"), errors.MissingParameterError, "driveline.input_inertia"),
    "table file missing": ("zhang2021", lambda r: r.__setitem__("actuation", {"model": "table", "pressure": 1e5, "file": "nope.csv"}), errors.SceneNotFoundError, "actuation.file"),
    "friction table lengths differ": ("chen2021", set_("friction", "mu", [0.07, 0.07]), errors.SceneError, "friction.mu"),
    "friction table not increasing": ("chen2021", set_("friction", "pressure", [5, 4, 3, 2, 1]), errors.PhysicalRangeError, "friction.pressure"),
    "analysis part missing": ("chen2021", drop("spline"), errors.MissingParameterError, "[spline]"),
    "fractal dimension out of range": ("cui2019", set_("contact", "fractal_dimension", 2.5), errors.PhysicalRangeError, "contact.fractal_dimension"),
    "angle out of range": ("chen2021", set_("spline", "pressure_angle_friction", "95 deg"), errors.PhysicalRangeError, "spline.pressure_angle_friction"),
}


@pytest.mark.parametrize("kind", sorted(MISTAKES))
def test_each_kind_of_mistake_raises_its_error_naming_the_field(kind):
    scene, change, error, text = MISTAKES[kind]
    with pytest.raises(error) as info:
        Scene(edit(scene, change))
    message = str(info.value)
    assert text in message
    assert "\n" not in message
    assert isinstance(info.value, ValueError)  # the hierarchy subclasses built-ins


def test_there_are_at_least_25_kinds():
    assert len(MISTAKES) >= 25


def _write(tmp_path, raw_text):
    path = tmp_path / "scene.toml"
    path.write_text(raw_text)
    return str(path)


def _zhang_text_with(old, new):
    text = (builtin_scene_dir() / "zhang2021.toml").read_text()
    assert old in text
    return text.replace(old, new)


@pytest.mark.parametrize(
    "old, new, field",
    [
        ('r_inner = "0.064 m"', 'r_inner = "0.1 m"', "plates.r_inner"),
        ('viscosity = "0.0681 Pa s"', 'viscosity = "0.0681 Pa s"\nviscosty = 1', "oil.viscosty"),
        ('viscosity = "0.0681 Pa s"', 'viscosity = "-0.0681 Pa s"', "oil.viscosity"),
    ],
)
def test_cli_exits_2_with_one_line_and_no_traceback(tmp_path, old, new, field):
    path = _write(tmp_path, _zhang_text_with(old, new))
    proc = subprocess.run(
        [sys.executable, "-m", "clutchocp.cli", "scenes", path], capture_output=True, text=True, timeout=120
    )
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and field in lines[0]
    assert "Traceback" not in proc.stderr + proc.stdout


def test_broken_toml_is_a_clean_error(tmp_path, capsys):
    path = _write(tmp_path, "[scene\nname = 1")
    assert main(["scenes", path]) == 2
    assert "not valid TOML" in capsys.readouterr().err


def test_cli_override_with_unknown_part_is_clean():
    from clutchocp.scene import load_scene

    with pytest.raises(errors.UnknownKeyError, match="did you mean 'oil'"):
        load_scene("zhang2021", overrides={"oill.viscosity": 0.1})
