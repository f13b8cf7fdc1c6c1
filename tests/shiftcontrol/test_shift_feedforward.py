"""The closed loop's feedforward on a design scene with a pressure reserve (``feedforward.pressure_reserve``)."""

import pytest

from clutchocp.scene import default_scene
from clutchocp.shiftcontrol.workflow import with_pressure_limit


def test_pressure_limit_below_the_scenes_own_step_lowers_the_step_too():
    scene = default_scene().without_uncertainty()
    assert scene.value("actuation.pressure") == pytest.approx(0.8e6)
    lowered = with_pressure_limit(scene, 0.6e6)       # below the 0.8 MPa step: the scene must stay valid
    assert lowered.value("actuation.max_pressure") == pytest.approx(0.6e6)
    assert lowered.value("actuation.pressure") == pytest.approx(0.6e6)
    higher = with_pressure_limit(scene, 1.2e6)
    assert higher.value("actuation.pressure") == pytest.approx(0.8e6)
    assert higher.value("actuation.max_pressure") == pytest.approx(1.2e6)
