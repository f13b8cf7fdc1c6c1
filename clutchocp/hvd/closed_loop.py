"""The sampled-data closed loop on the nonlinear HVD: scenario, simulation and metrics.

The controller runs every Ts; between samples its command is held (zero-order hold) and the
nonlinear DAE is integrated by CasADi IDAS on the simulation engine's compiled, scaled equations
(``model.hybrid.compiled()``, the same functions :func:`clutchocp.simulation.simulate` integrates).
One IDAS integrator over [0, Ts] is built once and called every sample with the held inputs as
parameters. The algebraic squeeze fluxes are made consistent (Newton) at the start and then
carried over from sample to sample: the inputs enter only the ODE, so they are continuous.

Scenario (fractions of the rated speed s_1..s_m, step duration D, soft-start time T_s): soft
start from standstill, the setpoint ramping from 0 to s_1 over T_s and held for D; setpoint steps
to s_2, ..., s_m at T_s + D, T_s + 2D, ...; at the last setpoint a load step of +``load_step`` x the
fan torque at T_s + m D and of -``load_step`` (from nominal) at T_s + (m + 1) D; end at
T_s + (m + 2) D. Metrics are taken per segment against the raw setpoint (see
:func:`closed_loop_metrics`).
"""

from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from .. import interrupt
from ..errors import SolverError
from .steady import rest_state

SETTLING_BAND = 0.02        # 2 % of the step size
STEADY_WINDOW = 1.0         # [s] at the end of a segment for the steady-state error
CYCLE_WINDOW = 2.0          # [s] at the end of a segment for the limit-cycle check
LIMIT_CYCLE_THRESHOLD = 1e-3  # oscillation (peak-to-peak, relative) counted as a limit cycle


@dataclass
class Scenario:
    """Reference and load-torque schedule of a closed-loop test (SI)."""

    t_end: float
    soft_start_time: float
    setpoints: tuple                # speeds [rad/s]
    step_times: tuple               # times of the setpoint steps after the soft start [s]
    load_times: tuple               # times of the load steps [s]
    load_values: tuple              # load-torque input after each load step [N m]
    segments: list = field(default_factory=list)   # (name, kind, t0, t1, setpoint, step size)

    def setpoint(self, t):
        """Speed setpoint at time t [rad/s]."""
        if t < self.soft_start_time:
            return self.setpoints[0] * t / self.soft_start_time
        k = int(np.searchsorted(self.step_times, t, side="right"))
        return self.setpoints[k]

    def load(self, t):
        """Load-torque input at time t [N m]."""
        k = int(np.searchsorted(self.load_times, t, side="right"))
        return 0.0 if k == 0 else self.load_values[k - 1]


def make_scenario(model, spec):
    """The closed-loop test of a controller spec on a model (see the module docstring)."""
    sc = spec.scenario
    fractions = tuple(sc["setpoints"])
    D, T0, rated = sc["step_duration"], sc["soft_start_time"], model.rated_speed
    setpoints = tuple(f * rated for f in fractions)
    m = len(setpoints)
    step_times = tuple(T0 + k * D for k in range(1, m))
    fan = model.load_torque(setpoints[-1])
    load_times = (T0 + m * D, T0 + (m + 1) * D)
    load_values = (sc["load_step"] * fan, -sc["load_step"] * fan)
    segments = [("soft_start", "soft_start", 0.0, T0 + D, setpoints[0], setpoints[0])]
    for k in range(1, m):
        segments.append((f"step_{fractions[k - 1]:g}_to_{fractions[k]:g}", "setpoint", T0 + k * D, T0 + (k + 1) * D,
                         setpoints[k], setpoints[k] - setpoints[k - 1]))
    segments.append((f"load_plus_{sc['load_step']:g}", "load", load_times[0], load_times[1], setpoints[-1], 0.0))
    segments.append((f"load_minus_{sc['load_step']:g}", "load", load_times[1], load_times[1] + D, setpoints[-1], 0.0))
    return Scenario(T0 + (m + 2) * D, T0, setpoints, step_times, load_times, load_values, segments)


