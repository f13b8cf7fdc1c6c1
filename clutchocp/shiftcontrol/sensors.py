"""What the TCU reads: shaft speeds from tooth wheels, the clutch pressure, the sump temperature, the
engine torque over CAN; each a small model of the real signal chain, tested against closed forms.

Every sensor is declared as plain data (a frozen dataclass made from the spec's ``[sensors.*]``
tables) and *realised* for one clutch with a random generator (:meth:`realize`): the tooth-pitch
pattern of its wheel, the phase of its timer, its pressure offset, its sump-sensor error, its
torque-signal error are drawn then, so a Monte Carlo sample is one transmission with one set of
sensors, reproducible from its seed. A realised channel is fed the plant's signal as the
simulation produces it (:meth:`advance`, output points between which the signal is linear) and
read at the TCU samples (:meth:`read`).

Speed from a tooth wheel (teeth Z, nominal pitch 2 pi / Z; tooth m spans (2 pi / Z)(1 + eps_m),
eps_m uniform in +-``pitch_error``, their mean removed so that the wheel closes):

* ``edge_timing``: a capture timer of resolution q stamps each edge (t_q = floor(t / q) q, the
  timer's phase random). At t_k the TCU takes the last edge before the previous sample and the
  edges since, e_0 < ... < e_n, and reports w = (angle from e_0 to e_n) / (e_n - e_0), the angle
  being the teeth counted between them times 2 pi / Z (the TCU counts its teeth; a missed edge is a
  gap of two periods and counts two), or the learned angles of those edges (``learned_revolutions``).
  At a constant speed w this is w within the quantisation, |w_meas / w - 1| <= q / (e_n - e_0);
  with pitch errors it is w n / (n + sum eps) over the n teeth passed.
* ``counting``: the edges in the last sample (t_{k-1}, t_k] times 2 pi / (Z Ts): at a constant speed
  floor(Z w Ts / 2 pi) or one more.
* ``ideal``: the plant's speed at t_k.

Every speed channel may add white noise (``noise`` [rad/s], standard deviation). The variance a
Kalman filter is designed with (:meth:`SpeedSensor.variance`) is that of these errors at a constant
speed: w^2 (q^2 / (6 Ts^2) + pitch_error^2 r (1 - r / Z) / (3 n^2)) + noise^2 for edge timing (two
independent quantised stamps; n = w Ts Z / 2 pi teeth passed, of which the r = n mod Z beyond whole
revolutions carry the error of r of Z uniform errors whose sum over the wheel is zero),
(2 pi / (Z Ts))^2 / 6 + noise^2 for counting
(the count's fractional part f makes it one edge off with probability f; f (1 - f) averaged over a
uniform f is 1/6), noise^2 for an ideal sensor.
"""

import math
from dataclasses import dataclass, replace

import numpy as np

from ..errors import ModelError
from ..physics.viscosity import KELVIN, walther_coefficients, walther_kinematic_viscosity

SPEED_METHODS = ("ideal", "edge_timing", "counting")
HISTORY_SAMPLES = 2        # constant-speed edges generated before t = 0 (the shafts turn before the shift)


