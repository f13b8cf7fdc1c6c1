"""Shared fixtures of the bench tests."""

import pytest

from clutchocp.bench.summary_work import evaluators
from clutchocp.bench.workprecision import run_method
from clutchocp.engagement.model import EngagementModel
from clutchocp.scene import load_scene


@pytest.fixture(scope="package")
def zhang_run():
    """zhang2021: its scene, its model and one engine run at rtol 1e-5 (read, not changed, by the tests)."""
    scene = load_scene("zhang2021")
    model = EngagementModel(scene)
    return scene, model, run_method(scene, model, "idas", 1e-5)


@pytest.fixture(scope="package")
def zhang_run_let_go(zhang_run):
    """A second zhang2021 run whose outputs were all read, so its segments let their samples go, and
    the evaluators of its segments taken before that: ``(run, kept)``."""
    scene, model, _ = zhang_run
    run = run_method(scene, model, "idas", 1e-5)
    kept = evaluators(run.result)
    run.result.load(run.result.names())
    return run, kept
