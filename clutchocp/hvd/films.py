"""One oil film of a hydro-viscous drive: axial load and transmitted torque (SI units).

Every film of an HVD pack has the same plates, oil and roughness, so one :class:`HvdFilm`
serves them all. For a film of land thickness h it publishes

* the axial load W = (1 - A_c/A_n) W_fluid(h, dh_T/dt) + W_c(h) [+ F4(h) with Liao's grooves],
  linear in the squeeze rate (Reynolds squeeze + inlet + centrifugal, PHYSICS.md; Bao Eq. 12),
* the torque T = T_v + T_g + T_c: shear on the lands (Cui Eq. 9), shear over the radial grooves
  (the groove share of Liao Eq. 2) and asperity friction mu W_c r_eff (Cui Eq. 19).

Contact acts on the land (non-grooved) area A_n = psi pi (r2^2 - r1^2) only (Cui Eq. 16). With
[groove] the land share is psi = K2 / (1 + K2) (Liao Eq. 2, K2 = theta2/theta1); with no
roughness and no contact T_v + T_g is exactly Liao Eq. 2.

The model is meant for linearisation and Newton solves, so by default the smooth forms of the
switching laws are used (phi_fs cut-off at H = 7, the flow factor below H = 0.5, the clamp of the
Cui Eq. 18 pressure range, the direction of the asperity friction): ``smooth=True``.
"""

import math

from ..errors import ModelError
from ..physics import contact, friction, hvc, roughness, shear, squeeze_film
from ..physics.backend import fmax, fmin, if_else, softplus, tanh

# Cui 2019 Eq. 18 is fitted on 0.1-1 MPa (Table 1); outside, the pressure fed to it is clamped.
CUI_PRESSURE_RANGE = (0.1e6, 1.0e6)
_CLAMP_WIDTH = 0.01e6          # width of the smooth clamp [Pa]


def smooth_clamp(x, lo, hi, width):
    """``min(max(x, lo), hi)`` with softplus corners of the given width (error <= width ln 2)."""
    return lo + softplus(x - lo, width) - softplus(x - hi, width)