@dataclass(frozen=True)
class SpeedSensor:
    """A shaft-speed sensor (see the module docstring).

    Parameters
    ----------
    method : {"ideal", "edge_timing", "counting"}
    teeth : int
        Teeth of the wheel, Z.
    timer_resolution : float
        Capture-timer tick q [s] (edge timing).
    pitch_error : float
        Half-width of each tooth's relative pitch error (uniform), e.g. 0.005.
    dropout : float
        Probability that an edge is missed, in [0, 1).
    noise : float
        Standard deviation of white noise added to each reading [rad/s].
    learned_revolutions : int
        Revolutions at steady speed over which the TCU has learned its wheel's tooth pitches before the
        shift (0: it takes every pitch as 2 pi / Z). The learning is simulated: the same timer stamps the
        edges of that many revolutions at the speed before the shift, and each edge's learned angle is its
        mean share of the revolution time (tooth-error adaptation).
    """

    method: str = "ideal"
    teeth: int = 60
    timer_resolution: float = 1e-6
    pitch_error: float = 0.0
    dropout: float = 0.0
    noise: float = 0.0
    learned_revolutions: int = 0

    def __post_init__(self):
        if self.method not in SPEED_METHODS:
            raise ModelError(f"speed sensor method {self.method!r}: allowed values are {', '.join(SPEED_METHODS)}")

    @property
    def averages(self):
        """True when a reading is the shaft's mean speed over the last sample (a tooth wheel), not its speed at t_k."""
        return self.method != "ideal"

    def realize(self, rng, speed, t0=0.0, sample_time=0.01):
        """The sensor on one shaft turning at ``speed`` [rad/s] before ``t0`` [s]: a :class:`SpeedChannel`."""
        return SpeedChannel(self, rng, speed, t0, sample_time)

    def variance(self, speed, sample_time):
        """Variance of a reading at a constant ``speed`` [rad/s] over a sample of ``sample_time`` [s], (rad/s)^2."""
        noise = self.noise ** 2
        if self.method == "ideal":
            return noise
        pitch = 2 * math.pi / self.teeth
        if self.method == "counting":
            return (pitch / sample_time) ** 2 / 6.0 + noise
        if self.learned_revolutions:
            # learned pitches: the reading's error is that of its two boundary edges (independent of each other)
            return 2 * self.boundary_variance(speed) / sample_time ** 2 + noise
        n = max(abs(speed) * sample_time / pitch, 1.0)         # teeth passed in one sample
        r = n % self.teeth                                     # whole revolutions carry no pitch error
        pitch_sum = self.pitch_error ** 2 / 3 * r * (1 - r / self.teeth)     # var of the sum of r of Z closing errors
        return speed ** 2 * (self.timer_resolution ** 2 / (6 * sample_time ** 2) + pitch_sum / n ** 2) + noise

    def boundary_variance(self, speed):
        """Variance [rad^2] of the angle error at the edge that ends a reading's window (and starts the next one's).

        A tooth-wheel reading is the angle between two boundary edges over their time, so its error is
        (E_k - E_k-1) / Ts with E the angle error at the boundary: the cumulative pitch error of the edge,
        p^2 (pitch_error^2 / 3) Z / 6 averaged over the wheel (a bridge of Z uniform errors that closes),
        and the timer's error as an angle, speed^2 q^2 / 12 (edge timing), or the count's fractional part,
        p^2 / 12 (counting). Consecutive readings share their boundary: their errors are anticorrelated.
        """
        if self.method == "ideal":
            return 0.0
        pitch = 2 * math.pi / self.teeth
        teeth = pitch ** 2 * self.pitch_error ** 2 / 3 * self.teeth / 6
        if self.method == "counting":
            return teeth + pitch ** 2 / 12
        stamp = speed ** 2 * self.timer_resolution ** 2 / 12
        if self.learned_revolutions:
            # the learned angle of an edge: from three stamps per revolution, averaged over the revolutions
            teeth = 2 * stamp / self.learned_revolutions
        return teeth + stamp

    def reading_time(self, t, sample_time, speed):
        """The time a reading at t stands for, on average [s]: t (ideal), the middle of the last sample
        (counting), that less half a tooth period (edge timing: the window ends at the last edge)."""
        if self.method == "ideal":
            return t
        lag = math.pi / (self.teeth * speed) if self.method == "edge_timing" and speed > 0 else 0.0
        return t - 0.5 * sample_time - lag

    def describe(self):
        """One line for reports."""
        if self.method == "ideal":
            return "ideal" + (f", noise {self.noise:g} rad/s" if self.noise else "")
        parts = [f"{self.teeth}-tooth wheel, {self.method.replace('_', ' ')}"]
        if self.method == "edge_timing":
            parts.append(f"timer {self.timer_resolution * 1e6:g} us")
        if self.pitch_error:
            parts.append(f"pitch error +-{100 * self.pitch_error:g} %")
        if self.learned_revolutions:
            parts.append(f"pitches learned over {self.learned_revolutions} revolutions")
        if self.dropout:
            parts.append(f"dropout {self.dropout:g}")
        if self.noise:
            parts.append(f"noise {self.noise:g} rad/s")
        return ", ".join(parts)


