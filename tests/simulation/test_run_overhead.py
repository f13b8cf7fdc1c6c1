"""The per-run shortcuts outside the integrator give what the general code gives.

Each shortcut is checked against an independent way to the same number: the interpolating
polynomial against ``numpy.polyfit``, the located crossing and peak against closed forms.
"""

import math

import numpy as np
import pytest

from clutchocp.simulation.locate import _cubic, _cubic_roots, _stationary, crossing_time, peak


@pytest.mark.parametrize("n", [2, 3, 4, 5])
def test_interpolating_polynomial_equals_numpy_polyfit(n):
    rng = np.random.default_rng(n)
    t = np.sort(rng.uniform(0.0, 2.0, 8))
    y = rng.normal(size=8)
    idx = np.arange(2, 2 + n)
    f, coef, t0, scale = _cubic(t, y, idx)
    reference = np.polyfit((t[idx] - t0) / scale, y[idx], n - 1)
    assert np.allclose(coef, reference, rtol=1e-10, atol=1e-12)
    for k in idx:                                   # through the samples
        assert f(t[k]) == pytest.approx(y[k], abs=1e-12)
    s = np.linspace(t[idx[0]], t[idx[-1]], 7)
    assert np.allclose([f(v) for v in s], np.polyval(reference, (s - t0) / scale), rtol=1e-10, atol=1e-12)


@pytest.mark.parametrize("coef", [[1.0, -6.0, 9.0, 1.0], [0.0, 2.0, -4.0, 1.0], [1.0, 0.0, 1.0, 0.0],
                                  [3.0, -2.0, 1.0], [0.5, -1.0, -3.0, 2.0, 1.0]])
def test_stationary_points_equal_the_roots_of_the_derivative(coef):
    roots = np.roots(np.polyder(np.trim_zeros(np.array(coef), "f")))
    reference = sorted(roots[np.isreal(roots)].real)
    assert np.allclose(sorted(_stationary(np.array(coef))), reference, rtol=1e-12, atol=1e-12)


def test_real_roots_of_a_cubic_equal_numpy_roots():
    rng = np.random.default_rng(7)
    cases = [rng.normal(size=4) for _ in range(200)] + [[1.0, -6.0, 11.0, -6.0], [1.0, 0.0, 0.0, -8.0],
                                                        [2.0, -3.0, 0.0, 1.0 + 1e-9], [1.0, 0.0, 1.0, 0.0]]
    for coef in cases:
        roots = np.roots(coef)
        real = sorted(roots[np.abs(roots.imag) <= 1e-7 * (1 + np.abs(roots))].real)
        found = sorted(_cubic_roots(*coef))
        assert len(found) == len(real), (coef, found, real)
        assert np.allclose(found, real, rtol=1e-9, atol=1e-9), (coef, found, real)


def test_crossing_and_peak_of_a_cubic_are_exact():
    """A cubic is reproduced exactly by the local polynomial: the crossing and the peak are its own."""
    t = np.linspace(0.0, 1.0, 11)
    y = -(t - 0.1) * (t - 0.5) * (t - 1.3)
    t_peak = (3.8 + math.sqrt(3.8**2 - 12 * 0.83)) / 6     # y' = -(3 t^2 - 3.8 t + 0.83) = 0, the maximum
    value, at = peak(t, y)
    assert at == pytest.approx(t_peak, abs=1e-12)
    assert value == pytest.approx(-(t_peak - 0.1) * (t_peak - 0.5) * (t_peak - 1.3), abs=1e-13)
    assert crossing_time(t, t**3, 0.2) == pytest.approx(0.2 ** (1 / 3), abs=1e-12)
    assert crossing_time(t, t**3, 2.0) is None


