"""The clutch catalogue (models/catalogue): every file loads, matches its README row and is consistent.

Consistency, computed here from the loaded scene (independently of the engagement model):
the Greenwood-Tripp contact pressure at zero gap exceeds the largest pressure the scene puts on the
friction area, and the locked driveline needs 30-70 % of the static torque capacity at the pressure
limit, except for the clutches the README flags as deliberately infeasible, which must really break
one of those limits.
"""

import math
import re
import warnings
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

from clutchocp.engagement.model import EngagementModel
from clutchocp.errors import PlausibilityWarning
from clutchocp.physics.contact import greenwood_tripp_pressure
from clutchocp.scene import list_scenes, load_scene

CATALOGUE = Path(__file__).resolve().parent.parent / "models" / "catalogue"
FILES = sorted(CATALOGUE.glob("*.toml"))
F52_AT_ZERO = 0.61663          # F_5/2(0) of Greenwood-Tripp, by quadrature


def readme_rows():
    """{file stem: {column header: cell}} of the README's clutch table."""
    lines = (CATALOGUE / "README.md").read_text(encoding="utf-8").splitlines()
    start = next(k for k, line in enumerate(lines) if line.startswith("| file | kind |"))
    header = [c.strip() for c in lines[start].strip("|").split("|")]
    rows = {}
    for line in lines[start + 2:]:
        if not line.startswith("|"):
            break
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        row = dict(zip(header, cells))
        rows[row["file"].strip("`")] = row
    return rows


ROWS = readme_rows()


def contact_capacity(scene):
    """(16 sqrt2 / 15) pi (n beta sigma)^2 sqrt(sigma / beta) E' F_5/2(0) [Pa]."""
    n, beta = scene.value("roughness.asperity_density"), scene.value("roughness.asperity_radius")
    sigma, E = scene.value("roughness.sigma"), scene.value("contact.E_equiv")
    return 16 * math.sqrt(2) / 15 * math.pi * (n * beta * sigma) ** 2 * math.sqrt(sigma / beta) * E * F52_AT_ZERO


def plate_force_at_limit(scene):
    """Force on the friction area at the pressure limit [N] (spring-applied: at zero pressure)."""
    p_max = max(scene.value("actuation.max_pressure"), scene.value("actuation.pressure"))
    area = math.pi * (scene.value("plates.r_outer") ** 2 - scene.value("plates.r_inner") ** 2)
    if not scene.has("piston"):
        return p_max * (scene.get("actuation.area") or area)
    k = scene.value("piston.spring_stiffness") * scene.value("piston.spring_count")
    preload, travel = scene.value("piston.spring_preload"), scene.value("piston.travel_to_pack")
    if scene.variant("piston") == "spring_applied":
        return k * (preload - travel)                       # Bao Eq. 21 at p = 0, at the kiss point
    return p_max * scene.value("piston.area") - k * (preload + travel)


def static_friction(scene):
    if scene.get("friction.static_coefficient") is not None:
        return scene.value("friction.static_coefficient")
    return scene.value("friction.mu" if scene.variant("friction") == "constant" else "friction.mu_static")


def torque_capacity(scene):
    """mu_s F r_eff n at the pressure limit [N m]."""
    r1, r2 = scene.value("plates.r_inner"), scene.value("plates.r_outer")
    r_eff = 2 * (r2**3 - r1**3) / (3 * (r2**2 - r1**2))
    return static_friction(scene) * max(plate_force_at_limit(scene), 0.0) * r_eff * scene.value("plates.n_interfaces")


def load_torque(scene, w):
    variant = scene.variant("load")
    if variant == "none":
        return 0.0
    if variant == "constant":
        return scene.value("load.torque")
    return scene.value("load.rated_torque") * (w / scene.value("load.rated_speed")) ** 2


def locked_torque(scene):
    """Torque the locked driveline carries [N m] (rigid body of both sides)."""
    if scene.value("driveline.input") == "prescribed_speed":
        return load_torque(scene, scene.value("driveline.input_speed"))
    T_in = scene.value("driveline.input_torque")
    if scene.value("driveline.output") == "fixed":
        return T_in
    J_in, J_out = scene.value("driveline.input_inertia"), scene.value("driveline.output_inertia")
    T_load = load_torque(scene, 0.0)
    return T_load + J_out * (T_in - T_load) / (J_in + J_out)


def number(cell):
    return float(re.match(r"-?[\d.]+(e[+-]?\d+)?", cell).group(0))