class SampledPlant:
    """The nonlinear HVD advanced one sample at a time with a held input (IDAS)."""

    def __init__(self, model, sample_time, rtol=1e-8, atol=1e-8):
        self.model = model
        self.cm = model.hybrid.compiled()["run"]
        self.Ts = float(sample_time)
        self.integrator = ca.integrator("hvd_sample", "idas", self.cm.dae, 0.0, [self.Ts],
                                        {"abstol": atol, "reltol": rtol, "calc_ic": True,
                                         "max_num_steps": 20000})
        self.t = 0.0

    def start(self, x, u, t=0.0):
        """Set the state (SI) and make the algebraic variables consistent for input u."""
        self.t = float(t)
        self.xs = np.asarray(x, float) / self.cm.x_nominal
        self.zs = self.cm.consistent_z(self.xs, np.asarray(u, float), self.t)

    @property
    def x(self):
        return self.xs * self.cm.x_nominal

    def step(self, u):
        """Advance by Ts holding input u; returns the new state (SI)."""
        try:
            r = self.integrator(x0=self.xs, z0=self.zs, p=np.asarray(u, float))
        except RuntimeError as err:
            interrupt.check(f"IDAS (closed loop) at t = {self.t:.6g} s")   # a Ctrl-C fails the step
            state = dict(zip(self.cm.x_names, self.x))
            raise SolverError(f"closed loop: IDAS failed between t = {self.t:.6g} s and {self.t + self.Ts:.6g} s "
                              f"with command {u[0]:.6g} Pa ({err}). State: {state}. Try: a longer valve time "
                              "constant or a smaller sample time") from None
        interrupt.check(f"IDAS (closed loop) at t = {self.t:.6g} s")
        self.xs = np.array(r["xf"], float).ravel()
        self.zs = np.array(r["zf"], float).ravel()
        self.t += self.Ts
        return self.x


@dataclass
class ClosedLoopResult:
    """Samples of a closed-loop run (at the controller's sample times) and its metrics."""

    t: np.ndarray
    series: dict
    metrics: dict
    scenario: Scenario


def simulate_closed_loop(model, controller, scenario, x0=None, rtol=1e-8, atol=1e-8):
    """Run the discrete controller on the nonlinear HVD through a scenario.

    Parameters
    ----------
    model : HvdModel
    controller : ScheduledController
    scenario : Scenario
    x0 : array, optional
        Initial state (default: standstill with the pack held fully open at rest).

    Returns
    -------
    ClosedLoopResult
    """
    Ts = controller.Ts
    n = round(scenario.t_end / Ts)
    if x0 is None:
        p_open = controller.p_max if model.orientation == "spring_applied" else controller.p_min
        x0 = rest_state(model, p_open)
    plant = SampledPlant(model, Ts, rtol, atol)
    x = np.asarray(x0, float)
    controller.reset(setpoint=scenario.setpoint(0.0), x=x, pressure=x[1])
    rows = {k: [] for k in ("t", "setpoint", "reference", "load_input", "command", "command_unsat", "integral")}
    states = []
    plant.start(x, [x[1], scenario.load(0.0)])
    for k in range(n + 1):
        t = k * Ts
        r, load = scenario.setpoint(t), scenario.load(t)
        u, u_unsat = controller.command(r, x)
        rows["t"].append(t)
        rows["setpoint"].append(r)
        rows["reference"].append(controller.reference(r))
        rows["load_input"].append(load)
        rows["command"].append(u)
        rows["command_unsat"].append(u_unsat)
        rows["integral"].append(controller.integral)
        states.append(x.copy())
        if k < n:
            controller.step(r, x)
            x = plant.step([u, load])
    series = {k: np.array(v) for k, v in rows.items()}
    states = np.array(states)
    for j, name in enumerate(model.state_names):
        series[name] = states[:, j]
    series.update(model.evaluate_many(states, np.column_stack([series["command"], series["load_input"]])))
    metrics = closed_loop_metrics(series, scenario, controller, model)
    return ClosedLoopResult(series["t"], series, metrics, scenario)


