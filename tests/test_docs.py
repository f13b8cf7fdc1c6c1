"""The documentation stays true: generated numbers, examples that run, documented keys, links that resolve.

The numbers the docs quote are measured by ``python benchmarks/docs_numbers.py`` and stored in
``benchmarks/docs_numbers.json``; here every generated block is checked against that JSON, the
cheap numbers are computed again, every Python example in docs/ runs, every summary.json key and
CSV column a command writes is on its page, and every .md path a doc names exists.
"""

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

import clutchocp
from clutchocp.cli import build_parser, main
from clutchocp.scene import load_scene
from repo_scripts import load_script

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
# The live re-computation of a stored number agrees within this relative tolerance: the runs are
# deterministic on one machine; this allows the last digits of another BLAS or compiler.
LIVE_REL_TOL = 1e-3


def load_docs_numbers():
    return load_script("benchmarks/docs_numbers.py")


dn = load_docs_numbers()
NUMBERS = dn.load_numbers()
USER_DOCS = [ROOT / "README.md", *sorted(DOCS.rglob("*.md")), ROOT / "models" / "README.md",
             ROOT / "controllers" / "README.md", ROOT / "CHANGELOG.md", ROOT / "benchmarks" / "RESULTS.md"]


def python_blocks():
    """(page, index, code) of every python block in docs/ (the README's example: test_readme.py)."""
    out = []
    for page in sorted(DOCS.rglob("*.md")):
        for k, code in enumerate(re.findall(r"```python\n(.*?)```", page.read_text(encoding="utf-8"), re.S)):
            out.append(pytest.param(code, id=f"{page.relative_to(ROOT)}#{k + 1}"))
    return out


# -- generated numbers --------------------------------------------------------------------------------
@pytest.mark.parametrize("page", dn.doc_files(), ids=lambda p: str(p.relative_to(ROOT)))
def test_docs_generated_blocks_are_what_the_stored_numbers_render(page):
    text = page.read_text(encoding="utf-8")
    for name, content in dn.blocks(text):
        assert name in dn.RENDERERS, f"{page.name}: unknown generated block '{name}'"
    assert dn.render_text(text, NUMBERS) == text, (
        f"{page.relative_to(ROOT)} is out of date: run `python benchmarks/docs_numbers.py --render` "
        "(or measure again without --render)")


def test_docs_every_block_has_numbers_measured():
    used = {name for page in dn.doc_files() for name, _ in dn.blocks(page.read_text(encoding="utf-8"))}
    for name in used:
        dn.RENDERERS[name](NUMBERS)          # raises KeyError if its item was never measured


def test_docs_scene_keys_page_is_generated_from_the_schema():
    assert dn.SCENE_KEYS.read_text(encoding="utf-8") == dn.scene_keys_page(), (
        "docs/scene-keys.md differs from clutchocp/scene/schema.py: run `python benchmarks/docs_numbers.py --render`")


def test_docs_scene_keys_page_lists_every_key_of_the_schema():
    from clutchocp.scene.schema import PARTS

    page = dn.SCENE_KEYS.read_text(encoding="utf-8")
    for name, part in PARTS.items():
        assert f"## {name}\n" in page
        for key in [*part.fields, *(k for fields in part.variants.values() for k in fields)]:
            assert f"| `{key}` |" in page, f"[{name}] {key}"


def test_docs_default_optimum_computed_again_matches_the_stored_one():
    stored = NUMBERS["optimize_default"]["optimal"]
    best = clutchocp.optimize()
    for key in ("engagement_time_s", "dissipated_energy_J", "jerk_integral"):
        assert best.summary["optimal"][key] == pytest.approx(stored[key], rel=LIVE_REL_TOL), key


# -- documented keys --------------------------------------------------------------------------------------
def test_docs_every_key_the_commands_wrote_is_documented():
    assert dn.undocumented_all(NUMBERS) == {}


def test_docs_the_key_check_reports_what_a_page_lacks(tmp_path):
    page = tmp_path / "page.md"
    page.write_text("| `a.{b,c}.d` | `runs[].<name>_s` | `x_<i>_m` | `out.png` |\n")
    keys = {"summary": [["a", "b", "d"], ["a", "c", "d"], ["runs[]", "lock_s"], ["a", "e", "d"], ["runs[]", "*"],
                        ["empty[]", "*"]],
            "csv": {"t.csv": ["x_3_m", "y_3_m"]}, "files": ["out.png", "other.png"]}
    assert dn.undocumented(keys, page) == ["a.e.d", "empty[].*", "t.csv: y_3_m", "file other.png"]


def test_docs_optimize_timeseries_columns_are_checked_on_the_simulate_page():
    """optimize writes its IDAS replay with simulate's columns: they are looked up on simulate's page."""
    keys = {"summary": [["scene"]], "csv": {"timeseries.csv": ["h_1", "no_such_column_xyz"]}, "files": []}
    missing = dn.undocumented_all({"optimize_default": {"keys": keys}})
    assert missing == {"optimize": ["timeseries.csv: no_such_column_xyz"]}


