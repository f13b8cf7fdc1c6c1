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

import hashlib
import os
import shutil
import subprocess
import tempfile
from pathlib import Path

import casadi as ca

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
    return ca.external(name, str(library))


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
