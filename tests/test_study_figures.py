"""Figures of a sweep: the heat maps drawn in two processes are the picture drawn in one."""

import numpy as np
import pytest
from PIL import Image

from clutchocp.scene import load_scene
from clutchocp.study import figures
from clutchocp.study.executor import start_method
from clutchocp.study.tasks import Task

FIELDS = ("actuation.pressure", "oil.viscosity")


def _rows():
    """A 3 x 4 grid of made-up results (one failed point: a blank cell)."""
    rows = []
    for i, p in enumerate((3e5, 4.5e5, 6e5)):
        for j, v in enumerate((0.04, 0.05, 0.06, 0.07)):
            ok = (i, j) != (1, 2)
            numbers = {"engagement_time_s": 4.0 + 0.1 * i - 0.2 * j, "lockup_torque_jump_Nm": -30.0 - 5 * i,
                       "peak_torque_Nm": 150.0 + 30 * j, "dissipated_energy_J": 2.7e5 + 1e3 * (i + j)}
            rows.append({"actuation.pressure": p, "oil.viscosity": v, "point_id": f"{i}{j}",
                         "status": "ok" if ok else "failed", "reason": "" if ok else "x",
                         **(numbers if ok else {})})
    return rows


def _draw(out, processes):
    out.mkdir()
    files = figures.draw_study(out, load_scene("zhang2021"), Task("zhang2021"), FIELDS, _rows(), False,
                               processes=processes)
    assert [f.name for f in files] == ["sweep_maps.png"]
    return np.asarray(Image.open(files[0]))


def test_heat_maps_drawn_by_two_processes_equal_those_drawn_by_one_pixel_for_pixel(tmp_path):
    one, two = _draw(tmp_path / "one", 1), _draw(tmp_path / "two", 2)
    assert one.shape == (720, 960, 3)                                # 9.6 x 7.2 in at 100 dpi
    assert np.array_equal(one, two)
    assert len(np.unique(one.reshape(-1, 3), axis=0)) > 100         # a picture, not a blank page


def test_a_part_whose_process_fails_is_drawn_by_the_sweep_process(tmp_path):
    if start_method() != "fork":
        pytest.skip("parts are drawn in forked processes only")
    calls = []

    def part(k):
        def draw():
            calls.append(k)                  # in the child this list is the child's copy
            if len(calls) == 1 and k == 1:
                raise RuntimeError("child failed")
            return np.full((2, 3, 3), k, np.uint8)
        return draw

    images = figures._render_all([part(0), part(1)], processes=2)
    assert [int(im[0, 0, 0]) for im in images] == [0, 1]
    assert calls == [0, 1]                   # this process drew part 0, then part 1 after the child failed
