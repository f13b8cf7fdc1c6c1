"""What no pressure command can do: the limits of an engagement, checked before solving, with numbers.

A user's clutch may ask for something no command within its limits can give. These checks compare
the limit with what the engagement needs, each by a bound that holds for every command, and refuse
a request that cannot be met in one line naming the limit, both numbers and the option or scene
field that moves it (:class:`~clutchocp.errors.ModelError`; the command line exits with code 2):

* **the contact at zero gap** (:func:`clutchocp.engagement.edges.zero_gap_pressure`): the asperities carry at most
  p_c(0) on the friction area, Greenwood-Tripp's K' E' F_5/2(0); a plate pressure above it has no
  settled film of positive thickness (the model's edge). Where the contact cannot carry the largest
  plate pressure at :data:`FILM_FLOOR` sigma, the problem keeps every film above that floor and the
  contact's capacity there caps what the pack can hold;
* **the pressure limit** (:func:`holding_capacity`): the static capacity mu_s F r_eff n of the pack
  pressed by the largest plate force F the command can give (the pressure limit on the pack face, or
  through a piston less its return springs at the kiss point; a spring-applied piston: its springs at
  zero pressure), capped by the contact at the film floor, against the torque the locked driveline
  carries (times 1 + the lock margin);
* **the kiss point**: a piston whose return springs at the kiss point need more than the pressure
  limit never reaches the pack;
* **the energy of a lock-up** (:func:`lockup_energy_bound`): with the clutch torque T_c and
  w_rel' = (T_lock - T_c) / I_eq between two inertias (I_eq = I_in I_out / (I_in + I_out); one of them
  alone for a prescribed input speed or a held output), the slip energy is

      E = int T_c w_rel dt = 1/2 I_eq w_rel(0)^2 + int T_lock w_rel dt >= 1/2 I_eq w_rel(0)^2

  whenever the driving torques T_lock = I_eq (T_in / I_in + T_load / I_out) are not negative (else
  their least work over t_max is added): no command dissipates less;
* **the temperature limit** (:func:`temperature_bound`): the plate temperatures are linear in the
  heat released, so the interface temperature at lock-up is its free response plus the convolution of
  the heat power with the impulse response g(t) of the thermal part. For the lining's conduction
  nodes (:class:`~clutchocp.engagement.thermal.LiningConduction`: C dT/dt = -K (T - T_oil) + Q e_0 with
  C diagonal, K symmetric positive definite) g(t) = e_0' C^-1/2 exp(-C^-1/2 K C^-1/2 t) C^-1/2 e_0 is
  a sum of decaying exponentials with weights >= 0, so it falls with time (heat spreads into the
  lining and core and convects away). The least the interface temperature can be, for any heat
  history of total E at t_f, is T_free(t_f) + E g(t_f) (all the heat at t = 0); the peak temperature
  is at least its smallest value over the lock-up times the problem allows;
* **the specific-power limit**: E <= q_max A t_f, so no lock-up under q_max is faster than
  E_min / (q_max A) (A the friction area of all interfaces); and the drag of the open pack at t = 0
  (its heat power at the initial state) must already be within the limit.

The fastest lock-up itself (t_max) has a bound here, the lock-up of a step to the pressure that
applies the clutch hardest (:meth:`~clutchocp.optimal.problem.EngagementOCP.fastest_lockup`), and
an exact value from a minimum-time solve where the end conditions ask more than a step gives
(:mod:`clutchocp.optimal.strategy`).
"""

import casadi as ca
import numpy as np
from scipy.linalg import expm

from ..engagement.edges import check_contact_capacity, zero_gap_pressure
from ..errors import ModelError, PhysicalRangeError

FILM_FLOOR = 0.02         # films >= FILM_FLOOR x sigma where the contact cannot carry the pressure limit at zero gap


