"""Monte Carlo of shift-control strategies: reproducible with its seed, numbers consistent, files clean."""

import json

import numpy as np
import pytest

from clutchocp.errors import SceneError
from clutchocp.scene import default_scene
from clutchocp.shiftcontrol.montecarlo import Strategy, parallel_map, run_sample, strategy_statistics
from clutchocp.shiftcontrol.report import run_robust
from clutchocp.scene.uncertainty import Uncertainty


T_MAX = 0.3      # [s]; the constant 0.8 MPa command locks the nominal default scene at 0.157 s


def _tasks(seed, n=2):
    scene = default_scene()
    draws = Uncertainty.from_scene(scene).samples(n, seed=seed)
    nominal = scene.without_uncertainty()
    strategy = Strategy("baseline", "constant command", np.array([0.0, 1.0]), np.array([0.8e6, 0.8e6]))
    return [{"scene_raw": nominal.raw, "scene_path": nominal.path, "overrides": d, "index": i,
             "strategies": [strategy], "t_max": T_MAX, "t_end": 0.6} for i, d in enumerate(draws)]


def _numbers(rows):
    return [{k: v for k, v in r.items() if k != "history"} for sample in rows for r in sample]


def test_samples_are_reproducible_with_the_seed_and_differ_with_another():
    first = _numbers(parallel_map(run_sample, _tasks(0), workers=1))
    again = _numbers(parallel_map(run_sample, _tasks(0), workers=1))
    other = _numbers(parallel_map(run_sample, _tasks(1), workers=1))
    assert first == again
    assert [r["friction.mu"] for r in first] != [r["friction.mu"] for r in other]
    for row in first:
        assert row["locked"] and row["jump_pct"] == pytest.approx(
            100 * abs(row["lockup_torque_jump_Nm"]) / row["locked_torque_Nm"])
        assert row["locked_within_t_max"] == (row["engagement_time_s"] <= T_MAX * 1.01)


def test_statistics_of_rows():
    rows = [{"strategy": "a", "locked": True, "locked_within_t_max": True, "jump_pct": v, "jerk_integral": 1.0,
             "engagement_time_s": 0.2, "dissipated_energy_J": 1.0} for v in (1.0, 2.0, 3.0)]
    rows.append({"strategy": "a", "locked": False, "locked_within_t_max": False, "jump_pct": None,
                 "jerk_integral": None, "engagement_time_s": None, "dissipated_energy_J": None})
    st = strategy_statistics(rows)["a"]
    assert st["lock_share"] == 0.75 and st["samples"] == 4
    assert st["jump_pct"] == {"median": 2.0, "p95": pytest.approx(2.9), "worst": 3.0}


@pytest.mark.slow
def test_robust_run_is_reproducible_with_its_seed(tmp_path):
    a = run_robust(out_dir=tmp_path / "a", samples=3, seed=5, workers=2, intervals=40, progress=False)
    b = run_robust(out_dir=tmp_path / "b", samples=3, seed=5, workers=1, intervals=40, progress=False)
    assert (tmp_path / "a" / "samples.csv").read_text() == (tmp_path / "b" / "samples.csv").read_text()
    assert a["statistics"] == b["statistics"]
    summary = json.loads((tmp_path / "a" / "summary.json").read_text())
    assert set(summary["statistics"]) >= {"baseline", "nominal_optimum", "closed_loop"}
    for name in ("jump_vs_fields.png", "distributions.png", "envelopes.png"):
        assert (tmp_path / "a" / name).stat().st_size > 10_000


def test_robust_feedforward_enters_the_strategy_list_when_installed(monkeypatch):
    """Plumbing only: a stand-in for clutchocp.optimal.robust.solve_robust (contract: one shared command,
    per-scenario lock times) returns the nominal optimum; the strategy list must pick it up, and the
    closed loop's feedforward when the spec asks for the robust curve."""
    from dataclasses import replace
    from types import SimpleNamespace

    from clutchocp.optimal.problem import EngagementOCP
    from clutchocp.shiftcontrol import workflow
    from clutchocp.shiftcontrol.spec import load_slip_spec

    scene = default_scene()
    seen = {}

    def stand_in(nominal, scenarios, *, t_max=None, intervals=60, **_):
        seen["scenarios"] = scenarios
        opt = EngagementOCP(nominal, intervals=intervals).solve(t_max=t_max)
        return SimpleNamespace(success=True, command_times=opt.command_times, command=opt.command,
                               scenarios=[opt], stats={"status": "stand-in"})

    monkeypatch.setattr(workflow, "robust_solver", lambda: (stand_in, lambda scene, corners: [corners[0]]))
    spec = replace(load_slip_spec(), t_max_fraction=1.0, schedule_field="")
    strategies, facts = workflow.build_strategies(scene.without_uncertainty(), Uncertainty.from_scene(scene),
                                                spec, intervals=30, say=lambda *a: None)
    assert [s.name for s in strategies] == ["baseline", "nominal_optimum", "robust_feedforward", "closed_loop"]
    assert facts["closed_loop"]["feedforward"] == "nominal_optimum"          # feedforward.curve = "nominal"
    spec.feedforward_curve = "robust"
    strategies, facts = workflow.build_strategies(scene.without_uncertainty(), Uncertainty.from_scene(scene),
                                                spec, intervals=30, say=lambda *a: None)
    assert facts["closed_loop"]["feedforward"] == "robust_feedforward"
    assert len(seen["scenarios"]) == 10                      # 2^3 corners, the centre and the diagonal's point
    assert facts["robust_feedforward"]["stats"] == {"status": "stand-in"}


