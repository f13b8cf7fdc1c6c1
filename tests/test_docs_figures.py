"""Figures an engineer can read: plain ticks, round-off drawn flat, legends outside the data, wrapped
titles, overrides in titles, sweep ticks at the sampled values, the brake's input jerk, the kiss spike."""

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

import clutchocp
from clutchocp.optimal import figures as optimal_figures
from clutchocp.plotting import clip_spike, finish, flat_value, overrides_of, scene_title
from clutchocp.scene import load_scene
from clutchocp.study import figures as study_figures
from clutchocp.study.tasks import Task


def figure(width=6.4):
    fig = Figure(figsize=(width, 4.2), layout="constrained")
    FigureCanvasAgg(fig)
    return fig, fig.add_subplot()


def test_flat_value_is_round_off_only():
    assert flat_value(-53.077484 + 1e-8 * np.array([0.0, 3.4, -6.8, 1.0])) == pytest.approx(-53.077484)
    assert flat_value([0.2847, 0.2850]) is None                  # 1e-3 apart: a signal
    assert flat_value([1.0, 1.0, 1.0]) is None                   # exactly equal: nothing to explain
    assert flat_value([np.nan, 2.0, 2.0 + 1e-12]) == pytest.approx(2.0)


def test_round_off_is_drawn_flat_with_its_value_and_no_offset():
    fig, ax = figure()
    ax.plot([0.05, 0.06, 0.07], -53.077484 + np.array([3.4e-8, -6.8e-8, 0.0]))
    finish(fig)
    low, high = ax.get_ylim()
    assert high - low == pytest.approx(0.1 * 53.077484, rel=1e-6)          # +-5 % around the value
    assert any("constant: -53.077484" in t.get_text() for t in ax.texts)
    fig.canvas.draw()
    assert ax.yaxis.get_major_formatter().get_offset() == ""


def test_log_ticks_are_plain_numbers_with_the_in_between_ticks_on_a_short_axis():
    fig, ax = figure()
    ax.plot([0.0, 1.0], [7.3, 85.0])
    ax.set_yscale("log")
    finish(fig)
    fig.canvas.draw()
    major = [t.get_text() for t in ax.get_yticklabels() if t.get_text()]
    minor = [t.get_text() for t in ax.get_yticklabels(minor=True) if t.get_text()]
    assert "10" in major and {"20", "40", "60"} <= set(minor)
    assert not any("times" in t or "^" in t or "$" in t for t in major + minor)


def test_a_legend_moves_outside_the_data_and_the_figure_widens():
    fig, ax = figure()
    ax.plot([0, 1], [0, 1], label="a curve with a long label that would cover the data")
    ax.legend()
    finish(fig)
    fig.canvas.draw()
    legend = ax.get_legend().get_window_extent()
    width = fig.get_figwidth()
    assert legend.x0 >= ax.get_window_extent().x1 and width > 6.4
    finish(fig)                                                              # a second call changes nothing
    assert fig.get_figwidth() == width


def test_a_long_title_is_wrapped_to_the_figure():
    fig, ax = figure(width=4.0)
    ax.set_title("zhang2021 (--set actuation.max_pressure=1.2 MPa, --set oil.viscosity=80 cSt): input jerk up to lock-up")
    finish(fig)
    fig.canvas.draw()
    assert "\n" in ax.title.get_text() and ax.title.get_window_extent().x1 <= fig.bbox.x1


def test_the_overrides_of_a_run_are_in_its_title():
    scene = load_scene("zhang2021", overrides={"oil.viscosity": "80 cSt", "actuation.max_pressure": "1.2 MPa"})
    assert overrides_of(scene) == {"actuation.max_pressure": "1.2 MPa", "oil.viscosity": "80 cSt"}
    assert overrides_of(load_scene("zhang2021")) == {}
    assert scene_title(scene, "speeds") == ("zhang2021 (--set actuation.max_pressure=1.2 MPa, "
                                            "--set oil.viscosity=80 cSt): speeds")


def test_a_spike_is_annotated_off_scale():
    fig, ax = figure()
    t = np.linspace(0.0, 1.0, 1001)
    y = np.sin(2 * np.pi * t)
    y[5] = 500.0
    ax.plot(t, y)
    assert clip_spike(ax, t, y, (0.004, 0.01), what="kiss", unit="rad/s^3") == 500.0
    assert ax.get_ylim()[1] < 2.0 and "kiss at t = 0.005 s: 500 rad/s^3" in ax.texts[0].get_text()


