"""The TCU's Kalman-filter slip controller: idle on the nominal clutch, estimates that match the clutch met
within the filter's covariance, and the generated C that computes what the Python runs, to round-off."""

import json
from dataclasses import replace

import casadi as ca
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from clutchocp.optimal.problem import EngagementOCP
from clutchocp.optimal.verify import run_numbers
from clutchocp.scene import default_scene
from clutchocp.shiftcontrol.closed_loop import post_lock_command, run_closed_loop, run_open_loop
from clutchocp.shiftcontrol.export import compile_shared, compiler, export_controller, generate_c, time_c_step
from clutchocp.shiftcontrol.lqg import _tcu_lqr, design_tcu_feedback
from clutchocp.shiftcontrol.schedule import FeedbackSchedule
from clutchocp.shiftcontrol.sensors import Sensors, sensors_from_spec
from clutchocp.shiftcontrol.spec import load_slip_spec
from clutchocp.shiftcontrol.tcu import STEP_INPUTS, STEP_OUTPUTS, clipped_command

INITIAL = {"w_in": 300.0, "w_out": 150.0, "p_valve": 0.0}


@pytest.fixture(scope="module")
def designed():
    scene = default_scene().without_uncertainty()
    opt = EngagementOCP(scene, intervals=30).solve()
    spec = load_slip_spec("slip_lqr_tcu")
    sensors = sensors_from_spec(spec, scene)
    design = design_tcu_feedback(scene, opt.command_times, opt.command, spec, sensors)
    return scene, opt, spec, sensors, design


def test_clipped_command_is_the_clipped_piecewise_linear_curve():
    """The clipped command's points, interpolated, equal np.clip of the original curve on a dense grid (crossings of
    both limits within one segment, a segment inside, a point on a limit), and its times increase strictly."""
    times, values = [0.0, 1.0, 2.0, 2.5, 3.0, 4.0], [-1.0, 3.0, 0.0, 2.0, 1.0, 1.0]
    t, v = clipped_command(times, values, 0.0, 2.0)
    grid = np.linspace(0.0, 4.0, 4001)
    assert np.all(np.diff(t) > 0)
    assert np.interp(grid, t, v) == pytest.approx(np.clip(np.interp(grid, times, values), 0.0, 2.0), abs=1e-12)


def _jump_pct(numbers):
    return 100 * abs(numbers["lockup_torque_jump_Nm"]) / numbers["locked_torque_Nm"]


def test_nominal_clutch_with_exact_readings_reproduces_the_open_loop(designed):
    """Exact readings (the design's own model of the sensors is not used): the filter stays at the nominal
    trajectory, the corrections are pascals, and the run is the open-loop optimum's."""
    scene, opt, spec, _, _ = designed
    ideal = Sensors()
    design = design_tcu_feedback(scene, opt.command_times, opt.command, spec, ideal)
    t_end = 1.3 * opt.t_f
    closed, tcu = run_closed_loop(scene, design.feedback, t_end, sensors=ideal.realize(np.random.default_rng(0),
                                                                                        INITIAL, spec.sample_time))
    times, values = post_lock_command(scene, opt.command_times, opt.command, opt.t_f, design.feedback.rate_limit)
    a, b = run_numbers(run_open_loop(scene, times, values, t_end)), run_numbers(closed)
    assert b["engagement_time_s"] == pytest.approx(a["engagement_time_s"], rel=0.01)
    assert abs(_jump_pct(b) - _jump_pct(a)) < 0.5
    assert np.max(np.abs(tcu["correction_Pa"])) < 300.0
    for values in tcu["estimates"].values():
        assert np.max(np.abs(values)) < 2e-3


