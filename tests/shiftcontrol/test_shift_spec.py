"""Slip-feedback specs and the robust command's input checks: every mistake ends in one clear line."""

import pytest

from clutchocp.cli import main
from clutchocp.errors import SceneError
from clutchocp.optimal.problem import LOCK_MARGIN
from clutchocp.shiftcontrol.spec import load_slip_spec, parse_slip_spec

GOOD = {"controller": {"type": "slip_lqi", "sample_time": "10 ms"}}
KALMAN = {"controller": {**GOOD["controller"], "progress": "time"}, "estimator": {"enabled": True, "method": "kalman"}}


def test_tcu_spec_loads_its_sensors():
    spec = load_slip_spec("slip_lqr_tcu")
    assert spec.estimator["method"] == "kalman" and spec.progress == "time"
    speed = spec.sensors["input_speed"]
    assert (speed["method"], speed["teeth"], speed["timer_resolution"], speed["pitch_error"]) == \
        ("edge_timing", 60, pytest.approx(1e-6), pytest.approx(0.005))
    assert spec.sensors["sump_temperature"]["error_C"] == 3.0
    assert spec.sensors["sump_temperature"]["oil_viscosity_40C"] == pytest.approx(80.12e-6)
    assert spec.estimated_parameters["driveline.input_torque"] == pytest.approx(0.05)
    assert spec.acceptance == {"lock_by_t_max": 1.03, "jump_p95_pct": 5.0, "jump_worst_pct": 10.0, "jerk_ratio": 1.15}
    assert (spec.lqi["terminal_slip_tolerance"], spec.lqi["terminal_slip_rate_tolerance"]) == (0.002, 0.05)
    assert load_slip_spec("slip_lqr").lqi["terminal_slip_tolerance"] is None       # terminal_weight there


def test_builtin_spec_loads_with_units():
    spec = load_slip_spec("slip_lqr")
    assert spec.sample_time == pytest.approx(0.01)
    assert spec.max_delay == pytest.approx(0.05)
    assert spec.anti_windup == "clamping" and spec.progress == "time"
    assert spec.lqi["slip_tolerance"] == pytest.approx(0.03)
    assert spec.t_max_fraction == pytest.approx(0.98)
    assert {k: spec.estimator[k] for k in ("enabled", "method", "activation", "gain_limit")} == \
        {"enabled": True, "method": "difference", "activation": 0.5, "gain_limit": 1.5}
    assert spec.sensors == {} and spec.valve == {"dead_time": 0.0, "assumed_dead_time": 0.0}
    assert (spec.schedule_field, spec.schedule_points) == ("oil.viscosity", 5)
    bare = parse_slip_spec(GOOD)            # without the tables: no estimator, no schedule
    assert not bare.estimator["enabled"] and bare.schedule_field == "" and bare.schedule_points == 1
    assert parse_slip_spec({**GOOD, "feedforward": {"t_max_fraction": 0.85}}).t_max_fraction == pytest.approx(0.85)
    assert spec.feedforward_curve == "nominal"
    assert parse_slip_spec({**GOOD, "feedforward": {"curve": "robust"}}).feedforward_curve == "robust"
    assert spec.pressure_reserve == 0.0
    assert parse_slip_spec({**GOOD, "feedforward": {"pressure_reserve": "0.2 MPa"}}).pressure_reserve == \
        pytest.approx(2e5)
    assert bare.lock_margin == LOCK_MARGIN         # the optimiser's own landing unless the spec says otherwise
    assert parse_slip_spec({**GOOD, "feedforward": {"lock_margin": 0.02}}).lock_margin == pytest.approx(0.02)


