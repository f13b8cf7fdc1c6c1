"""Study points and the study folder: grids, neighbour order, point names, lock, resume (no solves)."""

import json
import os
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from clutchocp.errors import PhysicalRangeError, UnknownKeyError
from clutchocp.scene import load_scene
from clutchocp.study.folder import LOCK, RESULTS, StudyFolder, StudyFolderError, format_cell, parse_cell
from clutchocp.study.points import StudySpecError, chains, grid_points, parse_grid, point_id


@pytest.fixture(scope="module")
def zhang():
    return load_scene("zhang2021")


def test_grid_values_are_evenly_spaced_and_in_si(zhang):
    name, values = parse_grid("actuation.pressure=0.2 MPa:0.6 MPa:5", zhang)
    assert name == "actuation.pressure"
    assert values == pytest.approx([2e5, 3e5, 4e5, 5e5, 6e5], rel=1e-15)
    assert parse_grid("oil.viscosity=0.02:0.02:1", zhang) == ("oil.viscosity", [0.02])


@pytest.mark.parametrize("text, words", [
    ("oil.viscosity=0.02:0.06", ["part.key=start:stop:count"]),
    ("oil.viscosity", ["part.key=start:stop:count"]),
    ("oil.viscosity=0.02:0.06:0", ["count", ">= 1"]),
    ("oil.viscosity=0.02:0.06:two", ["count", "whole number"]),
])
def test_bad_grid_specs_say_what_is_allowed(zhang, text, words):
    with pytest.raises(StudySpecError) as info:
        parse_grid(text, zhang)
    assert all(w in str(info.value) for w in words)
    assert "\n" not in str(info.value)


def test_grid_fields_are_checked_by_the_scene(zhang):
    with pytest.raises(UnknownKeyError, match="did you mean 'viscosity'"):
        parse_grid("oil.viscosty=0.02:0.06:3", zhang)
    with pytest.raises(PhysicalRangeError, match="oil.viscosity"):
        parse_grid("oil.viscosity=-0.02:0.06:3", zhang)


@pytest.mark.parametrize("sizes", [(4,), (3, 4), (2, 3, 2), (1, 5)])
def test_grid_is_full_and_consecutive_points_are_neighbours(sizes):
    axes = [(f"part{k}.key", [float(v) for v in range(n)]) for k, n in enumerate(sizes)]
    points = grid_points(axes)
    assert len(points) == int(np.prod(sizes))
    assert len({tuple(sorted(p.items())) for p in points}) == len(points)      # every combination once
    for a, b in zip(points, points[1:]):
        steps = [abs(a[name] - b[name]) for name, _ in axes]
        assert sorted(steps) == [0.0] * (len(axes) - 1) + [1.0]                # one field, one step


@pytest.mark.parametrize("n_points, n_chains, lengths", [(6, 2, [3, 3]), (7, 3, [2, 3, 2]), (2, 4, [1, 1]),
                                                        (5, 1, [5])])
def test_chains_are_contiguous_paths_of_near_equal_length(n_points, n_chains, lengths):
    points = grid_points([("a.x", [float(v) for v in range(n_points)])])
    runs = chains(points, n_chains)
    assert [len(r) for r in runs] == lengths
    assert sum(runs, []) == points                    # in order: each run a path of neighbours


def test_point_names_depend_on_values_not_on_order():
    assert point_id({"a.x": 0.1, "b.y": "reduced"}) == point_id({"b.y": "reduced", "a.x": float("0.1")})
    assert point_id({"a.x": 0.1}) != point_id({"a.x": float(np.nextafter(0.1, 1.0))})     # next float: another point
    assert point_id({"a.x": np.float64(0.3)}) == point_id({"a.x": 0.3})
    assert len(point_id({})) == 12


@settings(max_examples=200, deadline=None)
@given(st.floats(allow_nan=False, allow_infinity=False))
def test_csv_cells_round_trip_floats_exactly(x):
    assert parse_cell(format_cell(x)) == x
    assert parse_cell(format_cell(np.float64(x))) == x


def test_non_finite_and_missing_values_are_written_empty():
    assert format_cell(float("nan")) == format_cell(float("inf")) == format_cell(None) == ""
    assert parse_cell("") is None
    assert parse_cell(format_cell(True)) is True


SPEC = {"scene": "zhang2021", "task": "simulate", "fields": ["oil.viscosity"]}
COLUMNS = ["oil.viscosity", "point_id", "status", "reason", "engagement_time_s"]


