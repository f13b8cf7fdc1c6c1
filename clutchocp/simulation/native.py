"""CasADi functions compiled to machine code (opt-in: ``SimulationOptions(native=True)``).

CasADi generates C for a mode's normalised-time DAE (``CompiledMode.dae_tau``) with its Jacobian,
for its outputs and, where they call tables (interpolants), for its event functions
(``CompiledMode.event_values``); the system C compiler builds shared libraries that
``casadi.external`` loads. IDAS then integrates the same equations, with the right-hand side and Jacobian evaluated
as compiled code instead of CasADi's SX virtual machine: the same steps and results (bao2020:
2012 steps, lock-up time equal to 12 digits), the run 15 ms instead of 22 ms. Compiling costs
0.2-0.5 s per function; the libraries are kept in a per-user cache directory (:func:`cache_dir`),
named by the hash of their generated source (the model with all its numbers, and the compiler
flags), so the same model is compiled once per machine and later processes load it.

Scene values enter the equations as numbers, so a model built for one set of values has its own
hash: compiling it (1.6 s for a zhang2021 point, 4.4 s for bao2020, measured) costs far more than
its run on CasADi's virtual machine (0.2-1 s). Native code is therefore opt-in for single runs
(``SimulationOptions(native=True)``, ``clutchocp simulate --native``) and the default of sweeps
only for a model reused over all points (:mod:`clutchocp.study.parametric`), whose source does not
depend on the swept values: compiled once per machine, then loaded.
"""

import ctypes
import hashlib
import os
import shutil
import subprocess
import tempfile
from pathlib import Path

import casadi as ca
import numpy as np

FLAGS = ("-O1", "-fPIC", "-shared")


def cache_dir():
    """Folder of the compiled libraries: ``$CLUTCHOCP_NATIVE_CACHE``, else
    ``$XDG_CACHE_HOME/clutchocp/native``, else ``~/.cache/clutchocp/native`` (created on first use)."""
    explicit = os.environ.get("CLUTCHOCP_NATIVE_CACHE")
    if explicit:
        return Path(explicit)
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "clutchocp" / "native"


_FOUND = {}             # ($CC, $PATH) -> the compiler found for them (a sweep asks at every point)


def compiler():
    """Path of the C compiler ($CC, else cc or gcc), or None (looked up once per $CC and $PATH)."""
    key = (os.environ.get("CC"), os.environ.get("PATH"))
    if key not in _FOUND:
        _FOUND[key] = next((shutil.which(name) for name in (key[0], "cc", "gcc") if name and shutil.which(name)),
                           None)
    return _FOUND[key]


def compile_function(function, with_jacobian=False):
    """``function`` as an external Function built from generated C (None if that fails).

    Parameters
    ----------
    function : casadi.Function
        The function to compile; its name is the symbol looked up in the library.
    with_jacobian : bool
        Also compile its Jacobian (``jac_<name>``), which CasADi then uses for derivatives
        (IDAS's Newton matrix).
    """
    library = _library(function, with_jacobian)
    return ca.external(function.name(), str(library)) if library is not None else None


# A loop over samples compiled next to a function (see compile_columns). ``NAME`` is the function's
# C symbol. Input i of sample k starts at ``in[i] + k * stride_in[i]`` (stride 0: shared by all
# samples), output j at ``out[j] + k * stride_out[j]``; each sample is one call of the generated
# function itself, so every value is bit for bit the one a call through CasADi gives.
_COLUMNS_C = """
#include <stdlib.h>
CASADI_SYMBOL_EXPORT int NAME_columns(const casadi_real** in, const casadi_int* stride_in, casadi_real** out,
                                      const casadi_int* stride_out, casadi_int n) {
  casadi_int sz_arg, sz_res, sz_iw, sz_w, k, i, n_in = NAME_n_in(), n_out = NAME_n_out();
  const casadi_real** arg;
  casadi_real** res;
  casadi_int* iw;
  casadi_real* w;
  int mem, flag = 0;
  NAME_work(&sz_arg, &sz_res, &sz_iw, &sz_w);
  arg = (const casadi_real**) malloc((sz_arg + 1) * sizeof(const casadi_real*));
  res = (casadi_real**) malloc((sz_res + 1) * sizeof(casadi_real*));
  iw = (casadi_int*) malloc((sz_iw + 1) * sizeof(casadi_int));
  w = (casadi_real*) malloc((sz_w + 1) * sizeof(casadi_real));
  if (!arg || !res || !iw || !w) flag = 2;
  NAME_incref();
  mem = NAME_checkout();
  for (k = 0; k < n && !flag; ++k) {
    for (i = 0; i < n_in; ++i) arg[i] = in[i] + k * stride_in[i];
    for (i = 0; i < n_out; ++i) res[i] = out[i] + k * stride_out[i];
    if (NAME(arg, res, iw, w, mem)) flag = 1;
  }
  NAME_release(mem);
  NAME_decref();
  free(arg); free(res); free(iw); free(w);
  return flag;
}
"""