def test_at_least_24_clutches_each_with_a_readme_row_and_not_built_in():
    assert len(FILES) >= 24
    assert {p.stem for p in FILES} == set(ROWS)
    assert not {p.stem for p in FILES} & {sc.name for sc in list_scenes()}


def test_two_or_three_deliberately_infeasible():
    flagged = [name for name, row in ROWS.items() if row["deliberately infeasible: reason"] != "-"]
    assert 2 <= len(flagged) <= 3


def test_contact_capacity_closed_form_matches_the_library_quadrature():
    # the closed form with F_5/2(0) = 0.61663 against greenwood_tripp_pressure at H = 0 (its own F_5/2)
    scene = load_scene(FILES[0])
    args = (scene.value("contact.E_equiv"), scene.value("roughness.asperity_density"),
            scene.value("roughness.asperity_radius"), scene.value("roughness.sigma"))
    assert contact_capacity(scene) == pytest.approx(float(greenwood_tripp_pressure(0.0, *args)), rel=1e-4)


@pytest.mark.parametrize("path", FILES, ids=[p.stem for p in FILES])
def test_catalogue_clutch_loads_matches_readme_and_is_consistent(path):
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlausibilityWarning)      # a catalogue clutch is a plausible clutch
        scene = load_scene(path)
    assert scene.warnings == ()
    row = ROWS[path.stem]
    if scene.has("thermal"):       # the lining's conduction nodes: the README names material, thickness, cells
        described = (f"thermal: {scene.value('thermal.lining_material')} lining, "
                     f"{scene.value('plates.lining_thickness') * 1e3:g} mm, {scene.value('thermal.lining_cells')} cells")
        assert described in row["lining"], (described, row["lining"])
    else:
        assert "thermal" not in row["lining"]
    assert scene.name == path.stem and scene.kind == "engagement"
    assert scene.source.strip() and len(scene.value("scene.assumptions")) >= 5
    assert scene.get("actuation.max_pressure") is not None          # clutchocp optimize needs it
    # the README row is this file
    assert int(row["interfaces"]) == scene.value("plates.n_interfaces")
    r1, r2 = (float(v) / 1e3 for v in row["r_inner-r_outer [mm]"].split("-"))
    assert (r1, r2) == pytest.approx((scene.value("plates.r_inner"), scene.value("plates.r_outer")))
    area = math.pi * (r2**2 - r1**2)
    p_plate = plate_force_at_limit(scene) / area
    capacity_p = contact_capacity(scene)
    assert number(row["contact capacity at zero gap [MPa]"]) * 1e6 == pytest.approx(capacity_p, rel=5e-3)
    assert number(row["largest plate pressure [MPa]"]) * 1e6 == pytest.approx(p_plate, rel=5e-3, abs=1e3)
    T_lock, T_cap = locked_torque(scene), torque_capacity(scene)
    documented = row["locked torque / capacity at the limit [N m]"]
    lock_cell, cap_cell = documented.split("/")
    assert number(lock_cell.strip()) == pytest.approx(T_lock, rel=1e-3)
    assert number(cap_cell.strip()) == pytest.approx(T_cap, rel=1e-3, abs=0.5)
    infeasible = row["deliberately infeasible: reason"] != "-"
    assert infeasible == scene.title.startswith("Deliberately infeasible")
    if infeasible:       # it must really break a limit
        assert capacity_p <= p_plate or T_cap <= T_lock
    else:
        assert capacity_p > p_plate
        assert 0.30 <= T_lock / T_cap <= 0.70


# one clutch per branch of locked_torque: two inertias (with a piston), a brake (spring-applied), a
# prescribed input speed with a quadratic load
BRANCHES = ("at6_clutch_fill_60C", "winch_sahr_brake_gear_oil_50C", "tractor_pto_clutch_60C")


@pytest.mark.parametrize("name", BRANCHES)
def test_locked_torque_closed_form_matches_the_engagement_model(name):
    # the same number from the model's own lock-up condition (EngagementModel.locked_torque) at the
    # lock: both sides at the input speed
    scene = load_scene(CATALOGUE / f"{name}.toml")
    model = EngagementModel(scene)
    x = np.array(model.initial_state, dtype=float)
    w_in = scene.value("driveline.input_speed")
    for name in ("w_in", "w_out"):
        if name in model.state_names:
            x[model.state_names.index(name)] = w_in
    value = float(ca.Function("locked", [model.x], [model.locked_torque()])(x))
    assert value == pytest.approx(locked_torque(scene), rel=1e-9)
