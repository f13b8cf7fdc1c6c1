"""Settings of a hybrid simulation (shared by the IDAS and scipy paths)."""

from dataclasses import dataclass, field, fields

from clutchocp.errors import ModelError

METHODS = ("idas", "cvodes", "Radau", "BDF", "LSODA")
ODE_INTEGRATORS = ("bdf", "adams", "idas")


@dataclass
class SimulationOptions:
    """Tolerances and limits of :func:`clutchocp.simulation.simulate`.

    Parameters
    ----------
    rtol, atol : float
        Relative and absolute integration tolerances; ``atol`` applies to the *scaled*
        variables ``x / x_nominal`` (and ``z / z_nominal`` for IDAS).
    suppress_algebraic : bool
        IDAS only: leave the algebraic variables out of the error test. Needed when an input
        written into the equations (e.g. ``if_else(t >= t1, ...)``) jumps inside an
        integration interval; a :class:`~clutchocp.simulation.model.PiecewiseConstant` input
        is the better fix (the run restarts at its breaks).
    max_num_steps : int
        IDAS step limit per call.
    max_step : float or None
        Largest step [s] (None: unlimited).
    event_time_tol : float
        An event is located when its bracket is this short [s] ...
    event_value_tol : float
        ... or when |event function / scale| is at most this.
    event_band : float
        Hysteresis band on the scaled event functions (see ``README-engine.md``): an event
        whose function is within the band when its mode is entered is disarmed until the
        function leaves the band; leaving on the firing side fires it.
    max_switches : int
        Most mode switches in one simulation.
    max_instant_switches : int
        Most switches at one instant (zero dwell) before the run is declared chattering.
    chunk : int or None
        IDAS: output intervals per integrator call. None (default): each call ends just past
        the predicted next crossing of an event function (quadratic in its time derivatives),
        or at the end of the piece if none is predicted (see ``idas_path``). Every call is a
        restart (order 1, small first step); work integrated past an event is thrown away.
    chunk_growth : float or None
        IDAS, with ``chunk``: multiply the chunk by this after every call that saw no event.
    native : bool
        IDAS: compile each mode's DAE and its Jacobian, its outputs and its event functions that
        call tables to machine code (CasADi code generation and the system C compiler, see
        ``native.py``): the same equations and steps, a faster right-hand side, 0.2-0.5 s of
        compilation per function the first time. Without a C
        compiler the equations are evaluated as usual (with a warning).
    ode_integrator : {"bdf", "adams", "idas"}
        Method ``"idas"``: the integrator of a mode without algebraic variables (an ODE); a mode
        with algebraic variables is always integrated by IDAS. ``"bdf"`` (default): CasADi's
        CVODES with BDF, the ODE counterpart of IDAS's method (fewer steps at the same
        tolerance, no consistent initialisation). ``"adams"``: CVODES Adams-Moulton (for
        non-stiff modes; a call that fails is redone with BDF, which then integrates that mode
        for the rest of the run). ``"idas"``: IDAS.
    idas_options : dict
        Extra options passed to ``casadi.integrator(..., "idas", ...)`` (not to CVODES).
    max_wall_time : float or None
        Wall-time limit of one simulation [s] (None: none). Checked before every integrator
        call (an IDAS or CVODES call is bounded by ``max_num_steps``) and in every right-hand
        side evaluation of the scipy methods; when passed, a SolverError says when and where
        the run stopped.
    """

    rtol: float = 1e-8
    atol: float = 1e-8
    suppress_algebraic: bool = False
    max_num_steps: int = 20000
    max_step: float | None = None
    event_time_tol: float = 1e-9
    event_value_tol: float = 1e-6
    event_band: float = 1e-5
    max_switches: int = 100
    max_instant_switches: int = 5
    chunk: int | None = None
    chunk_growth: float | None = None
    native: bool = False
    ode_integrator: str = "bdf"
    idas_options: dict = field(default_factory=dict)
    max_wall_time: float | None = None

    def __post_init__(self):
        for name in ("rtol", "atol", "event_time_tol", "event_value_tol", "event_band"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and value > 0):
                raise ModelError(f"SimulationOptions.{name} must be a positive number, got {value!r}")
        if self.event_band <= self.event_value_tol:
            raise ModelError("SimulationOptions.event_band must exceed event_value_tol "
                             f"({self.event_band} <= {self.event_value_tol})")
        if self.max_wall_time is not None and not self.max_wall_time > 0:
            raise ModelError(f"SimulationOptions.max_wall_time must be positive or None, got {self.max_wall_time!r}")
        if self.max_step is not None and not self.max_step > 0:
            raise ModelError(f"SimulationOptions.max_step must be positive or None, got {self.max_step!r}")
        if self.chunk is not None and not (isinstance(self.chunk, int) and self.chunk >= 1):
            raise ModelError(f"SimulationOptions.chunk must be a positive integer or None, got {self.chunk!r}")
        if self.ode_integrator not in ODE_INTEGRATORS:
            raise ModelError(f"SimulationOptions.ode_integrator must be one of {ODE_INTEGRATORS}, "
                             f"got {self.ode_integrator!r}")
        if self.chunk_growth is not None and not self.chunk_growth >= 1:
            raise ModelError(f"SimulationOptions.chunk_growth must be >= 1 or None, got {self.chunk_growth!r}")

    def as_dict(self):
        """Plain dictionary (for summaries; the option values are numbers, strings, None and one
        flat dict of IDAS options, copied)."""
        return {f.name: dict(getattr(self, f.name)) if f.name == "idas_options" else getattr(self, f.name)
                for f in fields(self)}
