"""Cui 2019: mixed friction of one hydro-viscous-drive friction pair, against the paper.

Cui et al. 2019 (Chin. J. Mech. Eng.). Two parts:

1. Eq. 18 (contact COF, quartic in pressure) against the measured values of Table 1.
2. Figs 12-16 analogues with the Table 2 parameters (scene ``cui2019``), against film ratio
   lambda = h / sigma: average gap (Fig. 12), Greenwood-Tripp contact area ratio (Fig. 13),
   fluid torque (Cui Eq. 9, Fig. 14), asperity friction torque W_a f_a (R1 + R2) / 2 with the
   fractal load of Eq. 10-17 and f_a from Eq. 18 at the asperity pressure W_a / A_a (Eq. 19,
   Fig. 15), and their sum (Fig. 16). The paper gives these curves only as figures; the
   printed table compares the features its text states (fluid-torque peak near lambda = 2,
   asperity torque above fluid torque below lambda = 1.2, contact area almost zero above 2,
   h_T = h above 1.5).

All formulas come from :mod:`clutchocp.physics` (shear, contact, fractal, friction, roughness).
"""

from pathlib import Path

import numpy as np

from clutchocp.analyses.report import AnalysisResult, pct
from clutchocp.output import write_csv
from clutchocp.errors import ModelError
from clutchocp.physics.contact import effective_radius, greenwood_tripp_area_ratio, greenwood_tripp_pressure
from clutchocp.physics.fractal import cui_nominal_area, fractal_contact_load
from clutchocp.physics.friction import mu_cui2019
from clutchocp.physics.roughness import average_gap, average_gap_patir, combined_sigma
from clutchocp.physics.shear import viscous_torque
from clutchocp.scene import load_scene

NAME = "cui2019"

# ---- Reference data of Cui et al. 2019 (comparison targets, not results) --------------------
#: Table 1: contact pressure [Pa] and measured contact friction coefficient f_a [-].
TABLE1_PRESSURE = np.array([0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0]) * 1e6
TABLE1_COF = np.array([0.06, 0.05, 0.044, 0.039, 0.036, 0.034, 0.033, 0.0315, 0.03, 0.029])
#: Section 6 text: film ratio of the fluid-torque maximum (Fig. 14: "0 < lambda < 2 increases,
#: 2 < lambda < 3 decreases"), below which asperity torque exceeds fluid torque (Fig. 16:
#: "0 < lambda < 1.2"), above which the contact area is almost zero (Fig. 13) and above which
#: h_T and h are "basically the same" (Fig. 12).
TEXT_FLUID_PEAK_RATIO = 2.0
TEXT_CROSSOVER_RATIO = 1.2
TEXT_NO_CONTACT_RATIO = 2.0
TEXT_GAP_EQUAL_RATIO = 1.5
#: Film-ratio range of the figures.
FILM_RATIOS = np.linspace(0.02, 3.0, 150)


def from_scene(scene):
    """Keyword arguments of :func:`compute` from a scene.

    Reads plates.r_inner, plates.r_outer, plates.land_fraction, oil.viscosity,
    roughness.sigma_1, roughness.sigma_2, roughness.asperity_density, roughness.asperity_radius,
    contact (model "fractal_mb": E_equiv, fractal_dimension, fractal_scale, hardness,
    yield_strength; or "greenwood_tripp": E_equiv, fit), friction (model "cui2019", or
    "constant": mu), operating.speed_input, operating.speed_output.
    """
    for part in ("roughness", "contact", "friction", "oil"):
        if not scene.has(part):
            raise ModelError(f"scene '{scene.name}': the Cui analysis needs a [{part}] part")
    sigma_1 = scene.get("roughness.sigma_1")
    sigma_2 = scene.get("roughness.sigma_2")
    if sigma_1 is None or sigma_2 is None:
        raise ModelError("roughness.sigma_1 and roughness.sigma_2: the Cui analysis needs both (Cui Eq. 7)")
    contact = scene.variant("contact")
    if contact == "fractal_mb":
        contact_kw = dict(D=scene.value("contact.fractal_dimension"), G=scene.value("contact.fractal_scale"),
                          hardness=scene.value("contact.hardness"),
                          yield_strength=scene.value("contact.yield_strength"))
    elif contact == "greenwood_tripp":
        contact_kw = dict(fit=scene.value("contact.fit"))
    else:
        raise ModelError(f"contact.model = '{contact}': the Cui analysis takes 'fractal_mb' or 'greenwood_tripp'")
    friction = scene.variant("friction")
    if friction == "cui2019":
        mu = None
    elif friction == "constant":
        mu = scene.value("friction.mu")
    else:
        raise ModelError(f"friction.model = '{friction}': the Cui analysis takes 'cui2019' or 'constant'")
    return dict(
        r1=scene.value("plates.r_inner"), r2=scene.value("plates.r_outer"),
        land_fraction=scene.value("plates.land_fraction"), eta=scene.value("oil.viscosity"),
        sigma_1=sigma_1, sigma_2=sigma_2,
        asperity_density=scene.value("roughness.asperity_density"),
        asperity_radius=scene.value("roughness.asperity_radius"),
        E_equiv=scene.value("contact.E_equiv"), contact=contact, contact_kw=contact_kw, mu=mu,
        w_rel=scene.value("operating.speed_input") - scene.value("operating.speed_output"),
    )


