"""The top-level API, honest figures, located times and the optimize items a new user met."""

import dataclasses
import math

import numpy as np
import pytest
from matplotlib.figure import Figure

import clutchocp
from clutchocp.engagement import figures as engagement_figures
from clutchocp.errors import ClutchocpError, PhysicalRangeError
from clutchocp.optimal import figures as optimal_figures
from clutchocp.optimal import report as optimal_report
from clutchocp.optimal.bound import jerk_lower_bound, output_jerk_share
from clutchocp.optimal.problem import check_weights
from clutchocp.simulation.locate import crossing_time, peak, root_near


# -- top-level API -------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def bao():
    return clutchocp.simulate("bao2020")


def test_simulate_takes_a_scene_name_and_has_a_short_repr(bao):
    text = repr(bao)
    assert len(text) < 300 and "bao2020" in text and "lock-up 0.4398" in text
    assert len(repr(bao.result)) < 300


def test_simulate_engagement_takes_a_scene_name():
    from clutchocp.engagement.run import simulate_engagement
    run = simulate_engagement("zhang2021", output_points=201)
    assert run.summary["scene"] == "zhang2021"


def test_table_columns_carry_units(bao):
    table = bao.table()
    assert len(repr(table)) < 300
    units = table.units
    assert units["time_s"] == "s" and units["total_torque_Nm"] == "N m" and units["pressure_Pa"] == "Pa"
    assert units["film_1_closing_speed_m_s"] == "m/s" and units["mode"] == ""
    assert all(unit for name, unit in units.items() if name != "mode")       # no column without a unit
    assert {len(col) for col in table.values()} == {bao.result.t.size}


def test_plot_gives_a_figure_and_a_png(bao, tmp_path):
    fig = bao.plot(tmp_path / "bao.png")
    assert isinstance(fig, Figure) and len(fig.axes) == 4
    assert (tmp_path / "bao.png").read_bytes()[:4] == b"\x89PNG"


def test_api_run_settings_are_checked_like_the_scene(bao):
    with pytest.raises(PhysicalRangeError, match="output_points.*200000"):
        clutchocp.simulate("zhang2021", output_points=200_000_000)
    with pytest.raises(ClutchocpError, match="rtol"):
        clutchocp.simulate("zhang2021", rtol=10.0)
    with pytest.raises(ClutchocpError, match="t_end"):
        clutchocp.simulate("zhang2021", t_end=1e-12)


def test_overrides_reach_the_run():
    a = clutchocp.simulate("zhang2021", output_points=201)
    b = clutchocp.simulate("zhang2021", overrides={"oil.viscosity": "40 mPa s"}, output_points=201)
    assert b.model.scene.value("oil.viscosity") == pytest.approx(0.04)
    assert a.summary["engagement_time_s"] != b.summary["engagement_time_s"]


# -- per-film fluid force and energy columns ------------------------------------------------------
@pytest.mark.parametrize("scene", ["zhang2021", "default_driveline"])
def test_film_energy_from_the_per_film_fluid_force(scene):
    """int sum_i F_fluid,i x closing speed_i dt over the table = the film dissipation E_film."""
    table = clutchocp.simulate(scene).table()
    t = table["time_s"]
    n = sum(1 for name in table if name.endswith("_fluid_force_N"))
    power = sum(table[f"film_{i + 1}_fluid_force_N"] * table[f"film_{i + 1}_closing_speed_m_s"] for i in range(n))
    film = float(np.sum(0.5 * (power[1:] + power[:-1]) * np.diff(t)))
    assert film == pytest.approx(table["film_energy_J"][-1], rel=1e-5)


def test_the_energy_balance_closes_from_the_table_alone(bao):
    table, s = bao.table(), bao.summary
    last = {name: col[-1] - col[0] for name, col in table.items() if name.endswith("_energy_J")}
    work_in = last["source_energy_J"] + last["hydraulic_energy_J"] - last.get("load_energy_J", 0.0) \
        - last["spring_energy_J"]
    dissipated = sum(last.get(f"{k}_energy_J", 0.0) for k in ("slip", "film", "seal", "spline", "shaft", "impact"))
    stored = last["kinetic_energy_J"] + last["contact_energy_J"]
    assert dissipated == pytest.approx(s["dissipated_energy_J"], rel=1e-12)
    assert abs(work_in - stored - dissipated) / abs(work_in) == pytest.approx(s["energy_balance_rel_error"],
                                                                            rel=1e-3, abs=1e-12)


# -- located times and peaks ----------------------------------------------------------------------
def test_crossing_and_peak_on_the_local_cubic_match_closed_forms():
    t = np.linspace(0.0, 1.0, 21)
    y = np.sin(3.0 * t)
    # sin(3t) = 0.5 at t = pi/18; linear interpolation is off by ~1e-4 here
    assert crossing_time(t, y, 0.5) == pytest.approx(math.pi / 18, abs=2e-6)
    value, at = peak(t, y)
    assert at == pytest.approx(math.pi / 6, abs=2e-4) and value == pytest.approx(1.0, abs=2e-6)
    s = np.linspace(0.0, 0.3, 7)
    assert root_near(s, (0.31 - s) * (1 + 2 * (0.31 - s)), 0.3) == pytest.approx(0.31, abs=1e-12)


