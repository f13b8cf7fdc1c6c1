"""Clutch torque, load torque and torque-per-pressure gain as a TCU estimates them from its samples.

On a two-inertia driveline (input inertia J_in driven by the engine torque T_in the TCU is told,
output inertia J_out against the load T_L) Newton's law for each rigid rotor, integrated over one
TCU sample [t_{k-1}, t_k], gives the mean torques over that sample exactly from the two speed
samples:

    T_c = T_in - J_in (w_in[k] - w_in[k-1]) / Ts          (input rotor: J_in dw_in/dt = T_in - T_c)
    T_L = T_c  - J_out (w_out[k] - w_out[k-1]) / Ts        (output rotor: J_out dw_out/dt = T_c - T_L)

and the clutch's torque gain g = T_c / p_mean, with p_mean the trapezoidal mean of the two pressure
samples (the pressure-to-torque factor mu n r_m A of the contact, plus the viscous torque's share).
A locked clutch turns both rotors together, so it carries

    T_lock = (J_out T_in + J_in T_L) / (J_in + J_out)

(equal accelerations (T_in - T)/J_in = (T - T_L)/J_out), and the slip rate is
dw_rel/dt = (T_lock - T_c)(1/J_in + 1/J_out): the torque jump at lock-up is T_c(lock-) - T_lock.
"""

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError


@dataclass(frozen=True)
class TorqueEstimator:
    """Mean clutch and load torque over one TCU sample from speed and pressure samples.

    Parameters
    ----------
    input_inertia, output_inertia : float
        J_in, J_out [kg m^2] (the nominal scene's: the TCU knows the driveline, not the clutch).
    input_torque : float
        T_in [N m], the engine torque the TCU is told.
    sample_time : float
        Ts [s].
    """

    input_inertia: float
    output_inertia: float
    input_torque: float
    sample_time: float

    @staticmethod
    def unavailable(scene):
        """Why a scene's driveline has no estimator (a one-line reason), or None if it has one."""
        if scene.get("driveline.input") != "inertia" or scene.get("driveline.output", "inertia") != "inertia":
            return ("needs driveline.input = \"inertia\" and driveline.output = \"inertia\" (the clutch torque is "
                    "read from both rotors' accelerations)")
        if scene.get("driveline.shaft_stiffness") is not None:
            return "driveline.shaft_stiffness is set; the estimator assumes rigid rotors"
        return None

    @classmethod
    def from_scene(cls, scene, sample_time):
        """The estimator of a two-inertia scene (``driveline.input = "inertia"``, ``output = "inertia"``, rigid)."""
        reason = cls.unavailable(scene)
        if reason is not None:
            raise ModelError(f"slip feedback estimator: {reason}; set [estimator] enabled = false for this scene")
        return cls(scene.value("driveline.input_inertia"), scene.value("driveline.output_inertia"),
                   scene.value("driveline.input_torque"), sample_time)

    def locked_torque(self, load_torque):
        """Torque the locked clutch carries, T_lock [N m], for a load torque [N m]."""
        J_in, J_out = self.input_inertia, self.output_inertia
        return (J_out * self.input_torque + J_in * load_torque) / (J_in + J_out)

    def estimate(self, previous, current):
        """(T_c, T_L, p_mean) over the sample between two sample dicts (``w_in``, ``w_out`` [rad/s], ``p_valve`` [Pa]).

        Returns
        -------
        tuple of float : mean clutch torque [N m], mean load torque [N m], mean pressure [Pa].
        """
        pair = ([previous[n], current[n]] for n in ("w_in", "w_out", "p_valve"))
        return tuple(float(a[0]) for a in self.along(*pair))

    def along(self, w_in, w_out, p_valve):
        """The estimates along sampled signals (arrays over t_0 .. t_N): arrays (N,) of T_c, T_L, p_mean for samples 1..N."""
        w_in, w_out, p_valve = (np.asarray(a, float) for a in (w_in, w_out, p_valve))
        Ts = self.sample_time
        clutch = self.input_torque - self.input_inertia * np.diff(w_in) / Ts
        return clutch, clutch - self.output_inertia * np.diff(w_out) / Ts, 0.5 * (p_valve[1:] + p_valve[:-1])


@dataclass(frozen=True)
class FeedforwardAdaptation:
    """Rescale the TCU's command to the clutch it meets, from the estimates of :class:`TorqueEstimator`.

    The feedforward u_ff(t) makes the nominal clutch slip along the optimal path. A clutch whose
    torque gain is g instead of g_nom, or whose load is T_L instead of T_L,nom, follows the same slip
    path (dw_rel/dt = (T_lock - T_c)(1/J_in + 1/J_out)) when its torque is

        T_c = T_c,nom + (T_L - T_L,nom) J_in / (J_in + J_out)

    (the change of T_lock), i.e. when it gets the pressure (g_nom / g) p_nom + (T_L - T_L,nom) J_in /
    ((J_in + J_out) g). The valve lag is linear, so the command is scaled and shifted the same way:

        u = (g_nom / g) (u_ff + du) + (T_L - T_L,nom) J_in / ((J_in + J_out) g)

    with du the LQI correction, scaled with the feedforward so that its loop gain stays the designed
    one. g_nom and T_L,nom are the same estimates taken on the nominal trajectory at the same samples,
    so on the nominal clutch scale = 1 and shift = 0 exactly (the feedback stays idle). The
    adaptation acts while the nominal clutch torque of the sample is at least ``activation`` [N m]:
    before, the films carry the pressure and the torque is not proportional to it; after, on the
    approach to lock-up, the TCU holds its last estimate (:meth:`correction` returns (1, 0) outside
    that stretch). The ratio is kept within [1/gain_limit, gain_limit].

    Parameters
    ----------
    estimator : TorqueEstimator
    nominal : array (N + 1, 3)
        Row k: the nominal T_c [N m], T_L [N m] and mean pressure [Pa] over the sample ending at t_k
        (row 0: the values of row 1).
    activation : float
        Nominal clutch torque [N m] from which on the command is adapted.
    gain_limit : float
        Largest ratio g_nom / g or g / g_nom applied (> 1).
    """

    estimator: TorqueEstimator
    nominal: np.ndarray
    activation: float
    gain_limit: float

    def blended(self, other, weight):
        """The adaptation whose nominal estimates and activation are (1 - weight) x this one's + weight x ``other``'s."""
        w = float(weight)
        if self.nominal.shape != other.nominal.shape:
            raise ModelError("feedforward adaptation: two designs with different horizons cannot be blended")
        return FeedforwardAdaptation(self.estimator, (1 - w) * self.nominal + w * other.nominal,
                                     (1 - w) * self.activation + w * other.activation, self.gain_limit)

    def correction(self, row, previous, current):
        """(scale, shift [Pa]) of the command at a sample, for the nominal ``row`` (T_c, T_L, p_mean) of its time."""
        clutch_nom, load_nom, p_nom = (float(v) for v in row)
        if previous is None or clutch_nom < self.activation or p_nom <= 0.0:
            return 1.0, 0.0
        clutch, load, p_mean = self.estimator.estimate(previous, current)
        if clutch <= 0.0 or p_mean <= 0.0:
            return 1.0, 0.0
        gain, gain_nom = clutch / p_mean, clutch_nom / p_nom
        scale = min(max(gain_nom / gain, 1.0 / self.gain_limit), self.gain_limit)
        J_in, J_out = self.estimator.input_inertia, self.estimator.output_inertia
        return scale, (load - load_nom) * J_in / (J_in + J_out) * scale / gain_nom