class HvdFilm:
    """Load and torque of one HVD film.

    Parameters
    ----------
    scene : clutchocp.scene.Scene
        An HVD scene (plates, oil, optional film, roughness, contact, friction, groove parts).
    smooth : bool
        Smooth forms of the switching laws (default; needed for exact Jacobians).
    slip_width : float
        Slip speed [rad/s] over which the asperity friction changes direction
        (``tanh(w_rel / slip_width)``); the HVD model sets it to 1e-3 of the input speed.
    """

    def __init__(self, scene, smooth=True, slip_width=0.1):
        self.smooth = smooth
        self.slip_width = slip_width
        self.r1 = scene.value("plates.r_inner")
        self.r2 = scene.value("plates.r_outer")
        self.area = math.pi * (self.r2**2 - self.r1**2)
        self.eta = scene.value("oil.viscosity")
        self.rho = scene.value("oil.density")
        self.inlet_pressure = scene.get("film.inlet_pressure", 0.0)
        self.centrifugal = scene.get("film.centrifugal", False)
        self.flow_factor = scene.get("film.flow_factor", "patir_cheng")
        self.grooved = scene.has("groove")
        self.groove_depth = scene.value("groove.depth") if self.grooved else 0.0
        self.angle_ratio = scene.value("groove.angle_ratio") if self.grooved else None
        land = scene.value("plates.land_fraction")
        if self.grooved:
            groove_land = self.angle_ratio / (1.0 + self.angle_ratio)      # theta2 / (theta1 + theta2)
            if land != 1.0 and abs(land - groove_land) > 1e-3:
                raise ModelError(f"plates.land_fraction = {land:g} contradicts groove.angle_ratio = "
                                 f"{self.angle_ratio:g} (land share K2/(1+K2) = {groove_land:.4f}); "
                                 "give one of them or make them agree")
            land = groove_land
        self.land_fraction = land
        self.shear_factors = scene.get("film.shear_factors", "table")
        self.land_area = land * self.area                                # Cui Eq. 16
        self.r_eff = contact.effective_radius(self.r1, self.r2, rule="cui")  # Cui Eq. 19
        self.has_roughness = scene.has("roughness") and scene.value("roughness.sigma") > 0
        if self.has_roughness:
            self.sigma = scene.value("roughness.sigma")
            # with only the combined roughness known both surfaces are taken equally rough (phi_fs = 0)
            self.sigma_1 = scene.get("roughness.sigma_1", self.sigma / math.sqrt(2))
            self.sigma_2 = scene.get("roughness.sigma_2", self.sigma / math.sqrt(2))
        else:
            self.sigma = self.sigma_1 = self.sigma_2 = 0.0
        self.contact_model = scene.variant("contact") if scene.has("contact") else "none"
        if self.contact_model not in ("none", "greenwood_tripp"):
            raise ModelError(f"contact.model = '{self.contact_model}': the HVD model takes 'greenwood_tripp' "
                             "or 'none' (the fractal load of Cui Eq. 10-17 is for the static analysis)")
        if self.contact_model != "none" and not self.has_roughness:
            raise ModelError("roughness: asperity contact needs a [roughness] part with sigma > 0")
        if self.contact_model == "greenwood_tripp":
            self.E = scene.value("contact.E_equiv")
            self.fit = scene.value("contact.fit")
            self.n0 = scene.value("contact.area_factor")
            self.n_a = scene.value("roughness.asperity_density")
            self.beta = scene.value("roughness.asperity_radius")
        self.friction_model = scene.variant("friction") if scene.has("friction") else "none"
        if self.contact_model != "none" and self.friction_model not in ("constant", "cui2019"):
            raise ModelError(f"friction.model = '{self.friction_model}': the HVD model takes 'constant' or "
                             "'cui2019' (Cui Eq. 18)")
        self.mu_constant = scene.value("friction.mu") if self.friction_model == "constant" else None

    # -- asperities ---------------------------------------------------------------------------
    def film_ratio(self, h):
        """H = h / sigma [-]."""
        return h / self.sigma

    def area_ratio(self, h):
        """Real contact area ratio A_c/A_n = pi^2 (n_a beta sigma)^2 F2(H) (Cui Eq. 3), at most 0.99."""
        if self.contact_model == "none":
            return 0.0
        ratio = contact.greenwood_tripp_area_ratio(self.film_ratio(h), self.n_a, self.beta, self.sigma, n0=self.n0)
        return fmin(ratio, 0.99)

    def contact_pressure(self, h):
        """Mean asperity pressure on the lands, K' E' F_5/2(H) (Greenwood-Tripp) [Pa]."""
        if self.contact_model == "none":
            return 0.0
        return contact.greenwood_tripp_pressure(self.film_ratio(h), self.E, self.n_a, self.beta, self.sigma,
                                                fit=self.fit, smooth=self.smooth)

    def contact_force(self, h):
        """Asperity load W_c = p_c A_n on the land area [N] (Cui Eq. 15-16)."""
        return self.contact_pressure(h) * self.land_area

    def mu(self, p_contact):
        """Asperity friction coefficient at mean contact pressure p [Pa] (constant, or Cui Eq. 18)."""
        if self.friction_model == "constant":
            return self.mu_constant
        lo, hi = CUI_PRESSURE_RANGE
        if self.smooth:
            p = smooth_clamp(p_contact, lo, hi, _CLAMP_WIDTH)
        else:
            p = fmin(fmax(p_contact, lo), hi)
        return friction.mu_cui2019(p)                                           # Cui Eq. 18

    # -- axial load ---------------------------------------------------------------------------
    def fluid_load(self, h, dh_dt, w_in, w_out):
        """Load of the oil film [N]: squeeze + inlet + centrifugal on the non-contact area (Bao Eq. 12).

        ``dh_dt`` is the rate of the nominal film; the Reynolds equation takes the rate of the
        average gap, dh_T/dt = Phi(H) dh/dt (Bao Eq. 10).
        """
        phi_r = 1.0
        gap_rate = 1.0
        if self.has_roughness:
            H = self.film_ratio(h)
            gap_rate = roughness.average_gap_derivative(h, self.sigma)
            if self.flow_factor == "patir_cheng":
                phi_r = squeeze_film.pressure_flow_factor(H, smooth=self.smooth)
        kw = {"phi_r": phi_r, "inlet_pressure": self.inlet_pressure}
        if self.centrifugal:
            kw.update(rho=self.rho, w1=w_in, w2=w_out)
        load = squeeze_film.film_load(h, gap_rate * dh_dt, self.eta, self.r1, self.r2, **kw)
        return (1.0 - self.area_ratio(h)) * load

    def load(self, h, dh_dt, w_in, w_out, groove_coefficient=0.0):
        """Total axial load of the film [N] (> 0 pushes the plates apart).

        Parameters
        ----------
        h : film thickness on the lands [m].
        dh_dt : its rate [m/s].
        w_in, w_out : speeds of the friction plate and the separator [rad/s].
        groove_coefficient : K1 of Liao Eq. 9 [N m^3]; 0 leaves out the groove load F4.
        """
        W = self.fluid_load(h, dh_dt, w_in, w_out) + self.contact_force(h)
        if self.grooved:
            W = W + groove_coefficient * hvc.groove_load_factor(h, self.groove_depth, self.angle_ratio)  # Liao Eq. 9
        return W

    # -- torque -------------------------------------------------------------------------------
    def viscous_torque(self, h, w_rel):
        """Shear torque on the lands (Cui Eq. 9) plus over the grooves (Liao Eq. 2) [N m]."""
        land = shear.viscous_torque(w_rel, h, self.eta, self.r1, self.r2, sigma_1=self.sigma_1,
                                    sigma_2=self.sigma_2, area_ratio=self.area_ratio(h),
                                    land_fraction=self.land_fraction, smooth=self.smooth,
                                    method=self.shear_factors)                            # Cui Eq. 9
        if not self.grooved:
            return land
        groove_share = 1.0 - self.land_fraction                                # theta1 / (theta1 + theta2)
        groove = (groove_share * math.pi * self.eta * w_rel * (self.r2**4 - self.r1**4)
                  / (2.0 * (h + self.groove_depth)))                            # Liao Eq. 2, groove term
        return land + groove

    def contact_torque(self, h, w_rel):
        """Asperity friction torque mu W_c r_eff, signed with the slip (Cui Eq. 19) [N m].

        The direction is ``tanh(w_rel / slip_width)`` (smooth) or ``sign(w_rel)`` (exact).
        """
        if self.contact_model == "none":
            return 0.0
        W = self.contact_force(h)
        if self.smooth:
            direction = tanh(w_rel / self.slip_width)
        else:
            direction = if_else(w_rel > 0, 1.0, if_else(w_rel < 0, -1.0, 0.0))
        return direction * self.mu(self.contact_pressure(h)) * W * self.r_eff      # Cui Eq. 19

    def torque(self, h, w_rel):
        """Total torque of the film [N m]."""
        return self.viscous_torque(h, w_rel) + self.contact_torque(h, w_rel)
