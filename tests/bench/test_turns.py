"""clutchocp.bench.turns: tasks timed side by side, one call each per round, the best of each kept."""

import itertools

import pytest

from clutchocp.bench.turns import best_of_turns, wall


def _recording(log, name, times):
    """A task that logs its calls and reports the next of ``times`` [s] with the call's number."""
    count = itertools.count()

    def task():
        k = next(count)
        log.append(name)
        return times[k], (name, k)

    return task


def test_tasks_take_turns_after_one_untimed_call_each_and_the_fastest_call_counts():
    log = []
    tasks = {"a": _recording(log, "a", [9.0, 3.0, 1.0, 2.0]), "b": _recording(log, "b", [0.1, 5.0, 6.0, 4.0])}
    best = best_of_turns(tasks, 3)
    assert log == ["a", "b"] + ["a", "b"] * 3          # warm-up, then one call of each per round
    assert best == {"a": (1.0, ("a", 2)), "b": (4.0, ("b", 3))}   # the untimed call (b: 0.1 s) never counts
    assert list(best) == ["a", "b"]


def test_a_task_with_fewer_rounds_takes_its_turns_in_the_first_rounds():
    log = []
    tasks = {"slow": _recording(log, "slow", [1.0] * 3), "fast": _recording(log, "fast", [1.0] * 5)}
    best_of_turns(tasks, {"slow": 2, "fast": 4}, warm_up=False)
    assert log == ["slow", "fast", "slow", "fast", "fast", "fast"]


@pytest.mark.parametrize("rounds", [0, -3])
def test_every_task_is_timed_at_least_once(rounds):
    log = []
    best = best_of_turns({"a": _recording(log, "a", [2.0, 1.0])}, rounds)
    assert log == ["a", "a"] and best["a"] == (1.0, ("a", 1))


def test_wall_times_a_call_and_keeps_its_value():
    seconds, value = wall(lambda: sum(range(1000)))()
    assert value == 499500 and 0.0 < seconds < 1.0
