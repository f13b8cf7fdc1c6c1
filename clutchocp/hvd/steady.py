"""Steady states of the HVD: operating points for a commanded speed, and the static map.

At a steady state the output does not accelerate, the valve pressure equals its command and the
films do not move (the squeeze rates are zero), so the DAE reduces to

    sum_k T_k(h_k, w_in - w) = k w|w| + load_torque              (torque balance)
    W_film(h_k, 0) = W_k(p, h, w)                                 (film balance, Liao Eq. 12, 15)

* :func:`operating_point` fixes the speed w and solves for the pressure and the films with a
  CasADi Newton rootfinder, started from the static map.
* :func:`static_map` walks the first film h_1 from the open pack down into mixed friction and,
  for each h_1, solves for the speed (and the other films) and then the pressure, which enters
  the film balance linearly. Walking in the film rather than the pressure keeps every solve
  well posed from fully viscous to mixed friction.
"""

from dataclasses import dataclass, field

import casadi as ca
import numpy as np
from scipy.optimize import brentq

from ..errors import ModelError, SolverError

#: Relative slip below which the static map stops (the drive is practically locked).
LOCKED_SLIP = 2e-3
# Newton options: failures are detected from the residual afterwards, so no error and no warnings
_NEWTON = {"abstol": 1e-12, "max_iter": 60, "error_on_fail": False, "show_eval_warnings": False}


@dataclass
class OperatingPoint:
    """A steady state of the HVD model (SI units).

    Attributes
    ----------
    speed : output speed [rad/s].
    pressure : control pressure (= command) [Pa].
    films : thickness of each modelled film, piston side first [m].
    load_torque : load-torque input [N m].
    x, z, u : state, algebraic and input vectors in model order.
    outputs : the model's named outputs there.
    within_limits : True if the pressure is inside the valve range.
    """

    speed: float
    pressure: float
    films: np.ndarray
    load_torque: float
    x: np.ndarray
    z: np.ndarray
    u: np.ndarray
    outputs: dict = field(default_factory=dict)
    within_limits: bool = True


def _point(model, w, p, films, load_torque):
    x = np.concatenate([[w, p], films])
    u = np.array([p, load_torque])
    _, z, y = model.evaluate(x, u)
    within = model.p_min <= p <= model.p_max
    return OperatingPoint(float(w), float(p), np.asarray(films, float), float(load_torque), x, z, u, y, within)


class _SteadyFunctions:
    """CasADi residuals of the steady state, scaled (torque by the rated torque, forces by p_max A)."""

    def __init__(self, model):
        self.model = model
        xv, uv = model.vector("x"), model.vector("u")
        zero_z = ca.DM.zeros(len(model.z))
        ode = ca.substitute(model.ode, model.vector("z"), zero_z)
        alg = ca.substitute(model.alg, model.vector("z"), zero_z)
        torque_scale = max(model.rated_torque, 1e-9)
        res = ca.vertcat(ode[0] * model.J / torque_scale, alg / model.alg_nominal[0])
        self.residual = ca.Function("hvd_steady", [xv, uv], [res])
        self.torque_balance = ca.Function("hvd_torque_balance", [xv, uv], [ode[0] * model.J])
        m = model.n_states_film
        w, p = model.x["w"], model.x["p"]
        h = [model.x[f"h_{k + 1}"] for k in range(m)]
        td = model.u["load_torque"]
        subst_u = ca.vertcat(p, td)                       # command = pressure at steady state
        res_u = ca.substitute(res, uv, subst_u)
        self.p_nom, self.w_nom, self.h_nom = model.p_max, model.w_in, model.film_scale

        # unknowns for a given speed: [p / p_max, ln(h_k / h_nom)], parameters [w, load_torque]
        # (films by their logarithm: Newton can never step to a negative film)
        v = ca.SX.sym("v", 1 + m)
        unscaled = [v[0] * self.p_nom] + [ca.exp(v[1 + k]) * self.h_nom for k in range(m)]
        g = ca.substitute(res_u, ca.vertcat(p, *h), ca.vertcat(*unscaled))
        self.rf_speed = ca.rootfinder("hvd_op", "newton", ca.Function("g_op", [v, ca.vertcat(w, td)], [g]),
                                      _NEWTON)
        # unknowns for a given first film: [w / w_in, p / p_max, ln(h_k / h_nom), k >= 2],
        # parameters [h_1, load_torque]
        v2 = ca.SX.sym("v2", 1 + m)
        unscaled2 = [v2[0] * self.w_nom, v2[1] * self.p_nom] + [ca.exp(v2[1 + k]) * self.h_nom for k in range(1, m)]
        g2 = ca.substitute(res_u, ca.vertcat(w, p, *h[1:]), ca.vertcat(*unscaled2))
        self.rf_film = ca.rootfinder("hvd_map", "newton", ca.Function("g_map", [v2, ca.vertcat(h[0], td)], [g2]),
                                     _NEWTON)
        # pressure from the first film balance (linear in p): alg_1 = a + b p
        alg1 = ca.substitute(alg[0], uv, subst_u)
        self.alg1 = ca.Function("alg1", [xv, td], [alg1, ca.jacobian(alg1, p)])


