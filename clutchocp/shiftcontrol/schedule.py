"""Slip feedback scheduled on a scene field the TCU measures: one design per value of a calibration grid.

A transmission control unit reads its sump temperature, so it knows the oil viscosity to within its
sensor and calibration, not the friction coefficient or the load. With ``[schedule] field =
"oil.viscosity"`` and ``points = n`` the feedforward (the nominal optimum of the scene with that
field set, solved with the spec's time margin) and the slip feedback designed along it are made at
n values spread evenly over the field's uncertainty range. A clutch between two grid values is driven
by the two neighbouring designs blended linearly in the field (a TCU interpolating its calibration
tables); the controller meets the rest of the clutch (friction, load, and the error of the
interpolation) as an unknown.
Without a schedule (or a field that is not uncertain) there is one design, on the nominal scene.
"""

from dataclasses import dataclass

import numpy as np

from ..errors import MissingParameterError, ModelError
from .design import design_slip_feedback
from .lqg import design_tcu_feedback
from .sensors import sensors_from_spec


@dataclass
class FeedbackSchedule:
    """Slip-feedback designs at grid values of one scene field (plain data: it is sent to worker processes).

    Attributes
    ----------
    field : str
        The scheduled scene field (``""``: no schedule, one design).
    values : ndarray
        Its grid values (SI); ``[nan]`` without a schedule.
    feedbacks : list of SlipFeedback
        The feedback designed at each grid value.
    overrides : list of dict
        The scene overrides each design was made on (``{}`` without a schedule).
    lock_times : list of float
        Lock-up time of each design's feedforward on its own scene [s].
    adaptation_off : str or None
        Why the spec's feedforward adaptation cannot run on the scene (None: it runs, or the spec has it off).
    sensors : clutchocp.shiftcontrol.sensors.Sensors or None
        What the TCU reads (the Kalman-filter controller; None: the difference controller reads the exact states).
    """

    field: str
    values: np.ndarray
    feedbacks: list
    overrides: list
    lock_times: list
    adaptation_off: str | None = None
    sensors: object = None

    def index(self, scene):
        """Index of the grid value nearest a clutch's own value of the field (0 without a schedule)."""
        if not self.field:
            return 0
        return int(np.argmin(np.abs(self.values - scene.value(self.field))))

    def select(self, scene, value=None):
        """(feedback, overrides of the scene it stands for) for a clutch ``scene``.

        The TCU interpolates its calibration at its reading of the field (``value``; default: the
        clutch's own value): between two grid values the two designs are blended linearly in the field
        (:meth:`SlipFeedback.blended`), outside the grid the end design is used, and two designs that
        cannot be blended (different horizons) give the nearest one.
        """
        if not self.field:
            return self.feedbacks[0], self.overrides[0]
        value = scene.value(self.field) if value is None else float(value)
        upper = int(np.clip(np.searchsorted(self.values, value), 1, len(self.values) - 1))
        weight = (value - self.values[upper - 1]) / (self.values[upper] - self.values[upper - 1])
        if weight <= 0.0 or weight >= 1.0:
            i = upper - 1 if weight <= 0.0 else upper
            return self.feedbacks[i], self.overrides[i]
        blended = self.feedbacks[upper - 1].blended(self.feedbacks[upper], weight)
        if blended is None:
            i = int(np.argmin(np.abs(self.values - value)))
            return self.feedbacks[i], self.overrides[i]
        return blended, {self.field: float(value)}


def schedule_values(scene, spec, uncertainty):
    """Grid values (SI) of the spec's scheduled field over its spread in ``uncertainty`` (``[]``: no schedule).

    Raises
    ------
    ModelError
        The field is not a numeric scene field.
    """
    field = spec.schedule_field
    if not field or spec.schedule_points == 1:
        return []
    try:
        nominal = scene.value(field)
    except MissingParameterError:
        raise MissingParameterError(f"schedule.field = {field!r}: the scene '{scene.name}' has no such field") from None
    if not isinstance(nominal, (int, float)) or isinstance(nominal, bool):
        raise ModelError(f"schedule.field = {field!r}: must be a numeric scene field")
    spread = next((s for s in uncertainty.spreads if s.key == field), None)
    if spread is None or spread.kind == "values" and len(spread.values) == 1:
        return []
    low, high = spread.bounds
    return list(np.linspace(low, high, spec.schedule_points))


def design_schedule(scene, spec, uncertainty, feedforward_for, *, say=print):
    """The feedback schedule of a spec on a scene (see the module docstring).

    Parameters
    ----------
    scene : clutchocp.scene.Scene
        The nominal scene.
    spec : SlipControlSpec
    uncertainty : clutchocp.scene.uncertainty.Uncertainty
    feedforward_for : callable
        ``feedforward_for(design_scene) -> (times [s], command [Pa])``: the feedforward of a design scene.
    say : callable
        Progress messages.

    Returns
    -------
    FeedbackSchedule
    """
    values = schedule_values(scene, spec, uncertainty)
    overrides = [{spec.schedule_field: float(v)} for v in values] or [{}]
    kalman = spec.estimator["method"] == "kalman"
    sensors = sensors_from_spec(spec, scene) if kalman else None
    if sensors is not None and sensors.sump is not None and spec.schedule_field != "oil.viscosity":
        raise ModelError("sensors.sump_temperature: the TCU reads the viscosity through it only with "
                         "schedule.field = \"oil.viscosity\"")
    feedbacks, lock_times, adaptation_off = [], [], None
    for i, override in enumerate(overrides):
        design_scene = scene.with_overrides(override) if override else scene
        if override:
            say(f"  design {i + 1}/{len(overrides)}: {spec.schedule_field} = {values[i]:.4g}")
        times, command = feedforward_for(design_scene)
        if kalman:
            design = design_tcu_feedback(design_scene, times, command, spec, sensors)
        else:
            design = design_slip_feedback(design_scene, times, command, spec)
            adaptation_off = design.adaptation_off
        feedbacks.append(design.feedback)
        lock_times.append(float(design.t_lock))
    return FeedbackSchedule(spec.schedule_field if values else "", np.asarray(values, float) if values
                            else np.array([np.nan]), feedbacks, overrides, lock_times, adaptation_off, sensors)