def test_sweep_maps_tick_the_sampled_values_and_mark_failed_points(monkeypatch, tmp_path):
    figures = {}
    monkeypatch.setattr(study_figures, "save_figure", lambda fig, path: figures.setdefault(path.name, fig) and path)
    scene = load_scene("zhang2021")
    rows = []
    for p in (3e5, 4.5e5, 6e5):
        for eta in (0.05, 0.065, 0.08):
            failed = p == 6e5 and eta == 0.08
            rows.append({"actuation.pressure": p, "oil.viscosity": eta, "status": "failed" if failed else "ok",
                         "engagement_time_s": None if failed else 4 + eta * p / 1e5,
                         "lockup_torque_jump_Nm": None if failed else -53.077484 + 1e-8 * eta,
                         "peak_torque_Nm": None if failed else 100 * eta, "dissipated_energy_J": None if failed else p})
    task = Task("zhang2021", "simulate", {"film.load_sharing": "additive"}, {})
    study_figures.draw_study(tmp_path, scene, task, ("actuation.pressure", "oil.viscosity"), rows, False)
    fig = figures["sweep_maps.png"]
    ax = fig.axes[0]
    assert list(ax.get_xticks()) == pytest.approx([0.05, 0.065, 0.08])
    assert list(ax.get_yticks()) == pytest.approx([0.3, 0.45, 0.6])             # MPa
    assert any(t.get_text() == "x" for t in ax.texts)                          # the failed point
    jump = next(a for a in fig.axes if "jump" in a.get_title())
    assert any("the same at every point: -53.077484" in t.get_text() for t in jump.texts)
    assert "--set film.load_sharing=additive" in fig._suptitle.get_text()


@pytest.fixture(scope="module")
def brake():
    return clutchocp.simulate("zhang2021")


def test_a_brake_draws_the_input_jerk_not_a_zero_line(brake):
    scene = brake.model.scene
    fig = optimal_figures.jerk_figure(scene, (("run", brake, "C0"),))
    line = fig.axes[0].get_lines()[0]
    t, jerk = np.asarray(line.get_xdata()), np.asarray(line.get_ydata())
    assert "input jerk" in fig.axes[0].get_ylabel() and np.max(np.abs(jerk)) > 100.0
    torque = np.interp(t, brake.result.t, brake.result["total_torque_Nm"])
    expected = -np.gradient(torque, t) / scene.value("driveline.input_inertia")
    k = len(t) // 2
    assert jerk[k] == pytest.approx(expected[k], rel=1e-6, abs=1e-6)


def test_the_kiss_spike_does_not_set_the_jerk_scale():
    run = clutchocp.simulate("default_fill")
    fig = optimal_figures.jerk_figure(run.model.scene, (("run", run, "C0"),))
    ax = fig.axes[0]
    t, jerk = run.result.t, np.abs(run.result["output_jerk_rad_s3"])
    kiss = next(e.t for e in run.result.events if e.name == "impact")
    slip = t <= run.summary["engagement_time_s"]
    spike = jerk[slip & (t >= kiss) & (t <= kiss + 0.02 * t[slip][-1])].max()
    rest = jerk[slip & (t > kiss + 0.02 * t[slip][-1])].max()
    assert spike > 3 * rest                                   # the scene's own step kisses hard
    assert ax.get_ylim()[1] < 0.5 * spike                     # the scale is the slip phase's
    assert any("kiss" in a.get_text() and "off scale" in a.get_text() for a in ax.texts)


def test_film_pressures_are_drawn_against_the_cavitation_limit(monkeypatch, tmp_path):
    from clutchocp.engagement import figures as engagement_figures

    figures = {}
    monkeypatch.setattr(engagement_figures, "save_figure", lambda fig, path: figures.setdefault(path.name, fig))
    run = clutchocp.simulate("bao2020")
    engagement_figures.plot_engagement(run, tmp_path)
    left, right = figures["film_pressure.png"].axes[:2]
    p_cav = run.summary["film_cavitation_pressure_Pa"] / 1e6
    lowest = run.summary["min_film_pressure_Pa"] / 1e6
    for ax in (left, right):
        low, high = ax.get_ylim()
        assert low < p_cav < high and any(list(line.get_ydata()[:1]) == [p_cav] for line in ax.get_lines())
    low, high = right.get_ylim()
    # the suction after lock-up (bao2020's centrifugal film) is readable: not scaled to the impact's ~20 MPa
    assert low < lowest < 0.0 < high < 2.0
    assert any("cavitation pressure" in t.get_text() for t in right.get_legend().get_texts())
