"""Assemble the engagement DAE of a scene in CasADi, mode by mode.

The state vector is the same in every mode (so a mode switch is a reset of values, not of
shape); a part that the scene does not declare adds no state:

    [x0, v0]          piston position and velocity            (scene has a piston)
    h_1 .. h_n        film thicknesses, scaled by sigma        (always)
    v_1 .. v_n        plate velocities                         (pack.model = "masses")
    p_valve           valve output pressure                    (actuation.model = "valve_lag")
    w_in              input speed                              (driveline.input = "inertia")
    w_out             output speed                             (driveline.output = "inertia")
    theta_shaft       output shaft twist                       (driveline.shaft_stiffness given)
    T_interface, T_lining_1 .. T_lining_{N-1}, T_core
                      plate temperatures [degC]: interface, inside the lining, core  (a [thermal] part)
    E_*               energy accumulators for the balance check: source, hydraulic, slip, film,
                      contact, impact (always); load (a load on an output inertia), seal (a
                      piston), spline (splines), shaft (a compliant shaft), convection (a
                      [thermal] part: heat passed from the plates to the oil)

Modes are (axial phase) x (rotation): axial phase "approach" (piston travelling freely, plates at
rest; only with a piston and free travel) or "pressing"; rotation "slip_forward" (w_in > w_out),
"slip_reverse" or "locked"; a mode is named "<axial>_<rotation>". Events move between them: impact (Bao Eq. 22), lock-up and unlock.
Every mode also watches each film gap: a gap reaching zero is the model's edge (the asperity contact
could not carry the load, or there is none), so the event ``film_closed`` ends the run with a
:class:`~clutchocp.errors.ModelEdgeError` instead of a result (:mod:`clutchocp.engagement.edges`).

The piston (or its stand-in, which presses the pack with the pressure force p A) and the pack (plate
masses or massless) are parts picked once from the scene (:mod:`clutchocp.engagement.piston`,
:mod:`clutchocp.engagement.pack`), as the thermal part is (:mod:`clutchocp.engagement.thermal`): each
brings its states, equations, outputs and events, so the builder asks no "is there a piston?".
"""

from dataclasses import dataclass

import casadi as ca
import numpy as np

from ..errors import ModelError
from ..simulation.derivative import time_derivative
from ..simulation.model import Event, HybridModel, Mode
from .actuation import Actuation, read_table
from .films import FilmLaw
from .pack import Pressing, pack_part
from .piston import piston_part
from .thermal import plate_thermal

ENERGY_TERMS = ("E_source", "E_hydraulic", "E_load", "E_slip", "E_film", "E_contact", "E_seal", "E_spline", "E_shaft",
                "E_impact", "E_convection")
ROTATIONS = ("slip_forward", "slip_reverse", "locked")


@dataclass
class Turning:
    """The driveline in one rotation mode: torques [N m], output acceleration [rad/s^2], the hub's
    torque balance ``alg`` (a compliant shaft while slipping), shaft damping power [W], rates."""

    T_in: object
    T_load: object
    T_clutch: object
    a_out: object
    alg: list
    shaft_power: object
    T_shaft: object
    rates: dict


