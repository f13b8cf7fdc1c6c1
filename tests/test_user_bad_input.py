"""What a new user types wrong: every mistake ends with exit 2 and one line naming the field and what
is allowed (or runs with a warning naming the value); no traceback, no file written.

Over 100 kinds: scene files, every command-line flag, controller specs, --out and resource limits.
"""

import re
from pathlib import Path

import pytest

from clutchocp.cli import main

REPO = Path(__file__).resolve().parents[1]
BASE_SCENE = (REPO / "models" / "zhang2021.toml").read_text()
BASE_CONTROLLER = (REPO / "controllers" / "pi.toml").read_text()


def edited(text, section, key, value):
    """``text`` (TOML) with ``key`` of ``[section]`` set to the raw TOML ``value`` (None: removed)."""
    lines, out, inside, done = text.splitlines(), [], False, False
    for line in lines:
        header = re.match(r"^\[(.+)\]\s*$", line)
        if header:
            if inside and not done and value is not None:
                out.append(f"{key} = {value}")
                done = True
            inside = header.group(1) == section
        elif inside and re.match(rf"^{re.escape(key)}\s*=", line):
            done = True
            if value is not None:
                out.append(f"{key} = {value}")
            continue
        out.append(line)
    if inside and not done and value is not None:
        out.append(f"{key} = {value}")
    return "\n".join(out) + "\n"


# -- scene files: (section, key, raw TOML value, words the one line must contain) ----------------
SCENE_EDITS = [
    ("plates", "r_inner", '"0.1 m"', ["plates.r_inner", "r_outer"]),
    ("plates", "r_inner", '"-0.064 m"', ["plates.r_inner", "> 0"]),
    ("plates", "r_outer", "0", ["plates.r_outer", "> 0"]),
    ("plates", "r_outer", '"0.085 kg"', ["plates.r_outer", "unit"]),
    ("plates", "r_outer", '"0.085 meters"', ["plates.r_outer", "unknown symbol"]),
    ("plates", "r_outer", '"abc"', ["plates.r_outer", "not a number"]),
    ("plates", "r_outer", "nan", ["plates.r_outer", "finite"]),
    ("plates", "r_outer", "inf", ["plates.r_outer", "finite"]),
    ("plates", "r_outer", "[0.085]", ["plates.r_outer", "one number"]),
    ("plates", "r_outer", "true", ["plates.r_outer"]),
    ("plates", "r_outer", None, ["plates.r_outer", "missing"]),
    ("plates", "n_interfaces", "0", ["plates.n_interfaces", "from 1 to 64"]),
    ("plates", "n_interfaces", "5000", ["plates.n_interfaces", "from 1 to 64"]),
    ("plates", "n_interfaces", "1.5", ["plates.n_interfaces", "whole number"]),
    ("plates", "n_interfaces", '"two"', ["plates.n_interfaces", "whole number"]),
    ("plates", "lining_permeability", '"-4e-12 m^2"', ["plates.lining_permeability", ">= 0"]),
    ("plates", "land_fraction", "1.5", ["plates.land_fraction", "(0, 1]"]),
    ("plates", "r_innr", '"0.05 m"', ["plates.r_innr", "did you mean", "r_inner"]),
    ("oil", "viscosity", "0", ["oil.viscosity", "> 0"]),
    ("oil", "viscosity", '"46 cSt"', None),       # valid: kinematic viscosity with the oil's density
    ("oil", "viscosity", '"46 cSt m"', ["oil.viscosity", "unit"]),
    ("oil", "viscosity", '"0.04 Pa"', ["oil.viscosity", "Pa s"]),
    ("oil", "density", '"-850 kg/m^3"', ["oil.density", "> 0"]),
    ("oil", "viscosty", "0.04", ["oil.viscosty", "viscosity"]),
    ("roughness", "sigma", '"-1 um"', ["roughness.sigma", ">= 0"]),
    ("contact", "model", '"hertz"', ["contact.model", "allowed"]),
    ("contact", "E_equiv", '"2.7e7 N"', ["contact.E_equiv", "unit"]),
    ("friction", "mu", "3", ["friction.mu", "(0, 2)"]),
    ("friction", "mu", "-0.1", ["friction.mu", "(0, 2)"]),
    ("friction", "model", '"magic"', ["friction.model", "allowed"]),
    ("pack", "model", '"floating"', ["pack.model", "allowed"]),
    ("pack", "initial_gap", '"0 m"', ["pack.initial_gap", "> 0"]),
    ("actuation", "pressure", '"1e15 Pa"', ["actuation.pressure", "1e8"]),
    ("actuation", "pressure", '"-6e5 Pa"', ["actuation.pressure", "1e8"]),
    ("actuation", "pressure", '"6 psi s"', ["actuation.pressure", "unit"]),
    ("actuation", "initial_pressure", '"2e9 Pa"', ["actuation.initial_pressure", "1e8"]),
    ("actuation", "time_constant", '"0 s"', ["actuation.time_constant", "> 0"]),
    ("actuation", "time_constant", '"40 ms/s"', ["actuation.time_constant", "unit"]),
    ("actuation", "model", '"valve_lagg"', ["actuation.model", "allowed"]),
    ("driveline", "input_speed", '"1000 N"', ["driveline.input_speed", "unit"]),
    ("driveline", "input_inertia", '"0 kg m^2"', ["driveline.input_inertia", "> 0"]),
    ("simulation", "t_end", '"1e-12 s"', ["simulation.t_end", "1e-3 s"]),
    ("simulation", "t_end", '"1e9 s"', ["simulation.t_end", "1e4 s"]),
    ("simulation", "output_points", "200000000", ["simulation.output_points", "200000"]),
    ("simulation", "output_points", "1", ["simulation.output_points", "from 2"]),
    ("simulation", "rtol", "10", ["simulation.rtol", "1e-2"]),
    ("simulation", "atol", "0", ["simulation.atol", "1e-14"]),
    ("scene", "kind", '"gearbox"', ["scene.kind"]),
    ("scene", "name", "3", ["scene.name", "text"]),
]