def film_floor(film, plate_pressure):
    """Smallest film thickness the optimisation allows [m]: :data:`FILM_FLOOR` sigma if the contact
    cannot carry ``plate_pressure`` [Pa] at that film (the films could reach the model's edge, or come
    within 2 % of sigma of it: a user's clutch whose contact carried 1.501 MPa at zero gap under a
    1.5 MPa limit settled at h = 3e-4 sigma), else 0."""
    if film.contact_model == "none":
        return 0.0
    return FILM_FLOOR * film.sigma if float(film.contact_force(FILM_FLOOR * film.sigma)) / film.area < plate_pressure \
        else 0.0


def plate_force(model, pressure):
    """Force on the pack face [N] at a settled command ``pressure`` [Pa], the piston at the kiss point.

    Without a piston the pressure presses the pack face (``actuation.area``, else the plate area);
    with one, its drive force (pressure and springs) at the kiss point: an upper bound of the
    settled force, as the films close the springs take a little more (pressure-applied) or give a
    little less (spring-applied).
    """
    if not model.has_piston:
        return pressure * (model.scene.get("actuation.area") or model.film.area)
    return float(model.drive_force(pressure, model.travel))


def spring_applied(model):
    """True for a spring-applied piston (the pressure releases the clutch)."""
    return model.has_piston and model.scene.variant("piston") == "spring_applied"


def hardest_command(model, p_max):
    """The command that presses the pack hardest [Pa]: the pressure limit, or 0 for a spring-applied piston."""
    return 0.0 if spring_applied(model) else p_max


def usable_pressure(model, p_max):
    """The command that presses the pack hardest while the contact can carry its settled plate
    pressure at the film floor [Pa]: :func:`hardest_command`, or where that presses harder than the
    contact carries at zero gap, the command whose plate force is the contact's at the film floor."""
    p = hardest_command(model, p_max)
    film = model.film
    floor = film_floor(film, plate_force(model, p) / film.area)
    if floor == 0.0:
        return p
    target = float(film.contact_force(floor))
    F0 = plate_force(model, 0.0)
    slope = plate_force(model, 1.0) - F0                 # the plate force is affine in the pressure [N/Pa]
    return float(np.clip((target - F0) / slope, 0.0, p_max))


def own_profile_within_contact(scene, model, p_max):
    """The scene whose own pressure profile starts the optimiser, and a note where it is not ``scene``'s.

    A scene's own profile may press the pack harder than its asperity contact carries at zero gap: its
    run is refused before it starts (:func:`~clutchocp.engagement.edges.check_contact_capacity`), while
    commands the contact can carry may still lock the clutch (the holding capacity is checked by
    :func:`check_pack`). The optimiser's baseline is then the same profile with its pressures held
    within the contact: at most :func:`usable_pressure` (the command whose settled plate pressure the
    contact carries at the film floor), or for a spring-applied piston at least that oil pressure.

    Parameters
    ----------
    scene : clutchocp.scene.Scene
    model : clutchocp.engagement.model.EngagementModel
        The scene's model (its film law and piston).
    p_max : float
        The pressure limit [Pa].

    Returns
    -------
    (clutchocp.scene.Scene, str or None)
        The scene to simulate as the baseline and, if its pressures were changed, one line saying how.

    Raises
    ------
    PhysicalRangeError
        A pressure table (``actuation.model = "table"``) that presses harder than the contact carries:
        one line naming the capacity (the table is the user's to change).
    """
    try:
        check_contact_capacity(scene)
        return scene, None
    except PhysicalRangeError as err:
        refusal = err
    if scene.variant("actuation") == "table":
        raise PhysicalRangeError(f"scene '{scene.name}': {refusal}") from None
    usable = usable_pressure(model, p_max)
    pick = max if spring_applied(model) else min
    keys = ("actuation.pressure", "actuation.initial_pressure")
    held = scene.with_overrides({key: pick(scene.value(key), usable) for key in keys})
    try:
        capacity, _ = check_contact_capacity(held)
    except PhysicalRangeError:
        raise PhysicalRangeError(f"scene '{scene.name}': {refusal}") from None
    side = "at least" if spring_applied(model) else "at most"
    note = (f"the scene's own profile (actuation.pressure {scene.value('actuation.pressure') / 1e6:.4g} MPa) presses "
            f"harder than the contact carries at zero gap ({capacity.pressure_Pa / 1e6:.4g} MPa); the baseline is "
            f"that profile {side} {usable / 1e6:.4g} MPa, the command whose plate pressure the contact carries at "
            f"a film of {FILM_FLOOR:g} sigma")
    return held, note


