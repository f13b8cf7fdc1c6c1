"""Repeated engagements: heat carried from cycle to cycle, exact cooling of the conduction chain, limits, CLI."""

import csv
import json

import pytest

from clutchocp.cli import main
from clutchocp.engagement.cycles import run_cycles
from clutchocp.errors import ModelError
from clutchocp.engagement.run import simulate_engagement
from clutchocp.scene import load_scene


@pytest.fixture(scope="module")
def scene():
    return load_scene("default_driveline_thermal")


def test_without_losses_the_heat_accumulates_and_evens_out(scene):
    """No convection: each cycle starts where the last ended; a long open interval (600 s against the
    lining's diffusion time d^2 / alpha = 7.5 s) evens the plates out at 40 degC + heat / (C_s + C_f),
    whatever the profile the engagement left."""
    adiabatic = scene.with_overrides({"thermal.convection_coefficient": 0})
    first, second = run_cycles(adiabatic, cycles=2, cooling_time=0.0).cycles
    assert second["start_interface_temperature_C"] == pytest.approx(first["end_interface_temperature_C"], rel=1e-12)
    first, second = run_cycles(adiabatic, cycles=2, cooling_time=600.0).cycles
    area = 4 * 9.830043413082468e-3 * 1e6          # friction area [mm^2]
    heat = first["specific_energy_J_mm2"] * area
    assert second["start_interface_temperature_C"] == pytest.approx(40.0 + heat / (142 + 144), rel=1e-6)


def test_long_cooling_returns_to_the_first_cycle(scene):
    result = run_cycles(scene, cycles=2, cooling_time=600.0)
    first, second = result.cycles
    assert second["start_interface_temperature_C"] == pytest.approx(40.0, abs=1e-6)
    assert second["engagement_time_s"] == pytest.approx(first["engagement_time_s"], rel=1e-6)


def test_cooling_interval_follows_the_exact_solution(scene):
    """Cycle 2 starts from cycle 1's end temperatures relaxed over the interval by the chain's linear
    system (the matrix exponential, checked against CVODES in tests/physics/test_thermal.py)."""
    result = run_cycles(scene, cycles=2, cooling_time=2.0)
    run = simulate_engagement(scene)
    part = run.model.thermal
    expected = part.chain.relax([run.summary["final_plate_temperatures_C"][n] for n in part.names], 2.0, 40.0)[0]
    assert result.cycles[0]["end_interface_temperature_C"] == pytest.approx(expected, rel=1e-12)
    assert result.cycles[1]["start_interface_temperature_C"] == pytest.approx(expected, rel=1e-12)
    # the interface cools towards the oil while the lining behind it, hotter in places, gives heat back
    assert 40.0 < expected < run.summary["final_interface_temperature_C"]


def test_drift_and_temperature_limit(scene):
    result = run_cycles(scene, cycles=10, cooling_time=0.5, max_temperature_C=90.0)
    assert result.stop_reason == "temperature limit"
    assert len(result.cycles) == 3                      # 70.3, 86.1, then 95.8 degC
    times = [c["engagement_time_s"] for c in result.cycles]
    # A real drift, far above the event tolerance (1e-9 s). Its sign depends on the film regime: within
    # one engagement the heating thins the oil and slows the lock-up (less viscous torque), but a cycle
    # that starts hot also drains its films sooner; with the transmitted shear factor of the rough lining
    # (the viscous torque carries a large share of the slip) the first effect wins: 0.1830 s, 0.2002 s,
    # then 0.2106 s.
    assert times[1] > times[0] + 1e-3 and times[2] > times[1]
    summary = result.summary()
    assert summary["engagement_time_drift_s"] == pytest.approx(times[-1] - times[0])


def test_errors(scene, default_without_thermal):
    with pytest.raises(ModelError, match="thermal"):
        run_cycles(default_without_thermal, cycles=2)
    with pytest.raises(ModelError, match="cycles"):
        run_cycles(scene, cycles=0)
    with pytest.raises(ModelError, match="cooling_time"):
        run_cycles(scene, cycles=1, cooling_time=-1.0)


def test_cli_cycles_and_simulate_heat_files(tmp_path, capsys):
    out = tmp_path / "cycles"
    assert main(["cycles", "default_driveline_thermal", "--cycles", "2", "--cooling-time", "1",
                 "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["cycles_run"] == 2 and summary["stop_reason"] == "cycles"
    rows = list(csv.DictReader((out / "cycles.csv").open()))
    assert len(rows) == 2 and float(rows[1]["start_interface_temperature_C"]) > 40.0
    assert (out / "cycles.png").stat().st_size > 0
    assert main(["cycles", "zhang2021", "--out", str(tmp_path / "bad")]) == 2
    assert "thermal" in capsys.readouterr().err
    sim = tmp_path / "sim"
    assert main(["simulate", "default_driveline_thermal", "--out", str(sim)]) == 0
    header = (sim / "timeseries.csv").read_text().splitlines()[0].split(",")
    assert {"interface_temperature_C", "friction_plate_temperature_C", "specific_power_W_mm2", "T_interface",
            "T_lining_1", "T_core"} <= set(header)
    summary = json.loads((sim / "summary.json").read_text())
    assert summary["peak_interface_temperature_C"] > 40 and summary["specific_energy_J_mm2"] > 0
    assert (sim / "heat.png").stat().st_size > 0