@pytest.mark.parametrize("c", [0.013, 0.51, 0.987])
def test_crossing_and_peak_near_the_ends_and_pieces_of_the_samples_are_exact(c):
    """A crossing and a peak in the first, a middle and the last sample interval, the local
    polynomial's samples limited to one piece (labels as the modes of a run, array or list): each
    is exact for samples of a cubic (crossing of t^3 at c^3) and of a parabola (peak of -(t - c)^2)."""
    t = np.linspace(0.0, 1.0, 41)
    piece = np.where(t < 0.5, "slip", "locked")
    for labels in (None, piece, list(piece)):
        assert crossing_time(t, t**3, c**3, labels) == pytest.approx(c, abs=1e-12)
        value, at = peak(t, -(t - c) ** 2, labels)
        assert at == pytest.approx(c, abs=1e-12) and value == pytest.approx(0.0, abs=1e-13)


def test_padded_sizes_are_at_most_a_quarter_larger_and_few():
    from clutchocp.simulation.vectorized import padded_size

    sizes = [padded_size(n) for n in range(1, 5000)]
    assert all(n <= m <= max(n, 1.25 * (n - 1)) for n, m in zip(range(1, 5000), sizes))
    assert sizes[:8] == list(range(1, 9)) and padded_size(17) == 20 and padded_size(1622) == 1792
    assert len(set(sizes)) == 8 + 4 * 9 + 1        # 1..8, then four per octave up to 4096, then 5120


def test_column_function_on_padded_maps_equals_one_call_per_sample():
    """Maps are padded (the last sample repeated): each column is still the function of its own
    sample, and a few maps serve every sample count."""
    import casadi as ca

    from clutchocp.simulation.compiled import ColumnFunction

    xs, zs, pu, t = ca.SX.sym("xs", 2), ca.SX.sym("zs", 1), ca.SX.sym("pu", 2), ca.SX.sym("t")
    f = ca.Function("f", [xs, zs, pu, t], [ca.vertcat(xs[0] * ca.sin(t) + pu[0], zs[0] / (1 + xs[1] ** 2) - pu[1] * t)])
    column = ColumnFunction(f)
    rng = np.random.default_rng(3)
    p = np.array([0.3, -1.2])
    for n in (1, 3, 5, 17, 100):
        X, Z, T = rng.normal(size=(2, n)), rng.normal(size=(1, n)), rng.uniform(0, 1, n)
        reference = np.column_stack([np.array(f(X[:, k], Z[:, k], p, T[k])).ravel() for k in range(n)])
        assert np.array_equal(column(X, Z, p, T), reference)
    assert sorted(column._maps) == [1, 3, 5, 20, 112]
    column(np.zeros((2, 99)), np.zeros((1, 99)), p, np.zeros(99))              # 97-112 samples: one map
    assert sorted(column._maps) == [1, 3, 5, 20, 112]
    assert column(np.zeros((2, 0)), np.zeros((1, 0)), p, np.zeros(0)).shape == (2, 0)


def test_scalar_calls_of_the_numpy_translation_share_padded_maps(monkeypatch):
    """An interpolant called on n samples runs on a map of the padded size (the last sample
    repeated): the values equal CasADi's sample by sample, and 49 to 56 samples share one map."""
    import casadi as ca

    from clutchocp.physics.roughness import log_F52
    from clutchocp.simulation import vectorized

    h = ca.SX.sym("h")
    f = ca.Function("f", [h], [log_F52(h)])
    table = next(f.instructions_sx()[k].which_function() for k in range(f.n_instructions())
                 if f.instruction_id(k) == ca.OP_CALL)
    monkeypatch.setattr(vectorized, "_MAPS", {})          # the maps other tests left behind
    monkeypatch.setattr(vectorized, "_TABLES", {})        # log F_5/2 is a registered table: CasADi here
    # ... and the tables declared so far count as taken, so that none is registered into the empty registry
    # (nor left out of the real one: the counter is restored with it)
    monkeypatch.setattr(vectorized, "_TAKEN", [len(vectorized.declared_tables())])
    for n in (49, 51, 56):
        x = np.linspace(0.5, 3.0, n)
        got = vectorized._call(table, x)
        assert got.shape == (n,)
        assert np.array_equal(got, [float(table(v)) for v in x])
    assert [m for (name, m) in vectorized._MAPS if name == table.name()] == [56]
    assert vectorized._call(table, 1.5) == float(table(1.5))


