"""Heat limits in the optimal engagement: the temperature limit is met, and IDAS agrees."""

import pytest

from clutchocp.errors import ModelError
from clutchocp.optimal.heat import heat_check
from clutchocp.optimal.problem import EngagementOCP
from clutchocp.optimal.verify import verify
from clutchocp.scene import load_scene

INTERVALS = 30


@pytest.fixture(scope="module")
def free():
    ocp = EngagementOCP(load_scene("default_driveline_thermal"), intervals=INTERVALS)
    return ocp, ocp.solve()


def test_temperature_limit_below_the_free_optimum_is_met_and_replayed(free):
    ocp, opt = free
    peak = opt.terms["peak_interface_temperature_C"]
    limit = peak - 4.0
    limited = EngagementOCP(ocp.scene, intervals=INTERVALS, baseline=ocp.baseline, max_temperature_C=limit)
    result = limited.solve()
    assert result.terms["peak_interface_temperature_C"] <= limit + 1e-6
    assert result.terms["peak_interface_temperature_C"] == pytest.approx(limit, abs=0.05)   # the limit is active
    check, replay = verify(limited.exact, result)
    assert check["passed"]
    heat = heat_check(limited, result, replay)
    assert abs(heat["temperature_diff_K"]) < 1.0
    assert heat["idas"]["peak_interface_temperature_C"] < limit + 1.0
    assert heat["limits"]["max_temperature_C"] == limit


def test_specific_power_limit_is_met(free):
    ocp, opt = free
    area = 4 * ocp.model.film.area * 1e6
    peak = float(opt.outputs_points["interface_heat_power_W"].max()) / area
    limited = EngagementOCP(ocp.scene, intervals=INTERVALS, baseline=ocp.baseline,
                            max_specific_power_W_mm2=0.9 * peak)
    result = limited.solve()
    assert float(result.outputs_points["interface_heat_power_W"].max()) / area <= 0.9 * peak * (1 + 1e-6)


def test_limit_errors(default_without_thermal):
    scene = default_without_thermal
    with pytest.raises(ModelError, match="max_temperature_C: the scene has no"):
        EngagementOCP(scene, intervals=INTERVALS, max_temperature_C=80.0)
    with pytest.raises(ModelError, match="max_specific_power_W_mm2"):
        EngagementOCP(scene, intervals=INTERVALS, max_specific_power_W_mm2=-1.0)