def _oscillation(t, e):
    """Peak-to-peak of e about its least-squares line (a settling tail leaves almost nothing) [unit of e]."""
    if t.size < 3:
        return 0.0
    trend = np.polyval(np.polyfit(t - t[0], e, 1), t - t[0])
    return float(np.ptp(e - trend))


def closed_loop_metrics(series, scenario, controller, model):
    """Overshoot, 2 % settling, steady-state error, peak pressure rate, time in saturation, limit cycles.

    Per segment (see :class:`Scenario`): ``overshoot_pct`` (setpoint steps: beyond the new setpoint
    in % of the step; soft start: in % of the first setpoint), ``settling_time_s`` (setpoint
    steps: after the step until the speed stays within 2 % of the step size), ``peak_deviation_rel``
    (load steps: largest |w - r| / r), ``recovery_time_s`` (load steps: until |w - r| stays within
    0.5 % of r), ``steady_state_error_rel`` (|mean(w - r)| / r over the last second) and
    ``cycle_amplitude_rel`` (peak-to-peak of (w - r)/r about its trend line over the last two
    seconds: a sustained oscillation shows, a settling tail hardly does). ``limit_cycle`` is
    true if that amplitude exceeds ``LIMIT_CYCLE_THRESHOLD`` anywhere.
    """
    t, w = series["t"], series["w"]
    Ts = controller.Ts
    segments = {}
    for name, kind, t0, t1, ref, step in scenario.segments:
        sel = (t >= t0 - 1e-9) & (t < t1 - 1e-9)
        ts, ws = t[sel], w[sel]
        err = ws - ref
        end = ts >= t1 - STEADY_WINDOW - 1e-9
        cyc = ts >= t1 - CYCLE_WINDOW - 1e-9
        seg = {"t_start_s": t0, "reference_rad_s": ref,
               "steady_state_error_rel": float(abs(np.mean(err[end])) / ref),
               "cycle_amplitude_rel": _oscillation(ts[cyc], err[cyc]) / ref}
        if kind == "setpoint":
            seg["step_rad_s"] = step
            seg["overshoot_pct"] = float(max(0.0, np.max(np.sign(step) * err)) / abs(step) * 100)
            outside = np.nonzero(np.abs(err) > SETTLING_BAND * abs(step))[0]
            seg["settling_time_s"] = float(ts[outside[-1]] + Ts - t0) if outside.size else 0.0
        elif kind == "soft_start":
            after = ts >= scenario.soft_start_time
            seg["overshoot_pct"] = float(max(0.0, np.max(err[after])) / ref * 100)
        else:
            seg["peak_deviation_rel"] = float(np.max(np.abs(err)) / ref)
            outside = np.nonzero(np.abs(err) > 0.005 * ref)[0]
            seg["recovery_time_s"] = float(ts[outside[-1]] + Ts - t0) if outside.size else 0.0
        segments[name] = seg
    steps = [s for s in segments.values() if "settling_time_s" in s]
    u = series["command"]
    saturated = np.array([controller.saturated(v) for v in u[:-1]])
    pressure_rate = np.abs(series["pressure_rate_Pa_s"])
    return {
        "overshoot_pct": max((s["overshoot_pct"] for s in steps), default=0.0),
        "settling_time_s": max((s["settling_time_s"] for s in steps), default=0.0),
        "steady_state_error_rel": max(s["steady_state_error_rel"] for s in segments.values()),
        "cycle_amplitude_rel": max(s["cycle_amplitude_rel"] for s in segments.values()),
        "limit_cycle": bool(max(s["cycle_amplitude_rel"] for s in segments.values()) > LIMIT_CYCLE_THRESHOLD),
        "load_peak_deviation_rel": max(s.get("peak_deviation_rel", 0.0) for s in segments.values()),
        "peak_pressure_rate_Pa_s": float(np.max(pressure_rate)),
        "time_in_saturation_s": float(np.sum(saturated) * Ts),
        "segments": segments,
    }
