"""Output folders: written privately and put in place when complete; a busy or bad --out is refused first."""

import csv
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from clutchocp.cli import main
from clutchocp.errors import OutputFolderError
from clutchocp.scene import load_scene
from clutchocp.output import MARKER, check_output_folder, output_folder

REPO = Path(__file__).resolve().parents[1]


def one_line_error(capsys, *words):
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert "Traceback" not in err[0] and all(w in err[0] for w in words), err[0]
    return err[0]


def test_a_complete_folder_appears_only_at_the_end(tmp_path):
    target = tmp_path / "run"
    with output_folder(target) as folder:
        (folder.path / "summary.json").write_text("{}")
        assert not target.exists()                       # nothing under the target's name yet
        assert folder.path.parent == tmp_path and folder.path.name.startswith(".run.partial-")
        assert (tmp_path / ".run.lock").read_text() == str(os.getpid())
    assert (target / "summary.json").exists() and (target / MARKER).exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run"]        # no temp folder, no lock left


def test_an_error_inside_leaves_the_earlier_result_untouched(tmp_path):
    target = tmp_path / "run"
    with output_folder(target) as folder:
        (folder.path / "summary.json").write_text('{"run": 1}')
    with pytest.raises(RuntimeError):
        with output_folder(target) as folder:
            (folder.path / "summary.json").write_text('{"run": 2}')
            raise RuntimeError("solver failed")
    assert json.loads((target / "summary.json").read_text()) == {"run": 1}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run"]


def test_an_earlier_result_is_replaced_whole(tmp_path):
    target = tmp_path / "run"
    with output_folder(target) as folder:
        (folder.path / "old.csv").write_text("a")
        (folder.path / "summary.json").write_text("{}")
    with output_folder(target) as folder:
        (folder.path / "summary.json").write_text('{"new": true}')
    assert not (target / "old.csv").exists() and json.loads((target / "summary.json").read_text()) == {"new": True}


def test_a_folder_another_live_run_is_writing_is_refused(tmp_path, capsys):
    holder = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        (tmp_path / ".run.lock").write_text(str(holder.pid))
        assert main(["simulate", "zhang2021", "--out", str(tmp_path / "run")]) == 2
        one_line_error(capsys, "--out", f"process {holder.pid}", "writing this folder")
    finally:
        holder.kill()
        holder.wait()
    # the holder is gone: its lock is stale and the next run takes it
    assert main(["simulate", "zhang2021", "--out", str(tmp_path / "run")]) == 0
    assert (tmp_path / "run" / "timeseries.csv").exists() and not (tmp_path / ".run.lock").exists()


def test_two_simulate_runs_into_one_folder_never_mix(tmp_path):
    """Two real runs started together into one --out: one writes, the other is refused (exit 2);
    the folder holds one run's summary and CSV."""
    env = dict(os.environ, PYTHONPATH=str(REPO))
    out = str(tmp_path / "same")
    runs = [subprocess.Popen([sys.executable, "-m", "clutchocp.cli", "simulate", "zhang2021", "--out", out,
                              "--set", f"oil.viscosity={mu}", "--set", "driveline.input_speed='1000 rpm'"],
                             env=env, cwd=REPO, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True) for mu in (0.03, 0.05)]
    results = [(p.wait(timeout=120), p.stderr.read()) for p in runs]
    codes = sorted(code for code, _ in results)
    assert codes in ([0, 2], [0, 0]), results       # [0, 0]: the second started after the first had finished
    for code, err in results:
        assert code == 0 or ("--out" in err and len(err.strip().splitlines()) == 1)
    rows = list(csv.DictReader(open(tmp_path / "same" / "timeseries.csv")))
    summary = json.loads((tmp_path / "same" / "summary.json").read_text())
    t_end = load_scene("zhang2021").value("simulation.t_end")
    assert len(rows) > 100 and float(rows[-1]["time_s"]) == pytest.approx(t_end)
    # the CSV and the summary are of the same run: the two viscosities lock up at different times
    first_locked = next(float(r["time_s"]) for r in rows if r["mode"].endswith("locked"))
    assert first_locked == pytest.approx(summary["engagement_time_s"], abs=1e-9)


@pytest.mark.parametrize("make, words", [
    (lambda p: (p / "afile").write_text("x") and p / "afile", ["is an existing file"]),
    (lambda p: (p / "afile").write_text("x") and p / "afile" / "sub", ["is a file"]),
    (lambda p: (p / "notes").mkdir() or (p / "notes" / "a.txt").write_text("x") and p / "notes",
     ["not a clutchocp result"]),
    (lambda p: "", ["empty folder name"]),
    (lambda p: "   ", ["empty folder name"]),
])
def test_bad_out_is_refused_in_one_line(make, words, tmp_path, capsys):
    out = make(tmp_path)
    assert main(["simulate", "zhang2021", "--out", str(out)]) == 2
    one_line_error(capsys, "--out", *words)


def test_the_current_folder_is_never_replaced(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "my_notes.txt").write_text("keep")
    with pytest.raises(OutputFolderError, match="not a clutchocp result"):
        check_output_folder(".")
    assert (tmp_path / "my_notes.txt").read_text() == "keep"


@pytest.mark.skipif(os.geteuid() == 0, reason="root may write anywhere")
def test_an_unwritable_parent_is_refused(tmp_path, capsys):
    locked = tmp_path / "locked"
    locked.mkdir(mode=0o500)
    assert main(["simulate", "zhang2021", "--out", str(locked / "run")]) == 2
    one_line_error(capsys, "no permission")


def test_optimize_refuses_a_bad_out_before_solving(tmp_path, capsys, monkeypatch):
    from clutchocp.optimal import problem

    def no_solving(*args, **kwargs):
        raise AssertionError("the problem was built before --out was checked")
    monkeypatch.setattr(problem.EngagementOCP, "__init__", no_solving)
    (tmp_path / "afile").write_text("x")
    assert main(["optimize", "--out", str(tmp_path / "afile")]) == 2
    one_line_error(capsys, "--out", "existing file")


def test_a_failed_run_leaves_no_folder(tmp_path, capsys):
    # the solver fails (no contact to carry the load: the film closes); nothing is put in place
    code = main(["simulate", "zhang2021", "--out", str(tmp_path / "run"), "--set", "contact.model=none"])
    assert code == 2
    assert list(tmp_path.iterdir()) == []