# zhang2021 as these tolerances were set on: roughness split equally between the surfaces (its viscous
# peak is smoother than the lining-rough scene's) and a 4 s run, so 2001 points are 2 ms apart.
EQUAL_SPLIT_4S = {"roughness.sigma_1": 8.41e-6 / math.sqrt(2), "roughness.sigma_2": 8.41e-6 / math.sqrt(2),
                  "simulation.t_end": 4.0}


def test_response_times_do_not_depend_on_the_output_grid():
    coarse = clutchocp.simulate("zhang2021", output_points=2001, overrides=EQUAL_SPLIT_4S).summary
    fine = clutchocp.simulate("zhang2021", output_points=20001, overrides=EQUAL_SPLIT_4S).summary
    # read off the grid, the torque response time moved by 5.8e-5 s between these grids
    assert coarse["torque_response_time_s"] == pytest.approx(fine["torque_response_time_s"], abs=1e-6)
    assert coarse["pressure_response_time_s"] == pytest.approx(fine["pressure_response_time_s"], abs=1e-7)
    assert coarse["peak_torque_Nm"] == pytest.approx(fine["peak_torque_Nm"], rel=2e-6)
    # and against the closed form of the first-order lag: 10 % -> 90 % takes t_s ln 9
    assert coarse["pressure_response_time_s"] == pytest.approx(0.04 * math.log(9.0), rel=1e-6)


# -- engagement figures -----------------------------------------------------------------------------
def captured_figures(monkeypatch, module):
    figures = {}

    def keep(fig, path):
        figures[path.name] = fig
        return path
    monkeypatch.setattr(module, "save_figure", keep)
    return figures


def legend_texts(fig):
    return [t.get_text() for ax in fig.axes if ax.get_legend() for t in ax.get_legend().get_texts()]


def test_spring_applied_pressure_figure_shows_the_piston_force(bao, monkeypatch, tmp_path):
    figures = captured_figures(monkeypatch, engagement_figures)
    engagement_figures.plot_engagement(bao, tmp_path)
    fig = figures["pressure.png"]
    force = [line for ax in fig.axes for line in ax.get_lines() if "piston" in str(line.get_label())]
    assert force and np.max(np.abs(force[0].get_ydata())) > 1.0          # kN, not a flat zero line
    assert any("lock-up at" in text for text in legend_texts(fig))


def test_film_figure_shows_the_early_transient(bao, monkeypatch, tmp_path):
    figures = captured_figures(monkeypatch, engagement_figures)
    engagement_figures.plot_engagement(bao, tmp_path)
    left = figures["gaps.png"].axes[0]
    assert left.get_xlim()[1] < 0.1 * bao.result.t[-1]          # the squeeze phase fills the panel
    assert all(any("lock-up at" in t for t in legend_texts(figures[name])) for name in figures)


# -- optimize ---------------------------------------------------------------------------------------
def test_the_default_smooth_weight_follows_the_jerk_weight():
    assert check_weights(None)["smooth"] == 0.1
    assert check_weights({"jerk": 0, "time": 1})["smooth"] == 0.0       # no hidden penalty on a time objective
    assert check_weights({"jerk": 2})["smooth"] == pytest.approx(0.2)
    assert check_weights({"jerk": 0, "time": 1, "smooth": 0.3})["smooth"] == 0.3


@pytest.fixture(scope="module")
def best():
    return clutchocp.optimize(intervals=30)


def test_optimize_result_repr_table_and_plot(best, tmp_path):
    assert len(repr(best)) < 300 and len(repr(best.optimum)) < 300 and best.success
    table = best.table()
    assert list(table) == ["time_s", "pressure_command_Pa", "pressure_Pa", "phase", "to_next"]
    # the whole usable curve: the engagement up to lock-up, then the ramp to the clamp pressure and its hold
    lock_row = list(table["time_s"]).index(best.optimum.t_f)
    assert table["phase"][lock_row] == "clamp_ramp" and table["phase"][-1] == "clamp_hold"
    assert table["time_s"][-1] == pytest.approx(best.summary["clamp"]["ramp_end_s"])
    assert isinstance(best.plot(tmp_path / "p.png"), Figure) and (tmp_path / "p.png").exists()


def test_jerk_lower_bound_is_on_the_basis_of_the_jerk_integral(best):
    s = best.summary
    share = output_jerk_share(best.scene)
    slip_bound = jerk_lower_bound(s["initial_slip_rad_s"], s["initial_slip_rate_rad_s2"], best.optimum.t_f)
    assert s["slip_jerk_lower_bound"] == pytest.approx(slip_bound, rel=1e-12)
    assert s["jerk_lower_bound"] == pytest.approx(slip_bound * share**2, rel=1e-12)
    # the optimum's output jerk integral is above its bound, by the same order as the slip ratio
    assert 1.0 <= s["optimal"]["jerk_integral"] / s["jerk_lower_bound"] < 3.0


