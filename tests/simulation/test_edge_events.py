"""Edge events (Event.edge): a crossing that ends the run with a ModelEdgeError, found on every path, and
free for a run that never reaches it."""

import casadi as ca
import numpy as np
import pytest

from clutchocp.errors import ModelEdgeError, SolverError
from clutchocp.simulation import Event, HybridModel, Mode, SimulationOptions, simulate

TIGHT = SimulationOptions(rtol=1e-10, atol=1e-10, event_value_tol=1e-12)


def falling_gap(rate, with_edge=True):
    """A gap h' = -rate (h/1 + 1)^-1, h(0) = 1: it reaches 0 at t = 1.5 / rate (closed form of
    (h + 1)^2 / 2 = 2 - rate t)."""
    h, t = ca.SX.sym("h"), ca.SX.sym("t")
    events = [Event("closed", h, "fall", direction=-1, edge="the gap closed")] if with_edge else []
    mode = Mode("fall", {"h": h}, [-rate / (h + 1)], outputs={"twice": 2 * h}, events=events)
    return HybridModel([mode], t=t)


@pytest.mark.parametrize("method", ["idas", "cvodes", "Radau", "BDF"])
def test_an_edge_ends_the_run_at_its_crossing(method):
    with pytest.raises(ModelEdgeError) as info:
        simulate(falling_gap(1.0), {"h": 1.0}, np.linspace(0.0, 3.0, 7), method=method, options=TIGHT)
    err = info.value
    assert isinstance(err, SolverError)                        # a run that ends without a result
    assert err.t == pytest.approx(1.5, rel=1e-7)
    assert abs(err.states["h"]) < 1e-7
    assert err.outputs["twice"] == pytest.approx(2 * err.states["h"])
    assert (err.event, err.edge, err.mode) == ("closed", "the gap closed", "fall")
    assert str(err).startswith("the gap closed at t = ") and "no result beyond it" in str(err)


def test_an_edge_not_reached_changes_nothing():
    """The gap closes at t = 1.5 s; a run to 1 s with and without the edge event: the same samples and
    the same integrator work (the edge never shortens a call)."""
    grid = np.linspace(0.0, 1.0, 11)
    a = simulate(falling_gap(1.0), {"h": 1.0}, grid, options=TIGHT)
    b = simulate(falling_gap(1.0, with_edge=False), {"h": 1.0}, grid, options=TIGHT)
    np.testing.assert_array_equal(a["h"], b["h"])
    for key in ("n_steps", "n_integrator_calls"):
        assert a.stats[key] == b.stats[key], key
    assert a.events == []


def test_an_edge_already_crossed_at_the_start_ends_the_run_at_once():
    with pytest.raises(ModelEdgeError) as info:
        simulate(falling_gap(1.0), {"h": -0.5}, np.linspace(0.0, 1.0, 3), options=TIGHT)
    assert info.value.t == 0.0
