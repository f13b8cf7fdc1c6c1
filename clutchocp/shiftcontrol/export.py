"""The designed controller taken out of the tool: calibration tables (CSV, JSON), the per-sample step as C,
and every command `clutchocp robust` designs as a time/pressure CSV a test bench can replay.

Files (:func:`export_controller`, in the output folder of ``clutchocp robust``):

* ``calibration_limits.csv``: per design of the schedule, the scheduled field's value, sample time,
  command limits, rate limit, the dead time the TCU sends its feedforward early by, the lock-up
  threshold and sample count, the clamp pressure;
* ``calibration_feedforward.csv``: per design, the feedforward curve (piecewise linear) [s], [Pa];
* ``calibration_gain_schedule.csv``: per design and sample k, t_k, the feedforward at the sample, the
  integration length and the LQR gains on every state of the TCU and the slip-error integral, each
  column with its unit (the command in Pa per unit of the state);
* ``calibration_estimator.csv``: per design and sample, every entry of the Kalman filter's tables (A, B,
  C, M, y_ref, slip_row) in long form: matrix, row, column, value and its SI unit; of the prediction's
  bilinear term H the entries that are not zero, column ``d:<field>*<state or du>``; per sub-interval
  ``sub<s>`` of a sample the correction's column G_sub, the feedforward u_sub and the flag held_sub (1: the
  current correction acts there, 0: the previous one) through which the command clipped between samples acts;
* ``controller.json``: all of it (state and reading names with units, the tables as nested lists);
* ``tcu_step.c``, ``tcu_step.h``: the law of :func:`clutchocp.shiftcontrol.tcu.step_function`, generated
  by CasADi (``casadi.CodeGenerator``); its inputs are a sample's table rows, the readings and the TCU's
  state, in the order of :data:`clutchocp.shiftcontrol.tcu.STEP_INPUTS`.

An A2L (ASAM MCD-2 MC) description was considered: it needs the ECU's memory addresses and record
layouts from its linker map, which a design tool does not have, so the tables are written as CSV and
JSON (and the C function takes them as arguments) for the calibration tool chain to import.
"""

import json
import shutil
import subprocess
from pathlib import Path

import casadi as ca
import numpy as np

from ..errors import ModelError
from ..output import write_csv
from .tcu import LIMITS, STEP_INPUTS, STEP_OUTPUTS, step_function

C_NAME = "tcu_step"


def state_unit(name):
    """SI unit of a TCU state or reading."""
    if name.startswith("d:"):
        return "1"
    if name.startswith(("mean:", "edge:", "edge_prev:")):
        return "rad"
    if name.startswith("h_"):
        return "m"
    if name.startswith("T_"):
        return "degC"
    return {"p_valve": "Pa", "p_sensor": "Pa", "p_offset": "Pa", "du_prev": "Pa", "w_in": "rad/s", "w_out": "rad/s",
            "engine_torque": "N m", "integral": "rad"}.get(name, "SI")


def _ratio(top, bottom):
    if bottom == "1":
        return top
    if top == bottom:
        return "1"
    return f"{top}/({bottom})" if " " in bottom or "/" in bottom else f"{top}/{bottom}"


def write_command_csv(path, times, values):
    """A command as ``time [s]``, ``pressure [Pa]`` (piecewise linear between the rows, the last value held)."""
    return write_csv(path, {"time [s]": np.asarray(times, float), "pressure [Pa]": np.asarray(values, float)})


def write_commands(out, strategies, facts):
    """Every designed command as a CSV a test bench can replay: ``<strategy>_command.csv`` for the open-loop
    strategies (with their clamp ramp), ``closed_loop_feedforward_<i>.csv`` per design of the closed loop's
    schedule; the Kalman-filter controller's calibration and C code too (:func:`export_controller`)."""
    out = Path(out)
    files = []
    for s in strategies:
        if s.times is not None:
            files.append(write_command_csv(out / f"{s.name}_command.csv", s.times, s.values))
        elif s.feedback is not None:
            for i, feedback in enumerate(s.feedback.feedbacks):
                files.append(write_command_csv(out / f"closed_loop_feedforward_{i}.csv", feedback.ff_times,
                                               feedback.ff_values))
            if s.feedback.sensors is not None:
                files += export_controller(out, s.feedback)
    return files