def test_lock_time_difference_is_located_not_read_off_the_command_grid(best):
    """The lock time compared with collocation is the zero of the slip located between the replay's samples,
    not the event time nor a command-grid point. Measured on the merged physics: the replay of the default
    optimum on 30 intervals (t_f = 0.135022 s) slips at 0.1348598 s, its lock-up event fires at 0.1348869 s,
    the located zero is 0.1348815 s (0.104 % before t_f)."""
    ver = best.summary["verification"]
    t_f = best.optimum.t_f
    located = ver["idas"]["located_lock_time_s"]
    assert ver["lock_time_rel_diff"] == pytest.approx(abs(located - t_f) / t_f, rel=1e-12)
    assert ver["lock_time_rel_diff"] > 0.0
    # the located zero of the slip lies between the last slipping sample and the first that is not
    res = best.replay.result
    w_rel = res["w_in_rad_s"] - res["w_out_rad_s"]
    slip = np.nonzero((res.t <= ver["idas"]["engagement_time_s"]) & (w_rel > 0))[0]
    assert res.t[slip[-1]] <= located <= ver["idas"]["engagement_time_s"] + 1e-6 * t_f
    assert located != ver["idas"]["engagement_time_s"]             # a root found, not the event time taken


def test_baselines_figure_compares_at_the_engagement_time(best, monkeypatch, tmp_path):
    figures = captured_figures(monkeypatch, optimal_figures)
    optimal_figures.plot_optimum(tmp_path, best.scene, best.optimum, best.replay, best.ocp.baseline,
                                best.baselines, best.summary)
    right = figures["baselines.png"].axes[1]
    assert "engagement" in right.get_xlabel()
    assert any("lower bound" in t for t in legend_texts(figures["baselines.png"]))
    assert all(any("lock-up" in t for t in legend_texts(figures[name]))
               for name in ("pressure.png", "torque.png", "jerk.png", "speeds.png"))


def test_ctrl_c_during_a_sweep_stops_it_instead_of_dropping_the_point(best):
    from clutchocp import interrupt
    interrupt._state["requested"] = True           # as after a Ctrl-C that IPOPT swallowed
    try:
        with pytest.raises(interrupt.UserInterrupt, match="IPOPT"):
            optimal_report._sweep(best.ocp, best.optimum, [0.25], None, lambda *a, **k: None)
    finally:
        interrupt._state["requested"] = False


@pytest.mark.slow
def test_a_time_objective_is_not_held_back_by_the_smooth_term():
    from clutchocp.optimal.problem import EngagementOCP
    ocp = EngagementOCP(clutchocp.load_scene("default_driveline"), intervals=40)
    t_max = 1.5 * ocp.default_t_max()
    default = ocp.solve(t_max=t_max, weights={"jerk": 0, "time": 1})
    smooth = ocp.solve(t_max=t_max, weights={"jerk": 0, "time": 1, "smooth": 0.1})
    assert default.t_f < 0.95 * smooth.t_f


# -- hydro-viscous drive figures and limits -------------------------------------------------------
def test_a_controller_limit_beyond_the_valve_warns_with_the_value():
    from clutchocp.hvd.design import pressure_limits
    from clutchocp.hvd.model import HvdModel
    from clutchocp.hvd.spec import load_controller
    model = HvdModel(clutchocp.load_scene("liao2021_hvd"))
    spec = dataclasses.replace(load_controller("pi"), pressure_max=3.0e6)
    with pytest.warns(UserWarning, match="controller.pressure_max = 3e.06 Pa.*valve"):
        lo, hi = pressure_limits(model, spec)
    assert hi == model.p_max


@pytest.mark.slow
def test_closed_loop_figure_shows_valve_limits_and_load_steps(monkeypatch, tmp_path):
    from clutchocp.hvd import figures as hvd_figures
    from clutchocp.hvd import report as hvd_report
    figures = captured_figures(monkeypatch, hvd_figures)
    hvd_report.run_control("liao2021_hvd", "pi", out_dir=tmp_path / "ctl", verbose=False)
    texts = legend_texts(figures["closed_loop.png"])
    assert any("valve limits" in t for t in texts) and any("load steps" in t for t in texts)
    axis = figures["static_map.png"].axes[1].xaxis
    figures["static_map.png"].canvas.draw()
    labels = [t.get_text() for t in axis.get_ticklabels() if t.get_text()]
    assert len(labels) >= 3, labels


def test_a_pressure_release_has_no_zhang_response_times(bao):
    """bao2020 engages by releasing the pressure that holds it open (set 0 Pa below the initial
    63.66 MPa): Zhang's times, measured from a rise to the set pressure, do not apply, and its
    figures draw no torque-response panel."""
    scene = bao.model.scene
    assert scene.value("actuation.pressure") < scene.value("actuation.initial_pressure")
    assert bao.summary["torque_response_time_stable_s"] is None
    assert bao.summary["torque_response_time_s"] is None