def _scene_cases():
    for i, (section, key, value, words) in enumerate(SCENE_EDITS):
        if words is not None:
            yield pytest.param(section, key, value, words, id=f"scene-{section}.{key}-{i}")


@pytest.mark.parametrize("section, key, value, words", list(_scene_cases()))
def test_scene_file_mistakes(section, key, value, words, tmp_path, capsys):
    path = tmp_path / "my_clutch.toml"
    path.write_text(edited(BASE_SCENE, section, key, value))
    assert main(["scenes", str(path)]) == 2
    assert_one_line(capsys, words)


@pytest.mark.parametrize("text, words", [
    ("[plates\nr_inner = 1", ["my_clutch.toml"]),                       # TOML syntax
    ("[gearbox]\nratio = 3\n", ["gearbox"]),                             # unknown part
    ("", ["my_clutch.toml"]),                                             # empty file
])
def test_scene_file_structure_mistakes(text, words, tmp_path, capsys):
    path = tmp_path / "my_clutch.toml"
    path.write_text(BASE_SCENE + "\n" + text if text.startswith("[gearbox]") else text)
    assert main(["scenes", str(path)]) == 2
    assert_one_line(capsys, words)


def test_a_missing_required_part(tmp_path, capsys):
    text = BASE_SCENE.split("[actuation]")[0] + "[driveline]" + BASE_SCENE.split("[driveline]")[1]
    path = tmp_path / "my_clutch.toml"
    path.write_text(text)
    assert main(["scenes", str(path)]) == 2
    assert_one_line(capsys, ["actuation"])


