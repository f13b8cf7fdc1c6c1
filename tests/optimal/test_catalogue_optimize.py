"""``clutchocp optimize`` on every clutch of the catalogue (models/catalogue/), as a user runs it: each feasible
clutch ends in an optimum IDAS confirms, each deliberately infeasible one in a one-line refusal that names the
physical limit (the classification of benchmarks/bench_catalogue.py). Slow: 27 optimisations, about an hour
on two loaded cores (run with -m slow)."""

import importlib.util
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
CATALOGUE = sorted((ROOT / "models" / "catalogue").glob("*.toml"))


def _bench():
    spec = importlib.util.spec_from_file_location("bench_catalogue", ROOT / "benchmarks" / "bench_catalogue.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.slow
@pytest.mark.parametrize("path", CATALOGUE, ids=[p.stem for p in CATALOGUE])
def test_catalogue_clutch_is_verified_or_refused_with_its_limit(path, tmp_path):
    bench = _bench()
    row = bench.run_one(bench.clutchocp_command(), path.stem, str(path), "catalogue", tmp_path, timeout=1800)
    expected = "refused" if path.stem.startswith("infeasible_") else "verified"
    assert row["outcome"] == expected, row["message"]
    if expected == "verified":
        assert row["jump_pct"] <= 2.0
