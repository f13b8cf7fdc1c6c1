"""Result of a hybrid simulation: samples, per-mode segments, events and solver statistics."""

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from clutchocp.output import write_csv


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


class LazyOutputs(Mapping):
    """Outputs of a segment by name, each evaluated on all the segment's samples when first read
    and kept.

    A run's outputs (an engagement model has ~42) cost as much as a third of a warm run on its
    output grid, and most readers need few of them (a summary ~15). ``evaluate(names)`` gives
    ``{name: values}`` for at least ``names``; :meth:`load` asks it for several at once. Pickled
    (a result sent to another process), the mapping is a plain dict of all the outputs.

    Parameters
    ----------
    names : list of str
        The outputs, in the mode's order.
    evaluate : callable
        ``evaluate(names) -> {name: array of the segment's samples}``.
    """

    def __init__(self, names, evaluate):
        self._names = list(names)
        self._known = set(self._names)
        self._evaluate = evaluate
        self._values = {}

    def __getitem__(self, name):
        values = self._values.get(name)
        if values is None:
            if name not in self._known:
                raise KeyError(name)
            self.load([name])
            values = self._values[name]
        return values

    def get(self, name, default=None):
        """``self[name]``, or ``default`` if ``name`` is not an output here (without raising and
        catching a KeyError, as ``Mapping.get`` does: a summary asks ~50 times)."""
        values = self._values.get(name)
        if values is not None:
            return values
        return self[name] if name in self._known else default

    def __iter__(self):
        return iter(self._names)

    def __len__(self):
        return len(self._names)

    def __contains__(self, name):
        return name in self._known

    def load(self, names):
        """Evaluate those of ``names`` that are outputs here and not yet evaluated, in one call
        (other names are ignored)."""
        missing = [n for n in dict.fromkeys(names) if n in self._known and n not in self._values]
        if missing:
            self._values.update(self._evaluate(missing))
            if len(self._values) == len(self._names):
                self._evaluate = None                 # everything is here: drop the samples kept for it

    def evaluated(self):
        """Names of the outputs evaluated so far."""
        return [n for n in self._names if n in self._values]

    def __reduce__(self):
        self.load(self._names)
        return dict, ({name: self._values[name] for name in self._names},)

    def __repr__(self):
        return f"LazyOutputs({len(self._names)} outputs, {len(self._values)} evaluated)"


@dataclass
class Segment:
    """Samples of one stretch spent in one mode (unscaled, by name).

    ``outputs`` is a mapping by name: a dict, or :class:`LazyOutputs` evaluating each output on
    first read.
    """

    mode: str
    t: np.ndarray
    x: dict
    z: dict
    outputs: dict

    def names(self):
        return list(self.x) + list(self.z) + list(self.outputs)

    def values_of(self, name, default=None):
        """The samples of state, algebraic variable or output ``name`` (looked up in that order), or
        ``default``; an output is evaluated only when no state or algebraic variable has the name."""
        values = self.x.get(name)
        if values is None:
            values = self.z.get(name)
        if values is None:
            values = self.outputs.get(name, default)
        return values


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
        labels = np.empty(len(segments), dtype=object)     # one mode label a segment, repeated on its samples
        for i, s in enumerate(segments):
            labels[i] = s.mode
        mode = np.repeat(labels, [s.t.size for s in segments])
        return cls(t=t, mode=mode, segments=segments, events=events, stats=stats)

    def load(self, names):
        """Evaluate the outputs ``names`` not evaluated yet, in one call per segment (names that
        are not outputs of a segment's mode are skipped there): several outputs read together
        share the subexpressions they have in common. Reading ``result[name]`` evaluates one output
        by itself; the values are the same either way."""
        names = list(names)
        for seg in self.segments:
            if isinstance(seg.outputs, LazyOutputs):
                seg.outputs.load(names)

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
            values = seg.values_of(name)
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
        return float(seg.values_of(name, [np.nan])[-1])

    def event_times(self, name=None):
        """Times of all switches (or of the events called ``name``)."""
        return np.array([e.t for e in self.events if name is None or e.name == name])


def _short_repr(self):
    modes = []
    for seg in self.segments:
        if not modes or modes[-1] != str(seg.mode):
            modes.append(str(seg.mode))
    span = f"{self.t[0]:.4g} ... {self.t[-1]:.4g} s" if self.t.size else "empty"
    return (f"SimulationResult({self.t.size} samples, {span}, modes {' -> '.join(modes) or 'none'}, "
            f"{len(self.events)} events, {len(self.names())} variables)")


SimulationResult.__repr__ = _short_repr


# column-name suffix -> unit (longest suffixes first)
UNIT_SUFFIXES = (("_rad_s3", "rad/s^3"), ("_rad_s2", "rad/s^2"), ("_rad_s", "rad/s"), ("_m_s", "m/s"),
                 ("_Nm", "N m"), ("_Pa", "Pa"), ("_N", "N"), ("_W", "W"), ("_J", "J"), ("_m", "m"), ("_s", "s"))


def unit_of(name):
    """The unit a column name ends with (``"total_torque_Nm"`` -> ``"N m"``), "" if none."""
    return next((unit for suffix, unit in UNIT_SUFFIXES if name.endswith(suffix)), "")


class Table(dict):
    """Columns of equal length, each named with its unit (``"time_s"``, ``"pressure_Pa"``, ``"mode"``).

    A dict ``{name: numpy array}`` with a short repr, :attr:`units` and :meth:`to_csv`.
    """

    @property
    def units(self):
        """{column: unit} read off the name's suffix ("" for text columns such as ``mode``)."""
        return {name: unit_of(name) for name in self}

    def to_csv(self, path):
        """Write the table as CSV (the header holds the names with their units); returns the path."""
        return write_csv(path, {k: [str(v) for v in col] if k == "mode" else col for k, col in self.items()})

    def __repr__(self):
        rows = len(next(iter(self.values()))) if self else 0
        names = list(self)
        shown = ", ".join(names[:6]) + (f", ... ({len(names)} columns)" if len(names) > 6 else "")
        return f"Table({rows} rows: {shown})"
