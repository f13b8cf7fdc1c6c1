"""The TCU's sensor models against closed forms: tooth-wheel speeds (edge timing, counting, pitch
errors, dropouts), the lagged pressure sensor, the sump-temperature sensor, the CAN torque signal."""

import math

import numpy as np
import pytest

from clutchocp.physics.viscosity import walther_coefficients, walther_kinematic_viscosity
from clutchocp.shiftcontrol.sensors import (
    EngineTorqueSignal,
    PressureSensor,
    SpeedSensor,
    SumpSensor,
    pitch_pattern,
)

TS = 0.01


def _run(channel, speed_of_t, t_end, step=1e-3):
    """Feed a channel the speed w(t) on a 1 ms grid and read it at every TCU sample up to t_end."""
    readings, t_prev = [], 0.0
    for k in range(1, int(round(t_end / TS)) + 1):
        t = np.linspace(t_prev, k * TS, int(round(TS / step)) + 1)
        channel.advance(t, speed_of_t(t))
        readings.append(channel.read(k * TS))
        t_prev = k * TS
    return np.array(readings)


def _window(channel, t):
    """True times of the edges the edge-timing reading at t uses (the last before t - Ts and those since)."""
    stamps, true = np.asarray(channel.stamps), np.asarray(channel.true_times)
    inside = np.count_nonzero((stamps <= t) & (stamps > t - TS))
    seen = true[stamps <= t]
    return seen[-(inside + 1):]


@pytest.mark.parametrize("speed", [40.0, 150.0, 310.0])
def test_edge_timing_of_a_constant_speed_is_exact_within_the_timer_tick(speed):
    sensor = SpeedSensor("edge_timing", teeth=60, timer_resolution=1e-6)
    for seed in range(5):
        channel = sensor.realize(np.random.default_rng(seed), speed, sample_time=TS)
        readings = _run(channel, lambda t: np.full_like(t, speed), 0.1)
        t_k = np.arange(1, readings.size + 1) * TS
        spans = np.array([np.ptp(_window(channel, t)) for t in t_k])
        # two stamps each floor-quantised: the span is off by less than one tick
        assert np.all(np.abs(readings / speed - 1.0) <= 1e-6 / (spans - 1e-6) + 1e-12)
    fine = SpeedSensor("edge_timing", teeth=60, timer_resolution=1e-13).realize(np.random.default_rng(0), speed)
    assert _run(fine, lambda t: np.full_like(t, speed), 0.05) == pytest.approx(speed, rel=1e-9)


def test_edge_timing_of_a_linear_ramp_is_the_mean_speed_over_its_window():
    """w = w0 + a t: the angle is quadratic, and the reading is the window's angle over its time,
    w0 + a (e_0 + e_n) / 2 (fine timer, no pitch error)."""
    w0, a = 150.0, 800.0
    sensor = SpeedSensor("edge_timing", teeth=60, timer_resolution=1e-13)
    channel = sensor.realize(np.random.default_rng(4), w0)
    readings = _run(channel, lambda t: w0 + a * t, 0.08)
    for k, value in enumerate(readings, start=1):
        e = _window(channel, k * TS)
        if e[0] >= 0.0:                        # (before t = 0 the shaft turned at w0)
            assert value == pytest.approx(w0 + a * 0.5 * (e[0] + e[-1]), rel=1e-9)


def test_pitch_errors_give_the_known_periodic_pattern():
    """Tooth m spans (2 pi / Z)(1 + eps_m): a reading over n teeth at a constant speed is w n pitch / (angle
    the n teeth span), and the readings repeat every revolution (sample time a whole fraction of it)."""
    Z, e = 60, 0.005
    sensor = SpeedSensor("edge_timing", teeth=Z, timer_resolution=1e-13, pitch_error=e)
    rng = np.random.default_rng(7)
    pattern = pitch_pattern(Z, e, np.random.default_rng(7))
    assert np.all(np.abs(np.diff(np.append(pattern, 2 * math.pi)) / (2 * math.pi / Z) - 1) <= 2 * e)
    speed = 2 * math.pi / (5 * TS)             # one revolution in five samples
    channel = sensor.realize(rng, speed)
    readings = _run(channel, lambda t: np.full_like(t, speed), 0.2)
    np.testing.assert_allclose(channel.edges, pattern, rtol=0, atol=1e-15)
    for k, value in enumerate(readings, start=1):
        e_win = _window(channel, k * TS)
        first = int(np.argmin(np.abs(np.asarray(channel.true_times) - e_win[0])))
        index = [j for j in range(10 * Z) if abs(channel.edge_angle(j) - channel.edge_angle(0)
                                                  - speed * (e_win[0] - channel.true_times[0])) < 1e-9]
        n = e_win.size - 1
        span = channel.edge_angle(index[0] + n) - channel.edge_angle(index[0])
        assert value == pytest.approx(speed * n * (2 * math.pi / Z) / span, rel=1e-9), (k, first)
    assert readings[5:] == pytest.approx(readings[:-5], rel=1e-9)
    assert np.max(np.abs(readings / speed - 1)) > 1e-4        # the pattern is there