def compute(*, r1, r2, land_fraction, eta, sigma_1, sigma_2, asperity_density, asperity_radius,
            E_equiv, contact="fractal_mb", contact_kw=None, mu=None, w_rel, film_ratios=FILM_RATIOS):
    """Torques of one friction pair against film ratio (SI).

    Parameters
    ----------
    r1, r2 : float
        Inner and outer radius [m].
    land_fraction : float
        Non-grooved area fraction psi [-].
    eta : float
        Viscosity [Pa s].
    sigma_1, sigma_2 : float
        RMS roughness of the friction plate and of the separator disc [m].
    asperity_density, asperity_radius : float
        Asperity peak density [1/m^2] and tip radius [m] (Greenwood-Tripp area ratio).
    E_equiv : float
        Equivalent elastic modulus [Pa].
    contact : {"fractal_mb", "greenwood_tripp"}
        Asperity load law; ``contact_kw`` holds its parameters (D, G [m], hardness [Pa],
        yield_strength [Pa] for the fractal law; fit for Greenwood-Tripp).
    mu : float or None
        Contact COF; None = Cui Eq. 18 at the asperity pressure.
    w_rel : float
        Relative speed [rad/s].
    film_ratios : array
        Film ratios lambda = h / sigma [-].

    Returns
    -------
    dict of arrays over ``film_ratios``: ``h``, ``h_T``, ``h_T_patir`` [m], ``area_ratio`` [-],
    ``fluid_torque``, ``asperity_load`` [N], ``asperity_pressure`` [Pa], ``cof`` [-],
    ``asperity_torque``, ``total_torque`` [N m].
    """
    contact_kw = contact_kw or {}
    lam = np.asarray(film_ratios, dtype=float)
    sigma = combined_sigma(sigma_1, sigma_2)
    h = lam * sigma
    area_ratio = greenwood_tripp_area_ratio(lam, asperity_density, asperity_radius, sigma)    # Cui Eq. 3
    fluid = viscous_torque(w_rel, h, eta, r1, r2, sigma_1=sigma_1, sigma_2=sigma_2,
                           area_ratio=area_ratio, land_fraction=land_fraction)                # Cui Eq. 9
    nominal_area = cui_nominal_area(r1, r2, land_fraction)                                   # Cui Eq. 16
    if contact == "fractal_mb":
        load = fractal_contact_load(area_ratio, contact_kw["D"], contact_kw["G"], E_equiv,
                                    contact_kw["hardness"], contact_kw["yield_strength"], nominal_area)
    elif contact == "greenwood_tripp":
        load = nominal_area * greenwood_tripp_pressure(lam, E_equiv, asperity_density, asperity_radius,
                                                       sigma, fit=contact_kw.get("fit", "exact"))
    else:
        raise ModelError(f"contact = {contact!r}: allowed values are fractal_mb, greenwood_tripp")
    pressure = load / nominal_area
    cof = mu_cui2019(pressure) if mu is None else np.full_like(lam, mu)                       # Cui Eq. 18
    asperity = load * cof * effective_radius(r1, r2, rule="cui")                              # Cui Eq. 19
    return dict(film_ratio=lam, h=h, h_T=average_gap(h, sigma), h_T_patir=average_gap_patir(h, sigma),
                area_ratio=area_ratio, fluid_torque=fluid, asperity_load=load, asperity_pressure=pressure,
                cof=cof, asperity_torque=asperity, total_torque=fluid + asperity)


def _crossing(x, y):
    """First x where y changes sign (linear interpolation), or None."""
    s = np.sign(y)
    idx = np.nonzero(s[:-1] * s[1:] < 0)[0]
    if len(idx) == 0:
        return None
    k = idx[0]
    return float(x[k] - y[k] * (x[k + 1] - x[k]) / (y[k + 1] - y[k]))