def lock_state(model):
    """The model's state at lock-up as far as the locked torque depends on it: the initial state with
    both sides at the common speed (a prescribed input: its speed; a held output: rest; two
    inertias: the speed conserving their angular momentum)."""
    x = model.initial_state.copy()
    s = model.scene
    if model.input_inertia and model.output_inertia:
        I_in, I_out = s.value("driveline.input_inertia"), s.value("driveline.output_inertia")
        common = (I_in * s.value("driveline.input_speed") + I_out * s.value("driveline.output_speed")) / (I_in + I_out)
        x[model.index["w_in"]] = x[model.index["w_out"]] = common
    elif model.output_inertia:
        x[model.index["w_out"]] = s.value("driveline.input_speed")
    elif model.input_inertia:
        x[model.index["w_in"]] = 0.0
    return x


def locked_torque_at_lock(model):
    """Torque the locked driveline carries [N m] at :func:`lock_state` (with a compliant shaft, at the
    initial state: its twist at lock-up is not known before the engagement)."""
    state = model.initial_state if model.compliant else lock_state(model)
    return float(ca.Function("locked", [model.x], [model.locked_torque()])(state))


def holding_capacity(model, pressure):
    """Static capacity of the pack [N m] at the settled command ``pressure`` and what bounds it.

    Returns
    -------
    (float, float, float, bool)
        The capacity mu_s F_c r_eff n_driving, the plate pressure the command gives (force over the
        friction area) [Pa], the contact's pressure at the film floor [Pa] and whether that contact
        limit (rather than the command) sets the capacity.
    """
    film = model.film
    plate = plate_force(model, pressure) / film.area
    floor = film_floor(film, plate)
    contact = np.inf if film.contact_model == "none" else float(film.contact_force(floor)) / film.area
    carried = min(max(plate, 0.0), contact)
    return film.mu_static * carried * film.area * film.r_eff * model.n_driving, plate, contact, contact < plate


def check_pack(ocp):
    """Refuse a scene whose pack cannot be applied or cannot hold the locked torque (see the module
    notes): the kiss point, the pressure limit, the contact at the film floor."""
    model, film, scene = ocp.model, ocp.model.film, ocp.scene
    name = scene.name
    if model.has_piston and not spring_applied(model) and model.travel > 0:
        kiss = -plate_force(model, 0.0)               # the return springs' force at the kiss point [N]
        area = scene.value("piston.area")
        if ocp.p_max * area <= kiss:
            raise ModelError(f"scene '{name}': piston: the return springs need {kiss / area / 1e6:.4g} MPa to reach "
                             f"the pack (the kiss point), actuation.max_pressure is {ocp.p_max / 1e6:.4g} MPa: the "
                             f"piston never reaches the pack; raise actuation.max_pressure above "
                             f"{kiss / area / 1e6:.4g} MPa or lower piston.spring_preload")
    capacity, plate, contact, by_contact = holding_capacity(model, hardest_command(model, ocp.p_max))
    if model.has_piston and plate <= 0:
        raise ModelError(f"scene '{name}': piston: {ocp.apply_label()} presses the pack with no force (the springs "
                         f"give {plate * film.area:.4g} N at the kiss point); raise piston.spring_preload")
    needed = abs(ocp.lock_torque) * (1 + ocp.lock_margin)
    if capacity >= needed:
        return
    demand = (f"the locked driveline needs {abs(ocp.lock_torque):.4g} N m ({needed:.4g} N m with the "
              f"{100 * ocp.lock_margin:g} % lock margin)")
    per_force = film.mu_static * film.area * film.r_eff * model.n_driving      # capacity per plate pressure [N m/Pa]
    how = (f"mu_s {film.mu_static:.3g}, {model.n_driving} interfaces, r_eff {film.r_eff * 1e3:.4g} mm")
    if by_contact:
        raise ModelError(
            f"scene '{name}': contact capacity: the asperities carry at most {contact / 1e6:.4g} MPa at a film of "
            f"{FILM_FLOOR:g} sigma (the model's edge is zero gap), a static capacity of {capacity:.4g} N m ({how}), "
            f"below what {demand}: the clutch cannot hold at a positive film; "
            f"raise roughness.sigma_*, roughness.asperity_density or contact.E_equiv, or add plates.n_interfaces")
    want = needed / per_force                                           # plate pressure that would hold [Pa]
    if not model.has_piston:
        p_need = want * film.area / (scene.get("actuation.area") or film.area)
    elif not spring_applied(model):
        area = scene.value("piston.area")
        p_need = (want * film.area - plate_force(model, 0.0)) / area
    else:
        p_need = None
    fix = (f"raise actuation.max_pressure to at least {p_need / 1e6:.4g} MPa" if p_need is not None else
           "raise piston.spring_preload or piston.spring_stiffness (the springs apply this clutch)")
    raise ModelError(f"scene '{name}': pressure limit: at {ocp.apply_label()} the pack holds at most {capacity:.4g} N m "
                     f"({how}), {demand}: no command locks this clutch; {fix} "
                     f"or add plates.n_interfaces")


