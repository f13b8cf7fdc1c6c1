"""Summary measures of an engagement run: lock-up, torque jump, peak torque and jerk, energy balance,
Zhang's response times and the heat numbers, each read from a hybrid result (JSON-ready)."""

import numpy as np

from ..simulation.locate import crossing_time, peak
from .model import ENERGY_TERMS


def pieces(result):
    """Label of each sample: the index of its segment (one mode between two events)."""
    return np.concatenate([np.full(seg.t.size, i) for i, seg in enumerate(result.segments)])


def _first_crossing(t, y, level, piece=None):
    """First time y reaches ``level``, located on the local cubic of the samples (or None)."""
    return crossing_time(t, y, level, piece=piece)


def pressure_rise_time(model, result, fraction):
    """First time [s] the pressure has risen by ``fraction`` of the way to the set pressure (located on
    the local cubic of the samples), or None (also when the set pressure is not above the initial one)."""
    return pressure_rise_times(model, result, (fraction,))[fraction]


def pressure_rise_times(model, result, fractions, piece=None):
    """:func:`pressure_rise_time` of each of ``fractions`` (a dict ``{fraction: time [s] or None}``),
    the pressure samples read once; ``piece``: :func:`pieces` of ``result`` if already at hand."""
    p_set = model.scene.value("actuation.pressure")
    p0 = model.scene.value("actuation.initial_pressure")
    if p_set <= p0:       # no rise (a release: spring-applied clutch): Zhang's response times do not apply
        return dict.fromkeys(fractions)
    rise = (result["pressure_Pa"] - p0) / (p_set - p0)
    piece = pieces(result) if piece is None else piece
    return {fraction: _first_crossing(result.t, rise, fraction, piece) for fraction in fractions}


def _slipping(result):
    """Boolean mask of the output samples taken while the clutch slips."""
    return np.concatenate([np.full(seg.t.size, not str(seg.mode).endswith("locked")) for seg in result.segments])


def response_times(model, result, *, rise=None, piece=None, slipping=None):
    """Zhang 2021's response times [s], with the torque response measured to the largest slipping torque.

    Pressure response: from 10 % to 90 % of the set pressure. Torque response (peak-based): from
    50 % of the set pressure to 90 % of the largest slipping torque (viscous + asperity). Zhang's
    own definition, to the stable torque, is :func:`stable_torque_response`. ``rise``
    (:func:`pressure_rise_times` of 0.1, 0.5 and 0.9), ``piece`` (:func:`pieces`) and ``slipping``
    save reading them again when the caller has them.
    """
    t = result.t
    piece = pieces(result) if piece is None else piece
    rise = pressure_rise_times(model, result, (0.1, 0.5, 0.9), piece) if rise is None else rise
    t10, t50, t90 = rise[0.1], rise[0.5], rise[0.9]
    pressure_time = t90 - t10 if t10 is not None and t90 is not None else None
    slipping = _slipping(result) if slipping is None else slipping
    torque_time = None
    if t50 is not None and slipping.any():
        t_slip, piece_slip = t[slipping], piece[slipping]
        torque = np.abs(result["total_torque_Nm"][slipping])
        t90_torque = _first_crossing(t_slip, torque, 0.9 * peak(t_slip, torque, piece_slip)[0], piece_slip)
        if t90_torque is not None:
            torque_time = t90_torque - t50
    return pressure_time, torque_time


