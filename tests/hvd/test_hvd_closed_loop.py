"""The sampled-data closed loop on the nonlinear HVD: engine cross-check, linear agreement, done-when targets."""

import json

import numpy as np
import pytest

from clutchocp.hvd import HvdModel, Scenario, design, load_controller, run_control, simulate_closed_loop
from clutchocp.hvd.closed_loop import make_scenario
from clutchocp.hvd.workflow import linear_step
from clutchocp.scene import load_scene
from clutchocp.simulation import PiecewiseConstant, SimulationOptions, simulate

SCENES = ("liao2021_hvd", "cui2019_hvd")


@pytest.fixture(scope="module")
def cases():
    out = {}
    for scene in SCENES:
        model = HvdModel(load_scene(scene))
        for name in ("lqi", "pi"):
            spec = load_controller(name)
            out[scene, name] = (model, spec, design(model, spec))
    return out


def step_scenario(r0, r1, t_step, t_end):
    """Hold r0, step to r1 at t_step (no soft start, no load step)."""
    return Scenario(t_end, 0.0, (r0, r1), (t_step,), (), (), [("step", "setpoint", t_step, t_end, r1, r1 - r0)])


def start_at(point, sched, scenario):
    """Closed loop from a steady state with the controller started bumplessly there."""
    return simulate_closed_loop(sched.model, sched.controller, scenario, x0=point.point.x)


def test_sampled_loop_equals_the_engine_replaying_its_commands(cases):
    """The per-sample IDAS integrator and clutchocp.simulation.simulate integrate the same DAE."""
    model, _, sched = cases["cui2019_hvd", "lqi"]
    point = sched.points[2]
    run = start_at(point, sched, step_scenario(point.point.speed, 1.1 * point.point.speed, 0.2, 1.5))
    t, u = run.series["t"], run.series["command"]
    res = simulate(model.hybrid, dict(zip(model.state_names, point.point.x)), t,
                   u={"p_cmd": PiecewiseConstant(t[1:-1], u[:-1]), "load_torque": 0.0},
                   options=SimulationOptions(rtol=1e-10, atol=1e-10))
    for name in ("w", "p", "h_1"):
        engine = np.array([res[name][np.nonzero(res.t == tk)[0][-1]] for tk in t])
        np.testing.assert_allclose(run.series[name], engine, rtol=2e-6)


@pytest.mark.parametrize("scene", SCENES)
@pytest.mark.parametrize("name", ["lqi", "pi"])
def test_linear_and_nonlinear_closed_loops_agree_on_a_one_percent_step(cases, scene, name):
    _, spec, sched = cases[scene, name]
    point = sched.points[2]                                   # 0.6 x rated speed
    r0 = point.point.speed
    t_step, t_end = 0.5, 8.0
    run = start_at(point, sched, step_scenario(r0, 1.01 * r0, t_step, t_end))
    t = run.series["t"]
    after = t >= t_step - 1e-12
    y_lin = 0.01 * r0 * linear_step(point, sched.controller, spec, t[after] - t_step)
    y_nl = run.series["w"][after] - r0
    assert np.max(np.abs(y_nl - y_lin)) <= 0.02 * 0.01 * r0
    assert np.max(np.abs(run.series["w"][~after] - r0)) < 1e-9 * r0      # it started in steady state


@pytest.mark.parametrize("scene", SCENES)
@pytest.mark.parametrize("name", ["lqi", "pi"])
def test_done_when_targets_on_the_nonlinear_plant(cases, scene, name):
    """Soft start, 40 -> 60 -> 90 % setpoint steps, +-20 % load steps."""
    model, spec, sched = cases[scene, name]
    run = simulate_closed_loop(model, sched.controller, make_scenario(model, spec))
    m = run.metrics
    assert m["overshoot_pct"] <= 5.0
    assert m["steady_state_error_rel"] <= 0.005
    assert not m["limit_cycle"] and m["cycle_amplitude_rel"] <= 1e-3
    assert m["settling_time_s"] < spec.scenario["step_duration"]
    u = run.series["command"]
    assert np.all((u >= sched.controller.p_min) & (u <= sched.controller.p_max))
    assert set(m["segments"]) == {"soft_start", "step_0.4_to_0.6", "step_0.6_to_0.9", "load_plus_0.2",
                                  "load_minus_0.2"}


def test_run_control_writes_the_report(tmp_path):
    spec = tmp_path / "quick.toml"
    spec.write_text(load_controller("pi").path.read_text().replace('step_duration = "15 s"', 'step_duration = "6 s"')
                    .replace("schedule = [0.4, 0.5, 0.6, 0.7, 0.8, 0.9]", "schedule = [0.4, 0.6, 0.9]"))
    summary = run_control("cui2019_hvd", spec, out_dir=tmp_path / "out", verbose=False)
    saved = json.loads((tmp_path / "out" / "summary.json").read_text())
    for key in ("speed_rad_s", "pressure_Pa", "film_m"):
        assert isinstance(saved["operating_point"][key], float)
    assert saved["operating_point"]["speed_rad_s"] == pytest.approx(0.9 * 104.7)
    assert len(saved["linear"]["poles"]) == 3
    assert saved["margins"]["gain_margin_dB"] >= 6 and saved["margins"]["phase_margin_deg"] >= 45
    for key in ("overshoot_pct", "settling_time_s", "steady_state_error_rel", "peak_pressure_rate_Pa_s",
                "time_in_saturation_s"):
        assert isinstance(saved["closed_loop"][key], float)
    assert summary["closed_loop"]["overshoot_pct"] == saved["closed_loop"]["overshoot_pct"]
    for name in ("static_map.csv", "design_points.csv", "closed_loop.csv", "static_map.png", "bode.png", "step.png",
                 "closed_loop.png"):
        assert (tmp_path / "out" / name).stat().st_size > 0