# -- energy and heat ---------------------------------------------------------------------------
def lockup_energy_bound(model, t_max):
    """Least energy any lock-up by ``t_max`` [s] dissipates [J] (see the module notes), or None for a
    compliant output shaft (its twist stores energy the bound does not count)."""
    if model.compliant:
        return None
    s = model.scene
    w_in = s.value("driveline.input_speed")
    w_out = s.value("driveline.output_speed") if model.output_inertia else 0.0
    w_rel = w_in - w_out
    T_in = s.value("driveline.input_torque") if model.input_inertia else 0.0
    if model.input_inertia and model.output_inertia:
        I_in, I_out = s.value("driveline.input_inertia"), s.value("driveline.output_inertia")
        I_eq = I_in * I_out / (I_in + I_out)
        loads = _load_range(model, w_out, w_in)
        drive = min(I_eq * (T_in / I_in + T / I_out) for T in loads)
    elif model.output_inertia:            # prescribed input speed: the output's inertia alone
        I_eq = s.value("driveline.output_inertia")
        drive = min(_load_range(model, w_out, w_in))
    else:                                 # output held: the input's inertia alone
        I_eq = s.value("driveline.input_inertia")
        drive = T_in
    bound = 0.5 * I_eq * w_rel**2
    if drive < 0:
        bound += drive * w_rel * t_max if np.isfinite(t_max) else -np.inf
    return max(bound, 0.0)


def _load_range(model, w_lo, w_hi):
    """Load torques [N m] at speeds across [w_lo, w_hi] (their least bounds the load's work)."""
    fn = ca.Function("load", [model.x], [ca.SX(model.load_torque(model.state("w_out")))]) \
        if model.output_inertia else None
    if fn is None:
        return [0.0]
    x = model.initial_state.copy()
    out = []
    for w in np.linspace(w_lo, w_hi, 41):
        x[model.index["w_out"]] = w
        out.append(float(fn(x)))
    return out