def pitch_pattern(teeth, pitch_error, rng):
    """Angles [rad] of the edges of one revolution, the first at 0: cumulative pitches (2 pi / Z)(1 + eps_m),
    eps_m uniform in +-pitch_error with their mean removed (the wheel closes: the pitches sum to 2 pi)."""
    eps = rng.uniform(-pitch_error, pitch_error, teeth) if pitch_error else np.zeros(teeth)
    pitches = (2 * math.pi / teeth) * (1.0 + eps - eps.mean())
    return np.concatenate([[0.0], np.cumsum(pitches)[:-1]])


class SpeedChannel:
    """One realised speed sensor on one shaft (see :class:`SpeedSensor`)."""

    def __init__(self, sensor, rng, speed, t0, sample_time):
        self.sensor = sensor
        self.rng = rng
        self.Ts = float(sample_time)
        self._t, self._w = float(t0), float(speed)
        if sensor.method == "ideal":
            self._history = (np.array([self._t]), np.array([self._w]))
            return
        self.edges = pitch_pattern(sensor.teeth, sensor.pitch_error, rng)
        self._phase = rng.uniform(0.0, 2 * math.pi / sensor.teeth)          # angle of edge 0 at the start
        self._timer_phase = rng.uniform(0.0, sensor.timer_resolution)
        self._angle = 0.0                     # shaft angle at self._t [rad]
        self._next = 0                        # index of the next edge to pass
        self.stamps = []                      # recorded (quantised) edge times [s]
        self.true_times = []                  # the exact times of the recorded edges [s]
        self.teeth_seen = []                  # the edge number of each recorded edge (the TCU counts its teeth)
        self.learned = self._learn(speed) if sensor.learned_revolutions else \
            np.arange(sensor.teeth) * (2 * math.pi / sensor.teeth)
        start = t0 - HISTORY_SAMPLES * sample_time
        self._t = start
        self.advance(np.array([start, t0]), np.array([speed, speed]))

    def _learn(self, speed):
        """Learned edge angles of one revolution (edge 0 at 0): the mean share of the revolution time of each
        edge over ``learned_revolutions`` revolutions at ``speed``, stamped by the same timer."""
        Z, R, q = self.sensor.teeth, self.sensor.learned_revolutions, self.sensor.timer_resolution
        angles = self.edges[None, :] + 2 * math.pi * np.arange(R)[:, None]          # (R, Z) from edge 0
        angles = np.append(angles.ravel(), 2 * math.pi * R)
        stamps = np.floor((angles / speed + self._timer_phase) / q) * q if q > 0 else angles / speed
        start = stamps[:-1:Z]
        shares = (stamps[:-1].reshape(R, Z) - start[:, None]) / (stamps[Z::Z] - start)[:, None]
        return 2 * math.pi * shares.mean(axis=0)

    def learned_angle(self, j):
        """The angle [rad] the TCU takes for edge j (its learned pitches, or j 2 pi / Z)."""
        Z = self.sensor.teeth
        return (j // Z) * 2 * math.pi + self.learned[j % Z]

    def edge_angle(self, j):
        """Angle [rad] of edge j (counted from the start, j = 0, 1, ...)."""
        Z = self.sensor.teeth
        return self._phase + (j // Z) * 2 * math.pi + self.edges[j % Z]

    def advance(self, t, w):
        """Feed the shaft speed at output points ``t`` [s] (from the last time fed on; linear in between)."""
        t, w = np.asarray(t, float), np.asarray(w, float)
        if self.sensor.method == "ideal":
            self._t, self._w = float(t[-1]), float(w[-1])
            self._history = (t, w)
            return
        for i in range(t.size - 1):
            h = t[i + 1] - t[i]
            if h <= 0.0:
                continue
            w0, a = w[i], (w[i + 1] - w[i]) / h
            angle_end = self._angle + h * (w0 + 0.5 * a * h)
            while self.edge_angle(self._next) <= angle_end:
                # theta(tau) = angle + w0 tau + a tau^2 / 2 = edge angle: the root in [0, h]
                d = self.edge_angle(self._next) - self._angle
                disc = max(w0 * w0 + 2 * a * d, 0.0)
                tau = 2 * d / (w0 + math.sqrt(disc)) if w0 + math.sqrt(disc) > 0 else h
                self._record(t[i] + min(max(tau, 0.0), h))
                self._next += 1
            self._angle = angle_end
        self._t, self._w = float(t[-1]), float(w[-1])

    def _record(self, t_edge):
        if self.sensor.dropout and self.rng.uniform() < self.sensor.dropout:
            return
        q = self.sensor.timer_resolution
        stamp = math.floor((t_edge + self._timer_phase) / q) * q - self._timer_phase if q > 0 else t_edge
        self.stamps.append(stamp)
        self.true_times.append(t_edge)
        self.teeth_seen.append(self._next)

    def read(self, t):
        """The speed reading at the TCU sample ``t`` [s] (the channel fed up to ``t`` at least).

        ``self.time`` is then the time the reading stands for [s]: t for an ideal sensor, the middle of the
        window for a tooth wheel (its mean speed is the speed there, for a speed linear in time; the TCU
        knows it from its stamps, the window's ends)."""
        s = self.sensor
        self.time = t if s.method == "ideal" else t - 0.5 * self.Ts
        value = self._exact(t) if s.method == "ideal" else self._from_edges(t)
        return value + (s.noise * self.rng.standard_normal() if s.noise else 0.0)

    def _exact(self, t):
        tt, ww = self._history
        return float(np.interp(t, tt, ww))

    def _from_edges(self, t):
        stamps = np.asarray(self.stamps)
        pitch = 2 * math.pi / self.sensor.teeth
        seen = stamps[stamps <= t]
        if self.sensor.method == "counting":
            return float(np.count_nonzero(seen > t - self.Ts)) * pitch / self.Ts
        inside = np.count_nonzero(seen > t - self.Ts)
        window = seen[-(inside + 1):] if seen.size > inside else seen      # plus the last edge before
        if window.size < 2:
            window = seen[-2:]
        if window.size < 2:
            return 0.0
        span = window[-1] - window[0]
        if span <= 0:
            return 0.0
        self.time = 0.5 * (window[0] + window[-1])
        # the angle between the window's edges: the teeth counted between them (a missed edge shows as a
        # gap of two periods and counts two), with the learned pitches when the TCU has learned them
        last = len(seen) - 1
        first = last - (window.size - 1)
        return float((self.learned_angle(self.teeth_seen[last]) - self.learned_angle(self.teeth_seen[first])) / span)


def first_order_lag(t, p, lag, y0):
    """Output y(t) of dy/dt = (p - y) / lag from y(t_0) = y0, for p linear between the points ``t`` (exact):
    over a step of h with slope s, y - p + lag s decays as exp(-h / lag). ``lag`` = 0: y = p."""
    t, p = np.asarray(t, float), np.asarray(p, float)
    if lag <= 0:
        return p.copy()
    y = np.empty_like(p)
    y[0] = y0
    for i in range(t.size - 1):
        h = t[i + 1] - t[i]
        if h <= 0.0:
            y[i + 1] = y[i]
            continue
        s = (p[i + 1] - p[i]) / h
        y[i + 1] = p[i + 1] - lag * s + (y[i] - p[i] + lag * s) * math.exp(-h / lag)
    return y


@dataclass(frozen=True)
class PressureSensor:
    """The clutch-pressure sensor: first-order lag, a constant offset per unit, white noise.

    Parameters
    ----------
    noise : float
        Standard deviation of a reading's noise [Pa].
    offset : float
        Half-width of the unit's offset [Pa] (uniform, drawn once per clutch).
    lag : float
        Time constant of the sensor [s] (0: none); the reading follows dy/dt = (p - y) / lag.
    """

    noise: float = 0.0
    offset: float = 0.0
    lag: float = 0.0

    def realize(self, rng, pressure):
        """The sensor of one clutch, reading ``pressure`` [Pa] at the start: a :class:`PressureChannel`."""
        return PressureChannel(self, rng, pressure)

    def describe(self):
        return (f"noise {self.noise / 1e3:g} kPa, offset +-{self.offset / 1e3:g} kPa, lag {self.lag * 1e3:g} ms"
                if (self.noise or self.offset or self.lag) else "ideal")


class PressureChannel:
    """One realised pressure sensor (see :class:`PressureSensor`)."""

    def __init__(self, sensor, rng, pressure):
        self.sensor = sensor
        self.rng = rng
        self.offset = rng.uniform(-sensor.offset, sensor.offset) if sensor.offset else 0.0
        self._t, self._y = 0.0, float(pressure)
        self._times, self._values = [0.0], [self._y]

    def advance(self, t, p):
        """Feed the true pressure at output points ``t`` [s] (linear in between): the lag integrated exactly."""
        t, p = np.asarray(t, float), np.asarray(p, float)
        y = first_order_lag(t, p, self.sensor.lag, self._y)
        self._y = float(y[-1])
        self._times += list(t[1:])
        self._values += list(y[1:])
        self._t = float(t[-1])
        del self._times[:-64], self._values[:-64]

    def read(self, t):
        """The reading at ``t`` [Pa] (lagged pressure + offset + noise)."""
        y = float(np.interp(t, self._times, self._values))
        return y + self.offset + (self.sensor.noise * self.rng.standard_normal() if self.sensor.noise else 0.0)


@dataclass(frozen=True)
class SumpSensor:
    """The sump-temperature sensor through which the TCU knows the oil viscosity.

    The oil follows Walther's line (ASTM D341) through its datasheet viscosities; the TCU reads the
    temperature theta + e with e uniform in +-``error_C`` (drawn once per clutch) and takes the
    viscosity of that temperature. :meth:`believed_viscosity` maps the oil's true viscosity to the
    one the TCU believes.

    Parameters
    ----------
    error_C : float
        Half-width of the temperature error [deg C].
    nu_40C, nu_100C : float
        Kinematic viscosity of the oil at 40 and 100 deg C [m^2/s].
    density : float
        Oil density [kg/m^3].
    """

    error_C: float = 0.0
    nu_40C: float = 8.012e-5
    nu_100C: float = 9.5e-6
    density: float = 850.0

    def realize(self, rng):
        """The temperature error of one clutch's sensor [deg C]."""
        return rng.uniform(-self.error_C, self.error_C) if self.error_C else 0.0

    def temperature(self, viscosity):
        """The oil temperature [deg C] of a dynamic ``viscosity`` [Pa s] on the oil's Walther line."""
        A, B = walther_coefficients(40.0, self.nu_40C, 100.0, self.nu_100C)
        z = math.log10(math.log10(viscosity / self.density * 1e6 + 0.7))
        return 10.0 ** ((A - z) / B) - KELVIN

    def viscosity(self, temperature):
        """Dynamic viscosity [Pa s] of the oil at ``temperature`` [deg C]."""
        A, B = walther_coefficients(40.0, self.nu_40C, 100.0, self.nu_100C)
        return self.density * walther_kinematic_viscosity(temperature, A, B)

    def believed_viscosity(self, viscosity, error):
        """The viscosity [Pa s] the TCU takes for an oil of ``viscosity`` read ``error`` [deg C] off."""
        if not error:
            return float(viscosity)
        return float(self.viscosity(self.temperature(viscosity) + error))

    def describe(self):
        return f"+-{self.error_C:g} degC" if self.error_C else "ideal"


@dataclass(frozen=True)
class EngineTorqueSignal:
    """The engine torque the TCU is told over CAN.

    Parameters
    ----------
    source : {"nominal", "plant"}
        ``"nominal"``: the nominal scene's torque, whatever the plant's (a torque model calibrated on
        the nominal engine; the plant's spread is the scene's ``driveline.input_torque`` uncertainty);
        ``"plant"``: the plant's own torque, with the error and delay below.
    error : float
        Half-width of the signal's relative error (uniform, drawn once per clutch).
    delay : float
        Age of the signal when the TCU reads it [s].
    """

    source: str = "nominal"
    error: float = 0.0
    delay: float = 0.0

    def realize(self, rng):
        """The relative error of one clutch's signal."""
        return rng.uniform(-self.error, self.error) if self.error else 0.0

    def read(self, t, torque_at, nominal, error):
        """The torque signal at ``t`` [s]: (1 + error) x the nominal torque, or the plant's ``torque_at(t - delay)``."""
        base = nominal if self.source == "nominal" else torque_at(max(t - self.delay, 0.0))
        return (1.0 + error) * float(base)

    def describe(self):
        text = "nominal engine torque" if self.source == "nominal" else "plant engine torque"
        if self.error:
            text += f", +-{100 * self.error:g} %"
        if self.delay:
            text += f", {self.delay * 1e3:g} ms old"
        return text


@dataclass(frozen=True)
class ValveTiming:
    """The valve's dead time as the plant has it and as the TCU believes it [s].

    The plant's valve follows the command ``dead_time`` later (its lag is the scene's
    ``actuation.time_constant``); the TCU designs with ``assumed_dead_time`` and sends its feedforward
    that much early.
    """

    dead_time: float = 0.0
    assumed_dead_time: float = 0.0

    def describe(self):
        return f"dead time {self.dead_time * 1e3:g} ms (TCU assumes {self.assumed_dead_time * 1e3:g} ms)"


@dataclass(frozen=True)
class Sensors:
    """Everything the TCU reads, as declared in the spec (plain data)."""

    input_speed: SpeedSensor = SpeedSensor()
    output_speed: SpeedSensor = SpeedSensor()
    pressure: PressureSensor | None = PressureSensor()
    sump: SumpSensor | None = None
    engine_torque: EngineTorqueSignal = EngineTorqueSignal()
    valve: ValveTiming = ValveTiming()

    @property
    def ideal(self):
        """True when every reading is the plant's exact value (the TCU of the design)."""
        return (self.input_speed == SpeedSensor() and self.output_speed == SpeedSensor()
                and (self.pressure is None or self.pressure == PressureSensor())
                and (self.sump is None or not self.sump.error_C)
                and self.engine_torque == EngineTorqueSignal() and self.valve == ValveTiming())

    def nominal(self):
        """The same sensors without their unit errors (pitch errors, pressure offset, sump and torque-signal errors):
        what a nominal transmission has; noise, quantisation, lags and delays stay."""
        def speed(sensor):
            return replace(sensor, pitch_error=0.0, dropout=0.0)

        return replace(self, input_speed=speed(self.input_speed), output_speed=speed(self.output_speed),
                       pressure=replace(self.pressure, offset=0.0) if self.pressure is not None else None,
                       sump=replace(self.sump, error_C=0.0) if self.sump is not None else None,
                       engine_torque=replace(self.engine_torque, error=0.0))

    def describe(self):
        """The sensor models, for summary.json."""
        return {"input_speed": self.input_speed.describe(), "output_speed": self.output_speed.describe(),
                "pressure": self.pressure.describe() if self.pressure is not None else "none",
                "sump_temperature": self.sump.describe() if self.sump is not None else "none (viscosity known)",
                "engine_torque": self.engine_torque.describe(), "valve": self.valve.describe()}

    def realize(self, rng, initial, sample_time):
        """The sensors of one clutch: a :class:`SensorSet`; ``initial`` holds w_in, w_out [rad/s], p_valve [Pa]."""
        return SensorSet(self, rng, initial, sample_time)


class SensorSet:
    """The realised sensors of one clutch and their per-clutch draws (``draws``, for the samples table)."""

    def __init__(self, sensors, rng, initial, sample_time):
        self.sensors = sensors
        self.speeds = {"w_in": sensors.input_speed.realize(rng, initial["w_in"], 0.0, sample_time),
                       "w_out": sensors.output_speed.realize(rng, initial["w_out"], 0.0, sample_time)}
        self.pressure = None
        if sensors.pressure is not None and "p_valve" in initial:
            self.pressure = sensors.pressure.realize(rng, initial["p_valve"])
        self.sump_error = sensors.sump.realize(rng) if sensors.sump is not None else 0.0
        self.torque_error = sensors.engine_torque.realize(rng)
        self.draws = {"sump_temperature_error_C": self.sump_error, "engine_torque_signal_error": self.torque_error,
                      "pressure_offset_Pa": self.pressure.offset if self.pressure is not None else 0.0}

    def advance(self, t, w_in, w_out, p=None):
        """Feed the plant's speeds [rad/s] and pressure [Pa] at output points ``t`` [s]."""
        self.speeds["w_in"].advance(t, w_in)
        self.speeds["w_out"].advance(t, w_out)
        if self.pressure is not None and p is not None:
            self.pressure.advance(t, p)

    def read(self, t):
        """The readings at ``t`` [s]: ``w_in``, ``w_out`` [rad/s] and ``p_valve`` [Pa] (with a pressure sensor);
        ``time:w_in``, ``time:w_out``: the times the speed readings stand for [s] (see :meth:`SpeedChannel.read`)."""
        out = {name: channel.read(t) for name, channel in self.speeds.items()}
        out.update({f"time:{name}": channel.time for name, channel in self.speeds.items()})
        if self.pressure is not None:
            out["p_valve"] = self.pressure.read(t)
        return out

    def viscosity(self, true_viscosity):
        """The oil viscosity [Pa s] the TCU believes for the clutch's ``true_viscosity``."""
        if self.sensors.sump is None:
            return float(true_viscosity)
        return self.sensors.sump.believed_viscosity(true_viscosity, self.sump_error)


def sensors_from_spec(spec, scene):
    """The :class:`Sensors` a slip-control spec declares, for a scene (its oil for the sump sensor).

    Raises
    ------
    ModelError
        A sump sensor on a scene whose oil has no viscosity-temperature law and no datasheet in the spec.
    """
    tables = spec.sensors

    def speed(name):
        t = tables.get(name)
        if t is None:
            return SpeedSensor()
        return SpeedSensor(t["method"], int(t["teeth"]), t["timer_resolution"], t["pitch_error"], t["dropout"],
                           t["noise"], int(t["learned_revolutions"]))

    pressure = None
    if spec.measure_pressure:
        t = tables.get("pressure")
        pressure = PressureSensor(t["noise"], t["offset"], t["lag"]) if t is not None else PressureSensor()
    sump = None
    if "sump_temperature" in tables:
        t = tables["sump_temperature"]
        nu_40, nu_100 = t["oil_viscosity_40C"], t["oil_viscosity_100C"]
        if nu_40 is None:
            if (scene.variant("oil") or "constant") != "walther":
                raise ModelError("sensors.sump_temperature: the scene's oil has a constant viscosity; give the oil's "
                                 "datasheet (oil_viscosity_40C, oil_viscosity_100C) so the TCU can turn a temperature "
                                 "into a viscosity")
            nu_40, nu_100 = scene.value("oil.kinematic_viscosity_40C"), scene.value("oil.kinematic_viscosity_100C")
        sump = SumpSensor(t["error_C"], nu_40, nu_100, scene.value("oil.density"))
    t = tables.get("engine_torque")
    torque = EngineTorqueSignal(t["source"], t["error"], t["delay"]) if t is not None else EngineTorqueSignal()
    valve = ValveTiming(spec.valve["dead_time"], spec.valve["assumed_dead_time"])
    return Sensors(speed("input_speed"), speed("output_speed"), pressure, sump, torque, valve)