def export_controller(out, schedule):
    """Calibration tables, JSON and the generated C of a Kalman-filter controller's schedule (see the module
    docstring). Returns the files written."""
    out = Path(out)
    feedbacks = schedule.feedbacks
    field = schedule.field or "design"
    values = [float(v) if np.isfinite(v) else 0.0 for v in schedule.values]
    first = feedbacks[0]
    names, measured = first.names, first.measured
    files = [_limits_csv(out / "calibration_limits.csv", feedbacks, field, values),
             _feedforward_csv(out / "calibration_feedforward.csv", feedbacks),
             _gains_csv(out / "calibration_gain_schedule.csv", feedbacks, names),
             _estimator_csv(out / "calibration_estimator.csv", feedbacks, names, measured)]
    files.append(_json(out / "controller.json", schedule, field, values))
    files += generate_c(out, len(names), len(measured), first.parameters, first.subs)
    return files


def _limits_csv(path, feedbacks, field, values):
    return write_csv(path, {
        "design": list(range(len(feedbacks))), f"{field} [SI]": values,
        "sample_time [s]": [f.Ts for f in feedbacks], "samples": [f.horizon for f in feedbacks],
        "pressure_min [Pa]": [f.p_min for f in feedbacks], "pressure_max [Pa]": [f.p_max for f in feedbacks],
        "rate_limit [Pa/s]": [f.rate_limit for f in feedbacks],
        "feedforward_advance [s]": [f.advance for f in feedbacks],
        "lock_slip [rad/s]": [f.lock_slip for f in feedbacks], "lock_samples": [f.lock_samples for f in feedbacks],
        "clamp_pressure [Pa]": [f.clamp_pressure for f in feedbacks],
        "anti_windup_clamping": [int(f.anti_windup == "clamping") for f in feedbacks],
        "engine_torque_nominal [N m]": [f.nominal_torque for f in feedbacks]})


def _feedforward_csv(path, feedbacks):
    design, t, p = [], [], []
    for i, f in enumerate(feedbacks):
        design += [i] * f.ff_times.size
        t += list(f.ff_times)
        p += list(f.ff_values)
    return write_csv(path, {"design": design, "time [s]": t, "pressure [Pa]": p})


def _gains_csv(path, feedbacks, names):
    columns = {"design": [], "sample": [], "t [s]": [], "u_ff [Pa]": [], "dt [s]": []}
    gain_names = [f"K[{n}] [{_ratio('Pa', state_unit(n))}]" for n in names] + ["K[integral] [Pa/rad]"]
    for g in gain_names:
        columns[g] = []
    for i, f in enumerate(feedbacks):
        for k in range(f.horizon):
            columns["design"].append(i)
            columns["sample"].append(k)
            columns["t [s]"].append(k * f.Ts)
            columns["u_ff [Pa]"].append(f.tables["u_ff"][k])
            columns["dt [s]"].append(f.tables["dt"][k])
            for g, value in zip(gain_names, f.tables["K"][k]):
                columns[g].append(value)
    return write_csv(path, columns)


