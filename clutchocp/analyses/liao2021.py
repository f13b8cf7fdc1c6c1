"""Liao 2021: unequal oil films through a hydro-viscous clutch pack, against the paper.

Liao et al. 2021 (Energies 14, 7884). Three parts:

1. Figs 4-9 analogues: film thickness and viscous torque of each film for the groove
   depth h_a, angle ratio K2 and friction ratio K3/K1 values of Liao Table 1, each varied
   around the scene's base case with the scene's first film.
2. Table 3: for each of the nine tests the first film is taken from the table itself
   (the original-formula torque, Liao Eq. 2 with n equal films, inverted for the film
   sigma_bar, divided by alpha_1); the film recursion then predicts alpha_2..alpha_5 and
   the revised torque (Eq. 14), compared with the tabulated values and the bench torque.
3. The unit of K3/K1: the film growth sigma_n/sigma_1 with 0.1 read per m^2, cm^2, mm^2, um^2.

See :mod:`clutchocp.physics.hvc` for the recursion and the errata.
"""

from pathlib import Path

import numpy as np
from scipy.optimize import brentq

from clutchocp.analyses.report import AnalysisResult, pct
from clutchocp.output import write_csv
from clutchocp.errors import ModelError
from clutchocp.physics.hvc import film_distribution, modified_factors, revised_torque
from clutchocp.physics.shear import grooved_viscous_torque
from clutchocp.scene import load_scene

NAME = "liao2021"
MM = 1e-3
PER_MM2 = 1e6  # 1 / mm^2 in 1 / m^2

# ---- Reference data of Liao et al. 2021 (comparison targets and the paper's cases) -----------
#: Table 1 / captions of Figs 4-9: values swept one at a time (the others at the base case).
SWEEPS = {
    "groove_depth": np.array([0.25, 0.3, 0.35]) * MM,       # h_a [m], Figs 4-5
    "angle_ratio": np.array([1.5, 2.0, 2.5]),               # K2 [-], Figs 6-7
    "k3_over_k1": np.array([0.05, 0.1, 0.15]) * PER_MM2,    # K3/K1 [1/m^2], Figs 8-9
}
SWEEP_LABELS = {"groove_depth": ("h_a", 1 / MM, "mm"), "angle_ratio": ("K2", 1.0, ""),
                "k3_over_k1": ("K3/K1", 1 / PER_MM2, "1/mm^2")}
#: Table 3 rows: control pressure [Pa], speed difference [rad/s], h_a [m], K2 [-], K3/K1 [1/m^2],
#: tested torque, torque by the original formula [N m], alpha_1..alpha_5 [-], torque by the new formula [N m].
TABLE3 = [
    (0.70e6, 100.0, 0.25 * MM, 2.0, 0.10 * PER_MM2, 31.2, 39.7, (1.07, 0.93, 0.81, 0.71, 0.62), 33.5),
    (0.88e6, 100.0, 0.30 * MM, 2.0, 0.10 * PER_MM2, 27.8, 35.7, (1.13, 0.92, 0.76, 0.69, 0.50), 29.7),
    (1.00e6, 100.0, 0.35 * MM, 2.0, 0.10 * PER_MM2, 24.6, 31.8, (1.33, 0.98, 0.74, 0.56, 0.41), 25.7),
    (0.43e6, 100.0, 0.30 * MM, 1.5, 0.10 * PER_MM2, 35.3, 45.3, (1.00, 0.86, 0.74, 0.65, 0.57), 37.5),
    (0.77e6, 100.0, 0.30 * MM, 2.0, 0.10 * PER_MM2, 34.7, 43.5, (1.17, 0.93, 0.76, 0.62, 0.51), 35.8),
    (0.94e6, 100.0, 0.30 * MM, 2.5, 0.10 * PER_MM2, 31.9, 40.5, (1.42, 1.03, 0.77, 0.59, 0.43), 32.8),
    (0.12e6, 100.0, 0.30 * MM, 2.0, 0.05 * PER_MM2, 45.4, 58.1, (1.00, 0.88, 0.78, 0.70, 0.63), 48.9),
    (0.66e6, 100.0, 0.30 * MM, 2.0, 0.10 * PER_MM2, 38.7, 53.2, (1.10, 0.85, 0.68, 0.56, 0.46), 41.2),
    (0.86e6, 100.0, 0.30 * MM, 2.0, 0.15 * PER_MM2, 33.8, 47.4, (1.30, 0.88, 0.59, 0.47, 0.34), 35.0),
]
#: Length units tried for Liao's K3/K1 = 0.1 [1/length^2]: name -> factor to 1/m^2.
UNIT_CANDIDATES = {"1/m^2": 1.0, "1/cm^2": 1e4, "1/mm^2": 1e6, "1/um^2": 1e12}


