"""The scene format: which parts a scene may declare and the parameters of each.

A scene file is TOML.  Each table is a *part* (``[plates]``, ``[oil]``, ``[piston]`` ...).  A part
with variants chooses one with ``model = "..."``; the variant decides which parameters exist.
Quantities may carry units (``"8.4 um"``); plain numbers are SI.  Parts marked optional may be
left out: the model then compiles without them (no states, no equations, no cost).
"""

from dataclasses import dataclass, field as dc_field

MAX_PRESSURE = 1e8           # Pa
MAX_OUTPUT_POINTS = 200_000
MAX_INTERFACES = 64
MAX_LINING_CELLS = 20
LINING_CELLS = 6             # default conduction cells across a friction lining ([thermal])
# thermal.lining_material -> (conductivity W/(m K), density kg/m^3, specific heat J/(kg K)): the defaults
# of the lining_* keys. Paper: the values the shipped thermal scenes assume (oil-filled paper lining);
# sintered: a porous sintered-bronze lining. Both typical, not a particular product.
LINING_MATERIALS = {"paper": (0.2, 1000.0, 1500.0), "sintered": (25.0, 6500.0, 450.0)}
# Keys that no longer exist: name -> what took their place (the loader says so in one line).
RETIRED = {
    "thermal.heat_partition": "the heat now divides between separator and lining by conduction through the "
                              "lining (thermal.lining_conductivity, lining_density, lining_specific_heat); "
                              "remove it",
}

# Value checks: name -> (predicate on the SI value, phrase for the error message).
CHECKS = {
    "positive": (lambda v: v > 0, "> 0"),
    "nonnegative": (lambda v: v >= 0, ">= 0"),
    "fraction": (lambda v: 0 < v <= 1, "in (0, 1]"),
    "unit_interval": (lambda v: 0 <= v <= 1, "in [0, 1]"),
    "fractal_dimension": (lambda v: 1 < v < 2, "in (1, 2)"),
    "area_factor": (lambda v: 1 <= v <= 2, "in [1, 2] (Bao Eq. 18)"),
    "angle": (lambda v: 0 <= v < 1.5707963267948966, "in [0, 90) deg"),
    "friction": (lambda v: 0 < v < 2, "in (0, 2)"),
    "celsius": (lambda v: v > -273.15, "above absolute zero (> -273.15 degC)"),
    "any": (lambda v: True, "any value"),
    "cavitation_pressure": (lambda v: -1e6 <= v <= -1e3, "in [-1e6, -1e3] Pa (gauge: from -10 bar to -0.01 bar)"),
    # Limits that protect the machine and the meaning of a result (see RESOURCE_LIMITS):
    "pressure": (lambda v: 0 <= v <= MAX_PRESSURE, "in [0, 1e8] Pa (100 MPa is above any clutch or valve pressure)"),
    "positive_pressure": (lambda v: 0 < v <= MAX_PRESSURE,
                          "in (0, 1e8] Pa (100 MPa is above any clutch or valve pressure)"),
    "output_points": (lambda v: 2 <= v <= MAX_OUTPUT_POINTS,
                      f"from 2 to {MAX_OUTPUT_POINTS} (each point keeps every state and output: "
                      "200 000 points are about 100 MB of results)"),
    "interfaces": (lambda v: 1 <= v <= MAX_INTERFACES,
                   f"from 1 to {MAX_INTERFACES} (one film state each; no wet clutch has more, and the run "
                   "time grows faster than the count: 16 films took 2.4 s, 64 films 8.2 s)"),
    "tolerance": (lambda v: 1e-14 <= v <= 1e-2, "from 1e-14 to 1e-2 (looser tolerances give errors of percents)"),
    "lining_cells": (lambda v: 1 <= v <= MAX_LINING_CELLS,
                     f"from 1 to {MAX_LINING_CELLS} (one temperature state per cell boundary)"),
    "duration": (lambda v: 1e-3 <= v <= 1e4, "from 1e-3 s to 1e4 s (an engagement lasts milliseconds to seconds)"),
}