class EngagementModel:
    """The hybrid engagement model of a scene.

    Parameters
    ----------
    scene : clutchocp.scene.Scene
        An engagement scene.
    smooth : bool
        Smooth forms of the switching laws (for the optimal-control problem).
    pressure_command : casadi.SX, optional
        A scalar symbol that replaces the scene's pressure profile as the commanded pressure
        [Pa] (the control of the optimal-control problem). With the ``valve_lag`` actuation it
        drives the valve state; otherwise it is the pressure itself.
    """

    def __init__(self, scene, smooth=False, pressure_command=None):
        if scene.kind != "engagement":
            raise ModelError(f"scene '{scene.name}' is a {scene.kind} scene; an engagement needs kind = 'engagement'")
        self.shaft_stiffness = scene.get("driveline.shaft_stiffness")
        self.compliant = self.shaft_stiffness is not None
        if self.compliant and scene.value("driveline.shaft_damping") <= 0:
            raise ModelError("driveline.shaft_damping: must be > 0 with a compliant output shaft (the clutch hub "
                             "between clutch and shaft is massless, so its speed is set by the damping)")
        # Speed of the massless clutch hub at the shaft end: an algebraic variable while slipping.
        self.w_hub = ca.SX.sym("w_hub") if self.compliant else None
        self.load_table = None
        if scene.variant("load") == "table":
            data = read_table(scene.value("load.file"), "load.file")
            self.load_table = ca.interpolant("load_table", "linear", [data[:, 0]], data[:, 1])
            self.load_range = (float(data[0, 0]), float(data[-1, 0]))
        self.scene = scene
        self.thermal = plate_thermal(scene)
        self.film = FilmLaw(scene, smooth=smooth, temperature=self.thermal.interface_temperature())
        self.actuation = Actuation(scene, command=pressure_command)
        self.n = scene.value("plates.n_interfaces")
        self.n_driving = 1 if scene.get("driveline.driving_films", "all") == "first" else self.n
        self.H0 = scene.value("pack.initial_gap")
        self.sigma = self.film.sigma if self.film.sigma > 0 else self.H0 / 10
        self.plate_masses = np.asarray(scene.get("pack.plate_masses", np.zeros(self.n)), dtype=float)
        # The piston (or the stand-in that presses the pack with p A) and the pack (plate masses or
        # massless), picked once: each brings its own states, equations, outputs and events.
        self.piston = piston_part(scene, self._pack_area())
        self.pack = pack_part(scene, self.n, self.plate_masses)
        if self.piston.present and not self.pack.has_masses and scene.has("spline"):
            # behind a piston a massless pack's films close at speeds summing to the piston's; with spline
            # friction they carry unequal loads and, once cavitated, that split is implicit in the face force
            raise ModelError("spline: spline friction is modelled for a massless pack pressed by the pressure "
                             "directly (no [piston]), or leave out [spline]")
        self.input_inertia = scene.value("driveline.input") == "inertia"
        self.output_inertia = scene.value("driveline.output") == "inertia"
        self.t = ca.SX.sym("t")
        self._build_states()
        self.modes = {}
        self.axial_phases = self.piston.axial_phases
        for axial in self.axial_phases:
            for rotation in ROTATIONS:
                mode = self._build_mode(axial, rotation)
                self.modes[mode.name] = mode
        inputs = {"pressure_command": pressure_command} if pressure_command is not None else None
        self.hybrid = HybridModel(list(self.modes.values()), u=inputs, t=self.t)

    @property
    def has_piston(self):
        """True if the scene has a piston (read-only: the piston part was picked from the scene)."""
        return self.piston.present

    @property
    def masses(self):
        """True if the plates have masses (``pack.model = "masses"``; read-only)."""
        return self.pack.has_masses

    @property
    def travel(self):
        """Free travel of the piston before it meets plate 1 [m] (0 without a piston; read-only)."""
        return self.piston.travel

    # -- states -------------------------------------------------------------------------------
    def _build_states(self):
        names, nominal, initial = [], [], []

        def add(name, scale, value):
            names.append(name)
            nominal.append(scale)
            initial.append(value)

        s = self.scene
        # Plate and piston velocities: the pack closes its gaps H0 within about a tenth of the run
        # (bao2020: the squeeze stage takes ~0.1 s of 3 s). With H0 / t_end instead, the absolute
        # tolerance on the (quasi-static, tiny) slip-phase velocities was so tight that IDAS fell to
        # order 1 with an error-test failure at nearly every step (bao2020 with viscosity / 20:
        # 56 700 steps, energy balance 7e-6; at 12 000 rpm: lock time 1.4e-5 off at rtol 1e-8);
        # with this scale: 1 700 / 2 400 steps, energy balance <= 7e-8, lock time within 4e-8.
        v_scale = self.H0 / (0.1 * max(s.value("simulation.t_end"), 1e-6))
        for spec in self.piston.state_specs(self.H0, v_scale):
            add(*spec)
        for i in range(self.n):
            add(f"h_{i + 1}", self.sigma, self.H0)
        for spec in self.pack.state_specs(v_scale):
            add(*spec)
        if self.actuation.has_state:
            add("p_valve", max(s.value("actuation.pressure"), 1e5), s.value("actuation.initial_pressure"))
        w_scale = max(s.value("driveline.input_speed"), s.value("driveline.output_speed"), 1.0)
        if self.input_inertia:
            add("w_in", w_scale, s.value("driveline.input_speed"))
        if self.output_inertia:
            add("w_out", w_scale, s.value("driveline.output_speed"))
        if self.compliant:
            torque_scale = max(abs(s.value("driveline.input_torque")), 10.0)
            add("theta_shaft", torque_scale / self.shaft_stiffness, 0.0)
        for spec in self.thermal.state_specs:
            add(*spec)
        # Energy accumulators of the parts the scene has (a load, a piston seal, splines, a shaft)
        present = {"E_load": self.output_inertia and s.variant("load") not in ("", "none"),
                   "E_seal": "E_seal" in self.piston.energy_terms, "E_spline": s.has("spline"), "E_shaft": self.compliant,
                   "E_convection": self.thermal.present}
        self.energy_terms = tuple(name for name in ENERGY_TERMS if present.get(name, True))
        for name in self.energy_terms:
            add(name, 1.0, 0.0)
        self.state_names = tuple(names)
        self.nominal = np.array(nominal, dtype=float)
        self.initial_state = np.array(initial, dtype=float)
        self.x = ca.vertcat(*[self.thermal.symbols.get(name, ca.SX.sym(name)) for name in names])
        self.index = {name: i for i, name in enumerate(names)}

    def state(self, name):
        """The CasADi symbol of a named state (unscaled, SI)."""
        return self.x[self.index[name]]

    @property
    def n_states(self):
        """Number of physical states (energy accumulators excluded)."""
        return len(self.state_names) - len(self.energy_terms)

    # -- parts --------------------------------------------------------------------------------
    def speeds(self):
        """(w_in, w_out): states, or the prescribed/fixed values."""
        s = self.scene
        w_in = self.state("w_in") if self.input_inertia else s.value("driveline.input_speed")
        w_out = self.state("w_out") if self.output_inertia else 0.0
        return w_in, w_out

    def load_torque(self, w_out):
        """Load torque on the output [N m] (opposes forward rotation)."""
        model = self.scene.variant("load")
        if model in ("", "none"):
            return 0.0
        if model == "constant":
            return self.scene.value("load.torque")
        if model == "quadratic":
            k = self.scene.value("load.rated_torque") / self.scene.value("load.rated_speed") ** 2
            return k * w_out * ca.fabs(w_out)
        lo, hi = self.load_range      # table of torque against speed, held constant beyond its ends
        return self.load_table(ca.fmin(ca.fmax(w_out, lo), hi))

    def pressure(self):
        p_state = self.state("p_valve") if self.actuation.has_state else None
        return self.actuation.pressure(self.t, p_state)

    def piston_position(self, axial):
        """Piston travel [m] in axial phase ``axial`` (:meth:`~clutchocp.engagement.piston.Piston.position`)."""
        return self.piston.position(self.state, axial, self.n, self.H0)

    def drive_force(self, p, x0):
        """Net axial force on the piston from oil pressure and springs [N] (before pack and seal)."""
        return self.piston.drive_force(p, x0)

    def spring_energy(self, x0):
        """Energy in the piston springs at travel ``x0`` [J]."""
        return self.piston.spring_energy(x0)

    def seal_coefficient(self):
        """Viscous seal friction coefficient eta L pi D / psi [N s/m] (Bao Eq. 16)."""
        return self.piston.seal_coefficient()

    # -- one mode -----------------------------------------------------------------------------
    def _build_mode(self, axial, rotation):
        """The mode ``<axial>_<rotation>``: its equations, outputs and events."""
        s, film, n = self.scene, self.film, self.n
        p = self.pressure()
        w_in, w_out = self.speeds()
        w_clutch = self.clutch_side_speed(rotation)
        w_rel = w_in - w_clutch
        h = [self.state(f"h_{i + 1}") for i in range(n)]
        loads = [film.film_load(hi, w_in, w_clutch) for hi in h]
        direction = {"slip_forward": 1.0, "slip_reverse": -1.0, "locked": 0.0}[rotation]
        # Films that transmit torque: all of them, or only the first (Bao Eq. 26 as printed); the
        # others still carry axial load.
        driving = h[:self.n_driving]
        idle = [0.0] * (n - self.n_driving)
        T_visc = [film.viscous_torque(hi, w_rel) for hi in driving] + idle
        T_cont = [film.contact_torque(hi, w_rel, direction) for hi in driving] + idle
        T_film = [tv + tc for tv, tc in zip(T_visc, T_cont)]
        capacity = sum(film.static_capacity(hi) for hi in driving)

        # Axial dynamics: the piston alone while it travels freely, then the pack it presses
        drive = self.piston.drive(self.state, axial, p, n, self.H0)
        if axial == "approach":     # plates at rest: each film carries its static fluid load
            pressing = Pressing([0.0] * n, drive.free_travel(), 0.0, drive.hydraulic_power(0.0, 0.0),
                                fluid=[load.fluid(0.0) for load in loads])
        else:
            pressing = self.pack.press(self.state, drive, loads, T_film)
        rate = {name: 0.0 for name in self.state_names}
        rate.update(drive.rates)
        rate.update(pressing.rates)
        for i in range(n):
            rate[f"h_{i + 1}"] = pressing.dh[i]
        if self.actuation.has_state:
            rate["p_valve"] = self.actuation.state_rate(self.t, self.state("p_valve"))
        turning = self._rotation(rotation, T_film, w_in, w_out, w_clutch)
        rate.update(turning.rates)
        rate.update(self._energy_rates(rotation, loads, pressing, drive, turning, w_in, w_out, w_rel))
        heat_power = rate["E_slip"] + rate["E_film"]          # released at the friction interfaces
        rate.update(self.thermal.rates(heat_power))

        alg = turning.alg
        x_dict = {name: self.state(name) for name in self.state_names}
        z_dict = {"w_hub": self.w_hub} if alg else None
        jerk = time_derivative(ca.SX(turning.a_out), x_dict, [rate[name] for name in self.state_names],
                               z=z_dict, alg=alg or None, t=self.t)
        out = self._outputs(rotation, p, h, loads, (w_in, w_out, w_clutch), (T_visc, T_cont, capacity),
                            pressing, drive, turning, rate, heat_power, jerk)
        events = self._events(axial, rotation, direction, w_rel, capacity)
        torque_scale = max(abs(s.value("driveline.input_torque")), 10.0)
        w_scale = max(s.value("driveline.input_speed"), s.value("driveline.output_speed"), 1.0)
        return Mode(f"{axial}_{rotation}", x_dict, [rate[name] for name in self.state_names],
                    z=z_dict, alg=alg, outputs=out, events=events,
                    x_nominal=dict(zip(self.state_names, self.nominal)),
                    z_nominal={"w_hub": w_scale} if alg else None, alg_nominal=[torque_scale] if alg else None,
                    z_guess={"w_hub": s.value("driveline.output_speed")} if alg else None)

    def _rotation(self, rotation, T_film, w_in, w_out, w_clutch):
        """Torques and accelerations of the driveline in ``rotation`` (slipping or locked)."""
        s = self.scene
        T_in = s.value("driveline.input_torque") if self.input_inertia else 0.0
        T_load = self.load_torque(w_out) if self.output_inertia else 0.0
        I_in = s.get("driveline.input_inertia")
        I_out = s.get("driveline.output_inertia")
        alg, shaft_power, T_shaft, rates = [], 0.0, None, {}
        if self.compliant:
            c_shaft = s.value("driveline.shaft_damping")
            T_shaft = self.shaft_stiffness * self.state("theta_shaft") + c_shaft * (w_clutch - w_out)
            rates["theta_shaft"] = w_clutch - w_out
            shaft_power = c_shaft * (w_clutch - w_out) ** 2
            if rotation == "locked":
                T_clutch = T_shaft                         # hub locked to the input
            else:
                T_clutch = sum(T_film)
                alg = [T_clutch - T_shaft]                 # torque balance of the massless hub
            a_in = (T_in - T_clutch) / I_in if self.input_inertia else 0.0
            a_out = (T_shaft - T_load) / I_out if self.output_inertia else 0.0
        elif rotation == "locked":
            if self.input_inertia and self.output_inertia:
                w_dot = (T_in - T_load) / (I_in + I_out)
                T_clutch = T_load + I_out * w_dot          # torque the locked clutch carries
            elif self.input_inertia:                       # output held: input stays at rest
                w_dot, T_clutch = 0.0, T_in
            else:                                          # prescribed input speed
                w_dot, T_clutch = 0.0, T_load
            a_in = a_out = w_dot
        else:
            T_clutch = sum(T_film)
            a_in = (T_in - T_clutch) / I_in if self.input_inertia else 0.0
            a_out = (T_clutch - T_load) / I_out if self.output_inertia else 0.0
        if self.input_inertia:
            rates["w_in"] = a_in
        if self.output_inertia:
            rates["w_out"] = a_out
        return Turning(T_in, T_load, T_clutch, a_out, alg, shaft_power, T_shaft, rates)

    def _energy_rates(self, rotation, loads, pressing, drive, turning, w_in, w_out, w_rel):
        """Rates of the energy accumulators (work in = kinetic + stored + dissipated) [W].

        The film power is the fluid load the pack carries (tension-limited) times the closing speed:
        a cavitated film dissipates the work that pulls it open (the model keeps no cavity volume
        whose refilling would return it), so the balance closes with the limited load.
        """
        dh = pressing.dh
        source_power = turning.T_in * w_in if self.input_inertia else turning.T_clutch * w_in
        film_fluid_power = sum(f * (-dhi) for f, dhi in zip(pressing.fluid, dh))
        contact_power = sum(load.contact * (-dhi) for load, dhi in zip(loads, dh))
        return {"E_source": source_power,
                "E_hydraulic": pressing.hydraulic_power,
                "E_load": turning.T_load * w_out,
                "E_slip": turning.T_clutch * w_rel if rotation != "locked" else 0.0,
                "E_film": film_fluid_power,
                "E_contact": contact_power,
                "E_seal": drive.seal_power,
                "E_spline": pressing.spline_power,
                "E_shaft": turning.shaft_power,
                "E_impact": 0.0}

    def _outputs(self, rotation, p, h, loads, speeds, torques, pressing, drive, turning, rate, heat_power, jerk):
        """Named outputs of a mode (every column of the time series besides the states)."""
        n, dh = self.n, pressing.dh
        w_in, w_out, w_clutch = speeds
        T_visc, T_cont, capacity = torques
        T_clutch = turning.T_clutch
        out = {"pressure_Pa": p}
        for i in range(n):
            out[f"h_{i + 1}_m"] = h[i]
        out.update(self._positions(h))
        out["w_in_rad_s"] = w_in
        out["w_out_rad_s"] = w_out
        if self.compliant:
            out["w_hub_rad_s"] = w_clutch
            out["shaft_torque_Nm"] = turning.T_shaft
        out["viscous_torque_Nm"] = sum(T_visc) if rotation != "locked" else 0.0
        out["contact_torque_Nm"] = sum(T_cont) if rotation != "locked" else T_clutch
        out["total_torque_Nm"] = T_clutch
        out["static_capacity_Nm"] = capacity
        out["contact_force_N"] = sum(load.contact for load in loads) / n
        for i in range(n):
            # per film: the oil's share of the film load W = g(K (-dh/dt) + S) + C (Bao Eq. 12-13,
            # tension-limited), its mean gauge pressure over the area the oil acts on, and the closing
            # speed; int sum(force x speed) dt is E_film, so the CSV alone closes the balance
            out[f"film_{i + 1}_fluid_force_N"] = pressing.fluid[i]
            out[f"film_{i + 1}_mean_pressure_Pa"] = loads[i].mean_pressure(pressing.fluid[i])
            # the mean pressure of the averaged Reynolds film at the same closing speed without the
            # tension limit: below film.cavitation_pressure the film has cavitated
            out[f"film_{i + 1}_reynolds_pressure_Pa"] = loads[i].mean_pressure(loads[i].K * (-dh[i]) + loads[i].S)
            out[f"film_{i + 1}_closing_speed_m_s"] = -dh[i]
        out["pack_force_N"] = pressing.face_force
        out.update(drive.outputs())
        out["output_acceleration_rad_s2"] = turning.a_out
        out["output_jerk_rad_s3"] = jerk
        out["dissipated_power_W"] = (rate["E_slip"] + rate["E_film"] + drive.seal_power + pressing.spline_power
                                     + turning.shaft_power)
        out["interface_heat_power_W"] = heat_power
        out.update(self.thermal.outputs())
        out["kinetic_energy_J"] = self._kinetic_energy()
        out["spring_energy_J"] = drive.spring_energy
        if self.compliant:
            out["spring_energy_J"] += 0.5 * self.shaft_stiffness * self.state("theta_shaft") ** 2
        return out

    def clutch_side_speed(self, rotation):
        """Speed of the clutch plates on the output side [rad/s]: the output speed, or with a
        compliant shaft the hub speed (algebraic while slipping, the input speed when locked)."""
        w_in, w_out = self.speeds()
        if not self.compliant:
            return w_out
        return w_in if rotation == "locked" else self.w_hub

    def locked_torque(self):
        """Torque the clutch must carry to keep both sides locked [N m], from the current state."""
        s = self.scene
        w_in, w_out = self.speeds()
        T_in = s.value("driveline.input_torque") if self.input_inertia else 0.0
        if self.compliant:     # locked hub: the clutch carries the shaft torque
            return self.shaft_stiffness * self.state("theta_shaft") + s.value("driveline.shaft_damping") * (w_in - w_out)
        if self.input_inertia and self.output_inertia:
            T_load = self.load_torque(w_out)
            I_in, I_out = s.value("driveline.input_inertia"), s.value("driveline.output_inertia")
            return T_load + I_out * (T_in - T_load) / (I_in + I_out)
        if self.input_inertia:
            return T_in
        return self.load_torque(w_out)

    def _events(self, axial, rotation, direction, w_rel, capacity):
        """Impact, lock-up and unlock events leaving the mode ``axial/rotation``."""
        events = []
        torque_scale = max(abs(self.scene.get("driveline.input_torque", 0.0)), 10.0)
        if axial == "approach":
            events.append(self.piston.impact_event(self.state, rotation, self.pack, self.H0))
        else:
            mode = f"{axial}_{rotation}"
            events += [Event("film_closed", self.state(f"h_{i + 1}"), mode, direction=-1, scale=self.sigma,
                             edge=f"film {i + 1} closed (gap h_{i + 1} = 0)") for i in range(self.n)]
        needed = self.locked_torque()
        margin = capacity - ca.fabs(needed)
        if rotation == "locked":
            for sign, target in ((1.0, "slip_forward"), (-1.0, "slip_reverse")):
                events.append(Event("unlock", margin, f"{axial}_{target}", direction=-1,
                                    guard=sign * needed, scale=torque_scale))
        else:
            w_scale = max(self.scene.value("driveline.input_speed"), 1.0)
            reverse = "slip_reverse" if rotation == "slip_forward" else "slip_forward"
            events.append(Event("lockup", direction * w_rel, f"{axial}_locked", direction=-1,
                                reset=self._lock_reset(), guard=margin, scale=w_scale))
            events.append(Event("lockup", direction * w_rel, f"{axial}_{reverse}", direction=-1,
                                guard=-margin, scale=w_scale))
        return events

    def _lock_reset(self):
        """Equal speeds at lock-up: the residual slip dw left by the event location (|dw| within the
        event tolerance) is removed as a plastic impact of the two sides that conserves angular
        momentum (the rotational analogue of Bao Eq. 22); its kinetic energy loss, second order in
        dw, goes to E_impact, and with a prescribed input speed the drive's work w_in I_out dw to
        E_source, so the energy balance closes exactly whatever the event tolerance.
        """
        if self.compliant:          # the hub locks to the input; the shaft keeps its twist
            return None
        E_impact = self.state("E_impact")
        if self.input_inertia and self.output_inertia:
            I_in, I_out = self.scene.value("driveline.input_inertia"), self.scene.value("driveline.output_inertia")
            w_in, w_out = self.state("w_in"), self.state("w_out")
            common = (I_in * w_in + I_out * w_out) / (I_in + I_out)
            loss = 0.5 * I_in * I_out / (I_in + I_out) * (w_in - w_out) ** 2
            return {"w_in": common, "w_out": common, "E_impact": E_impact + loss}
        if self.output_inertia:     # prescribed input speed: an input of infinite inertia
            I_out, w_in, w_out = self.scene.value("driveline.output_inertia"), self.scene.value(
                "driveline.input_speed"), self.state("w_out")
            return {"w_out": ca.SX(w_in), "E_source": self.state("E_source") + w_in * I_out * (w_in - w_out),
                    "E_impact": E_impact + 0.5 * I_out * (w_in - w_out) ** 2}
        I_in, w_in = self.scene.value("driveline.input_inertia"), self.state("w_in")   # output held at rest
        return {"w_in": ca.SX(0.0), "E_impact": E_impact + 0.5 * I_in * w_in**2}

    def _pack_area(self):
        return self.scene.get("actuation.area") or self.film.area

    def _positions(self, h):
        """Plate positions x_i from the films: x_n = H0 - h_n, x_i = H0 - h_i + x_{i+1} (Bao Eq. 13)."""
        x_next, out = 0.0, {}
        for i in reversed(range(self.n)):
            x_next = self.H0 - h[i] + x_next
            out[f"x_{i + 1}_m"] = x_next
        return out

    def _kinetic_energy(self):
        s = self.scene
        w_in, w_out = self.speeds()
        ke = 0.0
        if self.input_inertia:
            ke += 0.5 * s.value("driveline.input_inertia") * w_in**2
        if self.output_inertia:
            ke += 0.5 * s.value("driveline.output_inertia") * w_out**2
        for term in self.piston.kinetic_energy_terms(self.state) + self.pack.kinetic_energy_terms(self.state):
            ke += term
        return ke

    # -- mode logic -------------------------------------------------------------------------
    def initial_mode(self):
        """The mode at t = 0.

        Equal initial speeds start locked: the locked mode's unlock events, armed on entry, then
        switch at once to the slip direction the needed torque asks for if the static capacity
        cannot hold it (and otherwise the sides stay together). Starting to slip 'forward' at
        zero slip instead would let the friction torque act against the actual slip direction.
        """
        axial = "approach" if self.travel > 0 else "pressing"
        w_in, w_out = self.scene.value("driveline.input_speed"), self.scene.value("driveline.output_speed")
        if not self.output_inertia:
            w_out = 0.0
        if w_in == w_out:
            return f"{axial}_locked"
        return f"{axial}_{'slip_forward' if w_in > w_out else 'slip_reverse'}"
