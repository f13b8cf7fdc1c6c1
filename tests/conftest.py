"""Shared test set-up: a non-interactive matplotlib backend for every test; shared scene fixtures; the tiers.

Tiers: ``pytest`` runs the full tier (everything but ``slow``); ``pytest --fast`` leaves out the
end-to-end modules in ``END_TO_END`` as well (whole commands, optimisation chains, Monte Carlo and
closed loops, documentation runs): under two minutes on two cores, for a check while working;
``pytest -m slow`` runs the long cases.
"""

import matplotlib

matplotlib.use("Agg")


import pytest  # noqa: E402

from clutchocp.scene import Scene, load_scene  # noqa: E402


@pytest.fixture(scope="session")
def default_without_thermal():
    """default_driveline without its [thermal] part (a scene whose laws have fixed temperatures)."""
    scene = load_scene("default_driveline")
    return Scene({part: table for part, table in scene.raw.items() if part != "thermal"}, scene.path)


# Test modules whose cases run whole engagements, optimisations or Monte Carlo end to end (measured:
# each costs 5-55 s of the full tier's ~300 s); the fast tier leaves them out.
END_TO_END = (
    "tests/optimal/test_optimal_phases.py", "tests/optimal/test_optimal_robust.py", "tests/optimal/test_optimal.py",
    "tests/optimal/test_optimal_strategy.py", "tests/optimal/test_thermal_optimal.py",
    "tests/optimal/test_catalogue_optimize.py",
    "tests/shiftcontrol/test_shift_montecarlo.py", "tests/shiftcontrol/test_shift_tcu.py",
    "tests/shiftcontrol/test_shift_closed_loop.py",
    "tests/hvd/test_hvd_closed_loop.py", "tests/hvd/test_hvd_control.py",
    "tests/engagement/test_engagement_trends.py", "tests/simulation/test_extreme.py",
    "tests/study/test_study_sweep.py", "tests/study/test_study_dask.py", "tests/study/test_study_engines.py",
    "tests/test_cli.py", "tests/test_docs.py", "tests/test_readme.py", "tests/test_examples.py",
    "tests/test_user_api.py", "tests/test_user_output.py", "tests/test_user_interrupt.py",
)


def pytest_addoption(parser):
    parser.addoption("--fast", action="store_true",
                     help="the fast tier: leave out the end-to-end modules (tests/conftest.py END_TO_END)")


def pytest_collection_modifyitems(config, items):
    if not config.getoption("--fast"):
        return
    kept, left = [], []
    for item in items:
        path = item.nodeid.split("::")[0]
        (left if any(path == m or path.endswith("/" + m) for m in END_TO_END) else kept).append(item)
    if left:
        config.hook.pytest_deselected(items=left)
        items[:] = kept
