"""Sweeps end to end: equal to single runs, failures recorded, Ctrl-C and resume, folder lock, optimize chains."""

import csv
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from clutchocp.cli import main
from clutchocp.engagement.run import simulate_engagement
from clutchocp.optimal.problem import EngagementOCP
from clutchocp.scene import load_scene
from clutchocp.simulation.native import compiler
from clutchocp.study import run_sweep
from clutchocp.study.folder import CALIBRATION, LOCK, RESULTS, parse_cell
from clutchocp.study.tasks import SIMULATE_COLUMNS, SIMULATE_RESULTS

ROOT = Path(__file__).resolve().parents[2]
GRID_2x2 = ["actuation.pressure=0.3 MPa:0.6 MPa:2", "oil.viscosity=0.04:0.06:2"]


def read_rows(folder):
    with (Path(folder) / RESULTS).open(newline="") as fh:
        return [{k: v if k in ("point_id", "status", "reason", "final_mode") else parse_cell(v) for k, v in r.items()}
                for r in csv.DictReader(fh)]


def _default_sigint():
    # a test run started in the background of a shell ignores SIGINT, and a child inherits that
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def cli(*args):
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    return subprocess.Popen([sys.executable, "-m", "clutchocp.cli", *args], cwd=ROOT, env=env, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, preexec_fn=_default_sigint)


@pytest.fixture(scope="module")
def single_runs():
    """The four points of GRID_2x2 run one by one with the Python API: {(pressure, viscosity): summary}."""
    base = load_scene("zhang2021")
    return {(p, v): simulate_engagement(base.with_overrides({"actuation.pressure": p, "oil.viscosity": v})).summary
            for p in (3e5, 6e5) for v in (0.04, 0.06)}


def test_a_four_point_sweep_on_two_workers_equals_four_single_runs(tmp_path, single_runs):
    summary = run_sweep("zhang2021", tmp_path / "s", grid=GRID_2x2, engine="local", workers=2, progress=False,
                        options={"reuse_model": False})
    assert (summary["points"], summary["points_ok"], summary["engine"]["workers"]) == (4, 4, 2)
    rows = read_rows(tmp_path / "s")
    assert len(rows) == 4
    for row in rows:
        single = single_runs[row["actuation.pressure"], row["oil.viscosity"]]
        for key in SIMULATE_RESULTS:
            assert row[key] == single[key], key                 # exactly: same equations, same steps
        assert row["n_steps"] == single["solver"]["statistics"]["n_steps"]
        assert row["model_reused"] is False and row["native_code"] is False
    assert (tmp_path / "s" / "sweep_maps.png").is_file() and (tmp_path / "s" / "summary.json").is_file()
    assert not (tmp_path / "s" / LOCK).exists()


TIGHT = {"rtol": 1e-11, "atol": 1e-13}


def test_by_default_one_model_serves_every_point_and_agrees_with_the_single_runs(tmp_path):
    """The same equations with the values as parameters (constants folded in another order,
    compiled C or CasADi's virtual machine: 1e-14 relative) agree with the single runs to 1e-9 when
    integrated tighter than that. Not step for step: a rounding-level change may move the
    integrator's step choices, and the results by up to its tolerance (zhang2021 at the scene's
    rtol 1e-8, x0 changed by 3e-15 relative: IDAS 591 steps instead of 640, the dissipated energy
    by 6.7e-8; CVODES 522 instead of 532)."""
    base = load_scene("zhang2021")
    single_runs = {(p, v): simulate_engagement(base.with_overrides({"actuation.pressure": p, "oil.viscosity": v}),
                                               **TIGHT).summary
                   for p in (3e5, 6e5) for v in (0.04, 0.06)}
    summary = run_sweep("zhang2021", tmp_path / "s", grid=GRID_2x2, engine="serial", progress=False, options=TIGHT)
    rows = read_rows(tmp_path / "s")
    assert summary["points_model_reused"] == 4 and all(r["model_reused"] for r in rows)
    assert summary["native_code"]["used"] == (compiler() is not None)
    for row in rows:
        single = single_runs[row["actuation.pressure"], row["oil.viscosity"]]
        assert row["final_mode"] == single["final_mode"]
        for key in SIMULATE_RESULTS[:-1]:
            if single[key] is None:                   # e.g. a point that does not lock up within t_end
                assert row[key] is None, key
                continue
            assert row[key] == pytest.approx(single[key], rel=1e-9, abs=1e-9 * abs(single["peak_torque_Nm"])), key
    assert rows[0]["build_time_s"] == 0.0


def test_a_field_that_cannot_be_a_parameter_falls_back_to_one_model_per_point(tmp_path):
    # the input speed sets the initial state and its scale: the model needs it as a number
    run_sweep("default_driveline", tmp_path / "s", grid=["driveline.input_speed=280:320:2"], engine="serial",
              progress=False, options={"native": False})
    rows = read_rows(tmp_path / "s")
    scene = load_scene("default_driveline", overrides={"driveline.input_speed": 320.0})
    assert [r["model_reused"] for r in rows] == [False, False]
    assert rows[1]["engagement_time_s"] == simulate_engagement(scene).summary["engagement_time_s"]