def test_compiler_lookup_is_remembered_per_environment(monkeypatch, tmp_path):
    """The C compiler is looked up once per ($CC, $PATH), so a changed environment is still honoured."""
    from clutchocp.simulation import native

    found = native.compiler()
    monkeypatch.setenv("PATH", str(tmp_path))
    monkeypatch.delenv("CC", raising=False)
    assert native.compiler() is None
    fake = tmp_path / "cc"
    fake.write_text("#!/bin/sh\n")
    fake.chmod(0o755)
    monkeypatch.setenv("PATH", str(tmp_path) + ":")
    assert native.compiler() == str(fake)
    monkeypatch.undo()
    assert native.compiler() == found


@pytest.fixture(scope="module")
def driveline_runs():
    """default_driveline on one model: on CasADi's virtual machine, again (everything cached), and
    as compiled code. Its locked mode's event functions call the log F_5/2 table."""
    from clutchocp.engagement.model import EngagementModel
    from clutchocp.engagement.run import simulate_engagement
    from clutchocp.scene import load_scene
    from clutchocp.simulation.native import compiler

    model = EngagementModel(load_scene("default_driveline"))
    runs = {"vm": simulate_engagement(model.scene, model=model), "again": simulate_engagement(model.scene, model=model)}
    if compiler() is not None:
        runs["native"] = simulate_engagement(model.scene, model=model, native=True)
    return model, runs


def test_a_second_run_of_a_model_reuses_everything_and_gives_the_same_numbers(driveline_runs):
    _, runs = driveline_runs
    first, again = runs["vm"], runs["again"]
    assert again.result.stats["n_integrators_built"] == 0
    assert np.array_equal(first.result.t, again.result.t)
    for name in first.result.names():
        assert np.array_equal(first.result[name], again.result[name], equal_nan=True), name
    for key in ("engagement_time_s", "lockup_torque_jump_Nm", "peak_torque_Nm", "peak_jerk_rad_s3",
                "torque_response_time_s", "pressure_response_time_s", "dissipated_energy_J"):
        assert first.summary[key] == again.summary[key], key


def test_compiled_event_functions_give_the_same_run(driveline_runs):
    """With native code the locked mode's events (table calls) are compiled too: their values agree
    with CasADi's to rounding, and the run has the same steps, lock-up time and jump."""
    model, runs = driveline_runs
    if "native" not in runs:
        pytest.skip("no C compiler")
    compiled = model.hybrid.compiled()
    locked = compiled["pressing_locked"]
    assert locked.event_values(True) is not locked.events_on                  # calls a table: compiled
    assert compiled["pressing_slip_forward"].event_values(True) is compiled["pressing_slip_forward"].events_on
    seg = next(s for s in runs["vm"].result.segments if s.mode == "pressing_locked")
    xs = np.array([seg.x[k] / nominal for k, nominal in zip(locked.x_names, locked.x_nominal)])
    pu = np.zeros(locked.pu.numel())
    a = locked.events_on(xs, np.zeros((0, seg.t.size)), pu, seg.t)
    b = locked.event_values(True)(xs, np.zeros((0, seg.t.size)), pu, seg.t)
    assert np.allclose(a, b, rtol=1e-12, atol=1e-12 * np.max(np.abs(a)))
    vm, native = runs["vm"].summary, runs["native"].summary
    assert native["solver"]["statistics"]["n_steps"] == vm["solver"]["statistics"]["n_steps"]
    assert native["engagement_time_s"] == pytest.approx(vm["engagement_time_s"], rel=1e-12)
    assert native["lockup_torque_jump_Nm"] == pytest.approx(vm["lockup_torque_jump_Nm"], rel=1e-9)
    for name in ("w_in_rad_s", "w_out_rad_s", "h_1_m", "total_torque_Nm", "output_jerk_rad_s3"):
        a, b = runs["vm"].result[name], runs["native"].result[name]
        assert np.allclose(a, b, rtol=1e-10, atol=1e-12 * np.nanmax(np.abs(a)), equal_nan=True), name


