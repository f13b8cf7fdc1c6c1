"""Tests of the hybrid DAE engine (clutchocp.simulation) against closed forms and a second integrator."""

import itertools
import math

import casadi as ca
import numpy as np
import pytest

from clutchocp.errors import ModelError, SolverError
from clutchocp.simulation import (
    Event,
    HybridModel,
    Mode,
    PiecewiseConstant,
    SimulationOptions,
    simulate,
    time_derivative,
)
from clutchocp.simulation.compiled import EventSpec
from clutchocp.simulation.events import ARMED, ENTRY, PASSED, EventMonitor, locate

TIGHT = SimulationOptions(rtol=1e-10, atol=1e-10, event_value_tol=1e-10, event_band=1e-8)


def sym(*names):
    return [ca.SX.sym(n) for n in names]


# --------------------------------------------------------------------------- models
def coulomb_pair(ramp=False, implicit_torque=False):
    """Input inertia J1 (torque k t if ramp) and output inertia J2 coupled by a friction clutch.

    Kinetic torque = static capacity Ts. Modes slip_pos / slip_neg (states w1, w2) and locked (w).
    With implicit_torque the slipping torque is an algebraic variable T solving
    T + T^3 / Ts^2 = 2 Ts + c |w_rel| (T = Ts for c = 0): a nonlinear residual for the rootfinder paths.
    """
    t = ca.SX.sym("t")
    J1, J2, Ts, k, c = sym("J1", "J2", "Ts", "k", "c")
    T1 = k * t if ramp else 0 * t
    T_need = J2 * T1 / (J1 + J2)           # torque that keeps the locked pair together

    def slip(name, sign, other):
        w1, w2, T = sym("w1", "w2", "T")
        torque = T if implicit_torque else Ts
        w_rel = w1 - w2
        z, alg = ({"T": T}, [T + T**3 / Ts**2 - 2 * Ts - c * sign * w_rel]) if implicit_torque else (None, None)
        events = [Event("lockup", w_rel, "locked", direction=-sign, guard=Ts - ca.fabs(T_need), scale=10.0,
                        reset={"w": (J1 * w1 + J2 * w2) / (J1 + J2)}),
                  Event("reverse", w_rel, other, direction=-sign, guard=ca.fabs(T_need) - Ts, scale=10.0)]
        return Mode(name, {"w1": w1, "w2": w2}, {"w1": (T1 - sign * torque) / J1, "w2": sign * torque / J2},
                    z=z, alg=alg, z_nominal={"T": 10.0} if implicit_torque else None, z_guess={"T": 5.0}
                    if implicit_torque else None, outputs={"T_clutch": sign * torque, "w_rel": w_rel},
                    events=events, x_nominal={"w1": 10.0, "w2": 10.0})

    w = ca.SX.sym("w")
    locked = Mode("locked", {"w": w}, {"w": T1 / (J1 + J2)}, outputs={"T_clutch": T_need}, x_nominal={"w": 10.0},
                  events=[Event("unlock", T_need - Ts, "slip_pos", direction=1, scale=10.0,
                                reset={"w1": w, "w2": w}),
                          Event("unlock_neg", -T_need - Ts, "slip_neg", direction=1, scale=10.0,
                                reset={"w1": w, "w2": w})])
    return HybridModel([slip("slip_pos", 1, "slip_neg"), slip("slip_neg", -1, "slip_pos"), locked],
                       p={"J1": J1, "J2": J2, "Ts": Ts, "k": k, "c": c}, t=t)


PAIR = {"J1": 1.0, "J2": 2.0, "Ts": 10.0, "k": 3.0, "c": 0.0}


