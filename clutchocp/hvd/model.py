"""The hydro-viscous drive of a scene as a semi-explicit index-1 DAE in CasADi.

The input shaft turns at a constant speed w_in; the output (inertia J) drives a fan/pump load
T_L = k w |w| (k from the rated point) plus a load-torque input. Control oil at pressure p acts
on the piston against the springs (Liao Eq. 15); the force left over presses the plate pack,
whose n films carry it by squeeze, inlet, centrifugal, groove and asperity loads and transmit
viscous and asperity torque. A proportional valve follows the pressure command with a lag.

    states    w       output speed [rad/s]
              p       valve (control-oil) pressure [Pa]
              h_k     film thickness on the lands [m], k = 1 (uniform films) or 1..n (Liao films)
    algebraic q_k     squeeze flux (dh_k/dt) / h_k^3 [1/(m^2 s)]: the rate at which film k carries
                      its load (the Reynolds squeeze load is proportional to it, so it scales well)
    inputs    p_cmd   pressure command [Pa]
              load_torque  load torque added to the fan law [N m] (disturbance)

    dw/dt   = (sum_k T_k(h_k, w_in - w) - k w|w| - load_torque) / J
    dp/dt   = (p_cmd - p) / tau_v
    dh_k/dt = h_k^3 q_k
    0       = W_film(h_k, h_k^3 q_k) - W_k,   W_1 = F_close - F_m(h_1),  W_{k+1} = W_k - F_m(h_{k+1})

The closing force on the pack (Liao Eq. 15, x_z = total film thickness, F_l the centrifugal
force of the rotating control oil on the piston):

* ``hvd.model = "spring_applied"`` (Liao's synchronous HVC): the springs close the pack and the
  pressure opens it, F_close = N k (x0 + x_z) - p A - F_l;
* ``"pressure_applied"`` (Cui's rig): the pressure closes the pack against return springs that
  are compressed by x0 with the pack open (total clearance x_open), F_close = p A + F_l -
  N k (x0 + x_open - x_z).

Uniform films (no [hvc] part): every film carries the same force and has the same thickness, so
one film state stands for all n (x_z = n h, torque n T). With [hvc] every film is a state and
each plate is held back in its spline by Liao's static friction F_m = K3 (K2/h + 1/(h + h_a))
(Liao Eq. 10-11, "trailing" film as in :mod:`clutchocp.physics.hvc`), balanced by the groove
load F4 = K1 / (h^3 + K2 (h + h_a)^3) (Liao Eq. 9) plus the other film loads (Liao Eq. 12-13,
generalised with the asperity load). K3 = f pi eta (w_in - w)(r2^4 - r1^4) / ((1 + K2) d) and
K1 = K3 / (K3/K1) with Liao's ratio K3/K1 (``hvc.friction_ratio``).

The piston and plates are massless (their axial modes are far faster than the squeeze, valve
and output dynamics) and the squeeze load is that of a plain annulus (PHYSICS.md); radial
grooves would shorten the squeeze paths, so the film dynamics here are on the slow side.
"""

import math

import casadi as ca
import numpy as np

from ..errors import ModelError
from ..physics import hvc
from ..physics.backend import fabs
from ..physics.squeeze_film import squeeze_geometry
from ..simulation.model import HybridModel, Mode
from .films import HvdFilm

INPUTS = ("p_cmd", "load_torque")