def test_counting_gives_whole_edges_per_sample():
    """Counting over Ts: floor(Z w Ts / 2 pi) or one more edges; over many samples the mean is w."""
    Z, speed = 60, 157.0
    sensor = SpeedSensor("counting", teeth=Z)
    channel = sensor.realize(np.random.default_rng(1), speed)
    readings = _run(channel, lambda t: np.full_like(t, speed), 1.0)
    counts = readings * TS / (2 * math.pi / Z)
    whole = math.floor(Z * speed * TS / (2 * math.pi))
    assert np.all(np.isin(np.rint(counts), [whole, whole + 1]))
    np.testing.assert_allclose(counts, np.rint(counts), atol=1e-9)
    assert np.mean(readings) == pytest.approx(speed, abs=2 * (2 * math.pi / Z) / TS / readings.size)
    # a window starting just after an edge counts exactly floor(Z w Ts / 2 pi) (the next edge is one pitch on)
    stamps = np.asarray(channel.stamps)
    t0 = stamps[stamps > 0.5][0] + 1e-9
    exact = np.count_nonzero((stamps > t0) & (stamps <= t0 + TS))
    assert exact == whole


def test_missed_edges_are_bridged_by_the_plausibility_check():
    speed, q = 180.0, 1e-6
    sensor = SpeedSensor("edge_timing", teeth=60, timer_resolution=q, dropout=0.1)
    channel = sensor.realize(np.random.default_rng(2), speed)
    readings = _run(channel, lambda t: np.full_like(t, speed), 0.2)
    recorded = len(channel.stamps)
    passed = channel._next
    assert recorded < 0.95 * passed                      # edges were missed ...
    assert np.all(np.abs(readings / speed - 1.0) < 1e-6 / 0.008)       # ... and the readings keep the tick bound


def test_reading_variance_matches_the_sensor_model():
    """The variance the Kalman filter is designed with against the spread of many realised sensors (speeds
    drawn over a band, so that a count's fractional part is spread as the model averages it)."""
    for sensor in (SpeedSensor("edge_timing", teeth=60, timer_resolution=1e-6, pitch_error=0.005),
                   SpeedSensor("edge_timing", teeth=60, timer_resolution=1e-6, pitch_error=0.005,
                               learned_revolutions=50),
                   SpeedSensor("edge_timing", teeth=60, timer_resolution=2e-5),
                   SpeedSensor("counting", teeth=60),
                   SpeedSensor("ideal", noise=0.3)):
        squares, predicted = [], []
        for seed in range(200):
            rng = np.random.default_rng(seed)
            speed = rng.uniform(200.0, 240.0)
            channel = sensor.realize(rng, speed)
            squares.extend((_run(channel, lambda t: np.full_like(t, speed), 0.05) - speed) ** 2)
            predicted.append(sensor.variance(speed, TS))
        assert np.mean(squares) == pytest.approx(np.mean(predicted), rel=0.25), sensor


def test_pressure_sensor_lag_offset_and_noise():
    tau = 0.004
    sensor = PressureSensor(lag=tau)
    channel = sensor.realize(np.random.default_rng(0), 0.0)
    # a ramp p = s t from rest: y = s (t - tau (1 - exp(-t / tau)))
    s = 2e7
    t = np.linspace(0.0, 0.02, 21)
    channel.advance(t, s * t)
    for ti in (0.003, 0.01, 0.02):
        assert channel.read(ti) == pytest.approx(s * (ti - tau * (1 - math.exp(-ti / tau))), rel=1e-3)
    assert channel.read(0.02) == pytest.approx(s * (0.02 - tau * (1 - math.exp(-0.02 / tau))), rel=1e-12)
    offsets = [PressureSensor(offset=1e4).realize(np.random.default_rng(i), 5e5).offset for i in range(200)]
    assert max(np.abs(offsets)) <= 1e4 and np.std(offsets) == pytest.approx(1e4 / math.sqrt(3), rel=0.15)
    noisy = PressureSensor(noise=5e3).realize(np.random.default_rng(1), 5e5)
    noisy.advance([0.0, 0.01], [5e5, 5e5])
    values = [noisy.read(0.01) for _ in range(2000)]
    assert np.mean(values) == pytest.approx(5e5, abs=3 * 5e3 / math.sqrt(2000))
    assert np.std(values) == pytest.approx(5e3, rel=0.1)


def test_sump_sensor_inverts_the_walther_line():
    sump = SumpSensor(error_C=3.0, nu_40C=80.12e-6, nu_100C=9.5e-6, density=850.0)
    A, B = walther_coefficients(40.0, 80.12e-6, 100.0, 9.5e-6)
    for theta in (20.0, 40.0, 43.0, 80.0):
        eta = 850.0 * walther_kinematic_viscosity(theta, A, B)
        assert sump.temperature(eta) == pytest.approx(theta, abs=1e-9)
        assert sump.believed_viscosity(eta, 0.0) == eta
        assert sump.believed_viscosity(eta, 3.0) == pytest.approx(850.0 * walther_kinematic_viscosity(theta + 3, A, B),
                                                                  rel=1e-12)
    errors = [sump.realize(np.random.default_rng(i)) for i in range(300)]
    assert max(np.abs(errors)) <= 3.0 and min(errors) < -2.5 and max(errors) > 2.5


def test_engine_torque_signal_delay_and_error():
    ramp = lambda t: 150.0 + 1000.0 * t                      # noqa: E731
    plant = EngineTorqueSignal("plant", error=0.05, delay=0.02)
    error = plant.realize(np.random.default_rng(3))
    assert abs(error) <= 0.05
    assert plant.read(0.1, ramp, 150.0, error) == pytest.approx((1 + error) * ramp(0.08), rel=1e-12)
    assert plant.read(0.01, ramp, 150.0, error) == pytest.approx((1 + error) * 150.0, rel=1e-12)   # before t = 0: held
    told = EngineTorqueSignal("nominal")
    assert told.read(0.1, ramp, 150.0, 0.0) == 150.0