def ramp_closed_form(t):
    """Exact speeds of coulomb_pair(ramp=True) with PAIR, w1(0) = 10, w2(0) = 0."""
    J1, J2, Ts, k = PAIR["J1"], PAIR["J2"], PAIR["Ts"], PAIR["k"]
    t_lock = (15.0 - np.sqrt(15.0**2 - 4 * 1.5 * 10.0)) / 3.0      # 10 + 1.5 t^2 - 15 t = 0
    t_unlock = Ts * (J1 + J2) / (J2 * k)                            # J2 k t / (J1 + J2) = Ts
    momentum = lambda s: 10.0 * J1 + k * s**2 / 2                   # only the input torque k t acts
    w_lock = lambda s: momentum(s) / (J1 + J2)
    if t < t_lock:
        return 10.0 + (k * t**2 / 2 - Ts * t) / J1, Ts * t / J2
    if t < t_unlock:
        return w_lock(t), w_lock(t)
    w2 = w_lock(t_unlock) + Ts * (t - t_unlock) / J2
    return w2 + k * (t - t_unlock) ** 2 / (2 * J1), w2


def brake():
    """A spinning inertia braked by Coulomb + viscous torque until it stops: w' = -a - b w."""
    w, a, b = sym("w", "a", "b")
    spin = Mode("spin", {"w": w}, {"w": -a - b * w}, x_nominal={"w": 10.0},
                events=[Event("stop", w, "stopped", direction=-1, scale=10.0)])
    stopped = Mode("stopped", {"w": w}, {"w": 0 * w}, x_nominal={"w": 10.0})
    return HybridModel([spin, stopped], p={"a": a, "b": b})


# --------------------------------------------------------------------------- closed forms
def test_coulomb_lockup_time_and_common_speed_hold_without_chatter():
    model = coulomb_pair()
    p = dict(PAIR, k=0.0)
    result = simulate(model, {"w1": 10.0, "w2": 0.0}, np.linspace(0, 2, 41), p=p, options=TIGHT)
    t_lock = 10.0 / (p["Ts"] * (1 / p["J1"] + 1 / p["J2"]))        # w_rel falls at Ts (1/J1 + 1/J2)
    w_common = (p["J1"] * 10.0) / (p["J1"] + p["J2"])              # momentum is conserved
    assert [e.name for e in result.events] == ["lockup"]            # locks once and holds: no chatter
    assert abs(result.events[0].t - t_lock) <= 1e-9
    assert result.final_mode == "locked"
    assert abs(result.final("w") - w_common) <= 1e-9 * w_common
    locked = result.mode == "locked"
    assert np.allclose(result["w"][locked], w_common, rtol=1e-10, atol=0)
    assert np.all(np.isnan(result["w1"][locked])) and np.all(np.isnan(result["w"][~locked]))
    # lock-up torque jump: Ts while slipping, 0 needed once locked
    ev = result.events[0]
    assert ev.outputs_before["T_clutch"] == pytest.approx(10.0) and ev.outputs_after["T_clutch"] == pytest.approx(0.0)


def test_viscous_coupling_stays_slipping_and_matches_exponential():
    w, w_in, c, J = sym("w", "w_in", "c", "J")
    mode = Mode("slip", {"w": w}, {"w": c * (w_in - w) / J}, outputs={"w_rel": w_in - w}, x_nominal={"w": 100.0},
                events=[Event("lockup", w_in - w, "locked", direction=-1, scale=100.0)])
    locked = Mode("locked", {"w": w}, {"w": 0 * w})
    model = HybridModel([mode, locked], p={"w_in": w_in, "c": c, "J": J})
    grid = np.linspace(0, 1, 51)
    result = simulate(model, {"w": 0.0}, grid, p={"w_in": 100.0, "c": 2.0, "J": 0.1})
    exact = 100.0 * (1 - np.exp(-2.0 * grid / 0.1))                  # J w' = c (w_in - w)
    assert result.events == [] and result.final_mode == "slip"
    assert np.allclose(result.t, grid)
    assert np.max(np.abs(result["w"] - exact)) <= 1e-6 * 100.0