def test_closed_loop_tracks_a_feedforward_with_a_time_margin_when_asked(monkeypatch):
    """feedforward.t_max_fraction < 1 (no robust feedforward): the nominal optimum strategy keeps t_max,
    the closed loop tracks an optimum that locks at that fraction of t_max on the nominal clutch. The fraction is
    0.95: with the transmitted shear-factor table and cavitating films the fastest lock-up that meets the end
    conditions on 30 intervals (a minimum-time solve) takes 0.1268 s = 0.939 t_max (measured), so a margin of
    10 % has no solution; the premise is asserted first."""
    from dataclasses import replace

    from clutchocp.optimal.problem import EngagementOCP
    from clutchocp.optimal.strategy import FASTEST_WEIGHTS
    from clutchocp.shiftcontrol import workflow
    from clutchocp.shiftcontrol.spec import load_slip_spec

    monkeypatch.setattr(workflow, "robust_solver", lambda: None)
    scene = default_scene()
    fraction = 0.95
    ocp = EngagementOCP(scene.without_uncertainty(), intervals=30)
    assert ocp.solve(t_max=np.inf, weights=FASTEST_WEIGHTS).t_f < fraction * ocp.default_t_max()
    spec = replace(load_slip_spec(), t_max_fraction=fraction, schedule_field="")
    strategies, facts = workflow.build_strategies(scene.without_uncertainty(), Uncertainty.from_scene(scene), spec,
                                                intervals=30, say=lambda *a: None)
    t_max = facts["t_max_s"]
    assert [s.name for s in strategies] == ["baseline", "nominal_optimum", "closed_loop"]
    assert strategies[1].notes["t_lock_s"] == pytest.approx(t_max, rel=1e-6)
    assert facts["closed_loop"]["feedforward"] == "nominal_optimum_with_margin"
    assert "0.95 t_max" in strategies[2].label
    # the IDAS replay of the tighter optimum locks where the collocation put it, within the lock-time tolerance
    assert facts["closed_loop"]["nominal_lock_s"] == pytest.approx(fraction * t_max, rel=0.01)


def test_closed_loop_is_scheduled_on_the_oil_viscosity(monkeypatch):
    """[schedule] field = "oil.viscosity", points = 3: one feedforward and feedback per viscosity at the
    ends and the centre of the scene's spread, each an optimum locking at t_max_fraction x t_max on its
    own scene; a clutch between two viscosities gets their designs blended."""
    from dataclasses import replace

    from clutchocp.shiftcontrol import workflow
    from clutchocp.shiftcontrol.spec import load_slip_spec

    monkeypatch.setattr(workflow, "robust_solver", lambda: None)
    scene = default_scene()
    nominal = scene.without_uncertainty()
    spec = replace(load_slip_spec(), schedule_points=3)
    strategies, facts = workflow.build_strategies(nominal, Uncertainty.from_scene(scene), spec, intervals=30,
                                                say=lambda *a: None)
    eta = nominal.value("oil.viscosity")
    schedule = strategies[-1].feedback
    assert facts["closed_loop"]["schedule"]["values"] == pytest.approx([0.7 * eta, eta, 1.3 * eta])
    for t_lock in facts["closed_loop"]["schedule"]["lock_times_s"]:
        assert t_lock == pytest.approx(spec.t_max_fraction * facts["t_max_s"], rel=0.01)
    assert schedule.index(nominal.with_overrides({"oil.viscosity": 0.8 * eta})) == 0
    assert schedule.index(nominal.with_overrides({"oil.viscosity": 1.1 * eta})) == 1
    feedback, overrides = schedule.select(nominal.with_overrides({"oil.viscosity": 1.35 * eta}))
    assert feedback is schedule.feedbacks[2] and overrides == {"oil.viscosity": pytest.approx(1.3 * eta)}
    # the three designs share their horizon (their optima lock within one TCU sample), so they blend
    feedback, overrides = schedule.select(nominal.with_overrides({"oil.viscosity": 1.1 * eta}))
    assert feedback.horizon == schedule.feedbacks[1].horizon and overrides == {"oil.viscosity": 1.1 * eta}
    # without the field in the uncertainty there is no grid: one design, on the nominal scene
    from clutchocp.shiftcontrol.schedule import schedule_values
    others = Uncertainty([s for s in Uncertainty.from_scene(scene).spreads if s.key != "oil.viscosity"])
    assert schedule_values(nominal, spec, others) == []
    assert schedule_values(nominal, replace(spec, schedule_points=1), Uncertainty.from_scene(scene)) == []
    with pytest.raises(SceneError, match=r"schedule\.field = 'oil\.viscosty': the scene 'default_driveline' has no"):
        schedule_values(nominal, replace(spec, schedule_field="oil.viscosty"), Uncertainty.from_scene(scene))