def test_estimates_of_a_clutch_met_and_the_filter_consistency(designed):
    """A clutch with 8 % less friction, 15 % more load and a 10 % slower valve, read through the spec's sensors:
    at the last sample each estimated parameter is within 1 % of its true relative change (the prior spreads are
    5-30 %; the filter's linearised model leaves a bias of that order, above its own covariance for the
    friction: the test bounds the error, not the covariance), the filter has shrunk every parameter's variance,
    and the normalised innovations of the run have a root mean square of order one (the filter's predicted
    spread of its readings is the spread it meets). On the default scene's 0.3 s budget (about 30 TCU samples;
    at the 0.135 s lock-up of its own step, 14 samples, the load estimate ended 0.012 off)."""
    scene, opt, spec, sensors, design = designed
    truth = {"friction.mu": -0.08, "load.torque": 0.15, "actuation.time_constant": 0.10}
    other = scene.with_overrides({k: scene.value(k) * (1 + v) for k, v in truth.items()})
    feedback = design.feedback
    innovations = []
    original = feedback._step

    class Recorder:
        def call(self, inputs):
            innovations.append(feedback.innovation.copy())
            return original.call(inputs)

    feedback._step = Recorder()
    try:
        _, tcu = run_closed_loop(other, feedback, 1.3 * opt.t_f,
                                 sensors=sensors.realize(np.random.default_rng(4), INITIAL, spec.sample_time))
    finally:
        feedback._step = original
    k = len(tcu["t"]) - 1
    P = design.P_post[k]
    for name in spec.estimated_parameters:
        i = feedback.names.index(f"d:{name}")
        assert abs(tcu["estimates"][name][-1] - truth.get(name, 0.0)) < 0.01, name
        assert P[i, i] < 0.5 * design.model.P0[i, i], name
    m = design.model
    z = [nu / np.sqrt(np.diag(m.C[j] @ design.P_prior[j] @ m.C[j].T + m.R[j])) for j, nu in enumerate(innovations)]
    rms = np.sqrt(np.mean(np.square(z), axis=0))
    assert np.all(rms > 0.2) and np.all(rms < 2.0), rms


def _one_sample(design, start, end, x0, relative):
    """The nonlinear slip model (its state rates, no linearisation) integrated over [start, end] from the model
    states x0 with the nominal feedforward and parameters changed by ``relative`` (Radau, tight tolerances)."""
    builder = design.builder
    lin = builder.lin
    rows = [lin.all_states.index(name) for name in lin.state_names]

    def rates(t, x):
        states, _, u = builder.trajectory(t)
        states = np.array(states)
        states[rows] = x
        return lin.values(states, u, None, relative)[0]

    return solve_ivp(rates, (start, end), x0, method="Radau", rtol=1e-11,
                     atol=1e-12 * np.abs(lin.nominal)).y[:, -1]


def test_bilinear_term_is_the_nonlinear_models_mixed_second_difference(designed):
    """H_k of a late sample (thin films, where the test clutch's friction column is 1.3-1.4 x the nominal one)
    against the mixed second difference of the nonlinear model integrated over the sample (no linearisation, no
    matrix exponential): friction +-1 % and a state deviation +-v (films 0.1 um thinner, 20 kPa more pressure)."""
    _, _, spec, _, design = designed
    builder, Ts = design.builder, spec.sample_time
    lin, n = builder.lin, builder.n
    k = design.feedback.horizon - 3
    start, end = k * Ts, min((k + 1) * Ts, design.t_lock)
    rows = [lin.all_states.index(name) for name in lin.state_names]
    x0 = np.array(builder.trajectory(start)[0])[rows]
    H = builder.column_derivative(start, end, Ts)
    films = [i for i, name in enumerate(lin.state_names) if name.startswith("h_")]
    v = np.zeros(n)
    v[films], v[lin.state_names.index("p_valve")] = -1e-7, 2e4
    h = 0.01
    ends = {(a, c): _one_sample(design, start, end, x0 + a * v, {"friction.mu": c * h}) for a in (1, -1) for c in (1, -1)}
    mixed = (ends[1, 1] - ends[1, -1] - ends[-1, 1] + ends[-1, -1]) / (4 * h)
    j = lin.parameter_names.index("friction.mu")
    speeds = [lin.state_names.index(name) for name in ("w_in", "w_out")]
    assert (H[:n, j, :n] @ v)[speeds] == pytest.approx(mixed[speeds], rel=0.02)
    assert np.all(np.abs(mixed[speeds]) > 0.005)      # the term is there [rad/s per unit friction change]
    p = lin.state_names.index("p_valve")              # the valve does not feel the friction (to the integration's
    assert (H[:n, j, :n] @ v)[p] == 0.0 and abs(mixed[p]) < 1e-2      # round-off of a 1 MPa pressure)


def test_terminal_tolerances_weigh_slip_and_rate_at_lock_up_on_their_own(designed):
    """The terminal slip and slip-rate tolerances equal to the running ones are the terminal weight 1 (same
    gains); a tighter slip-rate tolerance at lock-up alone raises the gains of the last sample on the rate's
    states and leaves the first sample's nearly as they were (the Riccati recursion runs backwards)."""
    scene, _, spec, _, design = designed
    model = design.model
    w_rel0 = float(model.y_ref[0][0] - model.y_ref[0][1])
    args = (model, w_rel0, design.t_lock, scene.value("actuation.max_pressure"))
    running = {key: value for key, value in spec.lqi.items() if not key.startswith("terminal_slip")}
    one = _tcu_lqr({**running, "terminal_weight": 1.0}, *args)
    same = _tcu_lqr({**running, "terminal_slip_tolerance": running["slip_tolerance"],
                     "terminal_slip_rate_tolerance": running["slip_rate_tolerance"]}, *args)
    assert same == pytest.approx(one, rel=1e-12, abs=1e-9 * np.max(np.abs(one)))
    tight = _tcu_lqr({**running, "terminal_slip_tolerance": running["slip_tolerance"],
                      "terminal_slip_rate_tolerance": 0.01 * running["slip_rate_tolerance"]}, *args)
    assert np.linalg.norm(tight[-1]) > 2 * np.linalg.norm(one[-1])


