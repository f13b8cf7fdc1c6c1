"""benchmarks/bench_first_call_stop.py: a call ended past the event keeps the samples before it and
takes fewer steps than the call to the end of the piece; CasADi's event stop leaves the samples
before the crossing, and the one after it, in the output buffer."""

import pytest

from clutchocp.simulation.idas_path import IdasPath
from repo_scripts import load_script


def _bench():
    return load_script("benchmarks/bench_first_call_stop.py")


def test_an_ended_first_call_keeps_its_samples_and_saves_steps():
    inner = IdasPath._integrate
    row = _bench().measure("zhang2021", 1e-7, past=5, repeats=1)
    assert IdasPath._integrate is inner                                     # the spy is removed
    assert row["ended_change"] == 0.0 and row["outputs_before_event"] + row["past"] < row["outputs"]
    assert row["ended_steps"] < row["full_steps"]
    assert 0.0 < row["event_t_s"] < row["piece_end_s"]
    # CasADi stopped the call at the delayed crossing: the sample after the event is written
    assert row["casadi_zero_message"]
    assert row["outputs_before_event"] < row["casadi_zero_written"] < row["outputs"]
    assert row["zero_change"] == 0.0
    assert 0.0 < row["ended_saving_share"] < 1.0


@pytest.mark.parametrize("argv", [["--past", "0"], ["--repeats", "0"], ["--rtol", "2"]])
def test_bad_arguments_are_refused(argv, capsys):
    with pytest.raises(SystemExit) as stop:
        _bench().main(argv)
    assert stop.value.code == 2
    assert argv[0] in capsys.readouterr().err
