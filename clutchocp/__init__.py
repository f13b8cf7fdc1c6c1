"""clutchocp: wet-clutch and hydro-viscous-drive simulation, optimal engagement pressure and control.

Python API first; the ``clutchocp`` command is a thin layer over it.
"""

from . import errors
from .scene import Scene, default_scene, list_scenes, load_scene

__version__ = "0.1.0"
__all__ = ["Scene", "default_scene", "errors", "list_scenes", "load_scene", "__version__"]