def test_functions_without_table_calls_switch_to_numpy_sooner(monkeypatch):
    """From MIN_SAMPLES_PLAIN samples a function that calls no table, or only registered tables
    (log F_5/2), is evaluated by its numpy form (the same values to rounding); one that calls
    another table stays on CasADi's map up to MIN_SAMPLES."""
    import casadi as ca

    from clutchocp.physics.roughness import log_F52
    from clutchocp.simulation import vectorized
    from clutchocp.simulation.compiled import ColumnFunction

    xs, zs, pu, t = ca.SX.sym("xs", 2), ca.SX.sym("zs", 0), ca.SX.sym("pu", 1), ca.SX.sym("t")
    plain = ColumnFunction(ca.Function("plain", [xs, zs, pu, t], [ca.vertcat(ca.exp(-xs[0]) * xs[1], pu * t)]))
    other = ca.interpolant("other_table", "linear", [[0.0, 1.0, 2.5, 5.0]], [1.0, 0.5, 2.0, 1.0])
    table = ColumnFunction(ca.Function("table", [xs, zs, pu, t], [ca.vertcat(other(1 + xs[0] ** 2), pu * t)]))
    registered = ColumnFunction(ca.Function("registered", [xs, zs, pu, t],
                                            [ca.vertcat(log_F52(1 + xs[0] ** 2), pu * t)]))
    n = vectorized.MIN_SAMPLES_PLAIN + 72
    assert n < vectorized.MIN_SAMPLES
    rng = np.random.default_rng(5)
    X, Z, P, T = rng.uniform(0, 2, (2, n)), np.zeros((0, n)), np.array([0.7]), np.linspace(0, 1, n)
    for column in (plain, table, registered):
        got = column(X, Z, P, T)
        reference = np.column_stack([np.array(column.function(X[:, k], Z[:, k], P, T[k])).ravel() for k in range(n)])
        assert np.allclose(got, reference, rtol=1e-14, atol=0)
    for column in (plain, registered):
        assert not column._maps and column._numpy is not None      # numpy form, no map built
    assert list(table._maps) == [vectorized.padded_size(n)]          # CasADi's map


def test_single_sample_functions_equal_the_casadi_calls(driveline_runs):
    """ode, guards and resets at one sample through the buffer interface equal CasADi's own call."""
    import casadi as ca

    model, _ = driveline_runs
    cm = model.hybrid.compiled()["pressing_slip_forward"]
    rng = np.random.default_rng(11)
    xs = (np.asarray(model.initial_state) / cm.x_nominal) * (1 + 0.1 * rng.random(cm.nx))
    zs, pu, t = np.zeros(cm.nz), rng.uniform(0.5, 1.5, cm.pu.numel()), 0.13
    pairs = [("ode", cm.f_ode), ("guards", cm.f_guards)] + [(("reset", i), f) for i, f in enumerate(cm.resets)]
    assert len(pairs) > 2
    for what, function in pairs:
        reference = np.array(ca.densify(function(xs, zs, pu, t))).ravel()
        assert np.array_equal(cm.at(what, xs, zs, pu, t), reference), what


def test_compiled_loop_over_samples_equals_casadi_calls_sample_by_sample():
    """The compiled loop evaluates the generated function itself on each sample: bit for bit what
    CasADi's call of the same compiled function gives, with a table call, an empty input, a
    parameter vector shared by all samples and outputs that are constant zeros."""
    import casadi as ca

    from clutchocp.physics.roughness import log_F52
    from clutchocp.simulation.compiled import ColumnFunction
    from clutchocp.simulation.native import compile_columns, compiler

    if compiler() is None:
        pytest.skip("no C compiler")
    xs, zs, pu, t = ca.SX.sym("xs", 3), ca.SX.sym("zs", 0), ca.SX.sym("pu", 2), ca.SX.sym("t")
    f = ca.Function("loop_probe", [xs, zs, pu, t],
                    [ca.densify(ca.vertcat(log_F52(1 + xs[0] ** 2) * pu[1], ca.exp(-xs[1] * t) / (1 + xs[2] ** 2),
                                           ca.SX(0), pu[0] * t))])
    external, loop = compile_columns(f)
    column = ColumnFunction(external, loop=loop)
    rng = np.random.default_rng(17)
    p = np.array([0.4, -2.5])
    for n in (1, 2, 7, 300):
        X, T = rng.uniform(0, 3, (3, n)), rng.uniform(0, 1, n)
        reference = np.column_stack([np.array(external(X[:, k], np.zeros(0), p, T[k])).ravel() for k in range(n)])
        got = column(X, np.zeros((0, n)), p, T)
        assert got.shape == (4, n) and np.array_equal(got, reference)
        vm = np.column_stack([np.array(f(X[:, k], np.zeros(0), p, T[k])).ravel() for k in range(n)])
        assert np.allclose(got, vm, rtol=1e-13, atol=0)        # CasADi's virtual machine, to rounding
    assert not column._maps                                    # no CasADi map was built
    assert column(np.zeros((3, 0)), np.zeros((0, 0)), p, np.zeros(0)).shape == (4, 0)


