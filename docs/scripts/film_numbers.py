"""Regenerate every number docs/physics.md quotes in its sections on the transmitted viscous torque and
on film tension (cavitation).

Run from the repository root:  python docs/scripts/film_numbers.py
(about half a minute; it simulates the built-in scenes).
"""

import math

import numpy as np
from scipy import integrate

from clutchocp.engagement.run import simulate_engagement
from clutchocp.physics import contact
from clutchocp.physics.cavitation import RESIDUAL_SLOPE, WIDTH
from clutchocp.physics.roughness import average_gap
from clutchocp.physics.shear import shear_factor_phi_f, shear_factor_phi_fs
from clutchocp.scene import load_scene


def one_dimensional_wall(eps):
    """Exact stresses of a film over the fixed wall h = 1 + eps cos x under a smooth wall sliding at U = 1
    (eta = 1), in units of the Couette stress E[1/h]: (smooth-wall drag, rough-wall viscous shear, form drag)."""
    x = np.linspace(0, 2 * np.pi, 200001)[:-1]
    h = 1 + eps * np.cos(x)
    I1, I2, I3 = (np.mean(h**-k) for k in (1, 2, 3))
    smooth = 4 * I1 - 3 * I2**2 / I3
    rough = 3 * I2**2 / I3 - 2 * I1
    return smooth / I1, rough / I1, (smooth - rough) / I1


def main():
    print("== which wall, which sign: the exact 1D periodic wall (units of eta U E[1/h])")
    for eps in (0.1, 0.3, 0.5):
        smooth, rough, form = one_dimensional_wall(eps)
        print(f"  eps = {eps}: smooth-wall drag {smooth:.3f}, rough-wall viscous shear {rough:.3f}, "
              f"form drag {form:.3f}")
    print("== Patir-Cheng factors (one rough wall): phi_f, Phi_fs, phi_f - Phi_fs, phi_f + Phi_fs")
    for H in (0.5, 1.0, 2.0, 3.0):
        f, fs = float(shear_factor_phi_f(H)), float(shear_factor_phi_fs(H, 1.0, 0.0))
        print(f"  H = {H}: {f:.4f}, {fs:.4f}, {f - fs:.4f}, {f + fs:.4f}")
    print("== phi_f = E[h / h_loc] (Patir density, H > 3) and h_T / h")
    for H in (3.5, 6.0):
        z = H / 3
        mean, _ = integrate.quad(lambda u: z / (z - u) * 35 / 32 * (1 - u * u) ** 3, -1, 1, epsrel=1e-13)
        print(f"  H = {H}: Cui Eq. 6 {float(shear_factor_phi_f(H)):.15f}, quadrature {mean:.15f}")
    for H in (0.5, 1.0, 2.0, 3.0):
        print(f"  H = {H}: h_T / h = {float(average_gap(H, 1.0)) / H:.4f}")

    print("== zhang2021 (Table 1: 1000 rad/s, I = 0.56 kg m^2, r = 64-85 mm)")
    w, inertia, r1, r2 = 1000.0, 0.56, 0.064, 0.085
    area_mm2 = math.pi * (r2**2 - r1**2) * 1e6
    energy = 0.5 * inertia * w**2
    steel = math.pi * (r2**2 - r1**2) * 2e-3 * 7850 * 460            # a 2 mm steel plate [J/K]
    print(f"  {w * 60 / (2 * math.pi):.0f} rpm, {w * r2:.0f} m/s at r2; {energy / 1e3:.0f} kJ on {area_mm2:.0f} mm^2 "
          f"= {energy / area_mm2:.1f} J/mm^2; two 2 mm steel plates ({steel:.0f} J/K each) would heat by "
          f"{energy / (2 * steel):.0f} K")
    base = load_scene("zhang2021")
    equal = {"roughness.sigma_1": 8.41e-6 / math.sqrt(2), "roughness.sigma_2": 8.41e-6 / math.sqrt(2)}
    for label, scene in (("lining rough", base), ("equal split", base.with_overrides(equal)),
                         ("1000 rpm", base.with_overrides({"driveline.input_speed": "1000 rpm"}))):
        s = simulate_engagement(scene).summary
        print(f"  {label}: lock-up {s['engagement_time_s']:.4g} s, peak {s['peak_torque_Nm']:.4g} N m, "
              f"{s['specific_energy_J_mm2']:.3g} J/mm^2")

    print("== n beta sigma and the real-area ratio at the settled film")
    for name in ("zhang2021", "default_driveline", "default_fill", "bao2020"):
        run = simulate_engagement(name)
        film = run.model.film
        H = run.result.final("h_1") / film.sigma
        gt = film.contact_model == "greenwood_tripp"
        law = (lambda x: contact.greenwood_tripp_area_ratio(x, film.n_a, film.beta, film.sigma)) if gt else \
            (lambda x: contact.zhang_area_ratio(x, film.n_a, film.beta, film.sigma))
        grid = np.linspace(-2, 3, 50001)
        at_cap = grid[np.argmin(np.abs(law(grid) - 0.99))]
        print(f"  {name} ({film.contact_model}): n beta sigma = {film.n_a * film.beta * film.sigma:.3f}, "
              f"settled H = {H:.3f}, area ratio {float(law(H)):.3f}, 99 % at H = {at_cap:.3f}")

    print("== tension limit")
    D = WIDTH**2 / 4
    print(f"  residual slope {RESIDUAL_SLOPE:g}, corner width {WIDTH:g} |L|, squeeze-load offset "
          f"(1 - eps) w^2 / (4 |L|) = {(1 - RESIDUAL_SLOPE) * D:.2e} |L|")
    for name in ("default_driveline", "default_driveline_thermal", "default_fill", "zhang2021", "bao2020",
                 "bao2020_as_published"):
        s = simulate_engagement(name).summary
        print(f"  simulate {name}: lock-up {s['engagement_time_s']:.4g} s, lowest mean film pressure "
              f"{s['min_film_pressure_Pa']:.4g} Pa (film "
              f"{s['min_film_pressure_film']} at {s['min_film_pressure_time_s']:.4g} s), energy balance "
              f"{s['energy_balance_rel_error']:.1e}")


if __name__ == "__main__":
    main()
