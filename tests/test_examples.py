"""The example scripts run headless and write their figures (the HVD one is slow: -m slow)."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def run_example(name, out, *extra):
    env = {**os.environ, "MPLBACKEND": "Agg"}
    proc = subprocess.run([sys.executable, str(EXAMPLES / name), "--out", str(out), *extra],
                          capture_output=True, text=True, timeout=300, env=env)
    assert proc.returncode == 0, proc.stderr[-2000:]
    pngs = list(Path(out).rglob("*.png"))
    assert pngs and all(p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for p in pngs)
    return pngs


@pytest.mark.parametrize("name", ["bao2020_figures.py", "zhang2021_figures.py"])
def test_seed_figure_examples_run(name, tmp_path):
    assert len(run_example(name, tmp_path)) >= 5


@pytest.mark.slow
def test_hvd_example_runs(tmp_path):
    run_example("hvd_speed_control.py", tmp_path)
