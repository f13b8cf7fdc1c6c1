"""Oil viscosity against temperature: the Walther relation of ASTM D341, or a constant.

ASTM D341 (Walther) relates the kinematic viscosity nu [mm^2/s = cSt] of a petroleum oil to the
absolute temperature T [K] by

    log10 log10 (nu + 0.7) = A - B log10 T,

a straight line on the ASTM viscosity-temperature chart, so two measured points (by custom the
kinematic viscosities at 40 and 100 degC of a datasheet) fix A and B. The 0.7 form holds for
nu >= 2 mm^2/s (ASTM D341 adds small correction terms below). The dynamic viscosity is
eta = rho nu with the density taken constant (a mineral oil's density falls about 0.065 % per K,
a 4 % change between 40 and 100 degC, which is left out).

Every function takes floats, numpy arrays or CasADi symbols (temperatures in degC).
"""

import math

from ..errors import PhysicalRangeError
from .backend import exp, log

__all__ = ["walther_coefficients", "walther_kinematic_viscosity", "OilViscosity"]

KELVIN = 273.15                  # 0 degC in K
_WALTHER_OFFSET = 0.7            # ASTM D341, valid for nu >= 2 mm^2/s
_LN10 = math.log(10.0)
_MM2_PER_M2 = 1e6


def _log10(x):
    return log(x) / _LN10


def _pow10(x):
    return exp(_LN10 * x)


def walther_coefficients(theta_1, nu_1, theta_2, nu_2):
    """Walther constants (A, B) through two viscosity points (ASTM D341).

    Parameters
    ----------
    theta_1, theta_2 : float
        Temperatures of the two points [deg C], different.
    nu_1, nu_2 : float
        Kinematic viscosities at those temperatures [m^2/s], each >= 2e-6 m^2/s (2 mm^2/s).

    Returns
    -------
    (A, B) : tuple of float
        ``log10 log10 (nu[mm^2/s] + 0.7) = A - B log10 (T[K])``; B > 0 for an oil whose
        viscosity falls with temperature.

    Raises
    ------
    PhysicalRangeError
        Equal temperatures, a viscosity below 2 mm^2/s, or viscosities that do not fall with
        temperature.
    """
    if theta_1 == theta_2:
        raise PhysicalRangeError("Walther fit: the two viscosity points need different temperatures")
    for theta, nu in ((theta_1, nu_1), (theta_2, nu_2)):
        if not nu * _MM2_PER_M2 >= 2.0:
            raise PhysicalRangeError(f"Walther fit: kinematic viscosity {nu * _MM2_PER_M2:g} mm^2/s at {theta:g} degC "
                                     "is below 2 mm^2/s, where ASTM D341's 0.7 form no longer holds")
    if (nu_1 - nu_2) * (theta_1 - theta_2) >= 0:
        raise PhysicalRangeError("Walther fit: the viscosity must fall as the temperature rises")
    z1 = math.log10(math.log10(nu_1 * _MM2_PER_M2 + _WALTHER_OFFSET))
    z2 = math.log10(math.log10(nu_2 * _MM2_PER_M2 + _WALTHER_OFFSET))
    l1, l2 = math.log10(theta_1 + KELVIN), math.log10(theta_2 + KELVIN)
    B = (z1 - z2) / (l2 - l1)
    return z1 + B * l1, B


def walther_kinematic_viscosity(theta, A, B):
    """Kinematic viscosity [m^2/s] at temperature ``theta`` [deg C] from Walther constants (ASTM D341)."""
    z = A - B * _log10(theta + KELVIN)
    return (_pow10(_pow10(z)) - _WALTHER_OFFSET) / _MM2_PER_M2


class OilViscosity:
    """The dynamic viscosity law of a scene's ``[oil]`` part.

    ``model = "constant"``: ``oil.viscosity`` at every temperature. ``model = "walther"``: ASTM D341
    through ``kinematic_viscosity_40C`` and ``kinematic_viscosity_100C``, times ``oil.density``.

    Parameters
    ----------
    scene : clutchocp.scene.Scene
    """

    def __init__(self, scene):
        self.model = scene.variant("oil") or "constant"
        self.density = scene.value("oil.density")
        if self.model == "walther":
            self.coefficients = walther_coefficients(40.0, scene.value("oil.kinematic_viscosity_40C"),
                                                     100.0, scene.value("oil.kinematic_viscosity_100C"))
        else:
            self.constant = scene.value("oil.viscosity")

    @property
    def temperature_dependent(self):
        return self.model == "walther"

    def dynamic(self, theta):
        """Dynamic viscosity [Pa s] at temperature ``theta`` [deg C] (float or CasADi symbol)."""
        if self.model == "walther":
            return self.density * walther_kinematic_viscosity(theta, *self.coefficients)
        return self.constant
