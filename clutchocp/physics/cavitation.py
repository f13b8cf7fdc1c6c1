"""Tension limit of a squeeze film: its mean pressure cannot go below the cavitation pressure.

A film between plates that move apart is in tension. Its oil cannot hold a mean gauge pressure much
below minus the ambient pressure: gas comes out of solution and the film cavitates (Hays & Feiten
1964; Parkins & May-Miller, J. Tribol. 106:360, 1984; Optasanu & Bonneau, J. Tribol. 122:162, 2000).
The averaged Reynolds film of :mod:`clutchocp.physics.squeeze_film` has no such limit: its load
W = K (-dh/dt) + S is linear in the closing speed and pulls with any force.

The limit is applied to the fluid load x (squeeze and centrifugal/inlet parts together) as a smooth,
strictly increasing saturation towards L = p_cav A_wet (L < 0), with a small residual slope eps::

    g(x) = L + eps d + (1 - eps) (d + sqrt(d^2 + w^2)) / 2,      d = x - L,

so g(x) -> x above the limit (g(x) - x = (1 - eps) w^2 / (4 d) + O(w^4 / d^3): 1e-4 |L| for a film at
rest, x = 0, with the default w = 0.02 |L|) and g(x) -> L + eps (x - L) below it: beyond the limit a cavitated film resists further
separation with eps times its squeeze coefficient. g is C-infinity, g' is in (eps, 1], and its
inverse is closed form (Y = g - L, a = (1 + eps)/2, b = (1 - eps)/2)::

    d = (a Y - b sqrt(Y^2 + eps w^2)) / eps = (Y^2 - b^2 w^2) / (a Y + b sqrt(Y^2 + eps w^2)),

the first form used for Y < 0 and the second for Y >= 0 (each free of cancellation there).

Why the residual slope (the DAE structure). With plate masses the film load is an explicit function
of the states (positions and velocities), so a pure saturation (eps = 0) would do: a plate pulled by
more than |L| accelerates at (F - |L|) / m. A massless pack, though, finds its film rates from the
force balance, dh/dt = -(g^-1(F - C) - S) / K: a pure saturation has no inverse below L, and a
massless plate pulled beyond the suction limit would separate infinitely fast. With eps > 0 the
inverse exists for every load: once cavitated the force balance is met by the contact load and the
film's residual resistance eps K, and the film opens on the time scale eps K / k_c (k_c the contact
stiffness) instead of K / k_c: 1000 times faster than it squeezes, but finite. The plates' mass,
which the massless pack neglects, would set that time scale instead (m / (eps K) << the slip time);
an engagement's lock-up changes by less than 1e-3 between eps = 1e-3 and 1e-2 (measured in
tests/engagement/test_cavitation.py).

Units: SI (N for loads; any consistent unit works, the functions are homogeneous of degree 1 in
(x, L, w)).
"""

from .backend import fmax, fmin, if_else, sqrt

RESIDUAL_SLOPE = 1e-3        # eps: d g / d x of a cavitated film [-]
WIDTH = 0.02                 # w / (|p_cav| A_n): width of the smooth corner, a fraction of the limit [-]


def tension_limited_load(load, limit, width, slope=RESIDUAL_SLOPE):
    """Fluid load of a film whose mean pressure cannot go far below the cavitation pressure [N].

    Parameters
    ----------
    load : float, array or CasADi symbol
        Fluid load of the linear (uncavitated) film law x = K (-dh/dt) + S [N]; > 0 pushes apart.
    limit : float or symbol
        Tension limit L = p_cav x wetted area [N], <= 0.
    width : float or symbol
        Width w of the smooth corner [N], > 0.
    slope : float
        Residual slope eps of a cavitated film, in (0, 1) [-].

    Returns
    -------
    W : same type as ``load``
        g(x) = L + eps d + (1 - eps)(d + sqrt(d^2 + w^2)) / 2, d = x - L [N]: strictly increasing,
        x + (1 - eps) w^2 / (4 d) for d >> w, L + eps d + (1 - eps) w^2 / (4 |d|) for -d >> w.
    """
    d = load - limit
    return limit + slope * d + 0.5 * (1.0 - slope) * (d + sqrt(d * d + width * width))


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
        L + d with d = (a Y - b sqrt(Y^2 + eps w^2)) / eps for Y = W - L < 0 and
        (Y^2 - b^2 w^2) / (a Y + b sqrt(Y^2 + eps w^2)) for Y >= 0, a = (1 + eps)/2, b = (1 - eps)/2.
    """
    a, b = 0.5 * (1.0 + slope), 0.5 * (1.0 - slope)
    Y = capped - limit
    # each branch is evaluated with Y clamped to its own side, so the unselected one stays finite
    # (a CasADi if_else evaluates both); the two are the same analytic function
    Yn, Yp = fmin(Y, 0.0), fmax(Y, 0.0)
    below = (a * Yn - b * sqrt(Yn * Yn + slope * width * width)) / slope
    above = (Yp * Yp - b * b * width * width) / (a * Yp + b * sqrt(Yp * Yp + slope * width * width))
    return limit + if_else(Y < 0.0, below, above)
