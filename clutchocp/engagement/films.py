"""The lubricated interfaces of a pack: squeeze-film load, asperity contact and torque per film.

Every film of a scene has the same plates, oil and roughness, so one ``FilmLaw`` serves all of
them; it publishes, for a film of thickness h, the load W = K (-dh/dt) + S carried by the film
(fluid + asperities) and the torque it transmits at a relative speed w_rel.

How the fluid and the asperities share the load is a model-form choice (``film.load_sharing``):

* ``"reduced"`` (default): the fluid pressure acts on the free area only, W = (1 - A_c/A_n) W_fluid
  + p_c A_n (Bao Eq. 12 and 27; Zhang Eq. 8 writes the same split with delta = A_c/A_n);
* ``"additive"``: the averaged Reynolds pressure is already a mean over the nominal area (Patir and
  Cheng's flow factors account for the asperities), so W = W_fluid + p_c A_n, the form of most
  mixed-lubrication engagement models.

The fluid load cannot pull the plates together with more than the cavitation pressure allows: its
mean gauge pressure over the area the oil acts on is limited to ``film.cavitation_pressure``
(:mod:`clutchocp.physics.cavitation`), so W = g(K (-dh/dt) + S_fluid) + C with the smooth limit g,
applied to the squeeze and centrifugal/inlet terms together; the contact load C is separate.
"""

import math
from dataclasses import dataclass

import casadi as ca
import numpy as np

from ..errors import ModelError
from ..physics import cavitation, contact, friction, roughness, shear, squeeze_film
from ..physics.backend import if_else, softplus
from ..physics.viscosity import OilViscosity

AREA_RATIO_CAP = 0.99           # largest real-area ratio: 1 % of the area is left to the oil
_AREA_CAP_WIDTH = 0.01          # width of its smooth corner [-]


@dataclass
class FilmLoad:
    """The axial load law of one film at its state (thickness, speeds): W(v) = g(K v + S) + C.

    v = -dh/dt is the closing speed [m/s]; g the tension limit of
    :func:`clutchocp.physics.cavitation.tension_limited_load`.

    Attributes
    ----------
    K : squeeze coefficient [N s/m] (the fluid's share of the area applied).
    S : static fluid load (centrifugal and inlet terms) [N].
    contact : asperity load [N].
    limit : tension limit L = p_cav x wetted area [N] (<= 0).
    width : width of the limit's smooth corner [N].
    wet_area : area the fluid pressure acts on [m^2].
    """

    K: object
    S: object
    contact: object
    limit: object
    width: object
    wet_area: object

    def fluid(self, v):
        """Fluid load at the closing speed ``v`` [N], its mean pressure limited at the cavitation pressure."""
        return cavitation.tension_limited_load(self.K * v + self.S, self.limit, self.width)

    def closing_speed(self, fluid):
        """Closing speed [m/s] at which the film carries the fluid load ``fluid`` [N] (inverse of :meth:`fluid`)."""
        return (cavitation.tension_limited_load_inverse(fluid, self.limit, self.width) - self.S) / self.K

    def mean_pressure(self, fluid):
        """Mean gauge pressure [Pa] of the fluid load ``fluid`` [N] over the area the oil acts on."""
        return fluid / self.wet_area

# Chen 2021 Eq. 5 is singular below 25 kPa and fitted for 0.2-2 MPa; Cui Eq. 18 is fitted for
# 0.1-1 MPa. Outside, the pressure fed to the law is clamped to the fitted range.
_CHEN_P_RANGE = (0.2e6, 2.0e6)
_CUI_P_RANGE = (0.1e6, 1.0e6)


