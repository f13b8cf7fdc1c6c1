"""Scene files: a clutch and the physics it needs (see :mod:`clutchocp.scene.schema`)."""

from .loader import Scene, builtin_scene_dir, default_scene, list_scenes, load_scene, parse_override

__all__ = ["Scene", "builtin_scene_dir", "default_scene", "list_scenes", "load_scene", "parse_override"]