# -- command-line flags ------------------------------------------------------------------------
SIM = ["simulate", "zhang2021"]
OPT = ["optimize"]
FLAG_CASES = [
    (SIM + ["--rtol", "10"], ["--rtol", "1e-2"]),
    (SIM + ["--rtol", "0"], ["--rtol"]),
    (SIM + ["--rtol", "-1e-6"], ["--rtol"]),
    (SIM + ["--rtol", "nan"], ["--rtol"]),
    (SIM + ["--rtol", "abc"], ["--rtol", "not a number"]),
    (SIM + ["--rtol", "1e-20"], ["--rtol", "1e-14"]),
    (SIM + ["--atol", "1"], ["--atol", "1e-2"]),
    (SIM + ["--atol", "inf"], ["--atol"]),
    (SIM + ["--method", "euler"], ["--method", "idas"]),
    (SIM + ["--set", "oil.viscosity"], ["--set", "part.key=value"]),
    (SIM + ["--set", "oil.viscosty=0.04"], ["oil.viscosty", "viscosity"]),
    (SIM + ["--set", "oil.viscosity=-1"], ["oil.viscosity", "> 0"]),
    (SIM + ["--set", "oil.viscosity=0.04 bar"], ["oil.viscosity", "unit"]),
    (SIM + ["--set", "plates.n_interfaces=5000"], ["plates.n_interfaces", "64"]),
    (SIM + ["--set", "simulation.output_points=200000000"], ["simulation.output_points", "200000"]),
    (SIM + ["--set", "simulation.t_end=1e-12 s"], ["simulation.t_end"]),
    (SIM + ["--set", "actuation.pressure=1e15 Pa"], ["actuation.pressure", "1e8"]),
    (SIM + ["--set", "gearbox.ratio=3"], ["gearbox"]),
    (SIM + ["--set", "=3"], ["--set"]),
    (["simulate", "no_such_scene"], ["no_such_scene"]),
    (["simulate", "chen2021"], ["engagement"]),
    (["simulate"], ["scene"]),
    (["simulate", "zhang2021", "--bogus"], ["--bogus"]),
    (OPT + ["--t-max", "0"], ["--t-max", "positive"]),
    (OPT + ["--t-max", "-0.2"], ["--t-max", "positive"]),
    (OPT + ["--t-max", "nan"], ["--t-max"]),
    (OPT + ["--t-max", "inf"], ["--t-max"]),
    (OPT + ["--t-max", "fast"], ["--t-max", "not a number"]),
    (OPT + ["--t-max", "0.01"], ["t_max"]),
    (OPT + ["--weights", ""], ["--weights", "name=number"]),
    (OPT + ["--weights", "jerk"], ["--weights", "name=number"]),
    (OPT + ["--weights", "jerk=abc"], ["--weights", "name=number"]),
    (OPT + ["--weights", "=1"], ["--weights", "name=number"]),
    (OPT + ["--weights", "speed=1"], ["weights", "speed", "allowed"]),
    (OPT + ["--weights", "jerk=-1"], ["weights.jerk", ">= 0"]),
    (OPT + ["--weights", "jerk=nan"], ["weights.jerk", ">= 0"]),
    (OPT + ["--weights", "jerk=0,energy=0"], ["weights", "positive"]),
    (OPT + ["--weights", "jerk=1,jerk=2"], ["--weights", "twice"]),
    (OPT + ["--weights", "jerk=1,,energy=1"], ["--weights"]),
    (OPT + ["--intervals", "0"], ["--intervals", "from 2 to 2000"]),
    (OPT + ["--intervals", "1"], ["--intervals", "from 2 to 2000"]),
    (OPT + ["--intervals", "100000"], ["--intervals", "from 2 to 2000"]),
    (OPT + ["--intervals", "2.5"], ["--intervals", "integer"]),
    (OPT + ["--degree", "0"], ["--degree", "from 1 to 9"]),
    (OPT + ["--degree", "12"], ["--degree", "from 1 to 9"]),
    (OPT + ["--degree", "three"], ["--degree", "integer"]),
    (OPT + ["--sweep-t-max", ""], ["--sweep-t-max"]),
    (OPT + ["--sweep-t-max", "a:b"], ["--sweep-t-max"]),
    (OPT + ["--sweep-t-max", "0.2:0.3"], ["--sweep-t-max"]),
    (OPT + ["--sweep-t-max", "0.2,nan"], ["--sweep-t-max", "positive"]),
    (OPT + ["--sweep-t-max", "0.2,inf"], ["--sweep-t-max", "positive"]),
    (OPT + ["--sweep-t-max", "-0.1,0.2"], ["--sweep-t-max"]),        # argparse reads it as an option
    (OPT + ["--sweep-t-max=-0.1,0.2"], ["--sweep-t-max", "positive"]),
    (OPT + ["--sweep-t-max", "0.2:0.3:0"], ["--sweep-t-max", "count", "from 2 to 50"]),
    (OPT + ["--sweep-t-max", "0.2:0.3:1"], ["--sweep-t-max", "count"]),
    (OPT + ["--sweep-t-max", "0.2:0.3:1000"], ["--sweep-t-max", "count"]),
    (OPT + ["--sweep-t-max", "0.2:0.3:2.5"], ["--sweep-t-max"]),
    (OPT + ["--max-temperature", "nan"], ["--max-temperature", "degC"]),
    (OPT + ["--max-temperature", "-300"], ["--max-temperature", "-273.15"]),
    (OPT + ["--max-specific-power", "0"], ["--max-specific-power"]),
    (OPT + ["--max-specific-power", "inf"], ["--max-specific-power"]),
    (["sweep", "zhang2021", "--samples", "0"], ["--samples", "from 1"]),
    (["sweep", "zhang2021", "--seed", "-1"], ["--seed", "from 0"]),
    (["sweep", "zhang2021", "--workers", "0"], ["--workers", "from 1"]),
    (["sweep", "zhang2021", "--output-points", "1"], ["--output-points", "from 2"]),
    (["sweep", "zhang2021", "--task", "optimize", "--t-max", "nan"], ["--t-max", "positive"]),
    (["sweep", "zhang2021", "--task", "optimize", "--intervals", "1"], ["--intervals", "from 2"]),
    (["sweep", "zhang2021", "--task", "optimize", "--degree", "10"], ["--degree", "from 1 to 9"]),
    (["robust", "--samples", "-5"], ["--samples", "from 1"]),
    (["robust", "--seed", "x"], ["--seed", "integer"]),
    (["robust", "--t-max", "0"], ["--t-max", "positive"]),
    (["robust", "--workers", "0"], ["--workers", "from 1"]),
    (["robust", "--intervals", "100000"], ["--intervals", "from 2 to 2000"]),
    (["cycles", "default_driveline_thermal", "--cycles", "0"], ["--cycles", "from 1"]),
    (["cycles", "default_driveline_thermal", "--cooling-time", "-1"], ["--cooling-time", ">= 0"]),
    (["cycles", "default_driveline_thermal", "--max-temperature", "inf"], ["--max-temperature"]),
    (["optimize", "zhang2021", "--set", "actuation.max_pressure=-1"], ["actuation.max_pressure", "(0, 1e8]"]),
    (["control", "zhang2021"], ["hvd"]),
    (["control", "liao2021_hvd", "--controller", "no_such_controller"], ["no_such_controller", "lqi, pi"]),
    (["scenes", "no_such_scene"], ["no_such_scene"]),
    (["frobnicate"], ["frobnicate"]),
    ([], ["COMMAND"]),
]