class FilmLaw:
    """Load and torque of one film between a friction plate and a separator (SI units).

    Parameters
    ----------
    scene : clutchocp.scene.Scene
        An engagement scene (plates, oil, film, roughness, contact, friction parts).
    smooth : bool
        Use the smooth forms of the switching laws (for optimisation).
    temperature : casadi.SX, optional
        Interface temperature [deg C] published by the thermal part; the viscosity and Chen's
        friction law follow it. None: the scene's fixed temperatures.
    """

    def __init__(self, scene, smooth=False, temperature=None):
        self.smooth = smooth
        self.r1 = scene.value("plates.r_inner")
        self.r2 = scene.value("plates.r_outer")
        self.area = math.pi * (self.r2**2 - self.r1**2)
        self.r_eff = contact.effective_radius(self.r1, self.r2, rule="bao")  # Bao Eq. 25-26
        self.eta = OilViscosity(scene).dynamic(temperature) if temperature is not None else scene.value("oil.viscosity")
        self.temperature_C = temperature if temperature is not None else scene.get("friction.temperature_C")
        self.rho = scene.value("oil.density")
        self.land_fraction = scene.value("plates.land_fraction")
        self.shear_factors = scene.get("film.shear_factors", "table")
        self.permeability = scene.value("plates.lining_permeability")
        self.lining_thickness = scene.value("plates.lining_thickness")
        self.flow_factor = scene.get("film.flow_factor", "patir_cheng")
        self.centrifugal = scene.get("film.centrifugal", False)
        self.inlet_pressure = scene.get("film.inlet_pressure", 0.0)
        self.load_sharing = scene.get("film.load_sharing", "reduced")
        self.cavitation_pressure = scene.get("film.cavitation_pressure", -1e5)
        self.sigma = scene.value("roughness.sigma")
        # Per surface: sigma_1 of the friction plate (lining), sigma_2 of the separator; they set the
        # Patir-Cheng shear factor phi_fs (Cui Eq. 7: V_r1 - V_r2). The pressure flow factor phi_r
        # of isotropic roughness (gamma = 1) and the contact laws depend on the combined sigma only.
        # With only the combined roughness known, both surfaces are taken equally rough (phi_fs = 0).
        self.sigma_1 = scene.get("roughness.sigma_1", self.sigma / math.sqrt(2))
        self.sigma_2 = scene.get("roughness.sigma_2", self.sigma / math.sqrt(2))
        self.n_a = scene.get("roughness.asperity_density")
        self.beta = scene.get("roughness.asperity_radius")
        self.contact_model = scene.variant("contact")
        if self.contact_model == "fractal_mb":
            raise ModelError("contact.model = 'fractal_mb' is for static analyses; an engagement needs "
                             "greenwood_tripp, zhang_gw or none")
        self.E = scene.get("contact.E_equiv")
        self.fit = scene.get("contact.fit", "exact")
        self.contact_force_form = scene.get("contact.force", "nominal")
        self.n0 = scene.get("contact.area_factor", 1.0)
        self.friction_model = scene.variant("friction")
        self.scene = scene
        self.mu_static = scene.get("friction.static_coefficient")
        if self.mu_static is None:
            self.mu_static = float(self.mu(0.0, 0.5e6, theta=100.0))   # Chen Eq. 5 at v = 0 does not depend on theta

    # -- asperities ---------------------------------------------------------------------------
    def area_ratio(self, h):
        """Real contact area ratio A_c/A_n [-] (0 without contact), below 0.99.

        The Greenwood-Tripp and Greenwood-Williamson ratios are not bounded by 1 (with Bao's
        data the GT ratio passes 1 near H = 0); the cap keeps 1 % of the area for the oil. It is a
        smooth minimum, 0.99 - softplus(0.99 - ratio, 0.01) = ratio - softplus(ratio - 0.99, 0.01)
        (the second form below the cap, free of cancellation for small ratios; the first above it,
        never above 0.99 in doubles): C-infinity, at most 0.99, and equal to the ratio within
        0.01 exp(-(0.99 - ratio)/0.01) (1e-19 at a ratio of 0.6).
        """
        if self.contact_model == "none":
            return 0.0
        H = h / self.sigma
        if self.contact_model == "greenwood_tripp":
            ratio = contact.greenwood_tripp_area_ratio(H, self.n_a, self.beta, self.sigma, n0=self.n0)
        else:
            ratio = contact.zhang_area_ratio(H, self.n_a, self.beta, self.sigma)
        return if_else(ratio < AREA_RATIO_CAP, ratio - softplus(ratio - AREA_RATIO_CAP, _AREA_CAP_WIDTH),
                       AREA_RATIO_CAP - softplus(AREA_RATIO_CAP - ratio, _AREA_CAP_WIDTH))

    def contact_force(self, h):
        """Asperity load over the nominal area [N]."""
        if self.contact_model == "none":
            return 0.0
        H = h / self.sigma
        if self.contact_model == "greenwood_tripp":
            # Greenwood-Tripp: nominal asperity pressure K' E' F_5/2(H), over the nominal area. Bao
            # Eq. 20 multiplies it once more by the area ratio C (contact.force = "area_ratio", kept
            # to reproduce Bao as published); that double-counts the contact area.
            p_c = contact.greenwood_tripp_pressure(H, self.E, self.n_a, self.beta, self.sigma,
                                                   fit=self.fit, smooth=self.smooth)
            if self.contact_force_form == "area_ratio":
                return self.area_ratio(h) * p_c * self.area                              # Bao Eq. 20
            return p_c * self.area
        # Zhang Eq. 6 and 8: pressure E*delta on the real area delta*A_n.
        delta = contact.zhang_area_ratio(H, self.n_a, self.beta, self.sigma)
        return delta * contact.zhang_contact_pressure(H, self.E, self.n_a, self.beta, self.sigma) * self.area

    # -- axial load ---------------------------------------------------------------------------
    def fluid_share(self, h):
        """Share of the nominal area the fluid pressure acts on [-] (``film.load_sharing``)."""
        if self.load_sharing == "reduced":
            return 1.0 - self.area_ratio(h)      # Bao Eq. 12, Zhang Eq. 8: fluid on A_n - A_c
        return 1.0                               # fluid on the whole nominal area, plus p_c A_n

    def film_load(self, h, w_in, w_out):
        """The load law of a film of thickness ``h``: fluid (shared as ``film.load_sharing`` says,
        tension-limited) + asperities.

        Parameters
        ----------
        h : float or CasADi symbol
            Nominal film thickness [m].
        w_in, w_out : float or CasADi symbol
            Speeds of the two plates [rad/s] (used by the centrifugal term only).

        Returns
        -------
        FilmLoad
        """
        phi_r = 1.0
        if self.flow_factor == "patir_cheng" and self.sigma > 0:
            phi_r = squeeze_film.pressure_flow_factor(h / self.sigma, smooth=self.smooth)
        kw = dict(phi_r=phi_r, permeability=self.permeability, lining_thickness=self.lining_thickness,
                  inlet_pressure=self.inlet_pressure)
        if self.centrifugal:
            kw.update(rho=self.rho, w1=w_in, w2=w_out)
        static = squeeze_film.film_load(h, 0.0, self.eta, self.r1, self.r2, **kw)
        # The load is linear in dh_T/dt; dh_T/dt = Phi(H) dh/dt (Bao Eq. 10).
        per_rate = squeeze_film.film_load(h, -1.0, self.eta, self.r1, self.r2, **kw) - static
        gap_rate = roughness.average_gap_derivative(h, self.sigma) if self.sigma > 0 else 1.0
        share = self.fluid_share(h)
        limit = self.cavitation_pressure * share * self.area                  # L = p_cav A_wet < 0
        return FilmLoad(K=share * per_rate * gap_rate, S=share * static, contact=self.contact_force(h),
                        limit=limit, width=-cavitation.WIDTH * limit, wet_area=share * self.area)

    def load_coefficients(self, h, w_in, w_out):
        """The linear (uncavitated) film law W = K (-dh/dt) + S: fluid + asperities.

        Parameters
        ----------
        h : float or CasADi symbol
            Nominal film thickness [m].
        w_in, w_out : float or CasADi symbol
            Speeds of the two plates [rad/s] (used by the centrifugal term only).

        Returns
        -------
        (K, S) : squeeze coefficient [N s/m] and static load [N] (fluid and asperities); the film
        follows it while its fluid load stays above the tension limit (:meth:`film_load`).
        """
        load = self.film_load(h, w_in, w_out)
        return load.K, load.S + load.contact

    # -- torque -------------------------------------------------------------------------------
    def mu(self, v, p, theta=None):
        """Asperity friction coefficient at slip speed v [m/s], nominal contact pressure p [Pa] and
        temperature theta [deg C] (default: the interface temperature; only Chen's law reads it)."""
        model, s = self.friction_model, self.scene
        if model == "constant":
            return s.value("friction.mu")
        if model == "stribeck":
            return friction.mu_stribeck(v, s.value("friction.mu_static"), s.value("friction.mu_kinetic"),
                                        s.value("friction.v_stribeck"), smooth=self.smooth)
        if model == "chen2021":
            theta = self.temperature_C if theta is None else theta
            return friction.mu_chen2021(v, _clamp(p, *_CHEN_P_RANGE), theta,
                                        smooth=self.smooth)
        if model == "cui2019":
            return friction.mu_cui2019(_clamp(p, *_CUI_P_RANGE))
        pressures, mus = s.value("friction.pressure"), s.value("friction.mu")
        table = ca.interpolant("mu_table", "linear", [pressures], mus)
        return table(_clamp(p, pressures[0], pressures[-1]))

    def viscous_torque(self, h, w_rel):
        """Viscous shear torque of the film [N m], same sign as w_rel (Cui Eq. 9).

        phi_fs is cut off smoothly at H = 7 (the exact cut is a jump of the torque once the two
        surfaces differ in roughness; see :func:`clutchocp.physics.shear.viscous_torque`).
        """
        return shear.viscous_torque(w_rel, h, self.eta, self.r1, self.r2, sigma_1=self.sigma_1,
                                    sigma_2=self.sigma_2, area_ratio=self.area_ratio(h),
                                    land_fraction=self.land_fraction, smooth=self.smooth, smooth_cutoff=True,
                                    method=self.shear_factors)

    def contact_torque(self, h, w_rel, direction):
        """Asperity friction torque [N m] while slipping in ``direction`` (+1 or -1) (Bao Eq. 25)."""
        F_c = self.contact_force(h)
        return direction * self.mu(w_rel * self.r_eff, F_c / self.area) * F_c * self.r_eff

    def static_capacity(self, h):
        """Largest torque the film holds without slipping [N m]."""
        return self.mu_static * self.contact_force(h) * self.r_eff


def _clamp(x, lo, hi):
    if isinstance(x, (ca.SX, ca.MX, ca.DM)):
        return ca.fmin(ca.fmax(x, lo), hi)
    return np.clip(x, lo, hi)