def _functions(model):
    if not hasattr(model, "_steady_functions"):
        model._steady_functions = _SteadyFunctions(model)
    return model._steady_functions


def _uniform_state(model, h1, load_torque):
    """Speed and pressure of uniform films h1 (exact: bracketed root in w, then linear in p)."""
    F = _functions(model)
    m = model.n_states_film

    def balance(w):
        x = np.concatenate([[w, model.p_max], np.full(m, h1)])
        return float(F.torque_balance(x, [model.p_max, load_torque]))

    w_hi = model.w_in
    if balance(0.0) <= 0:
        return None                               # the films cannot even start the load
    w = brentq(balance, 0.0, w_hi, xtol=1e-13 * w_hi, rtol=1e-14, maxiter=200)
    x = np.concatenate([[w, 0.0], np.full(m, h1)])
    a, b = (float(v) for v in F.alg1(x, load_torque))
    return w, -a / b


def _solve_first_film(model, h1, load_torque, guess):
    """(w, p, films) with the first film fixed at h1, Newton from ``guess`` = (w, p, h_2..)."""
    F = _functions(model)
    v0 = np.concatenate([[guess[0] / F.w_nom, guess[1] / F.p_nom], np.log(np.asarray(guess[2:]) / F.h_nom)])
    v = np.array(F.rf_film(v0, [h1, load_torque]), dtype=float).ravel()
    w, p = v[0] * F.w_nom, v[1] * F.p_nom
    films = np.concatenate([[h1], np.exp(v[2:]) * F.h_nom])
    x = np.concatenate([[w, p], films])
    ok = F.rf_film.stats()["success"] and np.all(np.isfinite(v)) and np.all(films > 0) and 0 <= w <= model.w_in
    if ok:
        ok = np.max(np.abs(np.array(F.residual(x, [p, load_torque])))) < 1e-8
    return (w, p, films) if ok else None


