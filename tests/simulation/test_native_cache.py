"""Native code: libraries cached on disk by the hash of their source, compiled once per machine."""

import casadi as ca
import numpy as np
import pytest

from clutchocp.simulation import native
from clutchocp.simulation.native import cache_dir, compile_function, compiler, native_status


def test_the_cache_folder_follows_the_environment(monkeypatch, tmp_path):
    monkeypatch.setenv("CLUTCHOCP_NATIVE_CACHE", str(tmp_path / "c"))
    assert cache_dir() == tmp_path / "c"
    monkeypatch.delenv("CLUTCHOCP_NATIVE_CACHE")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert cache_dir() == tmp_path / "xdg" / "clutchocp" / "native"


@pytest.mark.skipif(compiler() is None, reason="no C compiler")
def test_a_function_is_compiled_once_and_then_loaded_from_the_cache(monkeypatch, tmp_path):
    monkeypatch.setenv("CLUTCHOCP_NATIVE_CACHE", str(tmp_path))
    x = ca.SX.sym("x", 2)
    f = ca.Function("sweep_cache_probe", [x], [ca.sin(x[0]) * x[1] + 3.0])
    first = compile_function(f)
    libraries = sorted(tmp_path.glob("sweep_cache_probe_*.so"))
    assert len(libraries) == 1
    stamp = libraries[0].stat().st_mtime_ns
    calls = []
    real_run = native.subprocess.run
    monkeypatch.setattr(native.subprocess, "run", lambda *a, **k: calls.append(a) or real_run(*a, **k))
    second = compile_function(ca.Function("sweep_cache_probe", [x], [ca.sin(x[0]) * x[1] + 3.0]))
    assert calls == [] and libraries[0].stat().st_mtime_ns == stamp            # loaded, not compiled
    assert float(first([0.3, 2.0])) == float(second([0.3, 2.0])) == pytest.approx(np.sin(0.3) * 2 + 3, rel=1e-15)
    other = compile_function(ca.Function("sweep_cache_probe", [x], [ca.sin(x[0]) * x[1] + 4.0]))
    assert len(list(tmp_path.glob("sweep_cache_probe_*.so"))) == 2             # another model, another hash
    assert float(other([0.3, 2.0])) == pytest.approx(np.sin(0.3) * 2 + 4, rel=1e-15)


def test_the_summary_says_whether_native_code_was_used(monkeypatch):
    monkeypatch.setattr(native, "compiler", lambda: None)
    assert native_status(True) == {"requested": True, "used": False, "compiler": None}
    monkeypatch.setattr(native, "compiler", lambda: "/usr/bin/cc")
    assert native_status(True)["used"] and not native_status(False)["used"]