def test_a_second_sweep_into_a_locked_folder_is_refused(tmp_path):
    with StudyFolder(tmp_path / "s", SPEC, COLUMNS):
        assert (tmp_path / "s" / LOCK).read_text().split()[0] == str(os.getpid())
        with pytest.raises(StudyFolderError, match="another sweep .* is writing into this folder"):
            with StudyFolder(tmp_path / "s", SPEC, COLUMNS):
                pass
        assert (tmp_path / "s" / LOCK).is_file()            # the refused one left the lock alone
    assert not (tmp_path / "s" / LOCK).exists()


def test_a_lock_left_by_a_dead_process_is_taken_over(tmp_path):
    import socket

    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    folder = tmp_path / "s"
    folder.mkdir()
    (folder / LOCK).write_text(f"{dead.stdout.strip()} {socket.gethostname()} 2026-01-01T00:00:00\n")
    with StudyFolder(folder, SPEC, COLUMNS):
        assert (folder / LOCK).read_text().split()[0] == str(os.getpid())


def test_a_folder_holding_something_else_is_refused(tmp_path):
    with StudyFolder(tmp_path / "s", SPEC, COLUMNS):
        pass
    with pytest.raises(StudyFolderError, match="holds another sweep .*fields"):
        with StudyFolder(tmp_path / "s", dict(SPEC, fields=["oil.density"]), COLUMNS):
            pass
    (tmp_path / "run").mkdir()
    (tmp_path / "run" / "summary.json").write_text("{}")
    with pytest.raises(StudyFolderError, match="not empty and holds no sweep"):
        with StudyFolder(tmp_path / "run", SPEC, COLUMNS):
            pass
    assert not (tmp_path / "run" / LOCK).exists()


def test_rows_are_complete_on_disk_at_once_and_a_cut_line_is_dropped(tmp_path):
    rows = [{"oil.viscosity": 0.02, "point_id": "a1", "status": "ok", "reason": "", "engagement_time_s": 0.25},
            {"oil.viscosity": 0.04, "point_id": "b2", "status": "failed", "reason": "IDAS failed, at t = 1 s",
             "engagement_time_s": None}]
    with StudyFolder(tmp_path / "s", SPEC, COLUMNS) as folder:
        folder.append(rows[0])
        assert (tmp_path / "s" / RESULTS).read_text().count("\n") == 2       # header + row, already flushed
        folder.append(rows[1])
    with (tmp_path / "s" / RESULTS).open("a") as fh:
        fh.write("0.06,c3,ok,,0.2")                                          # interrupted mid-line
    with StudyFolder(tmp_path / "s", SPEC, COLUMNS) as folder:
        assert folder.finished() == rows
        folder.append(dict(rows[0], point_id="c3"))
        assert [r["point_id"] for r in folder.finished()] == ["a1", "b2", "c3"]
    assert json.loads((tmp_path / "s" / "study.json").read_text()) == SPEC


def test_on_resume_calibration_rows_of_a_point_without_its_results_row_are_dropped(tmp_path):
    row = {"oil.viscosity": 0.02, "point_id": "a1", "status": "ok", "reason": "", "engagement_time_s": 0.25}
    curve = {"time_s": [0.0, 0.1, 0.2], "pressure_Pa": [0.0, 5e5, 1e6]}
    with StudyFolder(tmp_path / "s", SPEC, COLUMNS) as folder:
        folder.append_curve(row, curve, ["oil.viscosity"])
        folder.append(row)
        folder.append_curve(dict(row, point_id="b2", **{"oil.viscosity": 0.04}), curve, ["oil.viscosity"])
        # interrupted here: b2's curve is written, its results row is not
    with StudyFolder(tmp_path / "s", SPEC, COLUMNS) as folder:
        assert [r["point_id"] for r in folder.finished()] == ["a1"]
    lines = (tmp_path / "s" / "calibration.csv").read_text().splitlines()
    assert lines == ["oil.viscosity,point_id,time_s,pressure_Pa", "0.02,a1,0.0,0.0", "0.02,a1,0.1,500000.0",
                     "0.02,a1,0.2,1000000.0"]


def test_figure_axes_draw_pressures_in_mpa_and_other_fields_in_si(zhang):
    from clutchocp.study.figures import field_axis

    assert field_axis(zhang, "actuation.pressure") == ("actuation.pressure [MPa]", 1e-6)
    assert field_axis(zhang, "oil.viscosity") == ("oil.viscosity [Pa s]", 1.0)
