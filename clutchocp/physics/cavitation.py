"""Tension limit of a squeeze film: its mean pressure cannot go below the cavitation pressure.

A film between plates that move apart is in tension. Its oil cannot hold a mean gauge pressure much
below minus the ambient pressure: gas comes out of solution and the film cavitates (Hays & Feiten
1964; Parkins & May-Miller, J. Tribol. 106:360, 1984; Optasanu & Bonneau, J. Tribol. 122:162, 2000).
The averaged Reynolds film of :mod:`clutchocp.physics.squeeze_film` has no such limit: its load
x = K (-dh/dt) + S is linear in the closing speed and pulls with any force.

The limit is applied to the fluid load x (squeeze and centrifugal/inlet parts together) as a smooth,
strictly increasing saturation towards L = p_cav A_wet (L < 0) with a small residual slope eps: a
hyperbola with the asymptotes W = L + eps (x - L) (cavitated) and W = x - delta (the film's own law),
placed so that it passes through the origin (a film at rest carries nothing)::

    g(x) = L + eps D + eps d + (1 - eps) (d + sqrt(d^2 + w^2)) / 2,   d = x - L - D,   D = w^2 / (4 |L|),

g(0) = 0 exactly; g(x) - x falls from 0 at x = 0 to -delta = -(1 - eps) D as x -> inf (2.5e-3 |L| with
the default corner width w = 0.1 |L|), and g(x) -> L + eps (x - L) below the limit: beyond it a
cavitated film resists further separation with eps times its squeeze coefficient. g is C-infinity,
g' is in (eps, 1), and its inverse is closed form (Y = g - L - eps D, a = (1 + eps)/2, b = (1 - eps)/2)::

    d = (a Y - b sqrt(Y^2 + eps w^2)) / eps = (Y^2 - b^2 w^2) / (a Y + b sqrt(Y^2 + eps w^2)).

Both directions are evaluated as the identity plus a small correction above the corner (a film at rest
has x = W = 0, and the sum L + D + d of numbers of size |L| would carry a round-off of 1e-16 |L| into its
closing speed: zhang2021's lock-up then converged only to 1e-8 with the tolerance) and in the form free
of cancellation below it. A hyperbola
with the exact asymptote x (no delta) would lie above it everywhere and carry w^2 / (4 |L|) at rest;
then a settled film would hold that much of the load, which the closed forms of a settled pack (the
stable torque f_c P_o A r_eff) see.

Why the residual slope (the DAE structure). With plate masses the film load is an explicit function
of the states (positions and velocities), so a pure saturation (eps = 0) would do: a plate pulled by
more than |L| accelerates at (F - |L|) / m. A massless pack, though, finds its film rates from the
force balance, dh/dt = -(g^-1(F - C) - S) / K: a pure saturation has no inverse below L, and a
massless plate pulled beyond the suction limit would separate infinitely fast. With eps > 0 the
inverse exists for every load: once cavitated the force balance is met by the contact load and the
film's residual resistance eps K, and the film opens on the time scale eps K / k_c (k_c the contact
stiffness) instead of K / k_c: 100 times faster than it squeezes, but finite. Where the contact
relaxes as the film opens (the usual case: a pressure that falls faster than the asperities can
unload through the film) the opening is quasi-static, C(h) = F - L, and does not depend on eps. The
plates' mass, which the massless pack neglects, would set that time scale instead (m / (eps K)).
eps = 1e-2 rather than smaller: with 1e-3 a cavitated film barely damped the plates (bao2020 at
12 000 rpm, whose centrifugal suction passes -1 bar after lock-up, and bao2020 from a 1 um gap, whose
over-pressed asperities throw the pack open) and IDAS closed their energy balances only to 2e-6 and
7e-6 at the scene tolerance, against 9e-9 and 7e-9 with 1e-2 (a run's lock-up moves by 4e-4 between
the two on the first, 2.5 % on the second, where the pack flies open); zhang2021's optimum converged in
179 IPOPT iterations instead of 345. A film pulled beyond the limit then carries up to a few per cent
more than L while it opens (zhang2021's optimum: -1.04 bar in the IDAS replay).

The corner width w = 0.1 |L| is chosen for the optimiser: zhang2021's collocation problem converged in
179 IPOPT iterations with it, 301 with 0.05 |L| or 0.02 |L| (each verified by IDAS to 0.09 %); a film's
squeeze load is then within 2.5e-3 |L| (0.25 kPa of mean pressure at -1 bar) of its own law, and a film
at rest is exact.

Units: SI (N for loads); the functions are homogeneous of degree 1 in (x, L, w).
"""