def test_lock_then_unlock_when_needed_torque_exceeds_capacity():
    model = coulomb_pair(ramp=True)
    grid = np.linspace(0, 6, 61)
    t_lock = (15.0 - np.sqrt(165.0)) / 3.0
    for method in ("idas", "Radau"):
        result = simulate(model, {"w1": 10.0, "w2": 0.0}, grid, p=PAIR, options=TIGHT, method=method)
        assert [(e.name, e.target) for e in result.events] == [("lockup", "locked"), ("unlock", "slip_pos")]
        assert abs(result.events[0].t - t_lock) <= 1e-8
        assert abs(result.events[1].t - 5.0) <= 1e-8                 # J2 k t / (J1 + J2) = Ts
        exact = np.array([ramp_closed_form(t) for t in result.t])
        common = result.mode == "locked"
        w1 = np.where(common, result["w"], result["w1"])
        w2 = np.where(common, result["w"], result["w2"])
        away = np.abs(result.t - result.events[0].t) > 1e-6          # the closed form switches at the exact time
        assert np.max(np.abs(w1 - exact[:, 0])[away]) <= 1e-6
        assert np.max(np.abs(w2 - exact[:, 1])[away]) <= 1e-6


def test_plastic_impact_conserves_momentum_and_changes_the_state_vector():
    x0, v0, x1, v1, x, v = sym("x0", "v0", "x1", "v1", "x", "v")
    F, m0, m1, d = sym("F", "m0", "m1", "d")
    approach = Mode("approach", {"x0": x0, "v0": v0, "x1": x1, "v1": v1},
                    {"x0": v0, "v0": F / m0, "x1": v1, "v1": 0 * v1},
                    x_nominal={"x0": 1e-3, "v0": 0.1, "x1": 1e-3, "v1": 0.1},
                    events=[Event("impact", x1 - x0, "together", direction=-1, scale=1e-3,
                                  reset={"x": x0, "v": (m0 * v0 + m1 * v1) / (m0 + m1)})])
    together = Mode("together", {"x": x, "v": v}, {"x": v, "v": F / (m0 + m1)}, x_nominal={"x": 1e-3, "v": 0.1})
    model = HybridModel([approach, together], p={"F": F, "m0": m0, "m1": m1, "d": d})
    p = {"F": 200.0, "m0": 0.5, "m1": 1.5, "d": 1e-3}
    result = simulate(model, {"x0": 0.0, "v0": 0.0, "x1": 1e-3, "v1": 0.0}, np.linspace(0, 0.01, 21), p=p)
    t_impact = np.sqrt(2 * p["d"] * p["m0"] / p["F"])
    ev = result.events[0]
    assert ev.name == "impact" and abs(ev.t - t_impact) <= 1e-9
    assert p["m0"] * ev.x_before["v0"] == pytest.approx((p["m0"] + p["m1"]) * ev.x_after["v"], rel=1e-12)
    v_plus = p["F"] * t_impact / p["m0"] * p["m0"] / (p["m0"] + p["m1"])
    after = result.mode == "together"
    tau = result.t[after] - t_impact
    assert np.allclose(result["v"][after], v_plus + p["F"] * tau / (p["m0"] + p["m1"]), rtol=1e-7, atol=1e-9)
    assert np.allclose(result["x"][after], p["d"] + v_plus * tau + p["F"] * tau**2 / (2 * (p["m0"] + p["m1"])),
                       rtol=1e-7, atol=1e-12)
    assert "x0" not in result.segments[-1].x and "x" not in result.segments[0].x


