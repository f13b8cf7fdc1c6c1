"""``clutchocp optimize`` on every clutch of the catalogue (models/catalogue/), as a user runs it: each feasible
clutch ends in an optimum IDAS confirms, each deliberately infeasible one in a one-line refusal that names the
physical limit (the classification of benchmarks/bench_catalogue.py). Slow: 27 optimisations, about an hour
on two loaded cores (run with -m slow)."""

from pathlib import Path

import pytest
from repo_scripts import load_script

ROOT = Path(__file__).resolve().parents[2]
CATALOGUE = sorted((ROOT / "models" / "catalogue").glob("*.toml"))


def _bench():
    return load_script("benchmarks/bench_catalogue.py")


@pytest.mark.slow
@pytest.mark.parametrize("path", CATALOGUE, ids=[p.stem for p in CATALOGUE])
def test_catalogue_clutch_is_verified_or_refused_with_its_limit(path, tmp_path):
    bench = _bench()
    row = bench.run_one(bench.clutchocp_command(), path.stem, str(path), "catalogue", tmp_path, timeout=1800)
    expected = "refused" if path.stem.startswith("infeasible_") else "verified"
    assert row["outcome"] == expected, row["message"]
    if expected == "verified":
        assert row["jump_pct"] <= 2.0


@pytest.mark.parametrize("message", [
    "scene 'x': pressure limit: at actuation.max_pressure = 0.6 MPa the pack holds at most 356 N m",
    "scene 'x': piston: the return springs need 0.512 MPa to reach the pack (the kiss point)",
    "scene 'x': contact capacity: the asperities carry at most 0.07619 MPa at a film of 0.02 sigma",
    "scene 'x': t_max = 0.1195 s is below the fastest lock-up that meets the end conditions",
    "scene 'x': temperature limit: a lock-up dissipates at least 2500 J",
    "scene 'x': specific-power limit: the open pack's drag already releases 0.09948 W/mm^2 at t = 0",
    "clamp margin 1.3: the pack's static capacity at 0.4722 MPa (the most the contact carries) is 167 N m",
    "scene 'x': even a step to actuation.max_pressure = 1.5 MPa does not lock up within simulation.t_end",
])
def test_the_optimisers_refusals_count_as_refusals(message):
    """Each refusal of clutchocp.optimal names a limit the benchmark recognises (and no solver)."""
    outcome, _ = _bench().classify(2, f"clutchocp optimize: error: {message}\n", None)
    assert outcome == "refused"


def test_the_table_goes_between_the_markers_of_the_page(tmp_path):
    bench = _bench()
    page = tmp_path / "benchmarks.md"
    page.write_text(f"## Catalogue\n\nText.\n\n{bench.DOCS_START}\nold\n{bench.DOCS_END}\n\n## Next\n", encoding="utf-8")
    bench.write_docs(page, ["# title", "", "| a |", "|---|", "| 1 |"])
    text = page.read_text(encoding="utf-8")
    assert "old" not in text and "| 1 |" in text and "# title" not in text
    assert text.startswith("## Catalogue") and text.rstrip().endswith("## Next")