from .backend import fabs, fmax, fmin, if_else, sqrt

RESIDUAL_SLOPE = 1e-2        # eps: d g / d x of a cavitated film [-]
WIDTH = 0.1                  # w / |L|: width of the smooth corner, a fraction of the limit [-]


def _offset(limit, width, slope):
    """(D, base): the corner's shift D = w^2 / (4 |L|) and the hyperbola's base L + eps D."""
    D = width * width / (4.0 * fabs(limit))
    return D, limit + slope * D


def tension_limited_load(load, limit, width, slope=RESIDUAL_SLOPE):
    """Fluid load of a film whose mean pressure cannot go far below the cavitation pressure [N].

    Parameters
    ----------
    load : float, array or CasADi symbol
        Fluid load of the linear (uncavitated) film law x = K (-dh/dt) + S [N]; > 0 pushes apart.
    limit : float or symbol
        Tension limit L = p_cav x wetted area [N], < 0.
    width : float or symbol
        Width w of the smooth corner [N], > 0 (default in the film law: WIDTH |L|).
    slope : float
        Residual slope eps of a cavitated film, in (0, 1) [-].

    Returns
    -------
    W : same type as ``load``
        g(x) [N] (module notes): strictly increasing, g(0) = 0, within (1 - eps) w^2 / (4 |L|) below x
        for x >= 0, L + eps (x - L) + O(w^2 / |x - L|) far below the limit.

    Notes
    -----
    Evaluated without cancellation: above the corner (d >= 0) as x + (1 - eps)(w^2 / (2 (s + d)) - D),
    s = sqrt(d^2 + w^2), so a film near rest (x -> 0) keeps full relative accuracy; below it as
    L + eps D + eps d + (1 - eps) w^2 / (2 (s - d)).
    """
    D, base = _offset(limit, width, slope)
    d = load - limit - D
    dp, dn = fmax(d, 0.0), fmin(d, 0.0)          # each branch finite on the other side (CasADi if_else)
    above = load + (1.0 - slope) * (width * width / (2.0 * (sqrt(dp * dp + width * width) + dp)) - D)
    below = base + slope * dn + (1.0 - slope) * width * width / (2.0 * (sqrt(dn * dn + width * width) - dn))
    return if_else(d >= 0.0, above, below)


def tension_limited_load_inverse(capped, limit, width, slope=RESIDUAL_SLOPE):
    """Linear-law fluid load x whose limited load is ``capped``: the inverse of :func:`tension_limited_load` [N].

    Parameters
    ----------
    capped : float, array or CasADi symbol
        Fluid load the film carries, W = g(x) [N] (any value: g maps onto the whole real line).
    limit, width, slope
        As in :func:`tension_limited_load`.

    Returns
    -------
    x : same type as ``capped``
        With Y = W - L - eps D, a = (1 + eps)/2, b = (1 - eps)/2, r = sqrt(Y^2 + eps w^2): for Y >= 0
        x = W + (1 - eps) D - b w^2 (eps Y / (Y + r) + b) / (a Y + b r) (the correction to W in closed
        form, free of cancellation, so x -> 0 as W -> 0 to full relative accuracy); for Y < 0
        x = L + D + (a Y - b r) / eps.
    """
    a, b = 0.5 * (1.0 + slope), 0.5 * (1.0 - slope)
    D, base = _offset(limit, width, slope)
    Y = capped - base
    # each branch is evaluated with Y clamped to its own side, so the unselected one stays finite
    # (a CasADi if_else evaluates both); the two are the same analytic function
    Yn, Yp = fmin(Y, 0.0), fmax(Y, 0.0)
    rn, rp = sqrt(Yn * Yn + slope * width * width), sqrt(Yp * Yp + slope * width * width)
    below = limit + D + (a * Yn - b * rn) / slope
    above = capped + (1.0 - slope) * D - b * width * width * (slope * Yp / (Yp + rp) + b) / (a * Yp + b * rp)
    return if_else(Y < 0.0, below, above)