@pytest.mark.parametrize("method", ["idas", "Radau"])
def test_index1_dae_matches_the_hand_eliminated_ode(method):
    # mass-spring-damper whose force is algebraic: m v' = -F, 0 = F - k x - c v  (linear in z)
    # plus y' = -q with the implicit 0 = q + q^3 - y - y^3, i.e. q = y (nonlinear in z)
    x, v, y, F, q = sym("x", "v", "y", "F", "q")
    m, k, c = 1.0, 4.0, 0.4
    states, ode = {"x": x, "v": v, "y": y}, {"x": v, "v": -F / m, "y": -q}
    z, alg = {"F": F, "q": q}, [F - k * x - c * v, q + q**3 - y - y**3]
    outputs = {"dF": time_derivative(F, states, ode, z=z, alg=alg), "dq": time_derivative(q, states, ode, z=z, alg=alg)}
    mode = Mode("dae", states, ode, z=z, alg=alg, outputs=outputs, z_guess={"q": 0.5})
    assert ca.is_equal(ca.simplify(mode.time_derivative(F) - outputs["dF"]), ca.SX(0))
    grid = np.linspace(0, 3, 31)
    result = simulate(HybridModel([mode]), {"x": 1.0, "v": 0.0, "y": 1.0}, grid, method=method, options=TIGHT)
    wd = np.sqrt(k / m - (c / (2 * m)) ** 2)                        # x'' + (c/m) x' + (k/m) x = 0
    g = c / (2 * m)
    x_exact = np.exp(-g * grid) * (np.cos(wd * grid) + g / wd * np.sin(wd * grid))
    v_exact = -np.exp(-g * grid) * (k / m) / wd * np.sin(wd * grid)
    assert np.max(np.abs(result["x"] - x_exact)) <= 1e-7
    assert np.max(np.abs(result["F"] - (k * x_exact + c * v_exact))) <= 1e-6
    assert np.max(np.abs(result["y"] - np.exp(-grid))) <= 1e-7
    assert np.max(np.abs(result["q"] - np.exp(-grid))) <= 1e-7
    a_exact = -(k * x_exact + c * v_exact) / m
    assert np.max(np.abs(result["dF"] - (k * v_exact + c * a_exact))) <= 1e-6   # d/dt through the algebraic F
    assert np.max(np.abs(result["dq"] + np.exp(-grid))) <= 1e-7                  # q = y = e^-t


def test_event_time_converges_as_tolerances_tighten():
    model = brake()
    a, b, w0 = 2.0, 3.0, 10.0
    t_stop = np.log(1 + b * w0 / a) / b                               # w(t) = (w0 + a/b) e^{-bt} - a/b
    errors = []
    for tol in (1e-4, 1e-6, 1e-8, 1e-10):
        options = SimulationOptions(rtol=tol, atol=tol, event_value_tol=tol, event_band=10 * tol)
        result = simulate(model, {"w": w0}, np.linspace(0, 2, 21), p={"a": a, "b": b}, options=options)
        errors.append(abs(result.events[0].t - t_stop))
    assert all(e2 < e1 for e1, e2 in itertools.pairwise(errors)), errors
    assert errors[-1] <= 1e-8 and errors[0] >= 1e-6


def test_idas_and_scipy_paths_agree_on_a_dae_with_lock_and_unlock():
    model = coulomb_pair(ramp=True, implicit_torque=True)
    grid = np.linspace(0, 6, 31)
    p = dict(PAIR, c=2.0)                      # slip torque grows with the slip speed: a nonlinear approach
    runs = {m: simulate(model, {"w1": 10.0, "w2": 0.0}, grid, p=p, options=TIGHT, method=m)
            for m in ("idas", "Radau")}
    idas, radau = runs["idas"], runs["Radau"]
    assert [e.name for e in idas.events] == [e.name for e in radau.events] == ["lockup", "unlock"]
    for e1, e2 in zip(idas.events, radau.events):
        assert abs(e1.t - e2.t) <= 1e-6
    assert list(idas.mode) == list(radau.mode)
    for name in ("w1", "w2", "w", "T"):
        assert np.nanmax(np.abs(idas[name] - radau[name])) <= 1e-6
    slipping = ~np.isnan(idas["T"])
    T, w_rel = idas["T"][slipping], idas["w_rel"][slipping]
    assert np.allclose(T + T**3 / 100.0, 20.0 + 2.0 * w_rel, rtol=1e-8, atol=0)   # z solves its residual
    assert np.ptp(T) > 1.0
    for method in ("BDF", "LSODA"):
        other = simulate(model, {"w1": 10.0, "w2": 0.0}, grid, p=p, method=method,
                         options=SimulationOptions(rtol=1e-9, atol=1e-9))
        assert [e.name for e in other.events] == ["lockup", "unlock"]
        assert abs(other.events[0].t - idas.events[0].t) <= 1e-5
    assert idas.stats["n_steps"] < 1200 and idas.stats["wall_time_s"] > 0      # 932 steps when written
    assert {"n_rhs_evals", "n_jacobian_evals", "n_error_test_failures"} <= set(idas.stats)


