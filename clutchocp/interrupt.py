"""Stopping a run on Ctrl-C, also inside IDAS and IPOPT.

Python turns SIGINT into ``KeyboardInterrupt`` at the next bytecode. Inside a CasADi call that
exception is caught by CasADi: IDAS reports a failed linear-solver setup ("psetup failed:
KeyboardInterrupt") that the event location and retry logic would take as a numerical failure
and go on, and IPOPT returns ``User_Requested_Stop``, which reads like a solver failure. So the
handler installed by :func:`catch_interrupts` also *remembers* the interrupt in a flag, and the
places that call the solvers ask :func:`check` afterwards (between integrator calls, after every
IPOPT solve, before an output folder is put in place). IPOPT gets an iteration callback
(:func:`ipopt_callback`) that stops it at the next iteration once the flag is set.

Inside a solver call (:func:`in_solver`) the handler only sets the flag: CasADi polls Python's
signal handlers during its evaluations, and an exception raised there is reported on stderr as a
failed evaluation ("res failed: KeyboardInterrupt", "the residual function failed unrecoverably")
before the run could say one line. The call finishes its current piece (an IDAS call between two
events, an IPOPT iteration) and the caller's :func:`check` stops the run.

Without :func:`catch_interrupts` (a library user's own program) the flag is never set and
nothing changes.
"""

import signal
import threading
from contextlib import contextmanager

_state = {"requested": False, "solver_depth": 0}


class UserInterrupt(KeyboardInterrupt):
    """The user pressed Ctrl-C (SIGINT); the message says where the run stopped."""


def requested():
    """True once a SIGINT arrived inside :func:`catch_interrupts` (until it is left)."""
    return _state["requested"]


def check(where=""):
    """Raise :class:`UserInterrupt` if the user asked to stop.

    Parameters
    ----------
    where : str
        What was running, for the message (e.g. ``"IDAS at t = 0.12 s"``).
    """
    if _state["requested"]:
        raise UserInterrupt(f"interrupted by the user{' during ' + where if where else ''}")


def _handler(signum, frame):
    _state["requested"] = True
    if not _state["solver_depth"]:
        raise UserInterrupt("interrupted by the user")


@contextmanager
def in_solver():
    """Around a CasADi solver call: a Ctrl-C only sets the flag (see the module notes); call
    :func:`check` after the block."""
    _state["solver_depth"] += 1
    try:
        yield
    finally:
        _state["solver_depth"] -= 1


@contextmanager
def catch_interrupts():
    """Inside this block a SIGINT sets the flag and raises :class:`UserInterrupt`.

    Only the main thread can install signal handlers; elsewhere the block does nothing.
    The previous handler and a clear flag are restored on exit.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, _handler)
    _state["requested"] = False
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
        _state["requested"] = False


def ipopt_callback():
    """A ``casadi.Callback`` for nlpsol's ``iteration_callback`` option: stop IPOPT on Ctrl-C.

    It returns 1 (stop: IPOPT ends with ``User_Requested_Stop``) once :func:`requested`;
    the caller then calls :func:`check`. One instance serves every solver (it keeps no state).
    """
    if "callback" not in _state:
        _state["callback"] = _make_callback()
    return _state["callback"]


def _make_callback():
    import casadi as ca

    class _StopOnInterrupt(ca.Callback):
        def __init__(self):
            ca.Callback.__init__(self)
            self.construct("stop_on_interrupt", {})

        def get_n_in(self):
            return ca.nlpsol_n_out()

        def get_n_out(self):
            return 1

        def get_name_in(self, i):
            return ca.nlpsol_out(i)

        def get_name_out(self, i):
            return "ret"

        def get_sparsity_in(self, i):
            return ca.Sparsity.dense(0, 0)  # the iterate is not looked at

        def eval(self, arg):
            return [1 if _state["requested"] else 0]

    return _StopOnInterrupt()


def ignore_sigint():
    """Initialiser of a worker process: Ctrl-C is handled by the parent, which stops the workers."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


@contextmanager
def sigint_held():
    """Hold Ctrl-C back while worker processes are forked: a SIGINT during a fork runs its handler
    inside the fork hooks, where the exception is lost; held, it is delivered after the block.
    The workers start with it held and ignore it (:func:`ignore_sigint`)."""
    held = hasattr(signal, "pthread_sigmask") and threading.current_thread() is threading.main_thread()
    if held:
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        if held:
            signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
