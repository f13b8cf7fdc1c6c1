"""A one-line-per-step progress display on stderr (silent when disabled)."""

import sys
import time


class Progress:
    """Counter, bar, elapsed time and a note for every finished step, written to ``stream``.

    Parameters
    ----------
    total : int
        Number of steps expected (the bar is capped at full if more come).
    enabled : bool
        False: print nothing.
    stream : file-like, optional
        Default ``sys.stderr``.
    """

    def __init__(self, total, enabled=True, stream=None):
        self.total, self.done, self.enabled = max(int(total), 1), 0, enabled
        self.stream = stream or sys.stderr
        self.start = time.perf_counter()

    @property
    def elapsed(self):
        """Seconds since the display started."""
        return time.perf_counter() - self.start

    def step(self, text):
        """Count one step and show ``text`` beside the bar."""
        self.done += 1
        self.note(text)

    def note(self, text):
        """Show ``text`` without counting a step."""
        if not self.enabled:
            return
        filled = round(20 * min(self.done, self.total) / self.total)
        self.stream.write(f"[{'#' * filled:<20}] {self.done:3d}/{self.total} {self.elapsed:6.1f} s  {text}\n")
        self.stream.flush()