# --------------------------------------------------------------------------- inputs
def step_input_model(as_input):
    """x1' = -x1 + z, x2' = x1, 0 = z - 10 u - 0.1 x2 with u stepping 0 -> 1 at t = 0.55 (off the grid)."""
    t, x1, x2, z, u = sym("t", "x1", "x2", "z", "u")
    step = u if as_input else ca.if_else(t >= 0.55, 1.0, 0.0)
    mode = Mode("m", {"x1": x1, "x2": x2}, {"x1": -x1 + z, "x2": x1}, z={"z": z}, alg=[z - 10 * step - 0.1 * x2])
    return HybridModel([mode], u={"u": u} if as_input else None, t=t)


def test_step_input_with_and_without_algebraic_suppression():
    grid = np.linspace(0, 1, 11)
    x0 = {"x1": 0.0, "x2": 0.0}
    reference = simulate(step_input_model(True), x0, grid, u={"u": PiecewiseConstant([0.55], [0.0, 1.0])},
                         options=TIGHT)
    at_step = np.nonzero(reference.t == 0.55)[0]
    assert at_step.size == 2 and reference["z"][at_step[0]] == 0 and reference["z"][at_step[1]] > 9.9
    # x1 stays 0 before the step; after it, x1 = 10 (1 - e^{-(t-0.55)}) + O(0.1 x2) (x2 = O(1e-1 t^2))
    late = reference.t > 0.55
    assert np.all(reference["x1"][reference.t <= 0.55] == 0)
    assert np.allclose(reference["x1"][late], 10 * (1 - np.exp(-(reference.t[late] - 0.55))), atol=0.02)
    with pytest.raises(SolverError, match=r"failed at t = 0\.55\d* s .*IDA_\w+.*Try:"):
        simulate(step_input_model(False), x0, grid, options=SimulationOptions(rtol=1e-8, atol=1e-8, max_num_steps=2000))
    suppressed = simulate(step_input_model(False), x0, grid,
                          options=SimulationOptions(rtol=1e-10, atol=1e-10, suppress_algebraic=True))
    on_grid = np.r_[np.arange(6), np.arange(8, 13)]                   # reference has t = 0.55 twice
    assert np.allclose(reference.t[on_grid], grid)
    assert np.max(np.abs(suppressed["x1"] - reference["x1"][on_grid])) <= 1e-6
    assert np.max(np.abs(suppressed["x2"] - reference["x2"][on_grid])) <= 1e-6


# --------------------------------------------------------------------------- events, hysteresis, chatter
def test_guard_failure_passes_a_crossing_and_the_next_one_fires():
    t, x = sym("t", "x")
    mode = Mode("wave", {"x": x}, {"x": ca.cos(t)},
                events=[Event("fall", x, "rest", direction=-1, guard=t - 4.0)])
    rest = Mode("rest", {"x": x}, {"x": 0 * x})
    model = HybridModel([mode, rest], t=t)
    for method in ("idas", "Radau"):
        result = simulate(model, {"x": 0.0}, np.linspace(0, 12, 49), method=method, options=TIGHT)
        assert [e.name for e in result.events] == ["fall"]             # x = sin t falls through 0 at pi, 3 pi
        assert abs(result.events[0].t - 3 * np.pi) <= 1e-8


