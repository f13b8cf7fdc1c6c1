"""Solver failures turned into messages that say when, where, why and what to try."""

import re

import numpy as np

from clutchocp.errors import ModelEdgeError, SolverError

_RESIDUAL = (("the equations gave NaN or Inf: an expression left its domain (log or sqrt of a negative "
              "number, division by zero), e.g. a gap closed without an event"),
             "add an event before the expression leaves its domain, or guard it (fmax) in the model")
_CALC_IC = ("consistent initial conditions (IDACalcIC) failed",
            "give a better z guess (Mode z_guess) or check the nominal scales")
HINTS = {
    "IDA_TOO_MUCH_WORK": (("the step limit was reached: the model is becoming singular or extremely stiff "
                           "here, or is badly scaled"),
                          ("check the nominal scales of the states, raise max_num_steps, or add an event where "
                           "the model changes character")),
    "IDA_TOO_MUCH_ACC": ("the tolerances cannot be met in floating point", "loosen rtol/atol"),
    "IDA_ERR_FAIL": ("repeated error-test failures: the solution or an input is discontinuous here",
                     ("give a jumping input as PiecewiseConstant, or set suppress_algebraic=True, "
                      "or add an event at the switch")),
    "IDA_CONV_FAIL": ("the Newton iteration did not converge",
                      "check the nominal scales and that d alg / d z is non-singular (index 1)"),
    "IDA_LSETUP_FAIL": ("the Jacobian could not be factorised (singular)",
                        "check that every algebraic variable is determined (index 1) and the scales"),
    "IDA_LSOLVE_FAIL": ("the linear solve failed (singular Jacobian)",
                        "check that every algebraic variable is determined (index 1) and the scales"),
    "IDA_RES_FAIL": _RESIDUAL,
    "IDA_REP_RES_ERR": _RESIDUAL,
    "IDA_FIRST_RES_FAIL": _RESIDUAL,
    "IDA_ILL_INPUT": ("IDAS rejected its input (non-finite values or an output interval too short)",
                      "check the initial state and the output grid"),
    "IDA_NO_RECOVERY": _CALC_IC,
    "IDA_LINESEARCH_FAIL": _CALC_IC,
    "IDA_CONSTR_FAIL": _CALC_IC,
    "IDA_BAD_EWT": ("a tolerance weight became non-positive or non-finite",
                    "check for NaN/Inf in the state, and that atol > 0"),
}
HINTS["scipy"] = ("the step size collapsed: the solution blows up or the model is singular here",
                  ("check the model near this time (a vanishing gap or denominator), the nominal scales, "
                   "or loosen the tolerances"))
HINTS["no_convergence"] = ("the algebraic equations could not be solved for z at this state",
                          ("give a better z guess (Mode z_guess), check the residual and z nominal scales, and "
                           "that d alg / d z is non-singular"))
HINTS["wall_time"] = (("the wall-time limit (SimulationOptions.max_wall_time) was reached: the model is extremely "
                       "stiff, badly scaled or switching modes very often here"),
                      ("look at the states named here for a vanishing gap or a huge scale, loosen rtol/atol, or "
                       "raise max_wall_time"))
# CVODES's flags whose IDAS counterpart has another name (the rest differ only in the prefix)
CVODES_AS_IDAS = {"CV_CONV_FAILURE": "IDA_CONV_FAIL", "CV_ERR_FAILURE": "IDA_ERR_FAIL",
                  "CV_RHSFUNC_FAIL": "IDA_RES_FAIL", "CV_REPTD_RHSFUNC_ERR": "IDA_REP_RES_ERR",
                  "CV_FIRST_RHSFUNC_ERR": "IDA_FIRST_RES_FAIL", "CV_UNREC_RHSFUNC_ERR": "IDA_RES_FAIL"}
_DEFAULT = ("the integrator stopped", "tighten or loosen the tolerances, check the scales and the model")


def idas_flag(message):
    """The IDAS (or CVODES) return flag named in a CasADi error message (or 'unknown')."""
    found = re.search(r"((?:IDA|CV)_[A-Z_]+)", str(message))
    return found.group(1) if found else "unknown"


def largest_scaled(names, scaled, nominal, count=3):
    """Text listing the ``count`` largest |scaled| values with their unscaled values."""
    scaled = np.asarray(scaled, float).ravel()
    if scaled.size == 0:
        return "none"
    order = np.argsort(-np.nan_to_num(np.abs(scaled), nan=np.inf))[:count]
    return ", ".join(f"{names[k]} = {scaled[k] * nominal[k]:.6g} ({scaled[k]:.3g} x nominal)" for k in order)


def solver_error(solver, flag, t, cm, xs, zs=None, detail=""):
    """Build a :class:`~clutchocp.errors.SolverError` for a failure at time ``t`` in mode ``cm``."""
    flag_as_idas = CVODES_AS_IDAS.get(flag) or str(flag).replace("CV_", "IDA_", 1)
    why, remedy = HINTS.get(flag) or HINTS.get(flag_as_idas, _DEFAULT)
    where = f"Largest scaled states: {largest_scaled(cm.x_names, xs, cm.x_nominal)}"
    if zs is not None and cm.nz:
        where += f"; algebraic: {largest_scaled(cm.z_names, zs, cm.z_nominal)}"
    message = (f"{solver} failed at t = {t:.12g} s in mode '{cm.name}' ({flag}: {why}{detail}). "
               f"{where}. Try: {remedy}.")
    err = SolverError(message)
    err.t, err.mode, err.flag = float(t), cm.name, flag
    err.states = cm.x_dict(xs)
    return err


def edge_error(spec, t, cm, xs, zs, outputs):
    """Build a :class:`~clutchocp.errors.ModelEdgeError` for the edge event ``spec`` (a compiled
    :class:`~clutchocp.simulation.compiled.EventSpec` with ``edge`` text) fired at time ``t`` in mode ``cm``.

    The error carries ``t``, ``mode``, ``event`` (its name), ``edge`` (its text), ``states`` (unscaled)
    and ``outputs`` (the mode's outputs there), so that the model's own layer can say why in its terms.
    """
    err = ModelEdgeError(f"{spec.edge} at t = {t:.9g} s in mode '{cm.name}': the model has no result beyond it")
    err.t, err.mode, err.event, err.edge, err.flag = float(t), cm.name, spec.name, spec.edge, "edge"
    err.states = cm.x_dict(xs)
    err.outputs = outputs
    return err
