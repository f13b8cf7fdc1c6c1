"""Timing things side by side: every task once per round, the best of each counts.

A ratio of two times is only as good as the conditions the two were taken under. Timed one after
the other, each over all its repeats, two times are taken seconds or minutes apart, and a machine
that slows down for a while (another process, a thermal limit) slows one and not the other: on the
quick bench single timings moved by up to 1.7x that way. Taking turns (one timed call of every task
per round, the best of each over the rounds) times them alike: a slow stretch slows every task of
its rounds, and the best of each comes from its fastest stretch.
"""

import math
import time


def best_of_turns(tasks, rounds, warm_up=True):
    """Call every task once per round, after one untimed call of each.

    Parameters
    ----------
    tasks : dict of str to callable
        ``name -> task``; a task takes no argument and returns ``(seconds, value)``: the time it
        measured itself [s] (its whole call, or the part it times, e.g. the integrations of a floor
        pass) and anything to keep from its fastest call.
    rounds : int or dict of str to int
        Timed calls of every task (at least one), or per task (``name -> count``): a task with
        fewer takes its turns in the first rounds (e.g. a slow peer timed a third as often).
    warm_up : bool
        Call every task once, untimed, before the rounds (builds and caches what the first call
        builds).

    Returns
    -------
    dict of str to (float, object)
        ``name -> (best seconds, value of that call)``, in the order of ``tasks``.
    """
    if warm_up:
        for task in tasks.values():
            task()
    counts = {name: max(1, rounds[name] if isinstance(rounds, dict) else rounds) for name in tasks}
    best = {name: (math.inf, None) for name in tasks}
    for round_ in range(max(counts.values(), default=0)):
        for name in (n for n in tasks if round_ < counts[n]):
            seconds, value = tasks[name]()
            if seconds < best[name][0]:
                best[name] = (seconds, value)
    return best


def wall(call):
    """A task (:func:`best_of_turns`) of ``call``: its wall time [s] and its return value."""
    def task():
        start = time.perf_counter()
        value = call()
        return time.perf_counter() - start, value

    return task
