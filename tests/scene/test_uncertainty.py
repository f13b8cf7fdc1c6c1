"""The uncertainty spec of a scene: parsing, draws against their closed-form statistics, errors."""

import math
import subprocess
import sys

import numpy as np
import pytest
from scipy.stats import norm

from clutchocp import load_scene
from clutchocp.errors import SceneError
from clutchocp.scene.uncertainty import NORMAL_TRUNCATION, Uncertainty


@pytest.fixture(scope="module")
def scene():
    return load_scene("default_driveline").without_uncertainty()


def with_section(scene, section):
    raw = dict(scene.raw, uncertainty=section)
    return type(scene)(raw, scene.path)


def test_default_scene_declares_the_spread_of_its_clutches():
    u = load_scene("default_driveline").uncertainty
    assert u.names == ("friction.mu", "oil.viscosity", "load.torque")
    assert [s.width for s in u.spreads] == pytest.approx([0.012, 0.3 * 0.0681, 20.0])


def test_scene_table_nested_table_and_command_line_read_alike(scene):
    quoted = Uncertainty.from_scene(with_section(scene, {"friction.mu": "uniform 10 %", "load.torque": "normal 20 N m"}))
    nested = Uncertainty.from_scene(with_section(scene, {"friction": {"mu": "uniform 10 %"},
                                                         "load": {"torque": "normal 20 N m"}}))
    cli = Uncertainty.from_scene(scene, extra=["friction.mu=uniform 10 %", "load.torque='normal 20 N m'"])
    assert quoted.spreads == nested.spreads == cli.spreads
    assert quoted.spreads[1].width == 20.0


def test_command_line_replaces_the_scene_entry(scene):
    u = Uncertainty.from_scene(with_section(scene, {"friction.mu": "uniform 10 %"}), extra=["friction.mu=uniform 5 %"])
    assert u.spreads[0].width == pytest.approx(0.006)


def test_uniform_draws_match_the_closed_form_mean_and_variance(scene):
    u = Uncertainty.from_scene(scene, extra=["friction.mu=uniform 10 %"])
    x = np.array([d["friction.mu"] for d in u.samples(20000, seed=3)])
    half = 0.012
    assert x.min() >= 0.12 - half and x.max() <= 0.12 + half
    assert abs(x.mean() - 0.12) < 4 * half / math.sqrt(3 * x.size)
    assert x.var() == pytest.approx(half**2 / 3, rel=0.03)


def test_truncated_normal_draws_match_the_closed_form_variance(scene):
    u = Uncertainty.from_scene(scene, extra=["oil.viscosity=normal 10 %"])
    sigma = 0.00681
    x = np.array([d["oil.viscosity"] for d in u.samples(40000, seed=5)])
    beta = NORMAL_TRUNCATION
    # Variance of a normal truncated symmetrically at +- beta sigma: sigma^2 [1 - 2 beta phi(beta) / (2 Phi(beta) - 1)]
    expected = sigma**2 * (1 - 2 * beta * norm.pdf(beta) / (2 * norm.cdf(beta) - 1))
    assert np.all(np.abs(x - 0.0681) <= beta * sigma)
    assert x.var() == pytest.approx(expected, rel=0.03)


def test_list_of_values_draws_each_with_equal_weight(scene):
    u = Uncertainty.from_scene(scene, extra=['film.flow_factor=["patir_cheng", "none"]',
                                             'driveline.output_inertia=["1.8 kg m^2", "2.2 kg m^2", 2.0]'])
    draws = u.samples(9000, seed=1)
    flow = [d["film.flow_factor"] for d in draws]
    assert set(flow) == {"patir_cheng", "none"}
    assert flow.count("none") == pytest.approx(4500, abs=4 * math.sqrt(9000 * 0.25))
    inertia = [d["driveline.output_inertia"] for d in draws]
    assert set(inertia) == {1.8, 2.2, 2.0}


def test_samples_are_reproducible_with_their_seed(scene):
    u = load_scene("default_driveline").uncertainty
    assert u.samples(5, seed=7) == u.samples(5, seed=7)
    assert u.samples(5, seed=7) != u.samples(5, seed=8)