def from_scene(scene):
    """Keyword arguments of :func:`film_cases` from a scene.

    Reads plates.r_inner, plates.r_outer, plates.n_interfaces (= number of films),
    oil.viscosity, groove.depth, groove.angle_ratio, hvc.friction_ratio, hvc.first_film,
    operating.speed_input, operating.speed_output.
    """
    for part in ("groove", "hvc", "oil"):
        if not scene.has(part):
            raise ModelError(f"scene '{scene.name}': the Liao analysis needs a [{part}] part")
    return dict(
        r1=scene.value("plates.r_inner"),
        r2=scene.value("plates.r_outer"),
        n_films=scene.value("plates.n_interfaces"),
        eta=scene.value("oil.viscosity"),
        w_rel=scene.value("operating.speed_input") - scene.value("operating.speed_output"),
        groove_depth=scene.value("groove.depth"),
        angle_ratio=scene.value("groove.angle_ratio"),
        k3_over_k1=scene.value("hvc.friction_ratio"),
        first_film=scene.value("hvc.first_film"),
    )


def film_cases(*, r1, r2, n_films, eta, w_rel, groove_depth, angle_ratio, k3_over_k1, first_film,
               sweeps=SWEEPS, friction_film="trailing"):
    """Films and per-film torques for each swept parameter value (Figs 4-9 analogues), SI.

    Returns
    -------
    dict: sweep name -> list of dicts with the parameter value, ``films`` [m],
    ``torques`` [N m] per film (Liao Eq. 2, n = 1, at each film), ``total`` (Eq. 14) and
    ``original`` (Eq. 2 with n films at the mean film) [N m], ``alpha`` [-].
    """
    base = dict(groove_depth=groove_depth, angle_ratio=angle_ratio, k3_over_k1=k3_over_k1)
    cases = {}
    for name, values in sweeps.items():
        cases[name] = []
        for v in values:
            par = dict(base, **{name: v})
            films = film_distribution(first_film, n_films, par["groove_depth"], par["angle_ratio"],
                                      par["k3_over_k1"], friction_film=friction_film)
            torques = grooved_viscous_torque(w_rel, films, eta, r1, r2, par["groove_depth"], par["angle_ratio"])
            alpha, mean = modified_factors(films)
            cases[name].append(dict(
                value=v, films=films, torques=torques, alpha=alpha,
                total=float(revised_torque(w_rel, films, eta, r1, r2, par["groove_depth"], par["angle_ratio"])),
                original=float(grooved_viscous_torque(w_rel, mean, eta, r1, r2, par["groove_depth"],
                                                      par["angle_ratio"], n_films)),
            ))
    return cases


def film_of_original_torque(torque, *, w_rel, eta, r1, r2, groove_depth, angle_ratio, n_films):
    """The single film thickness at which Liao Eq. 2 (n equal films) gives ``torque`` [m]."""
    def f(h):
        return grooved_viscous_torque(w_rel, h, eta, r1, r2, groove_depth, angle_ratio, n_films) - torque
    return brentq(f, 1e-9, 1.0, xtol=1e-16, rtol=1e-14)


def table3_comparison(*, r1, r2, eta, n_films=5, friction_film="trailing"):
    """Liao Table 3 re-derived: first film from the table, alpha_2..5 and Eq. 14 torque predicted.

    Returns
    -------
    list of dicts per test row: ``sigma_bar`` (film of the original formula) and
    ``first_film`` [m], ``films`` [m], ``alpha`` (sigma_bar / film) and ``alpha_paper``,
    ``torque_new`` (Eq. 14) and the paper's ``torque_new_paper``, ``torque_test`` [N m],
    ``growth_leading`` (sigma_5/sigma_1 with Eq. 13 as printed, NaN if it has no solution).
    """
    rows = []
    for p, dw, h_a, k2, kap, t_test, t_orig, alphas, t_new in TABLE3:
        geo = dict(w_rel=dw, eta=eta, r1=r1, r2=r2, groove_depth=h_a, angle_ratio=k2)
        sigma_bar = film_of_original_torque(t_orig, n_films=n_films, **geo)
        first = sigma_bar / alphas[0]
        films = film_distribution(first, n_films, h_a, k2, kap, friction_film=friction_film)
        try:
            lead = film_distribution(first, n_films, h_a, k2, kap, friction_film="leading")
            growth_leading = lead[-1] / lead[0]
        except ModelError:
            growth_leading = np.nan
        rows.append(dict(
            control_pressure=p, groove_depth=h_a, angle_ratio=k2, k3_over_k1=kap,
            sigma_bar=sigma_bar, first_film=first, films=films,
            alpha=sigma_bar / films, alpha_paper=np.array(alphas),
            torque_new=float(revised_torque(dw, films, eta, r1, r2, h_a, k2)),
            torque_new_paper=t_new, torque_original_paper=t_orig, torque_test=t_test,
            growth_leading=growth_leading,
        ))
    return rows


