"""Shared test set-up: a non-interactive matplotlib backend for every test; shared scene fixtures."""

import matplotlib

matplotlib.use("Agg")


import pytest  # noqa: E402

from clutchocp.scene import Scene, load_scene  # noqa: E402


@pytest.fixture(scope="session")
def default_without_thermal():
    """default_driveline without its [thermal] part (a scene whose laws have fixed temperatures)."""
    scene = load_scene("default_driveline")
    return Scene({part: table for part, table in scene.raw.items() if part != "thermal"}, scene.path)