def test_event_monitor_hysteresis_rules():
    specs = [EventSpec(0, "down", -1, "a", 0), EventSpec(1, "up", 1, "b", 1), EventSpec(2, "any", 0, "c", 2)]
    mon = EventMonitor(specs, band=1e-5)
    assert mon.enter(np.array([0.0, -1.0, 2e-6]), np.ones(3, bool)) is None
    assert mon.state == [ENTRY, ARMED, ENTRY]
    # a disarmed event at zero neither fires nor re-arms while it stays in the band
    crossings, state = mon.scan(np.array([0.0, -1.0, 2e-6]), np.array([-5e-6, -0.5, -9e-6]))
    assert crossings == [] and state == [ENTRY, ARMED, ENTRY]
    # leaving the band on the firing side fires at the band edge; the armed 'up' crossing fires at 0
    crossings, _ = mon.scan(np.array([0.0, -0.5, 0.0]), np.array([-1e-3, 0.5, 1e-3]))
    assert crossings == [(0, -1e-5), (1, 0.0)]
    # leaving on the pre-crossing side re-arms
    _, state = mon.scan(np.array([0.0, -0.5, 0.0]), np.array([1e-3, -0.4, -1e-3]))
    assert state == [ARMED, ARMED, ARMED]
    # an event already past its zero at entry fires at once if its guard holds, else is passed
    assert mon.enter(np.array([-1.0, -1.0, 1.0]), np.array([True, True, True])) == 0
    assert mon.enter(np.array([-1.0, -1.0, 1.0]), np.array([False, True, True])) is None
    assert mon.state[0] == PASSED


def test_contradicting_modes_are_reported_as_chatter():
    x = ca.SX.sym("x")
    a = Mode("a", {"x": x}, {"x": 0 * x}, events=[Event("to_b", x - 2.0, "b", direction=-1)])
    b = Mode("b", {"x": x}, {"x": 0 * x}, events=[Event("to_a", x - 2.0, "a", direction=-1)])
    with pytest.raises(SolverError, match="chatter"):
        simulate(HybridModel([a, b]), {"x": 1.0}, [0.0, 1.0])


def test_locate_meets_time_or_value_tolerance():
    f = lambda t: np.tanh(50 * (t - 0.3141592653589793))
    t, _, iterations = locate(lambda t, _: (f(t), None), 0.0, f(0.0), None, 1.0, f(1.0), None,
                              time_tol=1e-12, value_tol=1e-14)
    assert abs(t - 0.3141592653589793) <= 1e-12 and iterations < 60


# --------------------------------------------------------------------------- failures and messages
@pytest.mark.parametrize("grid", [[0.0, 3.0], np.linspace(0, 3, 31)])
def test_mode_invalid_past_its_event_is_still_switched_by_the_event(grid):
    x, z = sym("x", "z")
    # z = sqrt(1 - x) is NaN once x > 1; the event at x = 0.9 must be found although IDAS fails later
    going = Mode("going", {"x": x}, {"x": 1 + 0 * z}, z={"z": z}, alg=[z * z - (1 - x)], z_guess={"z": 1.0},
                 events=[Event("arrive", 0.9 - x, "parked", direction=-1)])
    parked = Mode("parked", {"x": x}, {"x": 0 * x})
    result = simulate(HybridModel([going, parked]), {"x": 0.0}, grid)
    assert [e.name for e in result.events] == ["arrive"] and abs(result.events[0].t - 0.9) <= 1e-9
    assert result.final("x") == pytest.approx(0.9, abs=1e-9)


def test_solver_error_says_when_where_why_and_what_to_try():
    x = ca.SX.sym("x")
    blow_up = Mode("blow", {"x": x}, {"x": x**2}, x_nominal={"x": 2.0})  # x = 1 / (1 - t): singular at t = 1
    with pytest.raises(SolverError) as info:
        simulate(HybridModel([blow_up]), {"x": 1.0}, np.linspace(0, 2, 5))
    err = info.value                            # an ODE mode: CVODES (BDF) by default
    assert err.mode == "blow" and 0.9 < err.t <= 1.0 and err.flag.startswith("CV_")
    assert str(err).startswith("CVODES failed") and "t = " in str(err) and "x = " in str(err) and "Try:" in str(err)
    with pytest.raises(SolverError) as info:
        simulate(HybridModel([blow_up]), {"x": 1.0}, np.linspace(0, 2, 5),
                 options=SimulationOptions(ode_integrator="idas"))
    err = info.value
    assert err.mode == "blow" and 0.9 < err.t <= 1.0 and err.flag.startswith("IDA_")
    assert str(err).startswith("IDAS failed") and "t = " in str(err) and "x = " in str(err) and "Try:" in str(err)
    with pytest.raises(SolverError, match=r"scipy Radau failed at t = (1|0\.99\d*) s in mode 'blow'.*Try:"):
        simulate(HybridModel([blow_up]), {"x": 1.0}, np.linspace(0, 2, 5), method="Radau")