def compile_columns(function):
    """``function`` compiled with a loop over samples: ``(external, loop)``, or None if that fails.

    ``external`` is the compiled function as a CasADi Function (as :func:`compile_function`);
    ``loop(inputs, strides, outputs, strides_out, n)`` evaluates it on ``n`` samples in one call
    from Python (``ctypes``): ``inputs`` and ``outputs`` are C-contiguous float64 numpy arrays
    holding sample ``k`` of argument ``i`` from element ``k * strides[i]`` on. A CasADi ``map``
    of the external costs ~0.2 us a sample in CasADi's calling machinery around each call (the
    outputs of a 2 000-sample run: ~0.4 ms); the loop calls the generated function directly.
    """
    library = _library(function, False, _COLUMNS_C.replace("NAME", function.name()))
    if library is None:
        return None
    try:
        entry = getattr(ctypes.CDLL(str(library)), f"{function.name()}_columns")
    except (OSError, AttributeError):
        return None
    entry.restype = ctypes.c_int
    entry.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_longlong]
    n_in, n_out = function.n_in(), function.n_out()

    def loop(inputs, strides, outputs, strides_out, n):
        pointers = np.array([a.ctypes.data for a in inputs], dtype=np.uintp)
        steps = np.asarray(strides, dtype=np.int64)
        results = np.array([a.ctypes.data for a in outputs], dtype=np.uintp)
        steps_out = np.asarray(strides_out, dtype=np.int64)
        assert len(inputs) == n_in and len(outputs) == n_out
        return entry(pointers.ctypes.data, steps.ctypes.data, results.ctypes.data, steps_out.ctypes.data, int(n))

    return ca.external(function.name(), str(library)), loop


def _library(function, with_jacobian, extra=""):
    """Path of the shared library of ``function`` (compiled now unless already in the cache), or None.

    ``extra`` is C source appended to the generated file (it enters the hash)."""
    cc = compiler()
    if cc is None:
        return None
    name = function.name()
    with tempfile.TemporaryDirectory() as work:
        generator = ca.CodeGenerator(f"{name}.c", {"with_header": False})
        generator.add(function)
        if with_jacobian:
            generator.add(function.jacobian())
        generator.generate(work + os.sep)
        source = Path(work, f"{name}.c")
        if extra:
            source.write_text(source.read_text() + extra)
        digest = hashlib.sha1(source.read_bytes() + f"{cc} {' '.join(FLAGS)}".encode()).hexdigest()[:16]
        folder = cache_dir()
        library = folder / f"{name}_{digest}.so"
        if not library.is_file():
            folder.mkdir(parents=True, exist_ok=True)
            partial = folder / f"{name}_{digest}.{os.getpid()}.tmp"
            built = subprocess.run([cc, *FLAGS, str(source), "-o", str(partial)], capture_output=True, check=False)
            if built.returncode != 0:
                partial.unlink(missing_ok=True)
                return None
            partial.replace(library)                  # atomic: concurrent processes never see half a file
    return library


def native_dae(cm):
    """The normalised-time DAE of compiled mode ``cm``, compiled with its Jacobian (or None).

    An external with the integrator's inputs (t, x, z, p, u) and outputs (ode, alg, quad, zero).
    """
    d = cm.dae_tau
    empty = ca.SX(0, 1)
    dae = ca.Function(f"{cm.name}_dae", [d["t"], d["x"], d["z"], d["p"], empty], [d["ode"], d["alg"], empty, empty],
                      ca.dyn_in(), ca.dyn_out())
    return compile_function(dae, with_jacobian=True)


def native_status(requested):
    """Whether compiled native code is used, for a summary.

    Parameters
    ----------
    requested : bool
        Whether the run asked for native code.

    Returns
    -------
    dict
        ``requested``, ``used`` (requested and a C compiler exists) and ``compiler`` (its path, or
        None: the equations are then evaluated by CasADi's virtual machine).
    """
    cc = compiler()
    return {"requested": bool(requested), "used": bool(requested and cc is not None), "compiler": cc}