def static_map(model, n_points=120, load_torque=0.0, film_range=None):
    """Output speed against control pressure, from the open pack into mixed friction.

    Parameters
    ----------
    model : HvdModel
    n_points : int
        Number of first-film values (log-spaced).
    load_torque : float
        Load-torque input [N m] (added to the fan law).
    film_range : (float, float), optional
        First-film range [m] (default: from the open pack to half the roughness).

    Returns
    -------
    dict of arrays: ``film_1_m``, ``pressure_Pa``, ``speed_rad_s``, ``viscous_torque_Nm``,
    ``contact_torque_Nm``, ``contact_pressure_Pa``, ``film_ratio``, ``within_valve_range`` (0/1),
    and ``films_m`` (n_points x films), ordered from the open pack to the closed one. The walk
    stops once the slip falls below ``LOCKED_SLIP`` of the input speed. With Liao's unequal
    films the asperities on the first film stop it thinning in mixed friction; from where the
    walk in the first film fails, the map continues in the speed.
    """
    h_hi, h_lo = film_range if film_range is not None else _default_film_range(model)
    films_grid = np.geomspace(h_hi, h_lo, n_points)
    rows = []
    guess = None
    m = model.n_states_film
    for h1 in films_grid:
        if m == 1:
            sol = _uniform_state(model, h1, load_torque)
            if sol is None:
                continue
            w, p = sol
            films = np.array([h1])
        else:
            if guess is None:
                sol = _uniform_state(model, h1, load_torque)
                if sol is None:
                    continue
                guess = np.concatenate([sol, np.full(m - 1, h1)])
            found = _solve_first_film(model, h1, load_torque, guess)
            if found is None:
                if rows:                                # asperity contact holds the first film:
                    rows += _continue_in_speed(model, rows[-1], load_torque, n_points - len(rows))
                    break                               # walk on in the speed instead
                continue
            w, p, films = found
            guess = np.concatenate([[w, p], films[1:]])
        rows.append(_point(model, w, p, films, load_torque))
        if w >= (1 - LOCKED_SLIP) * model.w_in:
            break                                  # the drive is locked from here on
    if len(rows) < 2:
        raise SolverError(f"scene '{model.scene.name}': no steady state found between films {h_lo:.3g} m and "
                          f"{h_hi:.3g} m; check the springs, the pressure range and the load")
    out = {
        "film_1_m": np.array([r.films[0] for r in rows]),
        "pressure_Pa": np.array([r.pressure for r in rows]),
        "speed_rad_s": np.array([r.speed for r in rows]),
        "viscous_torque_Nm": np.array([r.outputs["viscous_torque_Nm"] for r in rows]),
        "contact_torque_Nm": np.array([r.outputs["contact_torque_Nm"] for r in rows]),
        "contact_pressure_Pa": np.array([r.outputs["contact_pressure_Pa"] for r in rows]),
        "film_ratio": np.array([r.outputs["film_ratio_1"] for r in rows]),
        "within_valve_range": np.array([1.0 if r.within_limits else 0.0 for r in rows]),
        "films_m": np.array([r.films for r in rows]),
    }
    return out


def _continue_in_speed(model, start, load_torque, n_points):
    """Steady states from ``start`` up to the locked drive, the speed stepped evenly (Newton from the last)."""
    rows, last = [], start
    target = (1 - LOCKED_SLIP) * model.w_in
    step = (target - start.speed) / max(n_points, 1)
    while last.speed < target - 1e-9 * model.w_in and step > 1e-6 * model.w_in:
        try:
            point = operating_point(model, min(last.speed + step, target), load_torque, guess=last)
        except SolverError:
            step /= 2                                   # a tighter bend of the map: smaller steps
            continue
        rows.append(point)
        last = point
    return rows


def _default_film_range(model):
    """First-film range of the static map: open pack .. half the roughness [m]."""
    film = model.film
    sigma = film.sigma if film.has_roughness else model.film_scale
    if model.orientation == "pressure_applied":
        h_hi = model.open_clearance / model.n
    else:
        # spring-applied: the pack opens as far as the largest pressure moves the springs (no contact)
        inlet = float(film.fluid_load(1.0, 0.0, model.w_in, 0.0)) if film.inlet_pressure else 0.0
        total = (model.p_max * model.piston_area + inlet) / model.spring_rate - model.spring_preload
        if total <= 0:
            raise ModelError(f"hvd.pressure_max = {model.p_max:g} Pa cannot overcome the spring preload "
                             f"({model.spring_rate * model.spring_preload:g} N): the pack never opens")
        h_hi = 1.5 * total / model.n
    return h_hi, 0.5 * sigma