def test_corners_span_the_box_and_centre_is_nominal(scene):
    u = Uncertainty.from_scene(scene, extra=["friction.mu=uniform 10 %", "oil.viscosity=normal 10 %",
                                             'film.flow_factor=["patir_cheng", "none"]'])
    corners = u.corners()
    assert len(corners) == 2 * 2 * 2
    assert sorted({c["friction.mu"] for c in corners}) == pytest.approx([0.108, 0.132])
    assert sorted({c["oil.viscosity"] for c in corners}) == pytest.approx([0.0681 * 0.8, 0.0681 * 1.2])  # +- 2 sigma
    assert u.centre() == {"friction.mu": 0.12, "oil.viscosity": 0.0681, "film.flow_factor": "patir_cheng"}
    assert Uncertainty().corners() == [{}]


def test_a_draw_is_a_valid_scene_with_the_drawn_values(scene):
    u = load_scene("default_driveline").uncertainty
    draw = u.samples(1, seed=0)[0]
    realised = scene.with_overrides(draw)
    for key, value in draw.items():
        assert realised.value(key) == value


@pytest.mark.parametrize("spec, words", [
    ("friction.muu=uniform 10 %", "has no field 'muu'"),
    ("piston.mass=uniform 10 %", "does not set piston.mass"),
    ("friction.mu=triangular 10 %", "'uniform 10 %'"),
    ("friction.mu=uniform ten %", "not a percentage"),
    ("friction.mu=uniform 0 %", "> 0"),
    ("friction.mu=uniform 150 %", "reaches"),
    ("load.torque=uniform 20 Pa", "unit"),
    ("friction.mu=[0.1]", "at least two"),
    ("film.flow_factor=uniform 10 %", "list of its values"),
    ("film.flow_factor=[\"patir_cheng\", \"bogus\"]", "allowed values"),
    ("plates.r_inner=uniform 40 %", "reaches"),
    ("mu=uniform 10 %", "part.key"),
    ("friction.mu", "part.key=spec"),
])
def test_bad_specs_end_in_one_line_naming_the_field(scene, spec, words):
    with pytest.raises(SceneError) as err:
        Uncertainty.from_scene(scene, extra=[spec])
    message = str(err.value)
    assert words in message and "\n" not in message
    assert "uncertainty." in message or "--uncertain" in message


def test_sample_count_must_be_a_positive_whole_number():
    u = load_scene("default_driveline").uncertainty
    for bad in (0, -3, 2.5, True):
        with pytest.raises(SceneError, match="samples"):
            u.samples(bad)


def test_scenes_command_lists_the_uncertainty_and_rejects_a_bad_one(tmp_path):
    scene_text = (load_scene("default_driveline").path).read_text()
    good = subprocess.run([sys.executable, "-m", "clutchocp.cli", "scenes", "default_driveline"],
                          capture_output=True, text=True, timeout=120)
    assert good.returncode == 0 and "friction.mu: uniform 10 % (nominal 0.12)" in good.stdout
    bad_file = tmp_path / "bad.toml"
    bad_file.write_text(scene_text.replace('"friction.mu" = "uniform 10 %"', '"friction.mu" = "uniform 900 %"'))
    bad = subprocess.run([sys.executable, "-m", "clutchocp.cli", "scenes", str(bad_file)],
                         capture_output=True, text=True, timeout=120)
    assert bad.returncode == 2
    assert bad.stderr.count("\n") == 1 and "uncertainty.friction.mu" in bad.stderr and "Traceback" not in bad.stderr


def test_a_run_whose_overrides_change_an_uncertain_part_does_not_depend_on_the_spread(tmp_path):
    table = tmp_path / "load.csv"
    table.write_text("speed,torque\n0,100\n400,100\n")
    scene = load_scene("default_driveline", overrides={"load.model": "table", "load.file": str(table),
                                                       "load.torque": None})
    assert scene.variant("load") == "table"
    with pytest.raises(SceneError, match="uncertainty.load.torque"):
        scene.uncertainty