@dataclass(frozen=True)
class Field:
    """One parameter of a part.

    Attributes
    ----------
    kind : str
        ``"quantity"`` (number or number+unit), ``"quantity_list"``, ``"int"``, ``"bool"``,
        ``"str"``, ``"str_list"`` or ``"choice"``.
    dim : str
        Dimension of a quantity (a key of :data:`clutchocp.units.DIMENSIONS`).
    check : str
        Key of :data:`CHECKS` applied to the SI value (each element of a list).
    required : bool
        Whether the scene must give it (else ``default`` is used, if any).
    default : object
        Default value in SI (``None`` = absent unless given).
    choices : tuple of str
        Allowed values of a ``"choice"`` field.
    doc : str
        One-line meaning, with units.
    """

    kind: str = "quantity"
    dim: str = "1"
    check: str = "any"
    required: bool = True
    default: object = None
    choices: tuple = ()
    doc: str = ""
    span: "Span | None" = None


@dataclass(frozen=True)
class Span:
    """Where the values of a quantity key lie for a wet clutch (SI, both ends included).

    Attributes
    ----------
    typical : (float, float)
        Values a wet clutch has. Outside: a warning that names the range and the unit the number
        probably meant (the run goes on: a model can hold an unusual clutch).
    limit : (float, float)
        Values any wet clutch stays within. Outside: refused with one line (such a number is a
        unit slip, e.g. a radius of 85 m written for 85 mm).
    what : str
        What the value is, for the messages ("a clutch radius").
    zero : bool
        0 means "absent" for this key (no lining, no free travel, pressure released) and is
        accepted whatever the spans say.
    """

    typical: tuple
    limit: tuple
    what: str
    zero: bool = False

    def describe(self, dim):
        """The spans as a phrase for the scene-key reference, e.g. ``"typical 0.02 to 1.5 m; refused
        outside 0.001 to 5 m"``."""
        unit = "" if dim == "1" else f" {dim}"
        text = (f"typical {self.typical[0]:g} to {self.typical[1]:g}{unit}; refused outside "
                f"{self.limit[0]:g} to {self.limit[1]:g}{unit}")
        return text + ("; 0 = none" if self.zero else "")


def Q(dim, check="positive", doc="", **kw):
    """A quantity field (number or ``"number unit"``)."""
    return Field(kind="quantity", dim=dim, check=check, doc=doc, **kw)


def QOpt(dim, default, check="nonnegative", doc="", span=None):
    """An optional quantity field with an SI default."""
    return Field(kind="quantity", dim=dim, check=check, required=False, default=default, doc=doc, span=span)


# Spans shared by keys of the same kind (see Span). Sources: the seed papers' clutches (radii 43-160 mm,
# 0.2-2.5 MPa, ATF 3-70 mPa s, 600-9550 rpm) widened to cover passenger-car, truck, motorcycle and
# industrial wet clutches and brakes; the limits lie one to three decades beyond.
RADIUS = Span((0.01, 1.5), (1e-3, 5.0), "a clutch radius")
PRESSURE = Span((1e3, MAX_PRESSURE), (0.0, MAX_PRESSURE), "a clutch oil pressure", zero=True)
SPEED = Span((1.0, 2000.0), (0.0, 3e4), "a clutch shaft speed", zero=True)
# Inertias reflected to the clutch or brake shaft: 1e-4 kg m^2 (a small actuator's clutch) to 1e5 kg m^2.
# A car's mass at its gearbox output is 5-15 kg m^2; a 40 t truck's at its propshaft (r 0.5 m, axle 4:1)
# about 600 kg m^2; a haul truck's wheel-end brake behind a hub reduction 1e3-1e4 kg m^2 (25 t at 1.3 m
# through 6:1: 1174 kg m^2; 150 t of an ultra-class truck at 1.9 m through 6:1: 1.5e4 kg m^2); a rail
# axle's share (20 t at 0.5 m through 4:1) about 300 kg m^2. A brake at wheel speed with no reduction
# (ultra-class front wheels: about 4e5 kg m^2) is unusual but runs; 1e7 kg m^2 is no clutch's.
INERTIA = Span((1e-4, 1e5), (1e-7, 1e7), "a driveline inertia")
TORQUE = Span((0.0, 2e4), (0.0, 1e6), "a clutch or load torque", zero=True)
ROUGHNESS = Span((1e-8, 3e-5), (1e-10, 1e-3), "an RMS surface roughness", zero=True)
MODULUS = Span((1e6, 3e11), (1e4, 1e12), "an elastic modulus")
STRENGTH = Span((1e6, 1e10), (1e4, 1e11), "a hardness or yield strength")
TIME_CONSTANT = Span((1e-4, 5.0), (1e-7, 1e3), "a valve or pressure time constant")
ENGAGEMENT_TIME = Span((0.05, 5.0), (1e-3, 100.0), "a clutch engagement (slip-phase) time")
TEMPERATURE = Span((-40.0, 200.0), (-100.0, 500.0), "an oil or plate temperature")
HEAT_CAPACITY = Span((1.0, 1e5), (1e-3, 1e8), "a plate-pack heat capacity")
PISTON_AREA = Span((1e-4, 0.5), (1e-6, 10.0), "a piston area")
SPRING_RATE = Span((10.0, 1e8), (1e-2, 1e10), "a spring stiffness", zero=True)