def test_a_subset_of_strategies_skips_the_robust_feedforward(monkeypatch):
    """--strategies closed_loop: no robust solve (it would fail the test), the nominal optimum solved and run on the
    nominal clutch alone (its jerk is the closed loop's yardstick), the closed loop on every draw."""
    from dataclasses import replace

    from clutchocp.errors import ModelError
    from clutchocp.shiftcontrol import workflow
    from clutchocp.shiftcontrol.spec import load_slip_spec

    def solve(*args, **kwargs):
        raise AssertionError("the robust feedforward was solved although not asked for")

    monkeypatch.setattr(workflow, "robust_solver", lambda: (solve, lambda scene, corners: []))
    scene = default_scene()
    spec = replace(load_slip_spec(), schedule_field="")
    strategies, facts = workflow.build_strategies(scene.without_uncertainty(), Uncertainty.from_scene(scene), spec,
                                                intervals=30, say=lambda *a: None, chosen=("closed_loop",))
    assert [s.name for s in strategies] == ["nominal_optimum", "closed_loop"]
    assert strategies[0].notes["centre_only"] and not strategies[1].notes.get("centre_only")
    assert facts["robust_feedforward"] == "not asked for (--strategies)"
    with pytest.raises(ModelError, match="--strategies open_loop: allowed are baseline"):
        workflow.check_strategies(("open_loop",))
    assert workflow.check_strategies(("closed_loop", "baseline")) == ("baseline", "closed_loop")


def test_closed_loop_tracks_an_optimum_landing_above_the_locked_torque_when_asked(monkeypatch):
    """feedforward.lock_margin = 0.03: the closed loop tracks the nominal optimum whose slipping torque at
    lock-up is 3 % above the locked torque (the nominal optimum strategy keeps the optimiser's 0.5 %); replayed
    in IDAS that curve locks with a jump of -3 % of the locked torque."""
    from dataclasses import replace

    from clutchocp.optimal.problem import LOCK_MARGIN, EngagementOCP
    from clutchocp.optimal.verify import verify
    from clutchocp.shiftcontrol import workflow
    from clutchocp.shiftcontrol.spec import load_slip_spec

    monkeypatch.setattr(workflow, "robust_solver", lambda: None)
    tracked = []
    design_schedule = workflow.design_schedule

    def spy(scene, spec, uncertainty, feedforward_for, **kwargs):
        tracked.append(feedforward_for(scene))
        return design_schedule(scene, spec, uncertainty, feedforward_for, **kwargs)

    monkeypatch.setattr(workflow, "design_schedule", spy)
    scene = default_scene()
    nominal = scene.without_uncertainty()
    spec = replace(load_slip_spec(), t_max_fraction=1.0, schedule_field="", lock_margin=0.03)
    strategies, facts = workflow.build_strategies(nominal, Uncertainty.from_scene(scene), spec, intervals=30,
                                                say=lambda *a: None)
    assert "landing 3 % above the locked torque" in strategies[-1].label
    assert facts["closed_loop"]["feedforward_lock_margin"] == 0.03
    ocp = EngagementOCP(nominal, intervals=30, lock_margin=0.03)
    opt = ocp.solve(t_max=facts["t_max_s"])
    times, command = tracked[0]
    assert np.allclose(times, opt.command_times, rtol=1e-4) and np.allclose(command, opt.command, rtol=1e-3, atol=1e3)
    idas, _ = verify(ocp, opt)
    assert idas["torque_jump_Nm"] / idas["jump_reference_Nm"] == pytest.approx(-0.03, abs=0.005)
    own = EngagementOCP(nominal, intervals=30).solve(t_max=facts["t_max_s"])   # the optimiser's own landing
    assert own.terms["lockup_torque_jump_Nm"] / opt.terms["lockup_torque_jump_Nm"] == pytest.approx(LOCK_MARGIN / 0.03,
                                                                                                    rel=1e-6)
