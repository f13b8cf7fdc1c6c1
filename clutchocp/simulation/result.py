"""Result of a hybrid simulation: samples, per-mode segments, events and solver statistics."""

from dataclasses import dataclass, field

import numpy as np


@dataclass
class EventRecord:
    """One mode switch.

    ``x_before``/``z_before``/``outputs_before`` are in the source mode just before the
    switch, ``*_after`` in the target mode just after the reset (unscaled, by name).
    """

    name: str
    t: float
    source: str
    target: str
    x_before: dict
    x_after: dict
    z_before: dict
    z_after: dict
    outputs_before: dict
    outputs_after: dict
    iterations: int = 0


@dataclass
class Segment:
    """Samples of one stretch spent in one mode (unscaled, by name)."""

    mode: str
    t: np.ndarray
    x: dict
    z: dict
    outputs: dict

    def names(self):
        return list(self.x) + list(self.z) + list(self.outputs)


@dataclass
class SimulationResult:
    """Samples on the output grid plus both sides of every event and input break.

    ``result["w_rel"]`` gives any state, algebraic variable or output on all samples, NaN
    where the current mode does not have it. Times repeat at events (before, after).
    """

    t: np.ndarray
    mode: np.ndarray
    segments: list
    events: list
    stats: dict = field(default_factory=dict)

    @classmethod
    def from_segments(cls, segments, events, stats):
        t = np.concatenate([s.t for s in segments]) if segments else np.zeros(0)
        mode = np.concatenate([np.full(s.t.size, s.mode, dtype=object) for s in segments]) \
            if segments else np.zeros(0, dtype=object)
        return cls(t=t, mode=mode, segments=segments, events=events, stats=stats)

    def names(self):
        """Every state, algebraic variable and output name met in the run."""
        seen = {}
        for seg in self.segments:
            for n in seg.names():
                seen.setdefault(n, None)
        return list(seen)

    def __getitem__(self, name):
        if name not in self:
            raise KeyError(f"'{name}' is not a state, algebraic variable or output of this run; "
                           f"known: {self.names()}")
        parts = []
        for seg in self.segments:
            values = seg.x.get(name, seg.z.get(name, seg.outputs.get(name)))
            parts.append(np.full(seg.t.size, np.nan) if values is None else values)
        return np.concatenate(parts)

    def __contains__(self, name):
        return any(name in seg.x or name in seg.z or name in seg.outputs for seg in self.segments)

    @property
    def final_mode(self):
        return self.segments[-1].mode

    def final(self, name):
        """Value of ``name`` at the last sample (in the final mode)."""
        seg = self.segments[-1]
        return float(seg.x.get(name, seg.z.get(name, seg.outputs.get(name, [np.nan])))[-1])

    def event_times(self, name=None):
        """Times of all switches (or of the events called ``name``)."""
        return np.array([e.t for e in self.events if name is None or e.name == name])
