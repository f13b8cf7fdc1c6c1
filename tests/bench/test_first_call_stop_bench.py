"""benchmarks/bench_first_call_stop.py: a call ended past the event keeps the samples before it and
takes fewer steps than the call to the end of the piece; CasADi's event stop leaves the samples
before the crossing, and the one after it, in the output buffer; a first call ended early by a
restart moves the samples by no more than the tolerance."""

import pytest

from clutchocp.simulation.idas_path import IdasPath
from repo_scripts import load_script


def _bench():
    return load_script("benchmarks/bench_first_call_stop.py")


def test_an_ended_first_call_keeps_its_samples_and_saves_steps():
    inner = IdasPath._integrate
    plan = IdasPath._plan
    row = _bench().measure("zhang2021", 1e-7, past=5, repeats=1, parts=(2, 8))
    assert IdasPath._integrate is inner and IdasPath._plan is plan           # the spies are removed
    assert row["ended_change"] == 0.0 and row["outputs_before_event"] + row["past"] < row["outputs"]
    assert row["ended_steps"] < row["full_steps"]
    assert 0.0 < row["event_t_s"] < row["piece_end_s"]
    # CasADi stopped the call at the delayed crossing: the sample after the event is written
    assert row["casadi_zero_message"]
    assert row["outputs_before_event"] < row["casadi_zero_written"] < row["outputs"]
    assert row["zero_change"] == 0.0
    assert 0.0 < row["ended_saving_share"] < 1.0
    # runs whose first call ended early: other steps, an error of the tolerance's size like the run's own
    assert [r["parts"] for r in row["restarts"]] == [2, 8] and row["restart_best_parts"] in (2, 8)
    assert all(r["steps"] != row["whole_steps"] for r in row["restarts"])
    assert 0.0 < row["whole_error"] < 1e-5
    assert all(r["error"] < 3.0 * row["whole_error"] for r in row["restarts"])
    # zhang2021 locks at 1.6 s of 6 s: half the piece ends past the event, an eighth before it
    assert [(r["first_call_end_s"], r["ends_past_event"]) for r in row["restarts"]] == [(3.0, True), (0.75, False)]
    fastest = min(r["whole_ms"] for r in row["restarts"])
    assert row["restart_best_saving_share"] == 1.0 - fastest / row["whole_ms"]


def test_a_blind_first_call_ends_at_the_part_asked_for(monkeypatch):
    bench = _bench()
    from clutchocp.bench.workprecision import run_method
    from clutchocp.engagement.model import EngagementModel
    from clutchocp.scene import load_scene

    scene = load_scene("zhang2021")
    model = EngagementModel(scene)
    sizes = []
    inner = IdasPath._integrate

    def spy(path, cm, t0, xs0, zs0, pu, times):
        sizes.append(len(times))
        return inner(path, cm, t0, xs0, zs0, pu, times)

    monkeypatch.setattr(IdasPath, "_integrate", spy)
    as_is = run_method(scene, model, "idas", 1e-7)
    first_as_is = sizes[0]
    sizes.clear()
    ended = bench.run_ended(scene, model, 1e-7, 4)
    assert sizes[0] == first_as_is // 4                       # the first call: a quarter of the piece's outputs
    stats, stats_as_is = ended.summary["solver"]["statistics"], as_is.summary["solver"]["statistics"]
    assert stats["n_integrator_calls"] > stats_as_is["n_integrator_calls"]
    assert abs(ended.summary["engagement_time_s"] - as_is.summary["engagement_time_s"]) < 1e-6


@pytest.mark.parametrize("argv", [["--past", "0"], ["--repeats", "0"], ["--rtol", "2"], ["--parts", "1"],
                                  ["--parts", "2,x"]])
def test_bad_arguments_are_refused(argv, capsys):
    with pytest.raises(SystemExit) as stop:
        _bench().main(argv)
    assert stop.value.code == 2
    assert argv[0] in capsys.readouterr().err
