"""Ctrl-C stops a run, also inside IDAS and IPOPT: exit 130, one line, no output folder that looks complete."""

import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from clutchocp import interrupt
from clutchocp.engagement.run import simulate_engagement
from clutchocp.optimal.problem import EngagementOCP
from clutchocp.scene import load_scene
from clutchocp.simulation import idas_path

REPO = Path(__file__).resolve().parents[1]

# The child runs the real command line; a patched solver entry prints a marker on stderr when the
# run is inside IDAS (or IPOPT), and the test then sends a real SIGINT.
CHILD = textwrap.dedent("""
    import sys
    from clutchocp.simulation import idas_path
    from clutchocp import interrupt
    inside = sys.argv[1]
    if inside == "idas":                       # marker just before the third IDAS call
        original = idas_path._Integrator.__call__
        calls = [0]
        def call(self, *args):
            calls[0] += 1
            if calls[0] == 3:
                print("MARK", file=sys.stderr, flush=True)
            return original(self, *args)
        idas_path._Integrator.__call__ = call
    if inside == "ipopt":                      # marker just before the first IPOPT solve
        from clutchocp.optimal import problem
        solve_stage = problem.EngagementOCP._solve_stage
        def stage(self, *args):
            print("MARK", file=sys.stderr, flush=True)
            return solve_stage(self, *args)
        problem.EngagementOCP._solve_stage = stage
    from clutchocp.cli import main
    sys.exit(main(sys.argv[2:]))
""")


def run_and_interrupt(inside, argv, timeout=120):
    env = dict(os.environ, PYTHONPATH=str(REPO))
    proc = subprocess.Popen([sys.executable, "-c", CHILD, inside, *argv], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env, cwd=REPO)
    lines = []
    for line in proc.stderr:
        lines.append(line)
        if line.startswith("MARK"):
            proc.send_signal(signal.SIGINT)
            break
    out, err = proc.communicate(timeout=timeout)
    return proc.returncode, out, "".join(lines[1:]) + err


def no_complete_folder(parent, name):
    target = parent / name
    leftovers = [p.name for p in parent.iterdir() if p.name.startswith(f".{name}.")]
    return not target.exists() and not leftovers


def test_ctrl_c_inside_idas_exits_130_without_results(tmp_path):
    code, out, err = run_and_interrupt("idas", ["simulate", "bao2020", "--out", str(tmp_path / "run")])
    assert code == 130, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "interrupted by the user" in lines[0] and "Traceback" not in err
    assert no_complete_folder(tmp_path, "run")


def test_ctrl_c_inside_ipopt_exits_130_without_results(tmp_path):
    code, out, err = run_and_interrupt("ipopt", ["optimize", "--intervals", "30", "--out", str(tmp_path / "opt")])
    assert code == 130, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "interrupted by the user" in lines[0] and "Traceback" not in err
    assert "t_max" not in lines[0] or "IPOPT" in lines[0]        # not blamed on the user's limit
    assert no_complete_folder(tmp_path, "opt")


def test_ctrl_c_before_any_solver_exits_130(tmp_path):
    env = dict(os.environ, PYTHONPATH=str(REPO))
    child = "import sys, os, signal; from clutchocp.cli import main; " \
            "import clutchocp.scene as s; orig = s.load_scene; " \
            "s.load_scene = lambda *a, **k: (os.kill(os.getpid(), signal.SIGINT), orig(*a, **k))[1]; " \
            "sys.exit(main(sys.argv[1:]))"
    proc = subprocess.run([sys.executable, "-c", child, "simulate", "zhang2021", "--out", str(tmp_path / "run")],
                          capture_output=True, text=True, env=env, cwd=REPO, timeout=120)
    assert proc.returncode == 130
    assert len(proc.stderr.strip().splitlines()) == 1 and "interrupted" in proc.stderr
    assert no_complete_folder(tmp_path, "run")


def test_a_failure_inside_idas_after_ctrl_c_is_an_interrupt_not_a_retry(monkeypatch):
    # what CasADi does with a KeyboardInterrupt inside IDAS: the step fails ("psetup failed")
    def swallowed(self, *args):
        interrupt._state["requested"] = True          # the SIGINT handler ran inside the call
        raise RuntimeError("psetup failed: KeyboardInterrupt")
    monkeypatch.setattr(idas_path._Integrator, "__call__", swallowed)
    with pytest.raises(interrupt.UserInterrupt, match="IDAS at t = "):
        simulate_engagement(load_scene("zhang2021"))
    interrupt._state["requested"] = False


def test_ipopt_stops_at_the_next_iteration_after_ctrl_c():
    ocp = EngagementOCP(load_scene("default_driveline"), intervals=20)
    t_max = ocp.default_t_max()                        # the baseline run, before the Ctrl-C
    interrupt._state["requested"] = True
    try:
        with pytest.raises(interrupt.UserInterrupt, match="IPOPT"):
            ocp.solve(t_max=t_max)
    finally:
        interrupt._state["requested"] = False
    assert ocp.solver().stats()["return_status"] == "User_Requested_Stop"
    assert ocp.solver().stats()["iter_count"] == 0


def test_without_ctrl_c_the_solvers_run_as_before():
    run = simulate_engagement(load_scene("zhang2021"))
    assert run.summary["engagement_time_s"] is not None and np.isfinite(run.summary["dissipated_energy_J"])


def test_a_solver_failure_caused_by_ctrl_c_is_reported_as_the_interrupt(monkeypatch, capsys):
    from clutchocp import cli
    from clutchocp.errors import SolverError

    def failing(args):
        interrupt._state["requested"] = True         # Ctrl-C inside a solver that turned it into a failure
        raise SolverError("rootfinder failed")
    monkeypatch.setattr(cli, "_cmd_scenes", failing)
    assert cli.main(["scenes"]) == 130
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "interrupted by the user" in err[0] and "rootfinder" not in err[0]
    assert not interrupt.requested()
