"""Times and peaks between output samples: level crossings and extrema located on a local cubic.

A quantity read off the output grid is off by up to one sample spacing (zhang2021's torque response
time moved by 1e-3 s with the grid). Here the four samples around a crossing (or a peak) define a
cubic through them; its root (or its stationary point) is the located time. Within one mode the
solution is smooth, so the error falls as dt^4 (checked in tests/test_user_api.py against runs on
a 10x finer grid). Samples are only combined within one piece of the run (``piece``: equal labels,
e.g. the mode of each sample, with event instants separating pieces).
"""

import math

import numpy as np
from scipy.optimize import brentq

_TINY = float(np.finfo(float).tiny)    # np.finfo costs ~10 us a call: read once
_EPS = float(np.finfo(float).eps)


def _stencil(t, k, piece):
    """Indices of up to four samples around the interval [t[k], t[k+1]] in the same piece, times distinct."""
    lo, hi = k, k + 1
    same = (lambda i: piece is None or piece[i] == piece[k])
    gap = 1e-3 * (t[k + 1] - t[k])           # neighbours closer than this would make the fit singular
    for _ in range(2):
        if lo - 1 >= 0 and same(lo - 1) and t[lo - 1] < t[lo] - gap:
            lo -= 1
        if hi + 1 < len(t) and same(hi + 1) and t[hi + 1] > t[hi] + gap:
            hi += 1
    idx = list(range(lo, hi + 1))
    if len(idx) > 4:                       # keep the four nearest
        idx = idx[1:] if (t[k] - t[idx[0]]) > (t[idx[-1]] - t[k + 1]) else idx[:-1]
    return idx


def _window(t, y, piece, k):
    """The samples a stencil around sample ``k`` can reach (k - 3 .. k + 4) as Python lists, and the
    index of the first: the stencil and the cubic then work on floats, not numpy scalars (a few
    microseconds a call, the same numbers)."""
    first = max(k - 3, 0)
    part = slice(first, k + 5)
    return t[part].tolist(), y[part].tolist(), (None if piece is None else np.asarray(piece)[part].tolist()), first


def _cubic(t, y, idx):
    """The interpolating polynomial (degree ``len(idx) - 1``, at most 4) of the samples ``idx``, in a
    local time variable.

    Newton's divided differences on ``s = (t - t0) / scale`` in [0, 1], expanded to monomial
    coefficients (highest power first, as ``numpy.polyfit``), evaluated by Horner's rule on Python
    floats: the same polynomial as a least-squares fit of degree ``len(idx) - 1`` (exact through
    the points, tested against ``numpy.polyfit``) at a few microseconds instead of a matrix
    factorisation.

    Returns
    -------
    f : callable
        ``f(time)`` [s] -> the polynomial's value.
    coef : list of float
        Coefficients in ``s``, highest power first.
    t0, scale : float
        The local variable is ``s = (time - t0) / scale``.
    """
    t0 = float(t[idx[0]])
    scale = max(float(t[idx[-1]]) - t0, _TINY)
    s = [(float(t[i]) - t0) / scale for i in idx]
    c = [float(y[i]) for i in idx]
    n = len(s)
    for j in range(1, n):                       # divided differences, in place
        for i in range(n - 1, j - 1, -1):
            c[i] = (c[i] - c[i - 1]) / (s[i] - s[i - j])
    coef = [c[-1]]
    for k in range(n - 2, -1, -1):              # coef <- coef * (s - s_k) + c_k
        coef = [a - s[k] * b for a, b in zip(coef + [0.0], [0.0] + coef)]
        coef[-1] += c[k]

    def f(time):
        u, value = (time - t0) / scale, 0.0
        for a in coef:
            value = value * u + a
        return value

    return f, coef, t0, scale


def _sign(v):
    v = float(v)
    return (v > 0) - (v < 0)


def _stationary(coef):
    """Real roots of the derivative of the polynomial ``coef`` (highest power first); closed form up
    to a quadratic derivative."""
    d = [(len(coef) - 1 - i) * float(a) for i, a in enumerate(coef[:-1])]     # derivative, highest first
    while d and d[0] == 0:
        d = d[1:]
    if len(d) == 2:
        return [-d[1] / d[0]]
    if len(d) == 4:                             # five samples: a quartic's cubic derivative
        return _cubic_roots(*d)
    if len(d) != 3:
        return []
    a, b, c = d
    disc = b * b - 4 * a * c
    if disc < 0:
        return []
    q = -0.5 * (b + math.copysign(math.sqrt(disc), b))
    return [q / a] + ([c / q] if q != 0 else [])


