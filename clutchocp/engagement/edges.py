"""Where an engagement model holds, checked before a run: the asperity contact must carry, with a film left
(gap > 0), the largest pressure the run can put on the pack.

An asperity contact law carries at most its pressure at zero film ratio H = h / sigma = 0; Greenwood-Tripp

    p_c(H = 0) = K' E' F_5/2(0),   K' = (16 sqrt2 / 15) pi (n_a beta sigma)^2 sqrt(sigma / beta),   F_5/2(0) = 0.61663

(Bao 2020 Eq. 18-19 with the exact F_5/2; 0.77 MPa for Zhang 2021's asperities at sigma = 6 um, scaling as
sigma^2.5 E'). A pack pressed harder drives the model's gap below zero to find the load: that is the
model's edge, not a result. This module checks the bound before a run; the engagement model watches the
film gaps during the run (its ``film_closed`` events), because dynamics (plate or piston inertia, the
centrifugal film suction) can press a film beyond the static pressure. ``simulate`` calls
:func:`check_contact_capacity` with the scene's pressure profile; an optimiser that may command up to
``actuation.max_pressure`` calls it with ``max_pressure``.

The capacity is the film law's own contact force at zero gap (:meth:`~clutchocp.engagement.films.FilmLaw.contact_force`),
so it follows the scene's contact variant (Greenwood-Tripp exact or fitted, Bao's area-ratio force,
Zhang's E delta^2); ``contact.model = "none"`` carries nothing and has no such check (its films close
through the lining, which the run's events report). The pack pressure is the drive of the piston part
(:meth:`~clutchocp.engagement.piston.Piston.drive_force`) with every film closed, over one film's area:
the load of film 1 when nothing else carries it (no spline friction, no inlet-pressure support; both
only lower the load, so the check is on the safe side).
"""

import weakref
from dataclasses import dataclass

import numpy as np

from ..errors import PhysicalRangeError
from .actuation import read_table
from .films import FilmLaw
from .piston import piston_part

_LAWS = {"greenwood_tripp": "Greenwood-Tripp", "zhang_gw": "Zhang's Greenwood-Williamson contact (E delta^2)"}
_REMEDY = "raise roughness.sigma_* / contact.E_equiv / roughness.asperity_density"
# scene -> the outcome of its passed check at its own pressures: a Scene does not change, and a bench
# or sweep runs the same scene hundreds of times (~20-70 us a check, the contact law at zero gap)
_PASSED = weakref.WeakKeyDictionary()


@dataclass(frozen=True)
class ContactCapacity:
    """The largest nominal pressure a film's asperities carry at zero gap, and what it follows from.

    Attributes
    ----------
    pressure_Pa : float
        Contact load at H = 0 over the nominal area of one film [Pa].
    law : str
        The contact law, for messages.
    data : str
        The values it follows from (roughness, modulus, n beta sigma), for messages.
    """

    pressure_Pa: float
    law: str
    data: str


@dataclass(frozen=True)
class PackPressure:
    """The largest pressure a run puts on the pack with every film closed.

    Attributes
    ----------
    pressure_Pa : float
        Nominal pressure on film 1 [Pa]: the pack force over one film's area.
    oil_pressure_Pa : float
        The oil pressure at which it is reached [Pa].
    per_oil_pressure : float
        d(pack pressure) / d(oil pressure) [-]: positive for a pressure-applied pack, negative for a
        spring-applied piston (the oil releases it).
    at_zero_oil_Pa : float
        Pack pressure at zero oil pressure [Pa] (the springs alone).
    """

    pressure_Pa: float
    oil_pressure_Pa: float
    per_oil_pressure: float
    at_zero_oil_Pa: float


def zero_gap_pressure(film):
    """Largest pressure the asperity contact carries at a positive film [Pa]: its value at zero gap.

    The contact law's own pressure at h = 0 (Greenwood-Tripp: K' E' F_5/2(0), F_5/2(0) = 0.61663;
    Zhang's variant: E (pi n beta sigma F_1(0))^2), or infinity without a contact law.

    Parameters
    ----------
    film : clutchocp.engagement.films.FilmLaw
    """
    if film.contact_model == "none":
        return float("inf")
    return float(film.contact_force(0.0)) / film.area


def contact_capacity(scene, film=None):
    """The contact's capacity at zero gap (:class:`ContactCapacity`), or None for ``contact.model = "none"``
    (and for a scene that is not an engagement: its run refuses it).

    Parameters
    ----------
    scene : clutchocp.scene.Scene
        An engagement scene.
    film : clutchocp.engagement.films.FilmLaw, optional
        The scene's film law, if already built.
    """
    model = scene.variant("contact") if scene.kind == "engagement" else ""
    if model not in _LAWS:
        return None
    film = film if film is not None else FilmLaw(scene)
    pressure = zero_gap_pressure(film)
    n_beta_sigma = film.n_a * film.beta * film.sigma
    law = _LAWS[model]
    if model == "greenwood_tripp" and film.fit == "patir":
        law += " (Bao Eq. 19 fit of F_5/2)"
    if model == "greenwood_tripp" and film.contact_force_form == "area_ratio":
        law += " with Bao Eq. 20's area-ratio force"
    data = (f"sigma {film.sigma * 1e6:.3g} um, E' {film.E / 1e6:.4g} MPa, n beta sigma {n_beta_sigma:.3g}, "
            f"beta {film.beta * 1e3:.3g} mm")
    return ContactCapacity(pressure, law, data)