@pytest.mark.parametrize("argv, words", FLAG_CASES, ids=[" ".join(a[:1] + a[2:])[:60] or "no-args"
                                                          for a, _ in FLAG_CASES])
def test_command_line_mistakes(argv, words, tmp_path, capsys):
    needs_out = argv and argv[0] in ("simulate", "optimize", "control", "sweep", "robust", "cycles")
    code = main(argv + (["--out", str(tmp_path / "out")] if needs_out else []))
    assert code == 2
    assert_one_line(capsys, words)
    assert not (tmp_path / "out").exists()


# -- --out of every command ---------------------------------------------------------------------
@pytest.mark.parametrize("command", [["simulate", "zhang2021"], ["optimize"], ["control", "liao2021_hvd"],
                                     ["validate"], ["bench", "--quick"]])
@pytest.mark.parametrize("kind", ["file", "under_a_file", "empty"])
def test_bad_out_of_every_command(command, kind, tmp_path, capsys):
    (tmp_path / "afile").write_text("x")
    out = {"file": tmp_path / "afile", "under_a_file": tmp_path / "afile" / "run", "empty": ""}[kind]
    assert main(command + ["--out", str(out)]) == 2
    assert_one_line(capsys, ["--out"])


# -- controller specs ---------------------------------------------------------------------------
CONTROLLER_EDITS = [
    ("controller", "type", '"pid"', ["controller.type", "lqi, pi"]),
    ("controller", "sample_time", '"-10 ms"', ["controller.sample_time", "> 0"]),
    ("controller", "sample_time", '"10 kg"', ["controller.sample_time", "unit"]),
    ("controller", "sample_time", None, ["controller.sample_time", "missing"]),
    ("controller", "schedule", "[0.4, 0.4]", ["controller.schedule", "differ"]),
    ("controller", "schedule", "[0.4, 1.5]", ["controller.schedule", "(0, 1)"]),
    ("controller", "schedule", "0.5", ["controller.schedule", "list"]),
    ("controller", "pressure_min", '"2 MPa"', None),                  # only with pressure_max below
    ("controller", "feedforward", '"yes"', ["controller.feedforward", "true or false"]),
    ("controller", "sampletime", '"10 ms"', ["controller.sampletime", "sample_time"]),
    ("pi", "method", '"ziegler"', ["pi.method", "allowed"]),
    ("pi", "phase_margin", '"120 deg"', ["pi.phase_margin", "(0, 90)"]),
    ("pi", "max_sensitivity", "0.5", ["pi.max_sensitivity", "> 1"]),
    ("pi", "closed_loop_time_constant", '"0 s"', ["pi.closed_loop_time_constant", "> 0"]),
    ("anti_windup", "method", '"magic"', ["anti_windup.method", "allowed"]),
    ("anti_windup", "tracking_time", '"-1 s"', ["anti_windup.tracking_time", "> 0"]),
    ("scenario", "setpoints", "[0.4, 2.0]", ["scenario.setpoints", "(0, 1)"]),
    ("scenario", "load_step", '"big"', ["scenario.load_step"]),
]