def test_a_failing_point_is_recorded_with_its_reason_and_the_sweep_goes_on(tmp_path):
    # Smooth plates without asperity contact: through a permeable lining the film drains completely
    # and IDAS fails; without permeability the run completes (tests/test_extreme.py, same case).
    smooth = {"contact.model": "none", "contact.E_equiv": None, "roughness.sigma": 0, "film.flow_factor": "none"}
    summary = run_sweep("zhang2021", tmp_path / "s", grid=["plates.lining_permeability=0:4e-12:3"],
                        overrides=smooth, engine="serial", progress=False, options={"native": False})
    rows = read_rows(tmp_path / "s")
    assert [r["status"] for r in rows] == ["ok", "failed", "failed"]
    for row in rows[1:]:
        assert row["reason"].startswith("CVODES failed at t = ") and "Extreme case" in row["reason"]
        assert "did not converge" in row["reason"] or "error-test" in row["reason"] or "step limit" in row["reason"]
        assert "\n" not in row["reason"]
        assert all(row[k] is None for k in SIMULATE_COLUMNS[:-1] if k != "final_mode")   # no numbers but the time
        assert row["final_mode"] == ""
    assert summary["points_failed"] == 2 and len(summary["failures"]) == 2
    assert summary["failures"][0]["plates.lining_permeability"] == pytest.approx(2e-12)
    assert (tmp_path / "s" / "sweep_lines.png").is_file()


def test_ctrl_c_stops_cleanly_and_the_same_command_resumes_without_recomputing(tmp_path):
    out = tmp_path / "s"
    args = ["sweep", "zhang2021", "--grid", "oil.viscosity=0.04:0.08:20", "--out", str(out), "--native", "off",
            "--workers", "2"]
    proc = cli(*args)
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        if (out / RESULTS).is_file() and (out / RESULTS).read_text().count("\n") >= 2:      # header + 1 row
            break
        time.sleep(0.05)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130
    last = err.strip().splitlines()[-1]
    assert last.startswith("clutchocp sweep: interrupted after") and "run the same command again to resume" in last
    assert "Traceback" not in err
    kept = read_rows(out)
    assert 1 <= len(kept) < 20 and not (out / LOCK).exists()
    assert not (out / "summary.json").exists()

    # the same sweep on another engine: the engine is not part of the study
    summary = run_sweep("zhang2021", out, grid=args[3:4], engine="serial", progress=False,
                        options={"native": False})
    assert (summary["points_resumed"], summary["points_computed"]) == (len(kept), 20 - len(kept))
    rows = read_rows(out)
    assert len(rows) == 20 and len({r["point_id"] for r in rows}) == 20
    assert rows[:len(kept)] == kept                                  # finished rows untouched, not recomputed
    assert sorted(r["oil.viscosity"] for r in rows) == pytest.approx([0.04 + 0.04 * k / 19 for k in range(20)])


def test_a_sweep_into_a_folder_another_sweep_is_writing_is_refused_before_any_run(tmp_path, capsys):
    out = tmp_path / "s"
    out.mkdir()
    holder = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        (out / LOCK).write_text(f"{holder.pid} {socket.gethostname()} 2026-11-23T12:00:00\n")
        code = main(["sweep", "zhang2021", "--grid", "oil.viscosity=0.04:0.08:2", "--out", str(out)])
    finally:
        holder.kill()
        holder.wait()
    assert code == 2
    assert capsys.readouterr().err.strip().splitlines() == [
        f"clutchocp sweep: error: --out {out}: another sweep (process {holder.pid} on {socket.gethostname()}) is "
        f"writing into this folder ({LOCK}); wait for it to finish or choose another --out"]
    assert sorted(p.name for p in out.iterdir()) == [LOCK]


@pytest.mark.parametrize("args, words", [
    (["--grid", "oil.viscosty=0.02:0.06:3"], ["oil.viscosty", "did you mean 'viscosity'"]),
    (["--grid", "oil.viscosity=0.02:0.06:3", "--samples", "5"], ["--grid", "--samples", "not both"]),
    ([], ["--grid", "--samples"]),
    (["--grid", "oil.viscosity=0.02:0.06:3", "--workers", "0"], ["--workers", "from 1"]),
    (["--grid", "oil.viscosity=0.02:0.06:3", "--scheduler", "tcp://127.0.0.1:1", "--engine", "local"],
     ["--scheduler", "--engine dask"]),
])
def test_bad_sweep_input_is_one_line_and_exit_code_2(tmp_path, capsys, args, words):
    code = main(["sweep", "zhang2021", "--out", str(tmp_path / "s"), *args])
    assert code == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("clutchocp sweep: error:")
    assert all(w in lines[0] for w in words)


