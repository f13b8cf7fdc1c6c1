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

    d = (a Y - b sqrt(Y^2 + eps w^2)) / eps = (Y^2 - b^2 w^2) / (a Y + b sqrt(Y^2 + eps w^2)),

the first form used for Y < 0 and the second for Y >= 0 (each free of cancellation there). A hyperbola
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
stiffness) instead of K / k_c: 1000 times faster than it squeezes, but finite. Where the contact
relaxes as the film opens (the usual case: a pressure that falls faster than the asperities can
unload through the film) the opening is quasi-static, C(h) = F - L, and does not depend on eps. The
plates' mass, which the massless pack neglects, would set that time scale instead (m / (eps K)).

The corner width w = 0.1 |L| is chosen for the optimiser: zhang2021's collocation problem converged in
345 IPOPT iterations with it, 407 with 0.05 |L| and 560 with 0.02 |L| (each verified by IDAS to 0.08 %); a
film's squeeze load is then within 2.5e-3 |L| (0.25 kPa of mean pressure at -1 bar) of its own law, and a
film at rest is exact.

Units: SI (N for loads); the functions are homogeneous of degree 1 in (x, L, w).
"""

from .backend import fabs, fmax, fmin, if_else, sqrt

RESIDUAL_SLOPE = 1e-3        # eps: d g / d x of a cavitated film [-]
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
        for x >= 0, L + eps (x - L) + O(w^2 / |x|) far below the limit.
    """
    D, base = _offset(limit, width, slope)
    d = load - limit - D
    return base + slope * d + 0.5 * (1.0 - slope) * (d + sqrt(d * d + width * width))


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
        L + D + d with d = (a Y - b sqrt(Y^2 + eps w^2)) / eps for Y = W - L - eps D < 0 and
        (Y^2 - b^2 w^2) / (a Y + b sqrt(Y^2 + eps w^2)) for Y >= 0, a = (1 + eps)/2, b = (1 - eps)/2.
    """
    a, b = 0.5 * (1.0 + slope), 0.5 * (1.0 - slope)
    D, base = _offset(limit, width, slope)
    Y = capped - base
    # each branch is evaluated with Y clamped to its own side, so the unselected one stays finite
    # (a CasADi if_else evaluates both); the two are the same analytic function
    Yn, Yp = fmin(Y, 0.0), fmax(Y, 0.0)
    below = (a * Yn - b * sqrt(Yn * Yn + slope * width * width)) / slope
    above = (Yp * Yp - b * b * width * width) / (a * Yp + b * sqrt(Yp * Yp + slope * width * width))
    return limit + D + if_else(Y < 0.0, below, above)