def _controller_cases():
    for i, (section, key, value, words) in enumerate(CONTROLLER_EDITS):
        if words is not None:
            yield pytest.param(section, key, value, words, id=f"controller-{section}.{key}-{i}")


@pytest.mark.parametrize("section, key, value, words", list(_controller_cases()))
def test_controller_spec_mistakes(section, key, value, words, tmp_path, capsys):
    path = tmp_path / "my_pi.toml"
    path.write_text(edited(BASE_CONTROLLER, section, key, value))
    assert main(["control", "liao2021_hvd", "--controller", str(path), "--out", str(tmp_path / "out")]) == 2
    assert_one_line(capsys, words)
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("key, value, words", [
    ("integral_weight", "1e300", ["lqi.integral_weight", "1e6"]),
    ("input_weight", "0", ["lqi.input_weight", "1e-6"]),
    ("speed_weight", "-1", ["lqi.speed_weight", "[0, 1e6]"]),
    ("speed_weight", "1e300", ["lqi.speed_weight", "[0, 1e6]"]),
])
def test_lqi_weights_that_break_the_riccati_equation(key, value, words, tmp_path, capsys):
    text = (REPO / "controllers" / "lqi.toml").read_text()
    path = tmp_path / "my_lqi.toml"
    path.write_text(edited(text, "lqi", key, value))
    assert main(["control", "liao2021_hvd", "--controller", str(path), "--out", str(tmp_path / "out")]) == 2
    assert_one_line(capsys, words)


def test_controller_pressure_limits_that_leave_no_range(tmp_path, capsys):
    text = edited(edited(BASE_CONTROLLER, "controller", "pressure_min", '"2 MPa"'), "controller", "pressure_max",
                  '"1 MPa"')
    path = tmp_path / "my_pi.toml"
    path.write_text(text)
    assert main(["control", "liao2021_hvd", "--controller", str(path), "--out", str(tmp_path / "out")]) == 2
    assert_one_line(capsys, ["controller.pressure_min", "pressure_max"])


def assert_one_line(capsys, words):
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1, captured.err
    line = lines[0]
    assert "Traceback" not in captured.err, captured.err
    for word in words:
        assert word in line, f"{word!r} not in: {line}"
    assert line.startswith("clutchocp"), line


def test_the_suite_covers_over_100_kinds():
    kinds = (sum(1 for _ in _scene_cases()) + 3 + 1 + len(FLAG_CASES) + 15 + sum(1 for _ in _controller_cases())
             + 4 + 1)
    assert kinds >= 100, kinds


def test_a_loose_tolerance_runs_with_one_warning_naming_it(tmp_path, capsys):
    assert main(["simulate", "zhang2021", "--rtol", "1e-3", "--out", str(tmp_path / "out")]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "warning" in err[0] and "1e-3" in err[0]
    assert (tmp_path / "out" / "summary.json").exists()