def thermal_response(model):
    """The thermal part as a linear system: (free response T_free(t), impulse response g(t)) of the
    interface temperature [degC, K/J] as functions of time [s], or None if it has no thermal part
    or its equations are not linear in the temperatures and the heat."""
    thermal = model.thermal
    if not thermal.present:
        return None
    names = [name for name, _, _ in thermal.state_specs]
    T = ca.vertcat(*[thermal.symbols[n] for n in names])
    q = ca.SX.sym("q")
    rates = thermal.rates(q)
    f = ca.vertcat(*[rates[n] for n in names])
    out = ca.SX(thermal.interface_temperature())
    z = ca.vertcat(T, q)
    if ca.depends_on(ca.jacobian(ca.vertcat(f, out), z), z):
        return None
    fn = ca.Function("thermal", [z], [f, ca.jacobian(f, T), ca.jacobian(f, q), out, ca.jacobian(out, T)])
    T0 = np.array([value for _, _, value in thermal.state_specs], float)
    f0, A, b, out0, c = (np.array(v, float) for v in fn(np.append(T0, 0.0)))
    b, c = b.ravel(), c.ravel()
    # dT/dt = f0 + A (T - T0) + b q: the free response from T0 and the response to a heat impulse
    n = T0.size
    aug = np.zeros((n + 1, n + 1))
    aug[:n, :n], aug[:n, n] = A, f0.ravel()

    def free(t):
        return float(out0.ravel()[0] + c @ (expm(aug * t)[:n, n]))

    def impulse(t):
        return float(c @ expm(A * t) @ b)

    return free, impulse


def temperature_bound(model, energy, t_lo, t_hi):
    """Least peak interface temperature of any lock-up between ``t_lo`` and ``t_hi`` [s] that releases
    ``energy`` [J] (see the module notes) [degC]; None without a linear thermal part."""
    response = thermal_response(model)
    if response is None or energy is None:
        return None
    free, impulse = response
    times = np.linspace(t_lo, t_hi, 25) if np.isfinite(t_hi) and t_hi > t_lo else [t_lo]
    return min(free(t) + energy * impulse(t) for t in times)


def initial_heat_power(ocp):
    """Heat power released at the interfaces at t = 0 [W] (the open pack's drag at the initial state)."""
    mode = ocp.model.modes[ocp.model.initial_mode()]
    if "interface_heat_power_W" not in mode.outputs:
        return None
    fn = ca.Function("heat0", [ocp.model.x, ocp.u], [mode.outputs["interface_heat_power_W"]])
    return float(fn(ocp.model.initial_state, ocp.scene.value("actuation.initial_pressure")))


def check_heat(ocp, t_max, t_lo):
    """Refuse heat limits that no lock-up between ``t_lo`` (the fastest) and ``t_max`` [s] can meet."""
    limits = dict(ocp.heat_limits)
    if not limits:
        return
    name, model = ocp.scene.name, ocp.model
    energy = lockup_energy_bound(model, t_max)
    area_mm2 = model.n * model.film.area * 1e6
    if "interface_temperature_C" in limits and energy is not None:
        limit = limits["interface_temperature_C"]
        least = temperature_bound(model, energy, t_lo, t_max)
        if least is not None and least > limit:
            raise ModelError(f"scene '{name}': temperature limit: a lock-up dissipates at least {energy:.4g} J (the "
                             f"slip energy of the driveline's inertias), which heats the interface to at least "
                             f"{least:.4g} degC by lock-up; --max-temperature must be at least {least:.4g} degC for "
                             f"this clutch (it is {limit:.4g} degC)")
    if "interface_heat_power_W" in limits:
        q_max = limits["interface_heat_power_W"]
        start = initial_heat_power(ocp)
        if start is not None and start > q_max:
            raise ModelError(f"scene '{name}': specific-power limit: the open pack's drag already releases "
                             f"{start / area_mm2:.4g} W/mm^2 at t = 0; --max-specific-power must be at least "
                             f"{start / area_mm2:.4g} W/mm^2 for this clutch (it is {q_max / area_mm2:.4g} W/mm^2)")
        if energy is not None and energy / q_max > t_max:
            raise ModelError(f"scene '{name}': specific-power limit: a lock-up dissipates at least {energy:.4g} J over "
                             f"{area_mm2:.5g} mm^2 of friction area, which at {q_max / area_mm2:.4g} W/mm^2 takes at "
                             f"least {energy / q_max:.4g} s, longer than t_max = {t_max:.4g} s; --max-specific-power "
                             f"must be at least {energy / (area_mm2 * t_max):.4g} W/mm^2 for this clutch, or --t-max "
                             f"at least {energy / q_max:.4g} s")