def test_outputs_and_events_through_the_compiled_loop_give_the_run_of_casadi_maps(driveline_runs, monkeypatch):
    """default_driveline as compiled code, once through the compiled loops and once through
    CasADi maps of the same compiled functions: every column and event time bit for bit equal."""
    from clutchocp.engagement.model import EngagementModel
    from clutchocp.engagement.run import simulate_engagement
    from clutchocp.simulation import compiled
    from clutchocp.simulation.native import compiler

    if compiler() is None:
        pytest.skip("no C compiler")
    model, runs = driveline_runs
    looped = runs["native"]
    cm = model.hybrid.compiled()["pressing_locked"]
    assert cm.native_outputs_on()._loop is not None and cm.event_values(True)._loop is not None
    init = compiled.ColumnFunction.__init__
    monkeypatch.setattr(compiled.ColumnFunction, "__init__",
                        lambda self, function, max_maps=32, loop=None: init(self, function, max_maps))
    fresh = EngagementModel(model.scene)
    mapped = simulate_engagement(model.scene, model=fresh, native=True)
    assert fresh.hybrid.compiled()["pressing_locked"].native_outputs_on()._loop is None
    a, b = looped.series(), mapped.series()
    assert list(a) == list(b)
    for name in a:
        if name != "mode":
            assert np.array_equal(a[name], b[name], equal_nan=True), name
    assert looped.summary["events"] == mapped.summary["events"]


def test_events_and_outputs_evaluated_together_equal_the_separate_functions(driveline_runs, monkeypatch):
    """Where a mode's events call tables (default_driveline, locked), the grid samples' events and
    outputs come from one compiled function: its rows equal the compiled event function and the
    compiled outputs bit for bit, and the run equals the run with separate evaluations."""
    from clutchocp.engagement.model import EngagementModel
    from clutchocp.engagement.run import simulate_engagement
    from clutchocp.simulation.compiled import CompiledMode
    from clutchocp.simulation.native import compiler

    if compiler() is None:
        pytest.skip("no C compiler")
    model, runs = driveline_runs
    compiled = model.hybrid.compiled()
    locked = compiled["pressing_locked"]
    merged = locked.native_events_outputs()
    assert merged is not None and compiled["pressing_slip_forward"].native_events_outputs() is None   # no table call
    seg = next(s for s in runs["native"].result.segments if s.mode == "pressing_locked")
    xs = np.array([seg.x[k] / nominal for k, nominal in zip(locked.x_names, locked.x_nominal)])
    zs = np.zeros((0, seg.t.size))
    pu = np.random.default_rng(2).uniform(0.5, 1.5, locked.pu.numel())
    both = merged(xs, zs, pu, seg.t)
    n_events = len(locked.events)
    assert np.array_equal(both[:n_events], locked.event_values(True)(xs, zs, pu, seg.t), equal_nan=True)
    assert np.array_equal(both[n_events:], locked.native_outputs_on()(xs, zs, pu, seg.t), equal_nan=True)
    monkeypatch.setattr(CompiledMode, "native_events_outputs", lambda self: None)
    separate = simulate_engagement(model.scene, model=EngagementModel(model.scene), native=True)
    a, b = runs["native"].series(), separate.series()
    for name in a:
        if name != "mode":
            assert np.array_equal(a[name], b[name], equal_nan=True), name
    assert runs["native"].summary["events"] == separate.summary["events"]