@pytest.mark.parametrize("raw, match", [
    ({"controller": {"type": "slip_lqi"}}, r"controller\.sample_time: missing"),
    ({"controller": {"type": "pid", "sample_time": "10 ms"}}, r"controller\.type = 'pid': allowed values are slip_lqi"),
    ({"controller": {"type": "slip_lqi", "sample_time": "-1 ms"}}, r"controller\.sample_time = '-1 ms': must be > 0"),
    ({"controller": {"type": "slip_lqi", "sample_time": "10 kg"}}, r"controller\.sample_time"),
    ({**GOOD, "lqi": {"slip_tolerence": 0.1}}, r"lqi\.slip_tolerence: unknown key .*did you mean 'slip_tolerance'"),
    ({**GOOD, "lqi": {"slip_tolerance": 0}}, r"lqi\.slip_tolerance = 0: must be > 0"),
    ({**GOOD, "anti_windup": {"method": "back_calculation"}}, r"anti_windup\.method .*allowed values are clamping, none"),
    ({**GOOD, "scenario": {}}, r"\[scenario\]: unknown table"),
    ({"controller": {**GOOD["controller"], "pressure_min": "1 MPa", "pressure_max": "0.5 MPa"}},
     r"pressure_min = 1e\+06 Pa must be below"),
    ({"controller": {**GOOD["controller"], "progress": "speed"}}, r"controller\.progress = 'speed': allowed values are slip, time"),
    ({**GOOD, "feedforward": {"t_max_fraction": 1.2}}, r"feedforward\.t_max_fraction = 1\.2: must be in \(0, 1\]"),
    ({**GOOD, "feedforward": {"t_max_fraction": 0}}, r"feedforward\.t_max_fraction = 0: must be > 0"),
    ({**GOOD, "feedforward": {"curve": "best"}}, r"feedforward\.curve.*nominal, robust"),
    ({**GOOD, "feedforward": {"pressure_reserve": "-0.1 MPa"}}, r"feedforward\.pressure_reserve = '-0\.1 MPa'"),
    ({**GOOD, "feedforward": {"pressure_reserve": "0.1 MPa", "curve": "robust"}},
     r"feedforward\.pressure_reserve = 100000 Pa needs feedforward\.curve = \"nominal\""),
    ({**GOOD, "feedforward": {"lock_margin": -0.01}}, r"feedforward\.lock_margin = -0\.01: must be >= 0"),
    ({**GOOD, "feedforward": {"lock_margin": 0.5}}, r"feedforward\.lock_margin = 0\.5: must be in \[0, 0\.5\)"),
    ({**GOOD, "feedforward": {"lock_margin": 0.02, "curve": "robust"}},
     r"feedforward\.lock_margin = 0\.02 needs feedforward\.curve = \"nominal\""),
    ({**GOOD, "feedforward": {"t_max_fracton": 0.9}}, r"feedforward\.t_max_fracton: unknown key .*did you mean 't_max_fraction'"),
    ({**GOOD, "estimator": {"activation": 1.5}}, r"estimator\.activation = 1\.5: must be in \(0, 1\)"),
    ({**GOOD, "estimator": {"gain_limit": 0.8}}, r"estimator\.gain_limit = 0\.8: must be above 1"),
    ({**GOOD, "estimator": {"filter_time": "5 ms"}}, r"estimator\.filter_time: unknown key"),
    ({"controller": {**GOOD["controller"], "measure_pressure": False}, "estimator": {"enabled": True}},
     r"estimator\.enabled = true needs controller\.measure_pressure = true"),
    ({**GOOD, "schedule": {"points": 2.5}}, r"schedule\.points = 2\.5: must be a whole number from 1 to 25"),
    ({**GOOD, "schedule": {"points": 0}}, r"schedule\.points = 0: must be > 0"),
    ({**GOOD, "schedule": {"field": "oil.viscosity"}, "feedforward": {"curve": "robust"}},
     r"schedule\.field = 'oil\.viscosity' needs feedforward\.curve = \"nominal\""),
    ({**GOOD, "schedule": {"feild": "oil.viscosity"}}, r"schedule\.feild: unknown key .*did you mean 'field'"),
    ({**GOOD, "sensors": {"input_speed": {"method": "hall"}}}, r"sensors\.input_speed\.method = 'hall': allowed values"),
    ({**GOOD, "sensors": {"wheel_speed": {}}}, r"\[wheel_speed\]: unknown table"),
    ({**KALMAN, "sensors": {"input_speed": {"teeth": 2.5}}},
     r"sensors\.input_speed\.teeth = 2\.5: must be a whole number"),
    ({**GOOD, "sensors": {"pressure": {"noise": "5 kPa"}}}, r"\[sensors\] and \[valve\] need estimator\.method"),
    ({**KALMAN, "estimator": {"enabled": True, "method": "kalman", "parameters": {"friction.mu": "150 %"}}},
     r"estimator\.parameters\.\"friction\.mu\" = '150 %': the prior half-width must be below 100 %"),
    ({**KALMAN, "valve": {"dead_time": "20 ms"}},
     r"valve\.dead_time = 0\.02 s: must be below controller\.sample_time"),
    ({"controller": {**GOOD["controller"], "progress": "slip"}, "estimator": {"enabled": True, "method": "kalman"}},
     r"estimator\.method = \"kalman\" needs controller\.progress = \"time\""),
    ({**GOOD, "acceptance": {"lock_by_t_max": 0.9}}, r"acceptance\.lock_by_t_max = 0\.9: must be >= 1"),
    ({**KALMAN, "lqi": {"terminal_slip_tolerance": 0.01}},
     r"lqi\.terminal_slip_tolerance: give lqi\.terminal_slip_tolerance and lqi\.terminal_slip_rate_tolerance together"),
    ({**GOOD, "lqi": {"terminal_slip_tolerance": 0.01, "terminal_slip_rate_tolerance": 0.05}},
     r"lqi\.terminal_slip_tolerance and terminal_slip_rate_tolerance need estimator\.method = \"kalman\""),
    ({**KALMAN, "lqi": {"terminal_slip_tolerance": 0.01, "terminal_slip_rate_tolerance": -1}},
     r"lqi\.terminal_slip_rate_tolerance = -1: must be > 0"),
])
def test_bad_specs_raise_one_line(raw, match):
    with pytest.raises(SceneError, match=match) as info:
        parse_slip_spec(raw)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("argv, match", [
    (["robust", "--samples", "0"], "--samples: 0: samples from 1"),
    (["robust", "--workers", "0"], "--workers: 0: parallel processes from 1"),
    (["robust", "--uncertain", "friction.mu=uniform ten %"], "friction.mu"),
    (["robust", "--uncertain", "friction.nu=uniform 10 %"], "friction.nu"),
    (["robust", "--controller", "no_such_spec"], "no_such_spec"),
    (["robust", "--strategies", "closed_loop,open_loop"], "--strategies: 'closed_loop,open_loop': a comma-separated"),
])
def test_robust_command_bad_input_exits_2_with_one_line(argv, match, capsys, tmp_path):
    code = main(argv + ["--out", str(tmp_path / "out")])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert len(err) == 1 and match in err[0] and err[0].startswith("clutchocp robust: error:")
