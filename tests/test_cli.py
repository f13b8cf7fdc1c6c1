"""The commands end to end: files written with finite numbers, user mistakes exit 2 in one line."""

import csv
import json
import math

import pytest

from clutchocp.cli import main
from clutchocp.scene import list_scenes

ENGAGEMENT = [s.name for s in list_scenes() if s.kind == "engagement"]


def finite_json(value):
    if isinstance(value, dict):
        return all(finite_json(v) for v in value.values())
    if isinstance(value, list):
        return all(finite_json(v) for v in value)
    return not isinstance(value, float) or math.isfinite(value)


def csv_numbers_finite(path):
    with open(path, newline="") as handle:
        rows = list(csv.reader(handle))[1:]
    numbers = [float(c) for r in rows for c in r if c and c[0] in "-.0123456789"]
    return numbers and all(math.isfinite(x) for x in numbers)


@pytest.mark.parametrize("scene", ENGAGEMENT)
def test_simulate_writes_finite_files_for_every_engagement_scene(scene, tmp_path, capsys):
    assert main(["simulate", scene, "--out", str(tmp_path)]) == 0
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert finite_json(summary) and summary["energy_balance_rel_error"] <= 1e-6
    assert csv_numbers_finite(tmp_path / "timeseries.csv")
    assert {"gaps.png", "speeds.png", "torque.png", "pressure.png"} <= {p.name for p in tmp_path.glob("*.png")}
    assert "engagement (lock-up) time" in capsys.readouterr().out


def test_simulate_override_changes_the_run(tmp_path):
    assert main(["simulate", "zhang2021", "--out", str(tmp_path / "a")]) == 0
    assert main(["simulate", "zhang2021", "--out", str(tmp_path / "b"), "--set", "oil.viscosity=0.1"]) == 0
    a = json.loads((tmp_path / "a" / "summary.json").read_text())
    b = json.loads((tmp_path / "b" / "summary.json").read_text())
    assert a["engagement_time_s"] != b["engagement_time_s"]


def test_optimize_default_scene_writes_the_issue_keys(tmp_path):
    assert main(["optimize", "--out", str(tmp_path), "--intervals", "40"]) == 0
    summary = json.loads((tmp_path / "summary.json").read_text())
    for key in ("lockup_torque_jump_Nm", "engagement_time_s", "jerk_integral", "dissipated_energy_J"):
        assert math.isfinite(summary["optimal"][key]) and math.isfinite(summary["baseline"][key])
    assert summary["solver"]["status"] == "Solve_Succeeded"
    assert abs(summary["verification"]["lock_time_rel_diff"]) <= 0.01
    assert csv_numbers_finite(tmp_path / "pressure_profile.csv")


@pytest.mark.parametrize(
    "argv, text",
    [
        (["optimize", "--t-max", "0.01"], "t_max"),
        (["optimize", "--weights", "jerk"], "--weights"),
        (["optimize", "--sweep-t-max", "a:b"], "--sweep-t-max"),
        (["optimize", "--clamp-margin", "0.5"], "margin"),
        (["simulate", "zhang2021", "--set", "oil.viscosty=0.1"], "oil.viscosty"),
        (["simulate", "chen2021"], "engagement"),
        (["control", "zhang2021"], "hvd"),
        (["scenes", "no_such_scene"], "no_such_scene"),
    ],
)
def test_user_mistakes_exit_2_with_one_line(argv, text, tmp_path, capsys):
    assert main([*argv, "--out", str(tmp_path)] if argv[0] != "scenes" else argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and text in err[0] and "Traceback" not in err[0]
