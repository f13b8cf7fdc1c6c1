"""The model's edges: the contact's capacity at zero gap checked before a run, a film closing during a run
ends it in one line, and neither check costs a run that stays inside."""

import math
import time

import numpy as np
import pytest
from scipy import integrate, stats

from clutchocp.cli import main
from clutchocp.engagement import run as engagement_run
from clutchocp.engagement.edges import check_contact_capacity, contact_capacity, pack_pressure
from clutchocp.engagement.model import EngagementModel
from clutchocp.engagement.run import simulate_engagement
from clutchocp.errors import ModelEdgeError, PhysicalRangeError
from clutchocp.scene import load_scene

F52_AT_ZERO = 0.61663                    # F_5/2(0), PHYSICS.md (quadrature)
FILM_AREA = math.pi * (0.085**2 - 0.064**2)
SIGMA_6UM = {"roughness.sigma_1": "6 um"}
# Heavy plates (20 kg) under a fast valve (1 ms) in thin oil on a permeable lining: at 0.75 MPa the pack is
# inside the contact's 0.771 MPa, but the plates' momentum presses film 1 with 0.97 MPa and closes it at 1.84 ms.
SPIKE = {**SIGMA_6UM, "actuation.time_constant": "1 ms", "actuation.pressure": "0.75 MPa",
         "pack.model": "masses", "pack.plate_masses": ["20 kg"] * 4, "oil.viscosity": "5 mPa s",
         "plates.lining_permeability": "4e-11 m^2"}


def greenwood_tripp_at_zero(n, beta, sigma, E):
    """(16 sqrt2 / 15) pi (n beta sigma)^2 sqrt(sigma / beta) E' F_5/2(0) [Pa]."""
    return 16 * math.sqrt(2) / 15 * math.pi * (n * beta * sigma) ** 2 * math.sqrt(sigma / beta) * E * F52_AT_ZERO


def test_f52_at_zero_by_quadrature():
    value, _ = integrate.quad(lambda s: s**2.5 * stats.norm.pdf(s), 0, np.inf, epsabs=1e-13)
    assert value == pytest.approx(F52_AT_ZERO, abs=5e-6)


def test_greenwood_tripp_capacity_is_the_closed_form():
    """0.771 MPa for Zhang's asperities at sigma = 6 um (the review's case), 1.79 MPa at 8.41 um: sigma^2.5."""
    low = contact_capacity(load_scene("default_driveline", SIGMA_6UM))
    assert low.pressure_Pa == pytest.approx(greenwood_tripp_at_zero(7e7, 0.8e-3, 6e-6, 2.7e7), rel=1e-4)
    assert low.pressure_Pa == pytest.approx(0.771e6, rel=1e-3)
    assert "sigma 6 um, E' 27 MPa, n beta sigma 0.336" in low.data
    high = contact_capacity(load_scene("default_driveline"))
    assert high.pressure_Pa / low.pressure_Pa == pytest.approx((8.41 / 6) ** 2.5, rel=1e-4)


def test_the_variants_carry_their_own_capacity():
    """Zhang's E delta^2 with delta = pi n beta sigma F_1(0), F_1(0) = phi(0); Bao as published: the area
    ratio (capped at 0.99) times the Patir fit 4.4086e-5 x 4^6.804 of F_5/2(0); none without contact."""
    zhang = contact_capacity(load_scene("zhang2021"))
    delta = math.pi * 7e7 * 8e-4 * 8.41e-6 * stats.norm.pdf(0.0)
    assert zhang.pressure_Pa == pytest.approx(2.7e7 * delta**2, rel=1e-9)
    bao = contact_capacity(load_scene("bao2020_as_published"))
    n_beta_sigma = 7e7 * 9e-4 * 8.4e-6
    fit = 4.4086e-5 * 4**6.804
    area_ratio = min(math.pi**2 * n_beta_sigma**2 * 0.5, 0.99)        # F_2(0) = 1/2
    K = 16 * math.sqrt(2) / 15 * math.pi * n_beta_sigma**2 * math.sqrt(8.4e-6 / 9e-4)
    assert bao.pressure_Pa == pytest.approx(area_ratio * K * 3e9 * fit, rel=1e-4)
    assert "area-ratio force" in bao.law and "fit" in bao.law
    assert contact_capacity(load_scene("default_driveline", {"contact.model": "none", "contact.E_equiv": None})) is None


