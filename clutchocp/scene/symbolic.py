"""A scene some of whose values are CasADi symbols: one model for many values of those fields.

Robust optimisation (the scenarios' values as a parameter vector of one collocation problem) and
sweeps (one model per worker with the swept fields as parameters) both build the engagement model
from such a view; the model builder reads it like any scene.
"""

import casadi as ca


class SymbolicScene:
    """A scene whose fields ``symbols`` read as CasADi symbols; everything else is the scene's.

    Parameters
    ----------
    scene : clutchocp.scene.Scene
    symbols : dict or sequence of str
        ``{"part.key": casadi.SX}``, or field names (a new symbol each).

    Attributes
    ----------
    symbols : dict
        The free parameters, ``{"part.key": casadi.SX}`` in the order given.
    """

    def __init__(self, scene, symbols):
        self._scene = scene
        self.symbols = dict(symbols) if isinstance(symbols, dict) else {name: ca.SX.sym(name) for name in symbols}
        self._read = dict(self.symbols)
        # The lock-up capacity's static coefficient defaults to the (constant) friction coefficient,
        # which would otherwise be read as the nominal number: it follows the symbol.
        if ("friction.mu" in self._read and scene.variant("friction") == "constant"
                and scene.get("friction.static_coefficient") is None):
            self._read["friction.static_coefficient"] = self._read["friction.mu"]

    def value(self, name):
        return self._read[name] if name in self._read else self._scene.value(name)

    def get(self, name, default=None):
        return self._read[name] if name in self._read else self._scene.get(name, default)

    def __getattr__(self, attr):
        return getattr(self.__dict__["_scene"], attr)