class HvdModel:
    """The HVD DAE of a scene (see the module docstring).

    Parameters
    ----------
    scene : clutchocp.scene.Scene
        A scene of kind "hvd".
    smooth : bool
        Smooth forms of the switching laws (default: needed for exact Jacobians and Newton).

    Attributes
    ----------
    x, z, u : dict of name -> casadi.SX
        States, algebraic variables and inputs (unscaled SI).
    ode, alg : casadi.SX
        Right-hand sides, in the order of ``x`` and ``z``.
    outputs : dict of name -> casadi.SX
        Named quantities (torques, forces, films ...).
    hybrid : clutchocp.simulation.HybridModel
        One mode, "run", for :func:`clutchocp.simulation.simulate`.
    """

    def __init__(self, scene, smooth=True):
        if scene.kind != "hvd":
            raise ModelError(f"scene '{scene.name}' is a {scene.kind} scene; the HVD model needs kind = 'hvd'")
        self.scene = scene
        self.smooth = smooth
        self._read_driveline(scene)
        self._read_actuation(scene)
        self.film = HvdFilm(scene, smooth=smooth, slip_width=1e-3 * self.w_in)
        self.n = scene.value("plates.n_interfaces")
        self.nonuniform = scene.has("hvc")
        self.n_states_film = self.n if self.nonuniform else 1
        if self.nonuniform:
            self._read_hvc(scene)
        self.film_scale = self.film.sigma if self.film.has_roughness else 1e-5
        self._build()

    # -- scene ------------------------------------------------------------------------------
    def _read_driveline(self, s):
        if s.value("driveline.input") != "prescribed_speed":
            raise ModelError("driveline.input: the HVD model takes a constant input speed ('prescribed_speed')")
        if s.value("driveline.output") != "inertia":
            raise ModelError("driveline.output: the HVD model needs an output inertia ('inertia')")
        self.w_in = s.value("driveline.input_speed")
        if self.w_in <= 0:
            raise ModelError("driveline.input_speed: must be > 0 for an HVD")
        self.J = s.value("driveline.output_inertia")
        variant = s.variant("load")
        if variant == "quadratic":
            self.rated_torque = s.value("load.rated_torque")
            self.rated_speed = s.value("load.rated_speed")
            self.load_coefficient = self.rated_torque / self.rated_speed**2
            self.constant_load = 0.0
        elif variant == "constant":
            self.load_coefficient, self.constant_load = 0.0, s.value("load.torque")
            self.rated_torque, self.rated_speed = self.constant_load, self.w_in
        else:
            raise ModelError(f"load.model = '{variant}': the HVD model takes 'quadratic' (fan/pump) or 'constant'")

    def _read_actuation(self, s):
        self.orientation = s.variant("hvd")
        R1, R2 = s.value("hvd.cylinder_r_inner"), s.value("hvd.cylinder_r_outer")
        if R1 >= R2:
            raise ModelError(f"hvd.cylinder_r_inner = {R1:g} m must be smaller than hvd.cylinder_r_outer = {R2:g} m")
        self.cylinder_radii = (R1, R2)
        self.piston_area = math.pi * (R2**2 - R1**2)                       # Liao Eq. 15, F_y = p A
        self.spring_rate = s.value("hvd.spring_stiffness") * s.value("hvd.spring_count")
        self.spring_preload = s.value("hvd.spring_preload")
        self.open_clearance = s.get("hvd.open_clearance")
        self.control_oil_radius = s.get("hvd.control_oil_radius")
        self.valve_time_constant = s.value("hvd.valve_time_constant")
        self.p_min, self.p_max = s.value("hvd.pressure_min"), s.value("hvd.pressure_max")
        if self.p_min >= self.p_max:
            raise ModelError(f"hvd.pressure_min = {self.p_min:g} Pa must be below hvd.pressure_max = {self.p_max:g} Pa")

    def _read_hvc(self, s):
        if not s.has("groove"):
            raise ModelError("[groove]: Liao's unequal films ([hvc]) need the radial grooves (Liao Eq. 9-13)")
        self.spline_friction = s.get("hvd.spline_friction")
        if self.spline_friction is None:
            raise ModelError("hvd.spline_friction: missing, required with [hvc] (Liao Eq. 10 friction coefficient f)")
        self.effective_diameter = s.get("plates.effective_diameter")
        if self.effective_diameter is None:
            raise ModelError("plates.effective_diameter: missing, required with [hvc] (Liao Eq. 10 d)")
        self.friction_ratio = s.value("hvc.friction_ratio")

    # -- parts --------------------------------------------------------------------------------
    def cylinder_force(self, w):
        """Force of the rotating control oil on the piston, F_l [N] (Liao Eq. 15).

        F_l = (pi/4) rho w^2 (R2^2 - R1^2)(R2^2 + R1^2 - 2 r0^2), the integral of
        rho w^2 (r^2 - r0^2)/2 over the piston annulus R1..R2. Liao prints the plate radii r1, r2;
        the oil acts on the cylinder annulus (Table 2: R1 = 80 mm, R2 = 112 mm, r0 = 42 mm), so
        the cylinder radii are used. The cylinder turns with the output (Liao's omega_2).
        """
        if self.control_oil_radius is None:
            return 0.0
        R1, R2 = self.cylinder_radii
        r0 = self.control_oil_radius
        return math.pi / 4 * self.film.rho * w**2 * (R2**2 - R1**2) * (R2**2 + R1**2 - 2 * r0**2)

    def closing_force(self, p, total_film, w):
        """Force pressing the plate pack, F_close [N] (Liao Eq. 15, see the module docstring)."""
        hydraulic = p * self.piston_area + self.cylinder_force(w)
        if self.orientation == "spring_applied":
            return self.spring_rate * (self.spring_preload + total_film) - hydraulic
        return hydraulic - self.spring_rate * (self.spring_preload + self.open_clearance - total_film)

    def load_torque(self, w, extra=0.0):
        """Load torque on the output, k w |w| + constant + extra [N m]."""
        return self.load_coefficient * w * fabs(w) + self.constant_load + extra

    def liao_coefficients(self, w_rel):
        """(K1, K3) of Liao Eq. 9 and 11 at relative speed w_rel [N m^3, N m]."""
        f, d, K2 = self.spline_friction, self.effective_diameter, self.film.angle_ratio
        r1, r2 = self.film.r1, self.film.r2
        K3 = f * math.pi * self.film.eta * w_rel * (r2**4 - r1**4) / ((1 + K2) * d)   # Liao Eq. 11
        return K3 / self.friction_ratio, K3

    def spline_friction_force(self, h, K3):
        """Liao's static friction force on a plate, F_m = K3 (K2/h + 1/(h + h_a)) [N] (Liao Eq. 11)."""
        return K3 * hvc.friction_load_factor(h, self.film.groove_depth, self.film.angle_ratio)

    def film_forces(self, h, p, w):
        """Force each modelled film carries at balance, W_k [N] (Liao Eq. 12 chain, Eq. 15).

        Parameters
        ----------
        h : list of film thicknesses (one for uniform films) [m].
        p : control pressure [Pa].
        w : output speed [rad/s].

        Returns
        -------
        list of W_k and the groove coefficient K1 (0 for uniform films).
        """
        total = sum(h) if self.nonuniform else self.n * h[0]
        F = self.closing_force(p, total, w)
        if not self.nonuniform:
            return [F], 0.0
        K1, K3 = self.liao_coefficients(self.w_in - w)
        forces = []
        for hk in h:
            F = F - self.spline_friction_force(hk, K3)
            forces.append(F)
        return forces, K1

    # -- DAE --------------------------------------------------------------------------------
    def _build(self):
        m = self.n_states_film
        w, p = ca.SX.sym("w"), ca.SX.sym("p")
        h = [ca.SX.sym(f"h_{k + 1}") for k in range(m)]
        q = [ca.SX.sym(f"q_{k + 1}") for k in range(m)]
        r = [h[k] ** 3 * q[k] for k in range(m)]            # film rates dh_k/dt
        p_cmd, T_d = ca.SX.sym("p_cmd"), ca.SX.sym("load_torque")
        self.t = ca.SX.sym("t")
        self.x = {"w": w, "p": p, **{f"h_{k + 1}": h[k] for k in range(m)}}
        self.z = {f"q_{k + 1}": q[k] for k in range(m)}
        self.u = {"p_cmd": p_cmd, "load_torque": T_d}

        w_rel = self.w_in - w
        forces, K1 = self.film_forces(h, p, w)
        alg = [self.film.load(h[k], r[k], self.w_in, w, groove_coefficient=K1) - forces[k] for k in range(m)]
        multiplicity = 1 if self.nonuniform else self.n
        T_visc = multiplicity * sum(self.film.viscous_torque(hk, w_rel) for hk in h)
        T_cont = multiplicity * sum(self.film.contact_torque(hk, w_rel) for hk in h)
        T_clutch = T_visc + T_cont
        T_load = self.load_torque(w, T_d)
        ode = [(T_clutch - T_load) / self.J, (p_cmd - p) / self.valve_time_constant] + r
        self.ode = ca.vertcat(*ode)
        self.alg = ca.vertcat(*alg)

        out = {"w_out_rad_s": w, "slip_rad_s": w_rel, "pressure_Pa": p, "pressure_command_Pa": p_cmd}
        for k in range(m):
            out[f"film_{k + 1}_m"] = h[k]
        out["film_ratio_1"] = h[0] / self.film.sigma if self.film.has_roughness else h[0] * 0
        out["total_film_m"] = sum(h) if self.nonuniform else self.n * h[0]
        out["viscous_torque_Nm"] = T_visc
        out["contact_torque_Nm"] = T_cont
        out["clutch_torque_Nm"] = T_clutch
        out["load_torque_Nm"] = T_load
        out["contact_pressure_Pa"] = self.film.contact_pressure(h[0]) + 0 * w
        out["pack_force_N"] = forces[0] + 0 * w
        out["output_acceleration_rad_s2"] = ode[0]
        out["pressure_rate_Pa_s"] = ode[1]
        self.outputs = out

        force_scale = self.p_max * self.piston_area
        x_nominal = {"w": self.w_in, "p": self.p_max, **{f"h_{k + 1}": self.film_scale for k in range(m)}}
        # the squeeze load is about (3 pi / 2) eta G q (PHYSICS.md): q of the force scale is O(1)
        squeeze = 1.5 * math.pi * self.film.eta * squeeze_geometry(self.film.r1, self.film.r2)
        z_nominal = {f"q_{k + 1}": force_scale / squeeze for k in range(m)}
        self.x_nominal = np.array([x_nominal[name] for name in self.x])
        self.z_nominal = np.array([z_nominal[name] for name in self.z])
        self.alg_nominal = np.full(m, force_scale)
        self.mode = Mode("run", self.x, list(ode), z=self.z, alg=alg, outputs=out,
                         x_nominal=x_nominal, z_nominal=z_nominal, alg_nominal=self.alg_nominal)
        self.hybrid = HybridModel([self.mode], u=self.u, t=self.t)

        xv, zv, uv = self.vector("x"), self.vector("z"), self.vector("u")
        self.f_ode = ca.Function("hvd_ode", [xv, zv, uv], [self.ode])
        self.f_alg = ca.Function("hvd_alg", [xv, zv, uv], [self.alg])
        names = list(out)
        self.output_names = names
        self.f_outputs = ca.Function("hvd_outputs", [xv, zv, uv], [ca.vertcat(*[out[n] for n in names])])
        # the residuals are linear in z: z = -(d alg/dz)^-1 alg(z = 0)
        jac_z = ca.jacobian(self.alg, zv)
        alg_0 = ca.substitute(self.alg, zv, ca.DM.zeros(m))
        self._f_rates = ca.Function("hvd_rates", [xv, uv], [-ca.solve(jac_z, alg_0)])

    # -- helpers ----------------------------------------------------------------------------
    def vector(self, which):
        """Column of the symbols of ``"x"``, ``"z"`` or ``"u"`` in model order."""
        return ca.vertcat(*getattr(self, which).values())

    @property
    def state_names(self):
        return list(self.x)

    @property
    def algebraic_names(self):
        return list(self.z)

    @property
    def film_names(self):
        return [n for n in self.x if n.startswith("h_")]

    def rates(self, x, u):
        """Squeeze fluxes z solving the algebraic equations at (x, u) (they are linear in z) [1/(m^2 s)]."""
        return np.array(self._f_rates(x, u), dtype=float).ravel()

    def evaluate_many(self, X, U):
        """Outputs at many (state, input) rows at once: {output name: array} (numeric, SI)."""
        X, U = np.atleast_2d(X).T, np.atleast_2d(U).T
        Z = self._f_rates.map(X.shape[1])(X, U)
        Y = np.array(self.f_outputs.map(X.shape[1])(X, Z, U), dtype=float)
        return {name: Y[i] for i, name in enumerate(self.output_names)}

    def evaluate(self, x, u):
        """(dx/dt, z, outputs dict) at state ``x`` and input ``u`` (numeric, SI)."""
        x = np.asarray(x, float)
        z = self.rates(x, u)
        dx = np.array(self.f_ode(x, z, u), dtype=float).ravel()
        y = np.array(self.f_outputs(x, z, u), dtype=float).ravel()
        return dx, z, dict(zip(self.output_names, y))
