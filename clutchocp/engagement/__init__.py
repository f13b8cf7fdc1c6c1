"""Engagement model: the piston, plate pack, films and driveline of a scene as a hybrid DAE."""

from .model import EngagementModel

__all__ = ["EngagementModel"]
