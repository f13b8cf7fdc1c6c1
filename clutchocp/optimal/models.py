"""The engagement models of one scene that an optimisation uses, each built once and passed down.

An optimisation of a scene needs its engagement model with a pressure command input in up to four
places: the collocation problem (the smooth forms of the switching laws, then their exact forms for
the polish stage), the IDAS replays of a command (:mod:`clutchocp.optimal.replay`: the fastest
lock-up, the verification, the whole curve) and the clamp pressure (:mod:`clutchocp.optimal.clamp`).
The exact model with a command input is the same model in all of them (with plate masses the
problem transcribes the scene with a massless pack, a model of its own). :class:`SceneModels` builds
each once for a scene; problems of the same scene (the polish twin, a problem on another mesh, the
minimum-time problem) share it.
"""

import casadi as ca

from ..engagement.model import EngagementModel
from .clamp import ClampModel
from .replay import COMMAND, CommandModel


def quasi_static_scene(scene):
    """The scene with its plates taken as massless (``pack.model = "massless"``)."""
    return scene.with_overrides({"pack.model": "massless", "pack.plate_masses": None})


class SceneModels:
    """The engagement models of ``scene`` with a pressure command input, each built on first use.

    Parameters
    ----------
    scene : clutchocp.scene.Scene
        An engagement scene.
    """

    def __init__(self, scene):
        self.scene = scene
        self._commanded = {}
        self._replays = {}
        self._clamp = None

    def commanded(self, smooth=False, quasi_static_plates=False):
        """The model with the pressure command as its input, and that command's symbol.

        Parameters
        ----------
        smooth : bool
            Smooth forms of the switching laws (else the exact ones).
        quasi_static_plates : bool
            The scene with a massless pack (:func:`quasi_static_scene`).

        Returns
        -------
        (clutchocp.engagement.model.EngagementModel, casadi.SX)
        """
        key = (bool(smooth), bool(quasi_static_plates))
        if key not in self._commanded:
            command = ca.SX.sym(COMMAND)
            scene = quasi_static_scene(self.scene) if quasi_static_plates else self.scene
            self._commanded[key] = (EngagementModel(scene, smooth=smooth, pressure_command=command), command)
        return self._commanded[key]

    def replay(self, control="constant"):
        """The :class:`~clutchocp.optimal.replay.CommandModel` of the scene for a command of that form."""
        if control not in self._replays:
            model, command = self.commanded()
            self._replays[control] = CommandModel(self.scene, control, engagement=model, command=command)
        return self._replays[control]

    def clamp(self):
        """The :class:`~clutchocp.optimal.clamp.ClampModel` of the scene; with plate masses, of the scene
        with a massless pack (a settled pack has its plates at rest: the same films and capacity)."""
        if self._clamp is None:
            masses = self.scene.variant("pack") == "masses"
            scene = quasi_static_scene(self.scene) if masses else self.scene
            self._clamp = ClampModel(scene, *self.commanded(quasi_static_plates=masses))
        return self._clamp