def test_model_and_input_errors_are_reported_clearly():
    x, y = sym("x", "y")
    with pytest.raises(ModelError, match="unknown target"):
        HybridModel([Mode("a", {"x": x}, {"x": -x}, events=[Event("e", x, "nowhere")])])
    with pytest.raises(ModelError, match="lacks"):
        HybridModel([Mode("a", {"x": x}, {"x": -x}, events=[Event("e", x, "b")]),
                     Mode("b", {"y": y}, {"y": -y})]).compiled()
    with pytest.raises(ModelError, match=r"symbols \['y'\]"):
        HybridModel([Mode("a", {"x": x}, {"x": -y})]).compiled()
    model = HybridModel([Mode("a", {"x": x}, {"x": -x})])
    with pytest.raises(ModelError, match="missing"):
        simulate(model, {}, [0.0, 1.0])
    with pytest.raises(ModelError, match="increasing"):
        simulate(model, {"x": 1.0}, [0.0, 0.0])


def test_chunked_integration_gives_the_same_answer():
    model = coulomb_pair(ramp=True)
    grid = np.linspace(0, 6, 61)
    whole = simulate(model, {"w1": 10.0, "w2": 0.0}, grid, p=PAIR, options=TIGHT)
    chunked = simulate(model, {"w1": 10.0, "w2": 0.0}, grid, p=PAIR,
                       options=SimulationOptions(**{**TIGHT.as_dict(), "chunk": 7}))
    assert [e.name for e in chunked.events] == [e.name for e in whole.events]
    assert abs(chunked.events[0].t - whole.events[0].t) <= 1e-8
    assert np.nanmax(np.abs(chunked["w2"] - whole["w2"])) <= 1e-7
    runs = [simulate(model, {"w1": 10.0, "w2": 0.0}, grid, p=PAIR,
                     options=SimulationOptions(**{**TIGHT.as_dict(), "chunk": 2, "chunk_growth": growth}))
            for growth in (None, 2.0)]
    assert abs(runs[1].events[0].t - whole.events[0].t) <= 1e-8
    assert np.nanmax(np.abs(runs[1]["w2"] - whole["w2"])) <= 1e-7
    assert runs[1].stats["n_integrator_calls"] < runs[0].stats["n_integrator_calls"] / 2


def test_input_break_at_the_instant_of_an_event_is_applied():
    """x' = 1 until x = 1 - 1e-12 (an event 1e-12 s before the break); then x' = u, where u steps
    from 0 to 2 at t = 1. The break must still apply (it was skipped: x stayed at 1)."""
    x, u, t = ca.SX.sym("x"), ca.SX.sym("u"), ca.SX.sym("t")
    rise = Mode("rise", {"x": x}, [ca.SX(1.0)], events=[Event("full", 1 - 1e-12 - x, "driven", direction=-1)])
    driven = Mode("driven", {"x": x}, [u])
    model = HybridModel([rise, driven], u={"u": u}, t=t)
    grid = np.linspace(0.0, 2.0, 5)                        # t = 1 is a grid point and the break
    res = simulate(model, {"x": 0.0}, grid, u={"u": PiecewiseConstant([1.0], [0.0, 2.0])})
    assert res.event_times("full") == pytest.approx([1.0], abs=1e-9)
    assert res.final("x") == pytest.approx(3.0, rel=1e-9)   # 1 + 2 (2 - 1)