def _entries(f, names, measured):
    """(matrix, k, row name, column name, value, unit) of every estimator table entry of one design."""
    t = f.tables
    for k in range(f.horizon):
        for i, r in enumerate(names):
            for j, c in enumerate(names):
                yield "A", k, r, c, t["A"][k, i, j], _ratio(state_unit(r), state_unit(c))
            yield "B", k, r, "du", t["B"][k, i], _ratio(state_unit(r), "Pa")
            for j, c in enumerate(measured):
                yield "M", k, r, c, t["M"][k, i, j], _ratio(state_unit(r), state_unit(c))
        for i, r in enumerate(measured):
            for j, c in enumerate(names):
                yield "C", k, r, c, t["C"][k, i, j], _ratio(state_unit(r), state_unit(c))
            yield "y_ref", k, r, "", t["y_ref"][k, i], state_unit(r)
        for j, c in enumerate(names):
            yield "slip_row", k, "slip", c, t["slip_row"][k, j], _ratio("rad/s", state_unit(c))
        for s in range(f.subs):
            for i, r in enumerate(names):
                yield "G_sub", k, r, f"sub{s}", t["G_sub"][k, i, s], _ratio(state_unit(r), "Pa")
            yield "u_sub", k, f"sub{s}", "", t["u_sub"][k, s], "Pa"
            yield "held_sub", k, f"sub{s}", "", t["held_sub"][k, s], "1"
        factors = list(names) + ["du"]           # H acts on d (x) [xi; du]: the entries that are not zero
        for i, r in enumerate(names):
            for column in np.flatnonzero(t["H"][k, i]):
                d, c = names[f.parameters[column // len(factors)]], factors[column % len(factors)]
                unit = _ratio(state_unit(r), "Pa" if c == "du" else state_unit(c))
                yield "H", k, r, f"{d}*{c}", t["H"][k, i, column], unit


def _estimator_csv(path, feedbacks, names, measured):
    columns = {key: [] for key in ("design", "matrix", "sample", "row", "column", "value [SI: unit column]", "unit")}
    for d, f in enumerate(feedbacks):
        for entry in _entries(f, names, measured):
            for key, value in zip(list(columns)[1:], entry):
                columns[key].append(value)
            columns["design"].append(d)
    return write_csv(path, columns)


def _json(path, schedule, field, values):
    designs = []
    for value, f in zip(values, schedule.feedbacks):
        designs.append({
            "field_value": value, "sample_time_s": f.Ts, "samples": f.horizon, "pressure_min_Pa": f.p_min,
            "pressure_max_Pa": f.p_max, "rate_limit_Pa_s": f.rate_limit, "feedforward_advance_s": f.advance,
            "lock_slip_rad_s": f.lock_slip, "lock_samples": f.lock_samples, "clamp_pressure_Pa": f.clamp_pressure,
            "anti_windup": f.anti_windup, "engine_torque_nominal_Nm": f.nominal_torque,
            "feedforward": {"time_s": f.ff_times.tolist(), "pressure_Pa": f.ff_values.tolist()},
            "tables": {key: value.tolist() for key, value in f.tables.items()}})
    first = schedule.feedbacks[0]
    payload = {
        "controller": "TCU slip control: Kalman filter + time-varying LQR with integral action (clutchocp)",
        "schedule_field": field, "state": [{"name": n, "unit": state_unit(n)} for n in first.names],
        "readings": [{"name": n, "unit": state_unit(n)} for n in first.measured],
        "step_function": {"c_name": C_NAME, "inputs": list(STEP_INPUTS), "outputs": list(STEP_OUTPUTS),
                          "limits_order": list(LIMITS)},
        "sensors": schedule.sensors.describe() if schedule.sensors is not None else None,
        "designs": designs}
    path.write_text(json.dumps(payload, indent=1) + "\n", encoding="utf-8")
    return path


def generate_c(out, n, p, parameters=(), subs=0):
    """``tcu_step.c`` and ``tcu_step.h``: the per-sample law for n states, p readings, the estimated parameters
    at the state positions ``parameters`` and ``subs`` sub-intervals per sample
    (:attr:`~clutchocp.shiftcontrol.tcu.TCUFeedback.parameters`, ``subs``; CasADi code generation)."""
    out = Path(out)
    generator = ca.CodeGenerator(f"{C_NAME}.c", {"with_header": True})
    generator.add(step_function(n, p, tuple(parameters), int(subs)))
    generator.generate(str(out) + "/")
    return [out / f"{C_NAME}.c", out / f"{C_NAME}.h"]


def compiler():
    """The machine's C compiler (``cc``, else ``gcc`` or ``clang``), or None."""
    return next((path for path in map(shutil.which, ("cc", "gcc", "clang")) if path), None)


def compile_shared(folder, cc=None):
    """Compile ``tcu_step.c`` of ``folder`` into a shared library (``libtcu_step.so``); returns its path."""
    cc = cc or compiler()
    if cc is None:
        raise ModelError("no C compiler (cc, gcc, clang) on this machine")
    folder = Path(folder)
    library = folder / f"lib{C_NAME}.so"
    subprocess.run([cc, "-O2", "-shared", "-fPIC", "-o", str(library), str(folder / f"{C_NAME}.c"), "-lm"],
                   check=True, capture_output=True)
    return library


def time_c_step(folder, inputs, repeats=200_000, cc=None, parameters=()):
    """Seconds per call of the generated ``tcu_step`` on one sample's inputs (a dict by input name), measured by
    a C loop compiled with -O2 beside it (the time of the law alone, without Python); ``parameters`` as given to
    :func:`generate_c`."""
    cc = cc or compiler()
    if cc is None:
        raise ModelError("no C compiler (cc, gcc, clang) on this machine")
    folder = Path(folder)
    f = step_function(*_sizes(inputs), tuple(parameters), int(np.size(inputs["u_sub"])))
    arrays, pointers = [], []
    for i, name in enumerate(STEP_INPUTS):
        values = np.asarray(ca.DM(inputs[name]).full(), float).ravel(order="F")
        arrays.append(f"static const casadi_real in{i}[{max(values.size, 1)}] = {{"
                      + ", ".join(repr(float(v)) for v in values) + "};")
        pointers.append(f"in{i}")
    outputs = [f"static casadi_real out{i}[{max(f.nnz_out(i), 1)}];" for i in range(f.n_out())]
    source = f"""#include <stdio.h>
#include <time.h>
#include "{C_NAME}.h"
{chr(10).join(arrays)}
{chr(10).join(outputs)}
int main(void) {{
  const casadi_real* arg[{max(f.sz_arg(), f.n_in())}] = {{{", ".join(pointers)}}};
  casadi_real* res[{max(f.sz_res(), f.n_out())}] = {{{", ".join(f"out{i}" for i in range(f.n_out()))}}};
  static casadi_int iw[{max(f.sz_iw(), 1)}];
  static casadi_real w[{max(f.sz_w(), 1)}];
  struct timespec a, b;
  volatile casadi_real sink = 0;
  clock_gettime(CLOCK_MONOTONIC, &a);
  for (long i = 0; i < {int(repeats)}; ++i) {{ {C_NAME}(arg, res, iw, w, 0); sink += out0[0]; }}
  clock_gettime(CLOCK_MONOTONIC, &b);
  printf("%.9e\\n", ((b.tv_sec - a.tv_sec) + 1e-9 * (b.tv_nsec - a.tv_nsec)) / {int(repeats)});
  return 0;
}}
"""
    bench = folder / "tcu_step_bench.c"
    bench.write_text(source, encoding="utf-8")
    program = folder / "tcu_step_bench"
    subprocess.run([cc, "-O2", "-o", str(program), str(bench), str(folder / f"{C_NAME}.c"), "-lm"], check=True,
                   capture_output=True)
    done = subprocess.run([str(program)], check=True, capture_output=True, text=True)
    return float(done.stdout.strip())


def _sizes(inputs):
    """(n, p) of the step function from a sample's inputs."""
    return int(np.size(inputs["x_prior"])), int(np.size(inputs["y"]))