def stable_torque_response(model, result, *, t50=False, piece=None, slipping=None):
    """Zhang 2021's torque response to the stable transmitted torque (Zhang Section 3, Fig. 2).

    Zhang defines the torque response time as the time from 50 % of the set pressure to the
    torque reaching 90 % of its *stable* value. Once the film has drained (Zhang Section 2,
    'mechanical contact stage') the transmitted torque is the asperity friction torque alone, so
    the stable torque is the asperity torque at the end of the slip (the last slipping sample:
    just before lock-up, or at the end of the run), which for a massless pack at the set
    pressure P_o is f_c P_o A_n r_eff per film; the response is the first time the asperity
    torque reaches 90 % of it. The total torque is not used: its viscous part can exceed the
    stable torque from the start of the squeeze (zhang2021 at 1000 rad/s: 43 N m on the open gap
    against 53 N m stable), which would make the time negative and blind to the contact.
    ``t50`` (the 50 % pressure time, None if never), ``piece`` and ``slipping`` save reading them
    again when the caller has them.

    Returns
    -------
    (stable_torque, response_time) : [N m], [s]; each None if it does not exist (no slip, no
    asperity torque, or the pressure never reaches 50 %).
    """
    slipping = _slipping(result) if slipping is None else slipping
    if not slipping.any():
        return None, None
    t, contact_torque = result.t[slipping], np.abs(result["contact_torque_Nm"][slipping])
    stable = float(contact_torque[-1])
    piece = pieces(result) if piece is None else piece
    t50 = pressure_rise_times(model, result, (0.5,), piece)[0.5] if t50 is False else t50
    if stable <= 0 or t50 is None:
        return (stable if stable > 0 else None), None
    t90 = _first_crossing(t, contact_torque, 0.9 * stable, piece[slipping])
    return stable, (t90 - t50 if t90 is not None else None)


def energy_balance(model, result):
    """Energy bookkeeping of the run [J] and its relative error.

    work in (source + hydraulic - load + spring released) = kinetic energy change + contact
    (elastic) storage + dissipation (slip, film, seal, splines, shaft damping, impact); the spring
    energy includes the twist of a compliant shaft. With a [thermal] part the slip and film
    dissipation is closed through the plates instead: it must equal the heat stored in them plus
    the heat convected to the oil (so the balance checks the temperature states too).
    """
    E = {name: result.final(name) if name in model.energy_terms else 0.0 for name in ENERGY_TERMS}
    ke = result["kinetic_energy_J"]
    spring = result["spring_energy_J"]
    work_in = E["E_source"] + E["E_hydraulic"] - E["E_load"] + (spring[0] - spring[-1])
    interfaces = E["E_slip"] + E["E_film"]
    dissipated = interfaces + E["E_seal"] + E["E_spline"] + E["E_shaft"] + E["E_impact"]
    stored = (ke[-1] - ke[0]) + E["E_contact"]
    out = {"work_in_J": work_in, "kinetic_energy_change_J": ke[-1] - ke[0], "contact_storage_J": E["E_contact"],
           "dissipated_J": dissipated}
    closure = dissipated
    if model.thermal.present:
        out["heat_stored_J"] = float(result["stored_heat_J"][-1] - result["stored_heat_J"][0])
        out["heat_to_oil_J"] = E["E_convection"]
        closure = dissipated - interfaces + out["heat_stored_J"] + out["heat_to_oil_J"]
    scale = max(abs(work_in), abs(ke[-1] - ke[0]), abs(dissipated), 1e-12)
    out["rel_error"] = abs(work_in - stored - closure) / scale
    return out


def summary_outputs(model):
    """The outputs :func:`summarize` reads, which it evaluates together (one call per segment,
    :meth:`~clutchocp.simulation.result.SimulationResult.load`)."""
    names = ["pressure_Pa", "total_torque_Nm", "contact_torque_Nm", "output_jerk_rad_s3", "kinetic_energy_J",
             "spring_energy_J", "interface_heat_power_W"]
    for i in range(model.n):
        names += [f"film_{i + 1}_mean_pressure_Pa", f"film_{i + 1}_fluid_force_N"]
    if model.thermal.present:
        names += ["stored_heat_J", "interface_temperature_C", "friction_plate_temperature_C"]
    return names