def run_oil_pressures(scene):
    """The oil pressures [Pa] a run of the scene's own pressure profile passes through at its extremes:
    the initial and the set pressure, or every value of a pressure table (each profile is monotone
    between them, or piecewise linear through the table)."""
    if scene.variant("actuation") == "table":
        return tuple(float(p) for p in read_table(scene.value("actuation.file"), "actuation.file")[:, 1])
    return (scene.value("actuation.initial_pressure"), scene.value("actuation.pressure"))


def pack_pressure(scene, oil_pressures, film=None):
    """The largest nominal pressure on film 1 with every film closed, over ``oil_pressures`` [Pa].

    The pack force is the drive of the scene's piston part at full stroke (free travel plus every
    initial gap closed: x0 = travel + n H0; springs at their most compressed for a pressure-applied
    piston, least for a spring-applied one), or p A without a piston; it is linear in the oil
    pressure, so its largest value over a profile is at one of the profile's extremes. ``film``:
    the scene's :class:`~clutchocp.engagement.films.FilmLaw`, if already built.

    Returns
    -------
    PackPressure
    """
    film_area = (film if film is not None else FilmLaw(scene)).area
    part = piston_part(scene, scene.get("actuation.area") or film_area)
    stroke = part.travel + scene.value("plates.n_interfaces") * scene.value("pack.initial_gap")

    def on_pack(p):
        force = part.drive_force(p, stroke) if part.present else p * part.pack_area
        return float(force) / film_area

    at_zero = on_pack(0.0)
    slope = on_pack(1.0) - at_zero
    oil = max(oil_pressures, key=on_pack)
    return PackPressure(on_pack(oil), float(oil), slope, at_zero)


def check_contact_capacity(scene, *, max_pressure=None):
    """Refuse a run whose pack pressure exceeds what the contact carries at zero gap.

    Parameters
    ----------
    scene : clutchocp.scene.Scene
        An engagement scene.
    max_pressure : float, optional
        The largest oil pressure [Pa] the run may command (an optimiser's bound,
        ``actuation.max_pressure``); the check then covers every pressure from 0 to it. Default: the
        scene's own pressure profile (:func:`run_oil_pressures`).

    Returns
    -------
    (ContactCapacity, PackPressure) or None
        The two numbers compared (None without a contact law).

    Raises
    ------
    PhysicalRangeError
        One line naming both pressures, the contact data and what to change.

    Notes
    -----
    A scene that passed at its own pressures passes again without computing (a table profile,
    read from its file at each check, is always checked).
    """
    if scene.kind != "engagement" or scene.variant("contact") not in _LAWS:
        return None                                     # no contact law: no capacity (contact_capacity)
    table = scene.variant("actuation") == "table"
    remember = max_pressure is None and not table
    if remember and scene in _PASSED:
        return _PASSED[scene]
    film = FilmLaw(scene)
    capacity = contact_capacity(scene, film)
    source = ("actuation.max_pressure" if max_pressure is not None
              else "the pressures of actuation.file" if table else "actuation.pressure")
    oil = (0.0, float(max_pressure)) if max_pressure is not None else run_oil_pressures(scene)
    pack = pack_pressure(scene, oil, film)
    if pack.pressure_Pa <= capacity.pressure_Pa:
        if remember:
            _PASSED[scene] = (capacity, pack)
        return capacity, pack
    cap = f"{capacity.pressure_Pa / 1e6:.3g} MPa"
    applied = f"{pack.pressure_Pa / 1e6:.3g} MPa"
    if abs(pack.pressure_Pa - pack.oil_pressure_Pa) > 1e-9 * pack.pressure_Pa:
        springs = ", springs included" if pack.at_zero_oil_Pa else ""
        applied += f" on the pack (at {pack.oil_pressure_Pa / 1e6:.3g} MPa of oil{springs})"
    limit = (capacity.pressure_Pa - pack.at_zero_oil_Pa) / pack.per_oil_pressure if pack.per_oil_pressure else np.nan
    if pack.per_oil_pressure > 0 and limit > 0:
        change = f"lower {source} below {limit / 1e6:.3g} MPa"
    elif pack.per_oil_pressure < 0:
        change = (f"keep the oil pressure above {limit / 1e6:.3g} MPa (actuation.pressure, "
                  "actuation.initial_pressure) or soften the springs (piston.spring_stiffness, spring_preload)")
    else:
        change = "soften the springs (piston.spring_stiffness, spring_preload)"
    raise PhysicalRangeError(
        f"contact: {capacity.law} carries at most {cap} at zero gap ({capacity.data}), the run applies {applied}: "
        f"{change}, or {_REMEDY}")