def test_pack_pressure_with_springs_in_closed_form():
    """Pressure-applied piston: (p A - k n_s (preload + travel + n H0)) / A_film; spring-applied (Bao):
    k (preload - travel - n H0) - p A, largest where the oil pressure is lowest."""
    fill = load_scene("default_fill")
    pack = pack_pressure(fill, (0.0488e6, 0.8e6))
    springs = 4e3 * 12 * (0.01 + 1.5e-3 + 4 * 88e-6)
    assert pack.pressure_Pa == pytest.approx((0.8e6 * 9.83e-3 - springs) / FILM_AREA, rel=1e-12)
    assert pack.oil_pressure_Pa == 0.8e6
    bao = load_scene("bao2020")
    pack = pack_pressure(bao, (63.66e6, 0.0))
    area = math.pi * (0.16**2 - 0.12**2)
    assert pack.pressure_Pa == pytest.approx(2e6 * (0.04 - 0.5e-3 - 2 * 2e-4) / area, rel=1e-12)   # 2.22 MPa
    assert pack.oil_pressure_Pa == 0.0 and pack.per_oil_pressure < 0


def test_every_shipped_engagement_is_inside_the_capacity():
    """Largest pack pressure / capacity at zero gap (simulate; optimize up to actuation.max_pressure)."""
    ratios = {}
    for name in ("bao2020", "bao2020_as_published", "default_driveline", "default_driveline_thermal", "default_fill",
                 "zhang2021"):
        scene = load_scene(name)
        capacity, pack = check_contact_capacity(scene)
        _, pack_max = check_contact_capacity(scene, max_pressure=scene.value("actuation.max_pressure"))
        ratios[name] = (pack.pressure_Pa / capacity.pressure_Pa, pack_max.pressure_Pa / capacity.pressure_Pa)
    assert all(run < 1 and optimum < 1 for run, optimum in ratios.values()), ratios
    assert ratios["default_driveline"][1] == pytest.approx(1.5 / 1.7943, rel=1e-3)      # the closest: 0.84


def test_sigma_6um_is_refused_before_the_run(monkeypatch):
    """The review's case: the run drove the gap to -0.13 um and reported a lock-up. Now one line with both
    numbers, the contact data and what to change, before any model is built."""
    monkeypatch.setattr(engagement_run, "EngagementModel",
                        lambda *a, **k: pytest.fail("the model was built for a refused run"))
    with pytest.raises(PhysicalRangeError) as info:
        simulate_engagement(load_scene("default_driveline", SIGMA_6UM))
    assert str(info.value) == (
        "contact: Greenwood-Tripp carries at most 0.771 MPa at zero gap (sigma 6 um, E' 27 MPa, n beta sigma 0.336, "
        "beta 0.8 mm), the run applies 0.8 MPa: lower actuation.pressure below 0.771 MPa, or raise roughness.sigma_* "
        "/ contact.E_equiv / roughness.asperity_density")


def test_the_optimiser_bound_is_checked_up_to_max_pressure():
    """sigma 7 um carries 1.134 MPa: a run at 0.8 MPa is inside, an optimiser allowed 1.5 MPa is not."""
    scene = load_scene("default_driveline", {"roughness.sigma_1": "7 um"})
    capacity, _ = check_contact_capacity(scene)
    assert capacity.pressure_Pa == pytest.approx(1.134e6, rel=1e-3)
    with pytest.raises(PhysicalRangeError, match=r"the run applies 1.5 MPa: lower actuation.max_pressure below 1.13 MPa"):
        check_contact_capacity(scene, max_pressure=scene.value("actuation.max_pressure"))


def test_a_passed_check_is_remembered_per_scene_and_a_failed_one_is_not(monkeypatch):
    """A run checks its scene before it starts: the second check of the same scene object returns the
    first's numbers without evaluating the contact law again; a bound, a refused scene and a new scene
    object are checked anew, with the same numbers as a film law built for each function."""
    from clutchocp.engagement import edges
    scene = load_scene("default_driveline")
    first = check_contact_capacity(scene)
    assert first == (contact_capacity(scene), pack_pressure(scene, edges.run_oil_pressures(scene)))

    def unbuilt(*args, **kwargs):
        raise AssertionError("the film law was built again")

    monkeypatch.setattr(edges, "FilmLaw", unbuilt)
    again = check_contact_capacity(scene)
    assert again[0] is first[0] and again[1] is first[1]
    with pytest.raises(AssertionError, match="built again"):           # a bound is checked every time
        check_contact_capacity(scene, max_pressure=1e6)
    with pytest.raises(AssertionError, match="built again"):           # so is another scene object
        check_contact_capacity(load_scene("default_driveline"))
    monkeypatch.undo()
    refused = load_scene("default_driveline", SIGMA_6UM)
    for _ in range(2):
        with pytest.raises(PhysicalRangeError):
            check_contact_capacity(refused)