@pytest.mark.skipif(compiler() is None, reason="no C compiler (cc, gcc, clang) on this machine")
def test_generated_c_matches_the_python_controller_to_round_off(designed, tmp_path):
    """The law generated as C (CasADi's code generator), compiled with the machine's cc, fed every sample's
    inputs of a closed-loop run with sensors: its outputs equal the Python controller's to 1e-12."""
    scene, opt, spec, sensors, design = designed
    feedback = design.feedback
    calls = []
    original = feedback._step

    class Recorder:
        def call(self, inputs):
            out = original.call(inputs)
            calls.append(({k: np.array(ca.DM(v).full()) for k, v in inputs.items()},
                          {k: np.array(v.full()) for k, v in out.items()}))
            return out

    feedback._step = Recorder()
    try:
        other = scene.with_overrides({"friction.mu": 0.11, "load.torque": 110.0})
        run_closed_loop(other, feedback, 1.3 * opt.t_f,
                        sensors=sensors.realize(np.random.default_rng(2), INITIAL, spec.sample_time))
    finally:
        feedback._step = original
    # every sample of the run to the lock-up the TCU confirms (the nominal optimum locks within the default
    # scene's 0.3 s budget: a design of about 30 samples)
    assert len(calls) >= feedback.horizon - feedback.lock_samples
    files = generate_c(tmp_path, len(feedback.names), len(feedback.measured), feedback.parameters,
                       feedback.subs)
    assert [f.name for f in files] == ["tcu_step.c", "tcu_step.h"]
    compiled = ca.external("tcu_step", str(compile_shared(tmp_path)))
    assert compiled.name_in() == list(STEP_INPUTS) and compiled.name_out() == list(STEP_OUTPUTS)
    worst = 0.0
    for inputs, expected in calls:
        got = compiled.call(inputs)
        for key in STEP_OUTPUTS:
            value = np.array(got[key].full())
            scale = np.maximum(np.abs(expected[key]), 1.0)
            worst = max(worst, float(np.max(np.abs(value - expected[key]) / scale)))
    assert worst <= 1e-12
    seconds = time_c_step(tmp_path, calls[10][0], repeats=20_000, parameters=feedback.parameters)
    print(f"generated C: {seconds * 1e6:.2f} us per step ({len(feedback.names)} states, "
          f"{len(feedback.measured)} readings)")
    assert 0 < seconds < 1e-3


def test_export_writes_tables_with_units_and_json(designed, tmp_path):
    scene, _, _, sensors, design = designed
    schedule = FeedbackSchedule("", np.array([np.nan]), [design.feedback], [{}], [design.t_lock], None, sensors)
    files = export_controller(tmp_path, schedule)
    names = {f.name for f in files}
    assert {"calibration_limits.csv", "calibration_feedforward.csv", "calibration_gain_schedule.csv",
            "calibration_estimator.csv", "controller.json", "tcu_step.c", "tcu_step.h"} <= names
    header = (tmp_path / "calibration_gain_schedule.csv").read_text().splitlines()[0]
    assert "K[p_valve] [1]" in header and "K[w_in] [Pa/(rad/s)]" in header and "u_ff [Pa]" in header
    data = json.loads((tmp_path / "controller.json").read_text())
    table = np.array(data["designs"][0]["tables"]["K"])
    assert table == pytest.approx(design.feedback.tables["K"], rel=1e-15)
    assert [s["name"] for s in data["state"]] == list(design.feedback.names)
    estimator = (tmp_path / "calibration_estimator.csv").read_text().splitlines()
    assert estimator[0].startswith("design,matrix,sample,row,column,value [SI: unit column],unit")
    assert len(estimator) > 1000


def test_sensors_of_the_nominal_transmission_have_no_unit_errors(designed):
    _, _, _, sensors, _ = designed
    nominal = sensors.nominal()
    assert nominal.input_speed.pitch_error == 0 and nominal.pressure.offset == 0 and nominal.sump.error_C == 0
    assert nominal.input_speed.timer_resolution == sensors.input_speed.timer_resolution
    assert replace(sensors, valve=sensors.valve).describe()["input_speed"].startswith("60-tooth wheel, edge timing")
