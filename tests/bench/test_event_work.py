"""clutchocp.bench.event_work: the event checks of a run cover every sample it keeps in a mode with
events, give the mode's own event values, and are the ones that found the run's event."""

import numpy as np
import pytest

from clutchocp.bench.event_work import event_checks, event_work_time
from clutchocp.errors import ClutchocpError


def test_checks_cover_the_kept_samples_of_every_mode_with_events(zhang_run):
    _, model, run = zhang_run
    compiled = model.hybrid.compiled()
    with_events = [seg for seg in run.result.segments if compiled[seg.mode].events]
    assert with_events
    checks = event_checks(run)
    assert sum(t.size for *_, t in checks) == sum(seg.t.size for seg in with_events)
    assert np.array_equal(np.concatenate([t for *_, t in checks]), np.concatenate([seg.t for seg in with_events]))


def test_checks_give_the_event_functions_sample_by_sample(zhang_run):
    # a second evaluation: the mode's event Function called on one sample at a time (CasADi's DM path)
    _, model, run = zhang_run
    compiled = model.hybrid.compiled()
    modes = [compiled[seg.mode] for seg in run.result.segments if compiled[seg.mode].events]
    for cm, (evaluate, xs, zs, pu, t) in zip(modes, event_checks(run)):
        values = evaluate(xs, zs, pu, t)
        for k in (0, t.size // 2, t.size - 1):
            one = np.array(cm.f_events(xs[:, k], zs[:, k], pu, t[k]), dtype=float).ravel()
            assert values[:, k] == pytest.approx(one, rel=1e-12, abs=1e-12)


def test_the_slip_checks_hold_the_lockup_crossing(zhang_run):
    # lock-up ends the slipping segment: its event function keeps one sign on the samples before the
    # event and is within the location tolerance of zero on the event's own sample
    _, model, run = zhang_run
    lock = next(e for e in run.result.events if e.name == "lockup")
    slipping = next(seg for seg in run.result.segments if seg.mode == lock.source)
    cm = model.hybrid.compiled()[slipping.mode]
    index = next(spec.index for spec in cm.events if spec.name == "lockup")
    evaluate, xs, zs, pu, t = next(c for c in event_checks(run) if c[4][-1] == slipping.t[-1])
    values = evaluate(xs, zs, pu, t)[index]
    assert t[-1] == lock.t
    assert np.all(np.sign(values[:-1]) == np.sign(values[0])) and values[0] != 0
    assert abs(values[-1]) <= run.summary["solver"]["event_value_tol"]


def test_event_work_time_is_part_of_a_run(zhang_run):
    _, _, run = zhang_run
    seconds = event_work_time(run, repeats=2)
    assert 0 < seconds < run.result.stats["wall_time_s"]


def test_a_run_that_let_its_samples_go_needs_the_evaluators_taken_before(zhang_run_let_go):
    run, kept = zhang_run_let_go
    with pytest.raises(ClutchocpError, match="let its samples go"):
        event_checks(run)
    assert sum(t.size for *_, t in event_checks(run, kept)) > 0