def test_event_function_at_rest_curving_away_is_not_left_unwatched(monkeypatch):
    """x'' = 1 - 10 t from rest at x = 1: the event x = 0 has zero slope and a curvature pointing
    away at the start, so the quadratic prediction sees no crossing; the first call ends after one
    grid interval (not at the end of the piece), the next prediction finds the crossing, and it is
    located at the root of the closed form x = 1 + t^2 / 2 - 5 t^3 / 3."""
    from clutchocp.simulation.idas_path import IdasPath

    t = ca.SX.sym("t")
    x, v = sym("x", "v")
    fall = Mode("fall", {"x": x, "v": v}, {"x": v, "v": 1 - 10 * t},
                events=[Event("land", x, "rest", direction=-1)])
    rest = Mode("rest", {"x": x, "v": v}, {"x": 0 * x, "v": 0 * v})
    ends = []
    integrate = IdasPath._integrate

    def traced(self, cm, t0, xs0, zs0, pu, times):
        ends.append((cm.name, t0, float(np.atleast_1d(times)[-1])))
        return integrate(self, cm, t0, xs0, zs0, pu, times)

    monkeypatch.setattr(IdasPath, "_integrate", traced)
    grid = np.linspace(0.0, 100.0, 10001)
    result = simulate(HybridModel([fall, rest], t=t), {"x": 1.0, "v": 0.0}, grid, options=TIGHT)
    root = min(r.real for r in np.roots([-5 / 3, 0.5, 0.0, 1.0]) if abs(r.imag) < 1e-12 and r.real > 0)
    assert [e.name for e in result.events] == ["land"]
    assert abs(result.events[0].t - root) <= 1e-9
    assert ends[0] == ("fall", 0.0, pytest.approx(grid[1]))          # one interval first
    assert max(end for name, _, end in ends if name == "fall") < 2.0  # never far past the landing


def test_each_mode_gets_its_integrator_and_the_same_closed_form():
    """An ODE mode runs on CVODES, a mode with an algebraic variable on IDAS, in one run: both
    pieces follow x = exp(-t) (then x = exp(-t1) exp(-2 (t - t1)) with z = 2 x), and the event
    is located at x = 1/2; with ode_integrator='idas' both pieces run on IDAS to the same values."""
    x, z = sym("x", "z")
    ode = Mode("ode", {"x": x}, {"x": -x}, events=[Event("half", x - 0.5, "dae", direction=-1)])
    dae = Mode("dae", {"x": x}, {"x": -z}, z={"z": z}, alg=[z - 2 * x], z_guess={"z": 1.0})
    grid = np.linspace(0.0, 1.5, 31)
    t1 = math.log(2.0)
    exact = np.where(grid < t1, np.exp(-grid), 0.5 * np.exp(-2 * (grid - t1)))
    runs = {}
    for choice in ("bdf", "idas"):
        options = SimulationOptions(rtol=1e-10, atol=1e-12, event_value_tol=1e-10, ode_integrator=choice)
        runs[choice] = result = simulate(HybridModel([ode, dae]), {"x": 1.0}, grid, options=options)
        assert abs(result.events[0].t - t1) <= 1e-8
        on_grid = np.array([result["x"][np.searchsorted(result.t, g, side="right") - 1] for g in grid])
        assert np.max(np.abs(on_grid - exact)) <= 1e-8
    assert runs["bdf"].stats["n_pieces_bdf"] >= 1 and runs["bdf"].stats["n_pieces_idas"] >= 1
    assert runs["idas"].stats["n_pieces_bdf"] == 0 and runs["idas"].stats["n_pieces_idas"] >= 2


def test_a_failed_adams_call_is_redone_with_bdf():
    """x' = -1e5 (x - cos t) is stiff: CVODES Adams exceeds its step limit, the call is redone with
    BDF and the run ends on the slow manifold x ~ cos t (error ~ sin t / 1e5)."""
    t = ca.SX.sym("t")
    x = ca.SX.sym("x")
    stiff = Mode("stiff", {"x": x}, {"x": -1e5 * (x - ca.cos(t))})
    options = SimulationOptions(rtol=1e-8, atol=1e-10, ode_integrator="adams", max_num_steps=500)
    result = simulate(HybridModel([stiff], t=t), {"x": 1.0}, np.linspace(0.0, 2.0, 5), options=options)
    assert abs(result.final("x") - math.cos(2.0)) <= 2e-5
    assert result.stats["n_pieces_adams"] == 1 and result.stats["n_adams_redone_bdf"] == 1


def test_ode_integrator_must_be_known():
    with pytest.raises(ModelError, match="ode_integrator must be one of"):
        SimulationOptions(ode_integrator="rk4")