def summarize(model, result, wall_time, options, method):
    """The numbers of an engagement (JSON-ready; units in the key names)."""
    result.load(summary_outputs(model))
    locks = [e for e in result.events if e.name == "lockup" and e.target.endswith("locked")]
    locked_at_end = str(result.final_mode).endswith("locked")
    lock = locks[-1] if locks and locked_at_end else None
    jump = None
    t_lock = float(lock.t) if lock is not None else None
    if lock is not None:
        jump = float(lock.outputs_after["total_torque_Nm"] - lock.outputs_before["total_torque_Nm"])
    elif all(str(seg.mode).endswith("locked") for seg in result.segments):
        t_lock = float(result.t[0])          # locked from the start (equal speeds held): no slip, no jump
    energy = energy_balance(model, result)
    piece, slipping = pieces(result), _slipping(result)
    rise = pressure_rise_times(model, result, (0.1, 0.5, 0.9), piece)
    pressure_time, torque_time = response_times(model, result, rise=rise, piece=piece, slipping=slipping)
    stable_torque, stable_torque_time = stable_torque_response(model, result, t50=rise[0.5], piece=piece,
                                                               slipping=slipping)
    jerk = result["output_jerk_rad_s3"]
    summary = {
        "scene": model.scene.name,
        "engagement_time_s": t_lock,
        "lockup_torque_jump_Nm": jump,
        "peak_torque_Nm": peak(result.t, np.abs(result["total_torque_Nm"]), piece)[0],
        "peak_jerk_rad_s3": float(np.max(np.abs(jerk[np.isfinite(jerk)]))),
        "dissipated_energy_J": energy["dissipated_J"],
        "energy_balance_rel_error": energy["rel_error"],
        "energy": energy,
        "torque_response_time_s": torque_time,
        "stable_torque_Nm": stable_torque,
        "torque_response_time_stable_s": stable_torque_time,
        "pressure_response_time_s": pressure_time,
        "events": [{"name": e.name, "time_s": float(e.t), "from": e.source, "to": e.target} for e in result.events],
        "final_mode": str(result.final_mode),
        "wall_time_s": wall_time,
        "n_states": model.n_states,
        "solver": {"method": method, **{k: v for k, v in options.as_dict().items() if k != "idas_options"},
                   "statistics": result.stats},
    }
    summary.update(film_pressure_summary(model, result))
    summary.update(thermal_summary(model, result))
    summary["warnings"] = list(model.scene.warnings)
    return summary


def film_pressure_summary(model, result):
    """The lowest mean film pressure of the run (JSON-ready; units in the key names).

    The mean gauge pressure of a film is its fluid load over the area the oil acts on (the
    ``film_k_mean_pressure_Pa`` columns); the model limits it smoothly at ``film.cavitation_pressure``
    (:mod:`clutchocp.physics.cavitation`), so a value near that limit says the films were pulled apart.
    """
    lowest = None
    for i in range(model.n):
        pressure = np.asarray(result[f"film_{i + 1}_mean_pressure_Pa"])
        k = int(np.argmin(pressure))
        if lowest is None or pressure[k] < lowest[0]:
            lowest = (float(pressure[k]), i + 1, k)
    value, film, k = lowest
    return {"min_film_pressure_Pa": value, "min_film_pressure_film": film,
            "min_film_pressure_time_s": float(result.t[k]),
            "min_film_pressure_fluid_force_N": float(result[f"film_{film}_fluid_force_N"][k]),
            "film_cavitation_pressure_Pa": model.film.cavitation_pressure}


def thermal_summary(model, result):
    """Heat numbers a clutch is sized by (JSON-ready; units in the key names).

    The friction area is the nominal area of all interfaces, n_interfaces x pi (r2^2 - r1^2);
    the interface heat is the slip and squeeze-film dissipation. The temperatures need a
    [thermal] part.
    """
    area_mm2 = model.n * model.film.area * 1e6
    heat = result["interface_heat_power_W"]
    out = {"friction_area_mm2": area_mm2,
           "interface_heat_J": float(result.final("E_slip") + result.final("E_film")),
           "peak_specific_power_W_mm2": float(np.max(heat)) / area_mm2}
    out["specific_energy_J_mm2"] = out["interface_heat_J"] / area_mm2
    if model.thermal.present:
        # The interface is the lining's surface (and the lumped separator in contact with it); the
        # friction plates' bulk is their heat-capacity-weighted mean, lining and core.
        temperature, bulk = result["interface_temperature_C"], result["friction_plate_temperature_C"]
        k = int(np.argmax(temperature))
        out.update({"peak_interface_temperature_C": float(temperature[k]),
                    "peak_interface_temperature_time_s": float(result.t[k]),
                    "peak_friction_plate_temperature_C": float(np.max(bulk)),
                    "peak_core_temperature_C": float(np.max(result["T_core"])),
                    "final_interface_temperature_C": float(temperature[-1]),
                    "final_friction_plate_temperature_C": float(bulk[-1]),
                    "final_separator_temperature_C": float(temperature[-1]),
                    "final_plate_temperatures_C": {name: float(result.final(name)) for name in model.thermal.names}})
    return out