# The roughness split equally between the surfaces: there the optimum of each point is unique. With the
# lining rough and the separator smooth (the scene's own), the jerk optimum has several local optima
# (measured at 12 intervals, 110 N m: 1.6392 cold, 1.6001 warm from the 90 N m optimum; at 24 intervals
# 1.6574 cold, 1.6946 warm), so "the same optimum" would test IPOPT's luck, not the chain.
EQUAL_SPLIT = {"roughness.sigma_1": 8.41e-6 / 2**0.5, "roughness.sigma_2": 8.41e-6 / 2**0.5}


def test_an_optimize_chain_warm_starts_and_finds_the_cold_optimum(tmp_path):
    options = {"intervals": 12, "verify": False}
    run_sweep("default_driveline", tmp_path / "s", task="optimize", grid=["load.torque=90:110:2"],
              overrides=EQUAL_SPLIT, options=options, engine="serial", progress=False)
    rows = read_rows(tmp_path / "s")
    assert [r["status"] for r in rows] == ["ok", "ok"]
    assert [r["warm_start"] for r in rows] == [False, True]
    assert [r["problem_reused"] for r in rows] == [True, True]            # one problem for both points
    scene = load_scene("default_driveline", overrides=dict(EQUAL_SPLIT, **{"load.torque": rows[1]["load.torque"]}))
    cold = EngagementOCP(scene, intervals=12).solve()
    # the same optimum (measured: warm and cold agree to 1e-14; IPOPT's tolerance allows more)
    assert rows[1]["objective"] == pytest.approx(cold.objective, rel=1e-8)
    assert rows[1]["engagement_time_s"] == pytest.approx(cold.t_f, rel=1e-8)
    with (tmp_path / "s" / CALIBRATION).open(newline="") as fh:
        table = list(csv.DictReader(fh))
    assert list(table[0]) == ["load.torque", "point_id", "time_s", "pressure_Pa"]
    mine = [r for r in table if r["point_id"] == rows[1]["point_id"]]
    assert [float(r["pressure_Pa"]) for r in mine] == pytest.approx(list(cold.command), rel=0,
                                                                     abs=1e-8 * cold.command.max())
    assert (tmp_path / "s" / "optimal_curves.png").is_file() and (tmp_path / "s" / "sweep_lines.png").is_file()


def test_samples_are_the_seeded_draws_of_the_scene_uncertainty(tmp_path):
    from clutchocp.scene.uncertainty import Uncertainty

    extra = ("actuation.time_constant=uniform 25 %",)
    summary = run_sweep("zhang2021", tmp_path / "s", samples=3, seed=7, uncertain=extra, engine="serial",
                        progress=False, options={"native": False})
    draws = Uncertainty.from_scene(load_scene("zhang2021"), extra=extra).samples(3, seed=7)
    rows = read_rows(tmp_path / "s")
    assert [r["actuation.time_constant"] for r in rows] == [d["actuation.time_constant"] for d in draws]
    assert summary["fields"] == ["actuation.time_constant"] and summary["points_ok"] == 3
    assert (tmp_path / "s" / "sample_histograms.png").is_file() and (tmp_path / "s" / "sample_scatter.png").is_file()


def test_the_sweep_command_writes_its_folder_and_says_so(tmp_path, capsys):
    code = main(["sweep", "zhang2021", "--grid", "oil.viscosity=0.04:0.06:2", "--out", str(tmp_path / "s"),
                 "--engine", "serial", "--native", "off"])
    out = capsys.readouterr().out
    assert code == 0
    assert f"wrote {tmp_path / 's'}: sweep_lines.png, summary.json, results.csv" in out


def test_model_per_point_gives_each_optimize_point_its_own_problem(tmp_path):
    code = main(["sweep", "default_driveline", "--task", "optimize", "--grid", "load.torque=100:100:1",
                 "--set", f"roughness.sigma_1={EQUAL_SPLIT['roughness.sigma_1']}",
                 "--set", f"roughness.sigma_2={EQUAL_SPLIT['roughness.sigma_2']}",
                 "--intervals", "8", "--no-verify", "--engine", "serial", "--model-per-point",
                 "--out", str(tmp_path / "s")])
    assert code == 0
    assert [r["problem_reused"] for r in read_rows(tmp_path / "s")] == [False]


def test_ctrl_c_while_the_figures_are_drawn_says_that_every_point_is_kept(tmp_path, monkeypatch):
    import clutchocp.study.run as study_run
    from clutchocp.study import StudyInterrupted

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(study_run, "draw_study", interrupted)
    with pytest.raises(StudyInterrupted, match="interrupted after 2 of 2 points; the finished points are kept"):
        run_sweep("zhang2021", tmp_path / "s", grid=["oil.viscosity=0.04:0.06:2"], engine="serial", progress=False,
                  options={"native": False})
    assert len(read_rows(tmp_path / "s")) == 2 and not (tmp_path / "s" / LOCK).exists()
