"""The closed-form and function-level numbers docs/physics.md quotes (no simulations).

``python benchmarks/docs_numbers.py --only physics`` calls :func:`formulas` and adds the numbers of the
simulations it runs (the built-in scenes and their variants) before rendering the page's tables; run
alone, ``python docs/scripts/physics_numbers.py`` prints the same values as JSON (from the repository
root, a few seconds).
"""

import json
import math

import numpy as np

from scipy import optimize

from clutchocp.engagement.edges import check_contact_capacity, zero_gap_pressure
from clutchocp.engagement.films import AREA_RATIO_CAP, FilmLaw
from clutchocp.physics import contact, thermal
from clutchocp.physics.cavitation import RESIDUAL_SLOPE, WIDTH
from clutchocp.physics.roughness import average_gap
from clutchocp.physics.shear import shear_factor_phi_f, shear_factor_phi_fs, transmitted_shear_factor
from clutchocp.scene import load_scene

SHEAR_H = (0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 5.0)
WALL_AMPLITUDES = (0.1, 0.3, 0.5)
# The conduction chain against the semi-infinite solid: a 1 mm paper lining under a constant flux
PAPER = (0.2, 1000.0, 1500.0)          # k [W/(m K)], rho [kg/m^3], c [J/(kg K)] (thermal.lining_material)
LINING_FLUX = 1e5                      # W/m^2
CONDUCTION_CELLS = (3, 4, 6, 8, 10)
CONDUCTION_TIMES = (0.01, 0.02, 0.05, 0.1, 0.2, 0.3, 0.5)
# A steel plate of 2 mm over one friction face, for the heat of Zhang's stop (7850 kg/m^3, 460 J/(kg K))
STEEL = (7850.0, 460.0, 2e-3)
ZHANG_LOW_SPEED = "1000 rpm"


def one_dimensional_wall(eps):
    """Exact stresses of a film over the fixed wall h = 1 + eps cos x under a smooth wall sliding at U = 1
    (eta = 1), in units of the Couette stress E[1/h]: smooth-wall drag, rough-wall viscous shear, form drag
    (the Reynolds film's periodic solution; ``clutchocp.physics.rough_wall_flow`` in one dimension)."""
    x = np.linspace(0, 2 * np.pi, 200001)[:-1]
    h = 1 + eps * np.cos(x)
    I1, I2, I3 = (np.mean(h**-k) for k in (1, 2, 3))
    smooth = 4 * I1 - 3 * I2**2 / I3
    rough = 3 * I2**2 / I3 - 2 * I1
    return {"eps": eps, "smooth_drag": smooth / I1, "rough_viscous": rough / I1, "form_drag": (smooth - rough) / I1}


def shear_factors():
    """Patir-Cheng's factors of one rough wall and the deterministic-flow table, over the nominal film h."""
    rows = []
    for H in SHEAR_H:
        phi_f = float(shear_factor_phi_f(H))
        Phi_fs = float(shear_factor_phi_fs(H, 1.0, 0.0))
        table = float(transmitted_shear_factor(H, 1.0, 0.0, method="table"))
        rows.append({"H": H, "phi_f": phi_f, "Phi_fs": Phi_fs, "rough_viscous": phi_f - Phi_fs,
                     "patir_cheng": phi_f + Phi_fs, "table": table, "h_T_over_h": float(average_gap(H, 1.0)) / H})
    return rows


def zhang_as_printed():
    """The energy of one stop of zhang2021 (Table 1 as printed) on its friction face."""
    scene = load_scene("zhang2021")
    w, inertia = scene.value("driveline.input_speed"), scene.value("driveline.input_inertia")
    r1, r2 = scene.value("plates.r_inner"), scene.value("plates.r_outer")
    area = math.pi * (r2**2 - r1**2)
    energy = 0.5 * inertia * w**2
    rho, c, thickness = STEEL
    steel = area * thickness * rho * c
    return {"speed_rad_s": w, "speed_rpm": w * 60 / (2 * math.pi), "rim_speed_m_s": w * r2, "energy_J": energy,
            "area_mm2": area * 1e6, "specific_energy_J_mm2": energy / (area * 1e6), "steel_plate_J_K": steel,
            "two_steel_plates_rise_K": energy / (2 * steel), "low_speed": ZHANG_LOW_SPEED}