def unit_check(*, n_films, groove_depth, angle_ratio, first_film, value=0.1):
    """Film growth sigma_n / sigma_1 with K3/K1 = ``value`` read in each candidate unit.

    Returns ``{unit: growth}``; None where the films run away (no film below 1 m).
    """
    out = {}
    for unit, factor in UNIT_CANDIDATES.items():
        try:
            films = film_distribution(first_film, n_films, groove_depth, angle_ratio, value * factor)
            out[unit] = float(films[-1] / films[0]) if films[-1] < 1.0 else None
        except ModelError:
            out[unit] = None
    return out


def run(out_dir, scene=None):
    """Run the Liao analysis on a scene (default: built-in ``liao2021``), write its CSV files.

    Its figures are drawn from the result by :mod:`clutchocp.analyses.figures`.

    Returns
    -------
    AnalysisResult
    """
    scene = scene if scene is not None else load_scene("liao2021")
    out_dir = Path(out_dir)
    kw = from_scene(scene)
    result = AnalysisResult(NAME, f"Liao 2021 HVC film distribution ({scene.name})")
    s = result.summary

    # 1. Figs 4-9 analogues
    cases = film_cases(**kw)
    films0 = film_distribution(kw["first_film"], kw["n_films"], kw["groove_depth"], kw["angle_ratio"],
                               kw["k3_over_k1"])
    base_total = float(revised_torque(kw["w_rel"], films0, kw["eta"], kw["r1"], kw["r2"],
                                      kw["groove_depth"], kw["angle_ratio"]))
    base_orig = float(grooved_viscous_torque(kw["w_rel"], films0.mean(), kw["eta"], kw["r1"], kw["r2"],
                                             kw["groove_depth"], kw["angle_ratio"], kw["n_films"]))
    s[f"{NAME}.first_film_m"] = kw["first_film"]
    s[f"{NAME}.last_film_m"] = float(films0[-1])
    s[f"{NAME}.film_growth_last_over_first"] = float(films0[-1] / films0[0])
    s[f"{NAME}.revised_torque_N_m"] = base_total
    s[f"{NAME}.original_torque_mean_film_N_m"] = base_orig
    result.rows.append(("films (base case)", " ".join(f"{1e3 * f:.3f}" for f in films0) + " mm", "grow along the pack", ""))
    result.rows.append(("torque Eq. 14 / Eq. 2 at mean film", f"{base_total:.2f} / {base_orig:.2f} N m", "", ""))
    growth = {name: [c["films"][-1] / c["films"][0] for c in cs] for name, cs in cases.items()}
    for name, g in growth.items():
        label, scale, unit = SWEEP_LABELS[name]
        vals = ", ".join(f"{v * scale:g}" for v in SWEEPS[name])
        s[f"{NAME}.growth_increases_with_{name}"] = bool(np.all(np.diff(g) > 0))
        result.rows.append((f"sigma_n/sigma_1 for {label} = {vals} {unit}".rstrip(),
                            ", ".join(f"{x:.3f}" for x in g), "increasing (Sec. 4)",
                            "yes" if np.all(np.diff(g) > 0) else "NO"))
    rows = []
    for name, cs in cases.items():
        for c in cs:
            for i, (h, t, a) in enumerate(zip(c["films"], c["torques"], c["alpha"]), start=1):
                rows.append((name, c["value"], i, h, t, a))
    cols = list(zip(*rows))
    result.files.append(write_csv(out_dir / "liao2021_films.csv", {
        "swept_parameter": cols[0], "value [SI]": cols[1], "film [-]": cols[2],
        "thickness [m]": cols[3], "torque [N m]": cols[4], "alpha [-]": cols[5]}))

    # 2. Table 3
    t3 = table3_comparison(r1=kw["r1"], r2=kw["r2"], eta=kw["eta"], n_films=kw["n_films"]) \
        if kw["n_films"] == len(TABLE3[0][7]) else []
    if t3:
        firsts = np.array([r["first_film"] for r in t3])
        a_dev = np.array([np.max(np.abs(r["alpha"] / r["alpha_paper"] - 1)) for r in t3])
        t_dev = np.array([r["torque_new"] / r["torque_new_paper"] - 1 for r in t3])
        t_err = np.array([r["torque_new"] / r["torque_test"] - 1 for r in t3])
        inv_sum = np.array([np.sum(1 / r["alpha_paper"]) for r in t3])
        s[f"{NAME}.table3_first_film_median_m"] = float(np.median(firsts))
        s[f"{NAME}.table3_first_film_min_m"] = float(firsts.min())
        s[f"{NAME}.table3_first_film_max_m"] = float(firsts.max())
        s[f"{NAME}.table3_alpha_max_rel_deviation"] = float(a_dev.max())
        s[f"{NAME}.table3_new_torque_max_rel_deviation"] = float(np.max(np.abs(t_dev)))
        s[f"{NAME}.table3_new_torque_max_rel_error_vs_test"] = float(np.max(np.abs(t_err)))
        s[f"{NAME}.table3_sum_inverse_alpha_min"] = float(inv_sum.min())
        for k, r in enumerate(t3, start=1):
            result.rows.append((f"T3 row {k} (h_a {r['groove_depth'] / MM:g}, K2 {r['angle_ratio']:g}, "
                                f"K3/K1 {r['k3_over_k1'] / PER_MM2:g}): alpha",
                                " ".join(f"{a:.2f}" for a in r["alpha"]),
                                " ".join(f"{a:.2f}" for a in r["alpha_paper"]),
                                f"max {100 * np.max(np.abs(r['alpha'] / r['alpha_paper'] - 1)):.1f} %"))
            result.rows.append((f"T3 row {k}: torque Eq. 14 (test {r['torque_test']:g} N m)",
                                f"{r['torque_new']:.2f} N m", f"{r['torque_new_paper']:g} N m",
                                pct(r["torque_new"] / r["torque_new_paper"] - 1)))
        result.rows.append(("Table 3 first film (min / median / max)",
                            f"{firsts.min() / MM:.3f} / {np.median(firsts) / MM:.3f} / {firsts.max() / MM:.3f} mm",
                            f"scene: {kw['first_film'] / MM:g} mm", ""))
        result.rows.append(("max |Eq. 14 torque - test| / test", f"{100 * np.max(np.abs(t_err)):.2f} %",
                            "7.7 % (Table 3)", ""))
        result.rows.append(("Table 3 sum(1/alpha_i), = n if alpha = mean/sigma_i",
                            f"{inv_sum.min():.2f} .. {inv_sum.max():.2f}", f"{kw['n_films']}", ""))
        cols = {"control_pressure [Pa]": [r["control_pressure"] for r in t3],
                "groove_depth [m]": [r["groove_depth"] for r in t3],
                "angle_ratio [-]": [r["angle_ratio"] for r in t3],
                "k3_over_k1 [1/m^2]": [r["k3_over_k1"] for r in t3],
                "sigma_bar_original [m]": [r["sigma_bar"] for r in t3],
                "first_film [m]": [r["first_film"] for r in t3]}
        for i in range(kw["n_films"]):
            cols[f"alpha_{i + 1} [-]"] = [r["alpha"][i] for r in t3]
            cols[f"alpha_{i + 1}_paper [-]"] = [r["alpha_paper"][i] for r in t3]
        cols["torque_eq14 [N m]"] = [r["torque_new"] for r in t3]
        cols["torque_new_paper [N m]"] = [r["torque_new_paper"] for r in t3]
        cols["torque_original_paper [N m]"] = [r["torque_original_paper"] for r in t3]
        cols["torque_test [N m]"] = [r["torque_test"] for r in t3]
        cols["growth_leading_variant [-]"] = ["" if not np.isfinite(r["growth_leading"]) else r["growth_leading"]
                                              for r in t3]
        result.files.append(write_csv(out_dir / "liao2021_table3.csv", cols))

    # 3. unit of K3/K1
    units = unit_check(n_films=kw["n_films"], groove_depth=kw["groove_depth"], angle_ratio=kw["angle_ratio"],
                       first_film=kw["first_film"], value=kw["k3_over_k1"] / PER_MM2)
    for unit, g in units.items():
        if g is not None:
            key = unit.replace("1/", "per_").replace("^", "")
            s[f"{NAME}.growth_if_k3k1_{key}"] = g
    s[f"{NAME}.k3_over_k1_unit"] = "1/mm^2"
    result.rows.append((f"sigma_n/sigma_1, K3/K1 = {kw['k3_over_k1'] / PER_MM2:g} per m^2, cm^2, mm^2, um^2",
                        ", ".join("runaway" if g is None else f"{g:.4g}" for g in units.values()),
                        "per mm^2 (Table 3)", ""))

    result.figure_data = {"cases": cases, "t3": t3, "n_films": kw["n_films"]}
    return result