def test_one_sample_calls_through_bound_buffers_equal_casadi_calls():
    """One sample goes through arrays bound to the 1-sample map once: every call gives CasADi's own
    value for its sample (values refreshed, outputs that are constant zeros still zero, an empty
    input), also after the 1-sample map was evicted and built again, and the result is a copy."""
    import casadi as ca

    from clutchocp.simulation.compiled import ColumnFunction

    xs, zs, pu, t = ca.SX.sym("xs", 2), ca.SX.sym("zs", 0), ca.SX.sym("pu", 3), ca.SX.sym("t")
    f = ca.Function("one", [xs, zs, pu, t], [ca.densify(ca.vertcat(ca.exp(xs[0]) * pu[2] - t, ca.SX(0), xs[1] / pu[0]))])
    column = ColumnFunction(f, max_maps=2)
    rng = np.random.default_rng(23)
    kept = []
    for k in range(6):
        x, p, time_ = rng.normal(size=2), rng.uniform(0.5, 2.0, 3), float(rng.uniform())
        got = column(x, np.zeros(0), p, time_)
        assert got.shape == (3, 1)
        assert np.array_equal(got[:, 0], np.array(f(x, np.zeros(0), p, time_)).ravel())
        kept.append((got, np.array(f(x, np.zeros(0), p, time_)).ravel()))
        if k == 2:                                  # evict the 1-sample map: two other sizes
            column(np.zeros((2, 3)), np.zeros((0, 3)), p, np.zeros(3))
            column(np.zeros((2, 5)), np.zeros((0, 5)), p, np.zeros(5))
            assert 1 not in column._maps
    assert all(np.array_equal(got[:, 0], reference) for got, reference in kept)   # earlier results untouched


def _scan_one_by_one(monitor, s0, S):
    """The reference for ``EventMonitor.scan_block``: :meth:`scan` on every step, committed as passed."""
    prev = s0
    for j in range(S.shape[1]):
        crossings, new_state = monitor.scan(prev, S[:, j])
        if crossings:
            return j, crossings
        monitor.commit(new_state)
        prev = S[:, j]
    return None, []


@pytest.mark.parametrize("seed", range(40))
def test_block_scan_of_event_values_equals_the_scan_sample_by_sample(seed):
    """Event values near zero and near the band (signed zeros, NaN, values on the band), every arming
    state and direction mixed: the block scan finds the step, the crossings and the arming the
    step-by-step scan finds."""
    from clutchocp.simulation.compiled import EventSpec
    from clutchocp.simulation.events import ARMED, ENTRY, PASSED, EventMonitor

    rng = np.random.default_rng(seed)
    band = 1e-5
    n_events = int(rng.integers(1, 7))
    specs = [EventSpec(i, f"e{i}", int(rng.choice([-1, 0, 1])), "m", i) for i in range(n_events)]
    choices = np.array([0.0, -0.0, band, -band, 2 * band, -2 * band, 0.5 * band, np.nan, 1.0, -1.0])
    S = rng.choice(choices, size=(n_events, int(rng.integers(1, 40)))) * rng.choice([1.0, 1.5], size=(n_events, 1))
    S[:, : S.shape[1] // 2] = np.abs(S[:, : S.shape[1] // 2]) * rng.choice([-1.0, 1.0], size=(n_events, 1))
    s0 = rng.choice(choices, size=n_events)
    states = [str(rng.choice([ARMED, ENTRY, PASSED])) for _ in range(n_events)]
    for samples in (S, S[:, :1]):               # a block, and the single sample
        block, reference = EventMonitor(specs, band), EventMonitor(specs, band)
        block.state, reference.state = list(states), list(states)
        assert block.scan_block(s0, samples) == _scan_one_by_one(reference, s0, samples)
        assert block.state == reference.state