def contact_data(name, settled_gap):
    """n beta sigma of a scene's asperities, its real-area ratio at the settled film ``settled_gap`` [m]
    (capped, as the model uses it) and the film ratio H where the uncapped ratio reaches the cap (99 %)."""
    film = FilmLaw(load_scene(name))
    if film.contact_model == "greenwood_tripp":
        def raw(H):
            return float(contact.greenwood_tripp_area_ratio(H, film.n_a, film.beta, film.sigma, n0=film.n0))
    else:
        def raw(H):
            return float(contact.zhang_area_ratio(H, film.n_a, film.beta, film.sigma))
    cap = AREA_RATIO_CAP
    cap_H = optimize.brentq(lambda H: raw(H) - cap, -5.0, 5.0, xtol=1e-12) if (raw(-5.0) - cap) * (raw(5.0) - cap) < 0 \
        else None
    return {"contact": film.contact_model, "n_beta_sigma": film.n_a * film.beta * film.sigma,
            "settled_H": settled_gap / film.sigma, "area_ratio": float(film.area_ratio(settled_gap)), "cap": cap,
            "cap_H": cap_H}


def contact_capacities(names):
    """Each engagement scene's contact capacity at zero gap, and its largest pack pressure over it: for its
    own pressure profile (simulate) and up to ``actuation.max_pressure`` (optimize)."""
    rows = {}
    for name in names:
        scene = load_scene(name)
        checked = check_contact_capacity(scene)
        if checked is None:
            continue
        capacity, pack = checked
        top = scene.get("actuation.max_pressure")
        at_max = check_contact_capacity(scene, max_pressure=top)[1] if top else None
        rows[name] = {"law": capacity.law, "data": capacity.data, "capacity_Pa": capacity.pressure_Pa,
                      "run_ratio": pack.pressure_Pa / capacity.pressure_Pa,
                      "max_pressure_ratio": None if at_max is None else at_max.pressure_Pa / capacity.pressure_Pa}
    return rows


def conduction_errors():
    """Relative error of the lining chain's surface temperature rise against the semi-infinite solid
    (2 q sqrt(t / (pi k rho c)), Carslaw & Jaeger Sec. 2.9): 1 mm of paper, no separator, no core."""
    area = 1e-2
    out = {}
    for cells in CONDUCTION_CELLS:
        chain = thermal.lining_chain(1e-3, cells, *PAPER, area, surface_capacity=0.0, back_capacity=0.0,
                                     surface_loss=0.0, back_loss=0.0)
        rise = [chain.relax(np.zeros(chain.size), t, 0.0, heat=LINING_FLUX * area)[0] for t in CONDUCTION_TIMES]
        exact = thermal.semi_infinite_surface_rise(LINING_FLUX, np.array(CONDUCTION_TIMES), *PAPER)
        out[str(cells)] = [float(r / e - 1.0) for r, e in zip(rise, exact)]
    return {"times_s": list(CONDUCTION_TIMES), "flux_W_m2": LINING_FLUX, "errors": out}


def cavitation_constants():
    """The tension limit's residual slope, corner width and the largest offset of the squeeze load."""
    offset = (1 - RESIDUAL_SLOPE) * WIDTH**2 / 4           # (1 - eps) w^2 / (4 |L|), in units of |L|
    return {"residual_slope": RESIDUAL_SLOPE, "width": WIDTH, "offset": offset, "offset_Pa_at_1_bar": offset * 1e5}


def zero_gap_capacity(name, overrides=None):
    """What a scene's asperity contact carries at zero gap [Pa] (``edges.zero_gap_pressure``), with overrides."""
    return zero_gap_pressure(FilmLaw(load_scene(name, overrides=overrides or {})))


def formulas(engagement_scenes=("bao2020", "bao2020_as_published", "default_driveline", "default_driveline_thermal",
                                "default_fill", "zhang2021")):
    """Every closed-form number of docs/physics.md, JSON-ready."""
    six = {"roughness.sigma_1": "6 um"}
    return {
        "one_dimensional_wall": [one_dimensional_wall(eps) for eps in WALL_AMPLITUDES],
        "shear_factors": shear_factors(),
        "zhang_as_printed": zhang_as_printed(),
        "contact_capacity": contact_capacities(engagement_scenes),
        "capacity_examples": {"greenwood_tripp": zero_gap_capacity("default_driveline"),
                              "greenwood_tripp_6um": zero_gap_capacity("default_driveline", six),
                              "zhang_gw": zero_gap_capacity("zhang2021")},
        "conduction": conduction_errors(),
        "cavitation": cavitation_constants(),
    }


if __name__ == "__main__":
    print(json.dumps(formulas(), indent=1))