def test_docs_a_placeholder_alone_documents_only_scene_field_columns(tmp_path):
    page = tmp_path / "page.md"
    page.write_text("film number `<i>`; one column per swept field: `<field>`\n")
    keys = {"summary": [["lockup_s"], ["runs[]", "x"]], "csv": {"r.csv": ["oil.viscosity", "T_core"]},
            "files": ["a.png"]}
    assert dn.undocumented(keys, page) == ["lockup_s", "runs[].x", "r.csv: T_core", "file a.png"]


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """The folders of the quick commands, run now: {command: folder_keys}."""
    out = tmp_path_factory.mktemp("written")
    runs = {"simulate": [["simulate", "bao2020"], ["simulate", "default_driveline_thermal"]],
            "cycles": [["cycles", "default_driveline_thermal", "--cycles", "2", "--cooling-time", "1"]],
            "validate": [["validate"]],
            "sweep": [["sweep", "zhang2021", "--grid", "oil.viscosity=0.05:0.07:2", "--engine", "serial"]]}
    found = {}
    for command, argvs in runs.items():
        keys = []
        for k, argv in enumerate(argvs):
            folder = out / f"{command}_{k}"
            assert main([*argv, "--out", str(folder)]) == 0
            keys.append(dn.folder_keys(folder))
        found[command] = dn.merge_keys(*keys)
    return found


@pytest.mark.parametrize("command", ["simulate", "cycles", "validate", "sweep"])
def test_docs_the_keys_a_command_writes_now_are_on_its_page(command, written):
    assert dn.undocumented(written[command], DOCS / "commands" / f"{command}.md") == []


# -- pages, examples, links -----------------------------------------------------------------------------------
def test_docs_every_command_has_its_page():
    commands = set(build_parser()._subparsers._group_actions[0].choices)
    pages = {p.stem for p in (DOCS / "commands").glob("*.md")}
    assert commands <= pages, commands - pages
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    for command in commands:
        assert f"(docs/commands/{command}.md)" in readme


def test_docs_layout_pages_exist():
    for page in ("index", "quickstart", "own-clutch", "scene-keys", "controllers", "physics", "api", "benchmarks"):
        assert (DOCS / f"{page}.md").is_file(), page
    assert (ROOT / "CHANGELOG.md").read_text().startswith("# Changelog\n\n## Unreleased\n")
    assert (ROOT / "benchmarks" / "RESULTS.md").is_file()


@pytest.mark.parametrize("page", USER_DOCS, ids=lambda p: str(p.relative_to(ROOT)))
def test_docs_every_md_path_named_exists(page):
    text = page.read_text(encoding="utf-8")
    links = re.findall(r"\]\(([^)#\s]+\.md)(?:#[^)]*)?\)", text)
    spans = [s for s in re.findall(r"`([^`\s]+\.md)`", text) if "/" in s or (page.parent / s).exists()]
    for target in links:
        assert (page.parent / target).resolve().is_file(), f"{page.name}: link to {target}"
    for target in spans:
        assert (page.parent / target).is_file() or (ROOT / target).is_file(), f"{page.name}: {target}"


@pytest.mark.parametrize("page", USER_DOCS, ids=lambda p: str(p.relative_to(ROOT)))
def test_docs_point_to_nothing_a_user_does_not_have(page):
    text = page.read_text(encoding="utf-8")
    for pattern in ("../shared", "/work/", "shared/PHYSICS", "shared/DESIGN"):
        assert pattern not in text, f"{page.name} names {pattern}"


@pytest.mark.parametrize("code", python_blocks())
def test_docs_python_examples_run(code, tmp_path):
    proc = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=600,
                          env={**os.environ, "MPLBACKEND": "Agg"})
    assert proc.returncode == 0, proc.stderr[-2000:]


def test_docs_own_clutch_template_is_a_scene_that_locks(tmp_path):
    template = re.search(r"```toml\n(.*?)```", (DOCS / "own-clutch.md").read_text(encoding="utf-8"), re.S).group(1)
    path = tmp_path / "my_clutch.toml"
    path.write_text(template)
    scene = load_scene(path)
    assert scene.name == "my_clutch" and scene.has("thermal") and len(scene.uncertainty.names) == 3
    run = clutchocp.simulate(scene)
    assert run.summary["engagement_time_s"] is not None and run.summary["energy_balance_rel_error"] < 1e-6


def test_docs_stored_numbers_say_when_and_how_they_were_measured():
    for item, values in NUMBERS.items():
        assert item in dn.ITEMS, f"benchmarks/docs_numbers.json holds an unknown item '{item}'"
        assert re.fullmatch(r"\d{4}-\d\d-\d\d", values["measured"]), item
    json.dumps(NUMBERS, allow_nan=False)        # no NaN or infinity in the stored numbers
