"""Plausible values per scene key (schema.Span): refused with the unit meant, warned, or passed."""

import json
import warnings

import pytest

from clutchocp.cli import main
from clutchocp.errors import PhysicalRangeError, PlausibilityWarning
from clutchocp.scene import list_scenes, load_scene
from clutchocp.scene.schema import PARTS, Span


def spans():
    """Every (part.key, Field) of the schema with a span."""
    for part_name, part in PARTS.items():
        fields = dict(part.fields)
        for variant in part.variants.values():
            fields.update(variant)
        for key, spec in fields.items():
            if spec.span is not None:
                yield f"{part_name}.{key}", spec


# The review's examples: (override, refused?, the words of the one line)
EXAMPLES = [
    ({"plates.r_outer": 85}, True,
     "plates.r_outer = 85 m is not a clutch radius (typical 0.02 to 1.5 m, refused outside 0.001 to 5 m); "
     "did you mean 85 mm or 85 cm?"),
    ({"oil.viscosity": 40}, True,
     "oil.viscosity = 40 Pa s is not an oil viscosity (typical 0.0005 to 1 Pa s, refused outside 5e-05 to 20 Pa s); "
     "did you mean 40 mPa s?"),
    ({"roughness.sigma_1": 8}, True, "roughness.sigma_1 = 8 m is not an RMS surface roughness"),
    ({"roughness.sigma_1": 8}, True, "did you mean 8 um?"),
    ({"driveline.input_speed": 1e6}, True, "driveline.input_speed = 1e+06 rad/s is not a clutch shaft speed"),
    ({"actuation.pressure": 8}, False,
     "actuation.pressure = 8 Pa is unusual for a clutch oil pressure (typical 1000 to 1e+08 Pa); "
     "did you mean 8 bar or 8 MPa?"),
    ({"driveline.output_inertia": 1e6}, False,
     "driveline.output_inertia = 1e+06 kg m^2 is unusual for a driveline inertia (typical 0.0001 to 100000 kg m^2); "
     "did you mean 1e+06 kg cm^2?"),
    ({"driveline.input_speed": 3000}, False, "did you mean 3000 rpm?"),
    ({"thermal.oil_temperature_C": 313}, False, "did you mean 313 K"),
    ({"plates.r_outer": "85 m"}, True, "plates.r_outer = 85 m is not a clutch radius"),
]


@pytest.mark.parametrize("override, refused, words", EXAMPLES, ids=[f"{next(iter(e[0]))}={next(iter(e[0].values()))}"
                                                                      for e in EXAMPLES])
def test_unit_slips_are_refused_or_warned_with_the_unit_meant(override, refused, words):
    scene = load_scene("default_driveline")
    if refused:
        with pytest.raises(PhysicalRangeError) as info:
            scene.with_overrides(override)
        assert words in str(info.value)
        assert "\n" not in str(info.value)
    else:
        assert any(words in w for w in scene.with_overrides(override).warnings)


def test_values_a_clutch_has_pass_silently():
    scene = load_scene("default_driveline").with_overrides(
        {"plates.r_outer": "85 mm", "oil.viscosity": "40 mPa s", "actuation.pressure": "8 bar",
         "driveline.input_speed": "3000 rpm", "roughness.sigma_1": "8 um", "driveline.output_inertia": "1 kg m^2"})
    assert scene.warnings == ()


def test_zero_means_absent_where_the_key_says_so():
    """A released pressure, no free travel: 0 is not a unit slip (Span.zero)."""
    scene = load_scene("default_driveline").with_overrides({"actuation.initial_pressure": 0, "load.torque": 0})
    assert scene.warnings == ()
    with pytest.raises(PhysicalRangeError, match="roughness.asperity_radius"):
        load_scene("default_driveline").with_overrides({"roughness.asperity_radius": 1.0})


def test_every_span_is_sound():
    """Typical inside the limits, both ordered, a phrase for messages; the scene-key reference reads them."""
    found = list(spans())
    assert len(found) >= 60
    for name, spec in found:
        span = spec.span
        assert isinstance(span, Span)
        (lo, hi), (low, high) = span.typical, span.limit
        assert low <= lo < hi <= high, name
        assert span.what.split()[0] in ("a", "an"), name
        assert span.describe(spec.dim).startswith("typical "), name
    radius = PARTS["plates"].fields["r_outer"].span
    assert radius.describe("m") == "typical 0.02 to 1.5 m; refused outside 0.001 to 5 m"


def test_no_shipped_scene_is_refused_or_warned():
    """The scene re-check: every built-in scene inside the typical spans of all its keys."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlausibilityWarning)
        scenes = list_scenes()
    assert len(scenes) == 11
    assert all(scene.warnings == () for scene in scenes)


def test_load_scene_issues_the_warnings():
    with pytest.warns(PlausibilityWarning, match="default_driveline: actuation.pressure = 8 Pa is unusual"):
        load_scene("default_driveline", {"actuation.pressure": 8})


def test_cli_prints_a_warning_and_keeps_it_in_the_summary(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["simulate", "zhang2021", "--set", "driveline.input_speed=3000", "--set", "simulation.t_end=0.05",
                 "--out", str(out)]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["clutchocp simulate: warning: zhang2021: driveline.input_speed = 3000 rad/s is unusual for a "
                   "clutch shaft speed (typical 1 to 2000 rad/s); did you mean 3000 rpm?"]
    summary = json.loads((out / "summary.json").read_text())
    assert summary["warnings"] == ["driveline.input_speed = 3000 rad/s is unusual for a clutch shaft speed "
                                   "(typical 1 to 2000 rad/s); did you mean 3000 rpm?"]


def test_cli_refuses_a_unit_slip_in_one_line(tmp_path, capsys):
    assert main(["simulate", "default_driveline", "--set", "plates.r_outer=85", "--out", str(tmp_path / "r")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "plates.r_outer = 85 m is not a clutch radius" in err[0] and "85 mm" in err[0]
    assert not (tmp_path / "r").exists()