def operating_point(model, speed, load_torque=0.0, guess=None, map_data=None, require_limits=False):
    """Steady state at a commanded output speed (CasADi Newton rootfinder).

    Parameters
    ----------
    model : HvdModel
    speed : float
        Output speed [rad/s], 0 < speed < input speed.
    load_torque : float
        Load-torque input [N m].
    guess : OperatingPoint, optional
        Starting point (default: interpolated on the static map).
    map_data : dict, optional
        A :func:`static_map` result to start from (computed if needed).
    require_limits : bool
        Raise ModelError if the pressure lies outside the valve range.

    Returns
    -------
    OperatingPoint
    """
    if not 0 < speed < model.w_in:
        raise ModelError(f"operating speed {speed:g} rad/s: must lie between 0 and the input speed {model.w_in:g} rad/s")
    F = _functions(model)
    if guess is not None:
        p0, films0 = guess.pressure, np.asarray(guess.films)
    else:
        data = map_data if map_data is not None else static_map(model, load_torque=load_torque)
        w_map = data["speed_rad_s"]
        order = np.argsort(w_map)
        if not w_map[order[0]] <= speed <= w_map[order[-1]]:
            raise ModelError(f"operating speed {speed:.4g} rad/s is outside the static map "
                             f"({w_map.min():.4g}-{w_map.max():.4g} rad/s) of scene '{model.scene.name}'")
        if model.n_states_film == 1:
            p0 = float(np.interp(speed, w_map[order], data["pressure_Pa"][order]))
            films0 = np.exp([np.interp(speed, w_map[order], np.log(data["films_m"][order, 0]))])
        else:                                   # Liao's films: the map folds, start from its nearest state
            k = int(np.argmin(np.abs(w_map - speed)))
            p0, films0 = float(data["pressure_Pa"][k]), data["films_m"][k]
    v0 = np.concatenate([[p0 / F.p_nom], np.log(films0 / F.h_nom)])
    v = np.array(F.rf_speed(v0, [speed, load_torque]), dtype=float).ravel()
    p, films = v[0] * F.p_nom, np.exp(v[1:]) * F.h_nom
    x = np.concatenate([[speed, p], films])
    residual = np.max(np.abs(np.array(F.residual(x, [p, load_torque])))) if np.all(np.isfinite(v)) else np.inf
    if not (F.rf_speed.stats()["success"] and np.all(films > 0) and residual < 1e-8):
        raise SolverError(f"operating point at {speed:.6g} rad/s of scene '{model.scene.name}': Newton did not "
                          f"converge (largest scaled residual {residual:.3g}, from p = {p0:.6g} Pa). Try: a "
                          "speed inside the static map, or a guess from a nearby operating point")
    point = _point(model, speed, p, films, load_torque)
    if require_limits and not point.within_limits:
        raise ModelError(f"operating speed {speed:.4g} rad/s needs a control pressure of {p:.4g} Pa, outside the "
                         f"valve range hvd.pressure_min..pressure_max = {model.p_min:g}..{model.p_max:g} Pa")
    return point


def rest_state(model, pressure):
    """State with the output at rest (w = 0), the valve at ``pressure`` and the films balanced.

    The films solve W_film(h_k, 0) = W_k(p, h, 0) (no squeeze); for uniform films the balance is
    monotone in h and is bracketed, for Liao's films a Newton solve starts from the uniform one.

    Returns
    -------
    numpy array: the state [w, p, h_1..] (SI).
    """
    F = _functions(model)
    m = model.n_states_film

    def balance(h):
        x = np.concatenate([[0.0, pressure], np.full(m, h)])
        return float(np.array(F.residual(x, [pressure, 0.0]), dtype=float).ravel()[1])

    lo, hi = 1e-3 * model.film_scale, 1e-3 * model.film_scale
    while balance(hi) > 0:
        hi *= 2
        if hi > 1.0:
            raise ModelError(f"rest state at {pressure:g} Pa: the films do not balance below 1 m; the pack "
                             "pressure pulls the plates apart (check the springs and the pressure range)")
    if balance(lo) < 0:
        raise ModelError(f"rest state at {pressure:g} Pa: no film balance above {lo:g} m")
    h = brentq(balance, lo, hi, xtol=1e-15, rtol=1e-13, maxiter=200)
    films = np.full(m, h)
    if m > 1:
        g = ca.Function("g_rest", [model.vector("x")], [ca.substitute(
            ca.substitute(model.alg, model.vector("z"), ca.DM.zeros(m)), model.vector("u"),
            ca.vertcat(pressure, 0.0)) / model.alg_nominal[0]])
        hs = ca.SX.sym("hs", m)
        res = ca.Function("g_rest_h", [hs], [g(ca.vertcat(0.0, pressure, ca.exp(hs) * F.h_nom))])
        rf = ca.rootfinder("hvd_rest", "newton", res, _NEWTON)
        films = np.exp(np.array(rf(np.log(films / F.h_nom)), dtype=float).ravel()) * F.h_nom
        if not (rf.stats()["success"] and np.all(films > 0)):
            raise SolverError(f"rest state at {pressure:g} Pa: Newton did not converge for Liao's films")
    return np.concatenate([[0.0, pressure], films])