def test_a_piston_scene_names_the_oil_pressure_that_fits():
    scene = load_scene("default_fill", {"roughness.sigma": "6 um", "actuation.pressure": "0.9 MPa"})
    with pytest.raises(PhysicalRangeError, match=r"applies 0.842 MPa on the pack \(at 0.9 MPa of oil, springs "
                                                 r"included\): lower actuation.pressure below 0.829 MPa"):
        check_contact_capacity(scene)


def test_cli_refuses_sigma_6um_in_one_line(tmp_path, capsys):
    code = main(["simulate", "default_driveline", "--set", 'roughness.sigma_1="6 um"', "--out", str(tmp_path / "r")])
    assert code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("clutchocp simulate: error: contact: Greenwood-Tripp carries at most "
                                               "0.771 MPa at zero gap")
    assert not (tmp_path / "r").exists()


def test_a_film_closing_during_the_run_ends_it_in_one_line():
    """Inside the static bound (0.75 < 0.771 MPa) the plates' momentum still closes the films: the run
    ends at the crossing with the film, the time, its load and the capacity, and no result."""
    scene = load_scene("default_driveline", SPIKE)
    check_contact_capacity(scene)                                    # passes the check before the run
    start = time.perf_counter()
    with pytest.raises(ModelEdgeError) as info:
        simulate_engagement(scene, t_end=0.3)
    err = info.value
    text = str(err)
    assert "\n" not in text
    assert text.startswith("film 1 closed at t = 0.00183")
    assert "the contact could not carry the load (film load " in text
    assert "Greenwood-Tripp carries at most 7.583 kN = 0.771 MPa at zero gap" in text
    assert "no result beyond a closed film. Change: " in text
    load = float(text.split("film load ")[1].split(" kN")[0])
    assert load > 7.583                                              # the film was pressed beyond the contact
    assert abs(err.states["h_1"]) <= 1e-6 * 6e-6                     # located at h = 0 (sigma = 6 um)
    assert err.t == pytest.approx(1.84e-3, rel=0.01)
    assert "film load 9.555 kN = 0.972 MPa" in text and "pack force 6.2 kN" in text
    assert time.perf_counter() - start < 10.0


def test_cli_ends_a_closing_film_in_one_line(tmp_path, capsys):
    cli = ["simulate", "default_driveline", "--out", str(tmp_path / "r"), "--set", 'roughness.sigma_1="6 um"',
           "--set", 'actuation.time_constant="1 ms"', "--set", 'actuation.pressure="0.75 MPa"',
           "--set", 'pack.model="masses"', "--set", 'pack.plate_masses=["20 kg", "20 kg", "20 kg", "20 kg"]',
           "--set", 'oil.viscosity="5 mPa s"', "--set", 'plates.lining_permeability="4e-11 m^2"',
           "--set", "simulation.t_end=0.3"]
    assert main(cli) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "error: film 1 closed at t = 0.00183" in err[0]
    assert not (tmp_path / "r").exists()


def test_the_edge_events_cost_nothing_when_not_crossed():
    """The same run with the film_closed events removed: the same IDAS steps, calls and lock-up time
    (the events never shorten an integrator call)."""
    scene = load_scene("default_driveline")
    with_edges = simulate_engagement(scene)
    model = EngagementModel(scene)
    for mode in model.hybrid.modes.values():
        mode.events = [event for event in mode.events if not event.edge]
    without = simulate_engagement(scene, model=model)
    a, b = with_edges.summary, without.summary
    assert a["engagement_time_s"] == b["engagement_time_s"]
    for key in ("n_steps", "n_integrator_calls", "n_location_integrations"):
        assert a["solver"]["statistics"][key] == b["solver"]["statistics"][key], key
    assert sum(e.name == "film_closed" for m in with_edges.model.hybrid.modes.values() for e in m.events) == 4 * 3