def run(out_dir, scene=None):
    """Run the Cui analysis on a scene (default: built-in ``cui2019``), write its CSV files.

    Its figures are drawn from the result by :mod:`clutchocp.analyses.figures`.

    Returns
    -------
    AnalysisResult
    """
    scene = scene if scene is not None else load_scene("cui2019")
    out_dir = Path(out_dir)
    result = AnalysisResult(NAME, f"Cui 2019 HVD mixed friction ({scene.name})")
    s = result.summary

    # 1. Eq. 18 against Table 1
    eq18 = mu_cui2019(TABLE1_PRESSURE)
    dev = eq18 - TABLE1_COF
    s[f"{NAME}.eq18_table1_max_abs_deviation"] = float(np.max(np.abs(dev)))
    s[f"{NAME}.eq18_table1_max_rel_deviation"] = float(np.max(np.abs(dev / TABLE1_COF)))
    k = int(np.argmax(np.abs(dev)))
    result.rows.append((f"Eq. 18 vs Table 1, worst at {TABLE1_PRESSURE[k] / 1e6:g} MPa", f"{eq18[k]:.5f}",
                        f"{TABLE1_COF[k]:g}", pct(dev[k] / TABLE1_COF[k])))
    result.files.append(write_csv(out_dir / "cui2019_eq18.csv", {
        "pressure [Pa]": TABLE1_PRESSURE, "cof_table1 [-]": TABLE1_COF, "cof_eq18 [-]": eq18,
        "deviation [-]": dev}))

    # 2. Figs 12-16
    kw = from_scene(scene)
    r = compute(**kw)
    lam = r["film_ratio"]
    peak = int(np.argmax(r["fluid_torque"]))
    cross = _crossing(lam, r["asperity_torque"] - r["fluid_torque"])
    gap_dev = np.abs(r["h_T"] / r["h"] - 1)
    equal_from = lam[np.nonzero(gap_dev > 0.01)[0][-1] + 1] if np.any(gap_dev > 0.01) else lam[0]
    ka2 = float(np.interp(TEXT_NO_CONTACT_RATIO, lam, r["area_ratio"]))
    in_fit = (r["asperity_pressure"] >= TABLE1_PRESSURE[0]) & (r["asperity_pressure"] <= TABLE1_PRESSURE[-1])
    s[f"{NAME}.fluid_torque_peak_N_m"] = float(r["fluid_torque"][peak])
    s[f"{NAME}.fluid_torque_peak_film_ratio"] = float(lam[peak])
    if cross is not None:
        s[f"{NAME}.asperity_equals_fluid_film_ratio"] = cross
    s[f"{NAME}.area_ratio_at_film_ratio_2"] = ka2
    s[f"{NAME}.gap_within_1pct_above_film_ratio"] = float(equal_from)
    s[f"{NAME}.total_torque_at_min_film_ratio_N_m"] = float(r["total_torque"][0])
    s[f"{NAME}.total_torque_at_max_film_ratio_N_m"] = float(r["total_torque"][-1])
    s[f"{NAME}.asperity_pressure_max_Pa"] = float(r["asperity_pressure"].max())
    s[f"{NAME}.eq18_fit_range_film_ratio_min"] = float(lam[in_fit].min()) if in_fit.any() else 0.0
    s[f"{NAME}.eq18_fit_range_film_ratio_max"] = float(lam[in_fit].max()) if in_fit.any() else 0.0
    s[f"{NAME}.patir_gap_max_rel_deviation"] = float(np.max(np.abs(r["h_T_patir"] / r["h_T"] - 1)))
    result.rows += [
        ("film ratio of the fluid-torque peak", f"{lam[peak]:.2f} ({r['fluid_torque'][peak]:.2f} N m)",
         f"~{TEXT_FLUID_PEAK_RATIO:g} (Sec. 6.1)", ""),
        ("film ratio where asperity = fluid torque", "none" if cross is None else f"{cross:.2f}",
         f"~{TEXT_CROSSOVER_RATIO:g} (Sec. 6.3)", ""),
        ("contact area ratio at film ratio 2", f"{ka2:.4f}", "almost zero (Sec. 6.1)", ""),
        ("h_T within 1 % of h above film ratio", f"{equal_from:.2f}", f"~{TEXT_GAP_EQUAL_RATIO:g} (Sec. 6.1)", ""),
        ("total torque at film ratio " f"{lam[0]:g} / {lam[-1]:g}",
         f"{r['total_torque'][0]:.2f} / {r['total_torque'][-1]:.2f} N m", "", ""),
        ("asperity pressure in Eq. 18 fit range (0.1-1 MPa) for",
         f"{lam[in_fit].min():.2f} <= lambda <= {lam[in_fit].max():.2f}" if in_fit.any() else "nowhere", "", ""),
    ]
    cols = {"film_ratio [-]": lam, "h [m]": r["h"], "h_T [m]": r["h_T"], "h_T_patir [m]": r["h_T_patir"],
            "area_ratio [-]": r["area_ratio"], "fluid_torque [N m]": r["fluid_torque"],
            "asperity_load [N]": r["asperity_load"], "asperity_pressure [Pa]": r["asperity_pressure"],
            "contact_cof [-]": r["cof"], "asperity_torque [N m]": r["asperity_torque"],
            "total_torque [N m]": r["total_torque"]}
    result.files.append(write_csv(out_dir / "cui2019_mixed_friction.csv", cols))
    result.figure_data = {"r": r}
    return result