@dataclass(frozen=True)
class Part:
    """A table of a scene file: common fields, and variants chosen by ``model``."""

    doc: str
    fields: dict = dc_field(default_factory=dict)
    variants: dict = dc_field(default_factory=dict)
    default_variant: str = ""

    def allowed_fields(self, variant):
        """Fields allowed in this part for the given variant (``model`` included)."""
        out = dict(self.fields)
        if self.variants:
            out.update(self.variants[variant])
        return out


PARTS = {
    "scene": Part(
        "identity of the scene and the paper it comes from",
        fields={
            "name": Field(kind="str", doc="short name, used to load the scene"),
            "title": Field(kind="str", required=False, default="", doc="one-line description"),
            "source": Field(kind="str", doc="the paper (and table) the values come from"),
            "kind": Field(kind="choice", choices=("engagement", "hvd", "static"),
                          doc="what the scene is for"),
            "analysis": Field(kind="choice", required=False,
                              choices=("chen2021_pack", "cui2019_mixed", "liao2021_hvc"),
                              doc="static analysis run by 'clutchocp validate'"),
            "assumptions": Field(kind="str_list", required=False, default=(),
                                 doc="values not in the paper, each with its reason"),
            "default": Field(kind="bool", required=False, default=False,
                             doc="the default scene of 'clutchocp optimize'"),
        },
    ),
    "plates": Part(
        "friction-pair geometry",
        fields={
            "r_inner": Q("m", doc="inner radius of the friction surface [m]", span=RADIUS),
            "r_outer": Q("m", doc="outer radius of the friction surface [m]", span=Span((0.02, 1.5), (1e-3, 5.0), "a clutch radius")),
            "n_interfaces": Field(kind="int", check="interfaces",
                                  doc="number of lubricated friction interfaces (films)"),
            "land_fraction": QOpt("1", 1.0, "fraction", "non-grooved share of the area (Cui psi)"),
            "lining_thickness": QOpt("m", 0.0, doc="friction-lining thickness d [m] (Zhang); with [thermal] the heat "
                                                    "conducts through it",
                                      span=Span((1e-4, 5e-3), (1e-6, 0.05), "a friction-lining thickness", zero=True)),
            "lining_permeability": QOpt("m^2", 0.0, doc="lining permeability Phi [m^2] (Zhang)",
                                         span=Span((1e-17, 1e-10), (1e-22, 1e-8), "a lining permeability", zero=True)),
            "effective_diameter": Field(kind="quantity", dim="m", check="positive", required=False,
                                        doc="effective friction diameter d [m] (Liao Eq. 10)",
                                        span=Span((0.02, 3.0), (2e-3, 10.0), "a clutch diameter")),
        },
    ),
    "oil": Part(
        "lubricant: a constant viscosity, or Walther's law (ASTM D341) through two datasheet points",
        fields={
            "density": QOpt("kg/m^3", 870.0, "positive", "density [kg/m^3] (taken constant)",
                            span=Span((700.0, 1100.0), (300.0, 3000.0), "an oil density")),
        },
        variants={
            "constant": {"viscosity": Q("Pa s", doc="dynamic viscosity [Pa s]",
                                       span=Span((5e-4, 1.0), (5e-5, 20.0), "an oil viscosity"))},
            "walther": {
                "kinematic_viscosity_40C": Q("m^2/s", doc="kinematic viscosity at 40 degC [m^2/s] (datasheet)",
                                             span=Span((5e-6, 1e-3), (5e-7, 2e-2), "a kinematic viscosity at 40 degC")),
                "kinematic_viscosity_100C": Q("m^2/s", doc="kinematic viscosity at 100 degC [m^2/s] (datasheet)",
                                              span=Span((1e-6, 1e-4), (2e-7, 2e-3), "a kinematic viscosity at 100 degC")),
                "temperature_C": QOpt("degC", None, "celsius",
                                      "oil temperature [deg C] of a scene without [thermal] (with it: "
                                      "thermal.oil_temperature_C)", span=TEMPERATURE),
            },
        },
        default_variant="constant",
    ),
    "film": Part(
        "squeeze-film options of the averaged Reynolds equation",
        fields={
            "flow_factor": Field(kind="choice", choices=("patir_cheng", "none"), required=False,
                                 default="patir_cheng", doc="pressure flow factor phi_r"),
            "centrifugal": Field(kind="bool", required=False, default=False,
                                 doc="include the centrifugal term (Bao Eq. 11)"),
            "inlet_pressure": QOpt("Pa", 0.0, "pressure", doc="oil pressure at the inner radius [Pa]", span=PRESSURE),
            "load_sharing": Field(kind="choice", choices=("reduced", "additive"), required=False,
                                  default="reduced",
                                  doc="fluid load on the free area (1 - A_c/A_n) W_fluid + p_c A_n (Bao Eq. 12, "
                                      "'reduced') or the full W_fluid + p_c A_n ('additive')"),
            "shear_factors": Field(kind="choice", choices=("table", "patir_cheng"), required=False,
                                   default="table",
                                   doc="transmitted viscous shear factor of a rough lining on a smooth plate: "
                                       "'table' (default), the deterministic Reynolds flow over Gaussian rough walls "
                                       "(1 + 2.5/H^2 far out; 6-48 % above Patir-Cheng for H = 0.5-3, equal at "
                                       "H = 3.5-5), or 'patir_cheng', phi_f + |V_r1 - V_r2| Phi_fs (Cui Eq. 6-8 with "
                                       "the transmitted sign)"),
            "cavitation_pressure": QOpt("Pa", -1e5, "cavitation_pressure",
                                        doc="lowest mean gauge pressure a film holds when its plates are pulled "
                                            "apart [Pa]; the fluid load is limited smoothly there (the film "
                                            "cavitates). Default -1 bar: absolute zero at 1 bar ambient, the most "
                                            "suction any oil film can give (vapour pressure ~0 absolute); dissolved "
                                            "air comes out above that, so a gaseous cavity holds less (e.g. "
                                            "-0.3 bar)"),
        },
    ),
    "roughness": Part(
        "surface roughness and asperities (give sigma, or sigma_1 and sigma_2)",
        fields={
            "sigma": Field(kind="quantity", dim="m", check="nonnegative", required=False,
                           doc="combined RMS roughness [m]", span=ROUGHNESS),
            "sigma_1": Field(kind="quantity", dim="m", check="nonnegative", required=False,
                             doc="RMS roughness of the friction plate [m]", span=ROUGHNESS),
            "sigma_2": Field(kind="quantity", dim="m", check="nonnegative", required=False,
                             doc="RMS roughness of the separator [m]", span=ROUGHNESS),
            "asperity_density": QOpt("1/m^2", None, "positive", "asperity density n_a [1/m^2]",
                                     span=Span((1e6, 1e13), (1e2, 1e17), "an asperity density")),
            "asperity_radius": QOpt("m", None, "positive", "asperity tip radius beta [m]",
                                    span=Span((1e-7, 5e-3), (1e-9, 0.1), "an asperity tip radius")),
        },
    ),
    "contact": Part(
        "asperity contact law",
        variants={
            "none": {},
            "greenwood_tripp": {
                "E_equiv": Q("Pa", doc="equivalent elastic modulus E' [Pa]", span=MODULUS),
                "fit": Field(kind="choice", choices=("exact", "patir"), required=False,
                             default="exact", doc="F_5/2 exact or Bao Eq. 19 fit"),
                "area_factor": QOpt("1", 1.0, "area_factor", "elastoplastic area factor n0"),
                "force": Field(kind="choice", choices=("nominal", "area_ratio"), required=False,
                               default="nominal",
                               doc="asperity force p_c A_n ('nominal') or Bao Eq. 20's C p_c A_n ('area_ratio')"),
                "hardness": QOpt("Pa", None, "positive", "hardness H' [Pa]", span=STRENGTH),
            },
            "zhang_gw": {"E_equiv": Q("Pa", doc="equivalent elastic modulus E [Pa]", span=MODULUS)},
            "fractal_mb": {
                "E_equiv": Q("Pa", doc="equivalent elastic modulus E [Pa]", span=MODULUS),
                "fractal_dimension": Q("1", "fractal_dimension", "fractal dimension D"),
                "fractal_scale": Q("m", doc="fractal scale factor G [m]"),
                "hardness": Q("Pa", doc="hardness of the softer material [Pa]", span=STRENGTH),
                "yield_strength": Q("Pa", doc="yield (compressive) strength [Pa]", span=STRENGTH),
            },
        },
        default_variant="greenwood_tripp",
    ),
    "friction": Part(
        "asperity friction-coefficient law",
        fields={
            "static_coefficient": QOpt("1", None, "friction",
                                       "static COF for the lock-up capacity (default: law at v = 0)"),
        },
        variants={
            "constant": {"mu": Q("1", "friction", "friction coefficient")},
            "stribeck": {
                "mu_static": Q("1", "friction", "COF at zero slip"),
                "mu_kinetic": Q("1", "friction", "COF at high slip"),
                "v_stribeck": Q("m/s", doc="Stribeck velocity [m/s]",
                                span=Span((1e-3, 20.0), (1e-6, 1e3), "a Stribeck sliding speed")),
            },
            "chen2021": {"temperature_C": Field(kind="quantity", dim="degC", check="positive", required=False,
                                                doc="surface temperature [deg C] (Chen Eq. 5); with a "
                                                    "[thermal] part the law reads the interface temperature",
                                                span=TEMPERATURE)},
            "cui2019": {},
            "table": {
                "pressure": Field(kind="quantity_list", dim="Pa", check="nonnegative",
                                  doc="contact pressures [Pa]", span=PRESSURE),
                "mu": Field(kind="quantity_list", dim="1", check="friction", doc="COF at each pressure"),
            },
        },
        default_variant="constant",
    ),
    "spline": Part(
        "spline friction of the plates in their carriers (Chen 2021)",
        fields={
            "friction_coefficients": Field(kind="quantity_list", dim="1", check="friction",
                                           doc="spline COF mu_fs (one or more values)"),
            "pitch_radius_friction": Q("m", doc="spline pitch radius of the friction discs [m]", span=RADIUS),
            "pitch_radius_separator": Q("m", doc="spline pitch radius of the separators [m]", span=RADIUS),
            "pressure_angle_friction": Q("rad", "angle", "spline pressure angle, friction discs"),
            "pressure_angle_separator": Q("rad", "angle", "spline pressure angle, separators"),
            "first": Field(kind="choice", choices=("separator", "friction"), required=False,
                           default="separator", doc="plate type next to the piston"),
        },
    ),
    "groove": Part(
        "radial grooves (Liao Eq. 2)",
        fields={
            "depth": Q("m", "nonnegative", "groove depth h_a [m]",
                       span=Span((1e-5, 3e-3), (1e-7, 0.02), "a groove depth", zero=True)),
            "angle_ratio": Q("1", doc="non-groove / groove angle theta2/theta1 (K2)"),
        },
    ),
    "hvc": Part(
        "hydro-viscous clutch film distribution (Liao Eq. 13)",
        fields={
            "friction_ratio": Q("1/m^2", "nonnegative", "K3/K1 [1/m^2]"),
            "first_film": Q("m", doc="thickness of the film next to the piston [m]",
                            span=Span((1e-6, 2e-3), (1e-8, 0.01), "a film thickness")),
        },
    ),
    "operating": Part(
        "operating point of a static analysis",
        fields={
            "speed_input": QOpt("rad/s", 0.0, doc="input (friction plate) speed [rad/s]", span=SPEED),
            "speed_output": QOpt("rad/s", 0.0, doc="output (separator) speed [rad/s]", span=SPEED),
            "temperature_C": QOpt("degC", None, "positive", "oil / surface temperature [deg C]", span=TEMPERATURE),
            "pressures": Field(kind="quantity_list", dim="Pa", check="pressure", required=False,
                               doc="applied pressures [Pa]", span=PRESSURE),
        },
    ),
    "piston": Part(
        "piston with return or preload spring and seal friction",
        fields={
            "mass": Q("kg", doc="piston mass [kg]", span=Span((0.01, 50.0), (1e-4, 1e3), "a piston mass")),
            "area": Q("m^2", doc="hydraulic area [m^2]", span=PISTON_AREA),
            "spring_stiffness": QOpt("N/m", 0.0, doc="stiffness of one spring [N/m]", span=SPRING_RATE),
            "spring_count": Field(kind="int", check="positive", required=False, default=1,
                                  doc="number of springs"),
            "spring_preload": QOpt("m", 0.0, doc="initial spring compression [m]",
                                   span=Span((1e-5, 0.1), (1e-8, 1.0), "a spring compression", zero=True)),
            "travel_to_pack": QOpt("m", 0.0, doc="free travel before the piston meets plate 1 [m]",
                                   span=Span((1e-5, 0.02), (1e-8, 0.5), "a piston free travel", zero=True)),
            "seal_length": QOpt("m", 0.0, doc="seal contact length L [m] (Bao Eq. 16)",
                                span=Span((1e-4, 0.3), (1e-6, 2.0), "a seal length", zero=True)),
            "seal_diameter": QOpt("m", 0.0, doc="seal diameter D [m] (Bao Eq. 16)",
                                  span=Span((5e-3, 3.0), (1e-4, 10.0), "a seal diameter", zero=True)),
            "seal_clearance": QOpt("m", 1.0, "positive", "radial clearance psi [m] (Bao Eq. 16)",
                                   span=Span((1e-6, 0.02), (1e-8, 1.0), "a seal clearance")),
        },
        variants={"pressure_applied": {}, "spring_applied": {}},
        default_variant="pressure_applied",
    ),
    "pack": Part(
        "plate pack axial dynamics",
        fields={
            "initial_gap": Q("m", doc="initial film thickness H0 of every gap [m]",
                             span=Span((1e-6, 2e-3), (1e-9, 0.05), "an open-pack film thickness")),
        },
        variants={
            "masses": {"plate_masses": Field(kind="quantity_list", dim="kg", check="positive",
                                             doc="mass of each moving plate, piston side first [kg]",
                                             span=Span((0.01, 20.0), (1e-4, 500.0), "a clutch plate mass"))},
            "massless": {},
        },
        default_variant="massless",
    ),
    "actuation": Part(
        "engagement pressure",
        fields={
            "pressure": Q("Pa", "pressure", "set pressure P_o [Pa]", span=PRESSURE),
            "initial_pressure": QOpt("Pa", 0.0, "pressure", doc="pressure at t = 0 [Pa]", span=PRESSURE),
            "t_start": QOpt("s", 0.0, doc="time the command starts [s]",
                            span=Span((0.0, 10.0), (0.0, 1e4), "a command start time", zero=True)),
            "area": QOpt("m^2", None, "positive",
                         "area the pressure acts on when there is no piston [m^2] (default: plate area)",
                         span=PISTON_AREA),
            "max_pressure": QOpt("Pa", None, "positive_pressure", "upper pressure limit [Pa]", span=PRESSURE),
            "engagement_time_limit": QOpt("s", None, "positive",
                                          "the shift's budget for the slip phase [s]: the engagement-time limit "
                                          "t_max of optimize and robust when --t-max is not given (absent: the "
                                          "lock-up time of the scene's own profile)", span=ENGAGEMENT_TIME),
        },
        variants={
            "step": {},
            "ramp": {"ramp_time": Q("s", doc="time to reach the set pressure [s]", span=TIME_CONSTANT)},
            "first_order_lag": {"time_constant": Q("s", doc="lag t_s [s] (Zhang Eq. 7)", span=TIME_CONSTANT)},
            "valve_lag": {"time_constant": Q("s", doc="valve time constant [s], a state", span=TIME_CONSTANT)},
            "table": {"file": Field(kind="str", doc="CSV file (time s, pressure Pa), relative to the scene")},
        },
        default_variant="first_order_lag",
    ),
    "driveline": Part(
        "rotating side",
        fields={
            "input": Field(kind="choice", choices=("prescribed_speed", "inertia"),
                           doc="input side: fixed speed or an inertia"),
            "input_speed": Q("rad/s", "nonnegative", "initial (or prescribed) input speed [rad/s]", span=SPEED),
            "output": Field(kind="choice", choices=("inertia", "fixed"), required=False,
                            default="inertia", doc="output side: an inertia, or held at rest (a brake)"),
            "input_inertia": QOpt("kg m^2", None, "positive", "input inertia [kg m^2]", span=INERTIA),
            "input_torque": QOpt("N m", 0.0, "any", "torque driving the input [N m]",
                                 span=Span((-2e4, 2e4), (-1e6, 1e6), "a driving torque")),
            "output_inertia": QOpt("kg m^2", None, "positive", "output inertia [kg m^2]", span=INERTIA),
            "output_speed": QOpt("rad/s", 0.0, "nonnegative", "initial output speed [rad/s]", span=SPEED),
            "shaft_stiffness": QOpt("N m", None, "positive", "output-shaft torsional stiffness [N m/rad]",
                                    span=Span((10.0, 1e7), (1e-2, 1e10), "a shaft torsional stiffness")),
            "shaft_damping": QOpt("N m s", 0.0, doc="output-shaft torsional damping [N m s/rad]",
                                  span=Span((1e-4, 1e4), (0.0, 1e7), "a shaft damping", zero=True)),
            "driving_films": Field(kind="choice", choices=("all", "first"), required=False, default="all",
                                   doc="films whose torque acts between input and output: all, or only the "
                                       "first (Bao Eq. 26 as printed)"),
        },
    ),
    "load": Part(
        "load torque on the output",
        fields={},
        variants={
            "none": {},
            "constant": {"torque": Q("N m", "nonnegative", "load torque [N m]", span=TORQUE)},
            "quadratic": {
                "rated_torque": Q("N m", doc="torque at the rated speed [N m]", span=TORQUE),
                "rated_speed": Q("rad/s", doc="rated output speed [rad/s]", span=SPEED),
            },
            "table": {"file": Field(kind="str", doc="CSV file (speed rad/s, torque N m)")},
        },
        default_variant="none",
    ),
    "thermal": Part(
        "plate temperatures (optional): the heat of the slip and squeeze films enters the interface, where "
        "the separator (lumped steel) touches the friction lining; it conducts through the lining (a few "
        "nodes across its thickness) into the friction plate's steel core (lumped), and both plate groups "
        "convect to the oil. The interface temperature (the lining's surface) drives the oil and friction laws",
        fields={
            "oil_temperature_C": Q("degC", "celsius", "cooling-oil temperature [deg C]", span=TEMPERATURE),
            "initial_temperature_C": QOpt("degC", None, "celsius",
                                          "plate temperature at t = 0 [deg C] (default: the oil temperature)",
                                          span=TEMPERATURE),
            "separator_heat_capacity": Q("J/K", doc="heat capacity of the separator steel heated by the pack's "
                                                    "interfaces, whole pack [J/K]; lumped: its faces are at the "
                                                    "interface temperature", span=HEAT_CAPACITY),
            "friction_plate_heat_capacity": Q("J/K", doc="heat capacity of the friction plates (core and "
                                                         "lining), whole pack [J/K]; the lining's share "
                                                         "n_interfaces A d rho c is resolved by the conduction "
                                                         "nodes, the rest is the lumped steel core",
                                              span=HEAT_CAPACITY),
            "convection_coefficient": Q("W/m^2/K", "nonnegative",
                                        "heat transfer coefficient to the oil [W/(m^2 K)], over one face "
                                        "area per interface for each of the two plate groups (the separator "
                                        "at the interface temperature, the friction plate at its core)",
                                        span=Span((10.0, 1e5), (0.0, 1e7), "a convection coefficient", zero=True)),
            "lining_material": Field(kind="choice", choices=tuple(LINING_MATERIALS), required=False,
                                     default="paper",
                                     doc="defaults of the three lining_* properties: " + "; ".join(
                                         f"{name} {k:g} W/(m K), {rho:g} kg/m^3, {c:g} J/(kg K)"
                                         for name, (k, rho, c) in LINING_MATERIALS.items())
                                     + " (typical values; give the supplier's data where known)"),
            "lining_conductivity": QOpt("W/m/K", None, "positive",
                                        "thermal conductivity of the friction lining [W/(m K)] "
                                        "(default: thermal.lining_material's)",
                                        span=Span((0.05, 100.0), (1e-3, 500.0), "a lining thermal conductivity")),
            "lining_density": QOpt("kg/m^3", None, "positive",
                                   "density of the friction lining [kg/m^3] (default: thermal.lining_material's)",
                                   span=Span((300.0, 9000.0), (50.0, 22000.0), "a lining density")),
            "lining_specific_heat": QOpt("J/kg/K", None, "positive",
                                         "specific heat capacity of the friction lining [J/(kg K)] "
                                         "(default: thermal.lining_material's)",
                                         span=Span((200.0, 3000.0), (50.0, 10000.0), "a lining specific heat")),
            "lining_cells": Field(kind="int", check="lining_cells", required=False, default=LINING_CELLS,
                                  doc="conduction cells across the lining, finest at the surface (each cell "
                                      "1.5 x the one before); one temperature state per cell boundary. "
                                      f"{LINING_CELLS} keep the surface temperature under a constant flux "
                                      "within 5 % of the semi-infinite solution from 0.05 s on"),
        },
    ),
    "simulation": Part(
        "integration settings",
        fields={
            "t_end": Q("s", "duration", doc="end time [s]"),
            "rtol": QOpt("1", 1e-8, "tolerance", "relative tolerance"),
            "atol": QOpt("1", 1e-10, "tolerance", "absolute tolerance (scaled states)"),
            "output_points": Field(kind="int", check="output_points", required=False, default=2001,
                                   doc="number of output times"),
        },
    ),
    "hvd": Part(
        "hydro-viscous drive control piston, springs (Liao Eq. 15) and pressure valve",
        fields={
            "cylinder_r_inner": Q("m", doc="inner radius R1 of the control-oil cylinder [m] (Liao Eq. 15)",
                                  span=RADIUS),
            "cylinder_r_outer": Q("m", doc="outer radius R2 of the control-oil cylinder [m] (Liao Eq. 15)",
                                  span=RADIUS),
            "spring_stiffness": Q("N/m", doc="stiffness k of one spring [N/m]", span=SPRING_RATE),
            "spring_count": Field(kind="int", check="positive", required=False, default=1,
                                  doc="number of springs N"),
            "spring_preload": QOpt("m", 0.0, doc="spring precompression x0 [m]",
                                   span=Span((1e-5, 0.1), (1e-8, 1.0), "a spring compression", zero=True)),
            "control_oil_radius": QOpt("m", None, "nonnegative",
                                       "free-surface radius r0 of the rotating control oil [m] (Liao Eq. 15); "
                                       "absent: no centrifugal cylinder force",
                                       span=Span((0.01, 1.5), (1e-3, 5.0), "a clutch radius", zero=True)),
            "valve_time_constant": Q("s", doc="time constant of the pressure valve [s] (a state)",
                                     span=TIME_CONSTANT),
            "pressure_min": QOpt("Pa", 0.0, "pressure", doc="lowest control pressure the valve gives [Pa]",
                                 span=PRESSURE),
            "pressure_max": Q("Pa", "positive_pressure", doc="highest control pressure the valve gives [Pa]",
                              span=PRESSURE),
            "spline_friction": QOpt("1", None, "friction",
                                    "friction coefficient f of the plates in their splines (Liao Eq. 10); "
                                    "needed with [hvc]"),
        },
        variants={
            "spring_applied": {},
            "pressure_applied": {
                "open_clearance": Q("m", doc="total pack clearance with the piston on its stop [m]",
                                    span=Span((1e-5, 5e-3), (1e-8, 0.05), "a pack clearance")),
            },
        },
        default_variant="pressure_applied",
    ),
}

# Parts a scene of each kind must declare.
REQUIRED_PARTS = {
    "engagement": ("scene", "plates", "oil", "roughness", "contact", "friction", "pack",
                   "actuation", "driveline", "simulation"),
    "hvd": ("scene", "plates", "oil", "hvd", "driveline", "load"),
    "static": ("scene", "plates"),
}
