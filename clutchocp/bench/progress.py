"""The progress of a benchmark on stderr: a tqdm bar (steps done, elapsed time) and a note line per step."""

import sys

from tqdm import tqdm


class Progress(tqdm):
    """A tqdm bar counting the steps of a benchmark, with a line above it for every note.

    Parameters
    ----------
    total : int
        Number of steps expected.
    enabled : bool
        False: print nothing.
    stream : file-like, optional
        Default ``sys.stderr``.
    """

    def __init__(self, total, enabled=True, stream=None):
        super().__init__(total=max(int(total), 1), disable=not enabled, file=stream or sys.stderr, unit="step",
                         dynamic_ncols=True)

    def step(self, text):
        """Count one step and write ``text`` above the bar."""
        self.update(1)
        self.note(text)

    def note(self, text):
        """Write ``text`` above the bar, after the elapsed time, without counting a step."""
        if not self.disable:
            self.write(f"{self.format_interval(self.format_dict['elapsed'])}  {text}", file=self.fp)