def _cubic_roots(a, b, c, d):
    """Real roots of ``a x^3 + b x^2 + c x + d`` (``a != 0``): the trigonometric form for three real
    roots, Cardano's for one, each polished by two Newton steps (tested against ``numpy.roots``)."""
    b, c, d = b / a, c / a, d / a
    p = c - b * b / 3.0                          # depressed cubic y^3 + p y + q, x = y - b/3
    q = 2.0 * b**3 / 27.0 - b * c / 3.0 + d
    disc = (q / 2.0) ** 2 + (p / 3.0) ** 3
    if disc < 0:                                 # three real roots (p < 0)
        r = 2.0 * math.sqrt(-p / 3.0)
        phi = math.acos(max(-1.0, min(1.0, 3.0 * q / (p * r))))
        ys = [r * math.cos((phi - 2.0 * math.pi * k) / 3.0) for k in range(3)]
    else:
        w = math.sqrt(disc)
        u, v = -q / 2.0 + w, -q / 2.0 - w
        ys = [math.copysign(abs(u) ** (1 / 3), u) + math.copysign(abs(v) ** (1 / 3), v)]
    roots = []
    for y in ys:
        x = y - b / 3.0
        for _ in range(2):
            slope = (3.0 * x + 2.0 * b) * x + c
            if slope == 0:
                break
            x -= (((x + b) * x + c) * x + d) / slope
        roots.append(x)
    return roots


def crossing_time(t, y, level, piece=None, start=0):
    """First time ``y`` reaches ``level`` from below at or after sample ``start`` (None if never).

    Parameters
    ----------
    t, y : ndarray
        Sample times [s] (non-decreasing; repeated at events) and values.
    level : float
        The level.
    piece : ndarray, optional
        Label of each sample's piece (e.g. the mode); the cubic only joins samples of one piece.
    start : int
        First sample to consider.

    Returns
    -------
    float or None
        The located time [s].
    """
    t, y = np.asarray(t, float), np.asarray(y, float)
    above = np.nonzero(y[start:] >= level)[0]
    if above.size == 0:
        return None
    k = start + above[0]
    if k == 0 or t[k] <= t[k - 1] or (piece is not None and piece[k] != piece[k - 1]):
        return float(t[k])
    k -= 1
    if y[k] == level:
        return float(t[k])
    t, y, piece, first = _window(t, y, piece, k)
    k -= first
    f, *_ = _cubic(t, y, _stencil(t, k, piece))
    lo, hi = t[k], t[k + 1]
    if _sign(f(lo) - level) == _sign(f(hi) - level):   # the cubic misses it: linear fallback
        return float(lo + (level - y[k]) * (hi - lo) / (y[k + 1] - y[k]))
    return float(brentq(lambda s: f(s) - level, lo, hi, xtol=1e-15, rtol=4 * _EPS))


def peak(t, y, piece=None):
    """Largest value of ``y`` and its time, refined between samples by the local cubic.

    Returns
    -------
    (float, float)
        Peak value and its time [s]. A peak on the first or last sample of a piece (a jump at an
        event) is the sample itself.
    """
    t, y = np.asarray(t, float), np.asarray(y, float)
    k = int(np.argmax(y))
    best = (float(y[k]), float(t[k]))
    t, y, piece, first = _window(t, y, piece, k)
    k -= first
    for a in (k - 1, k):
        if a < 0 or a + 1 >= len(t) or t[a + 1] <= t[a] or (piece is not None and piece[a] != piece[a + 1]):
            continue
        idx = _stencil(t, a, piece)
        if len(idx) < 3:
            continue
        f, coef, t0, scale = _cubic(t, y, idx)
        lo, hi = t[a], t[a + 1]
        for r in _stationary(coef):
            s = t0 + r * scale
            if lo < s < hi and f(s) > best[0]:
                best = (float(f(s)), float(s))
    return best


def root_near(t, y, t_guess):
    """Zero of the cubic through the last four samples (``t`` ascending, one piece) nearest ``t_guess``.

    For a crossing at the end of a piece (lock-up: the slip speed reaches zero where the event ends
    the slip mode), the root may lie a little past the last sample; it is found by extending the
    cubic.

    Returns
    -------
    float or None
        The root [s], or None if the cubic has no real root within four sample spacings of ``t_guess``.
    """
    t, y = np.asarray(t, float)[-4:], np.asarray(y, float)[-4:]
    if t.size < 2 or np.any(np.diff(t) <= 0):
        return None
    f, coef, t0, scale = _cubic(t, y, np.arange(t.size))
    roots = [t0 + r.real * scale for r in np.roots(coef) if abs(r.imag) < 1e-12]
    spacing = t[-1] - t[-2]
    roots = [r for r in roots if abs(r - t_guess) <= 4 * spacing]
    return float(min(roots, key=lambda r: abs(r - t_guess))) if roots else None
