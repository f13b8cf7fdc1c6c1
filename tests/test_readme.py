"""The README: short, the two set-up commands CI runs at its top, an example whose printed numbers are true."""

import os
import re
import subprocess
import sys
from pathlib import Path
from repo_scripts import load_script

ROOT = Path(__file__).resolve().parent.parent
README = (ROOT / "README.md").read_text(encoding="utf-8")
SETUP = (
    'python3 -m venv .venv && . .venv/bin/activate && pip install . && clutchocp optimize --out out/optimize',
    'python3 -m venv .venv && . .venv/bin/activate && pip install ".[test]" && pytest',
)


def load_docs_numbers():
    return load_script("benchmarks/docs_numbers.py")


def test_readme_is_read_in_five_minutes():
    assert len(README.splitlines()) <= 300


def test_readme_opens_with_the_two_setup_commands_byte_for_byte():
    first_block = README.split("```bash\n", 1)[1].split("```", 1)[0]
    assert first_block.splitlines() == list(SETUP)
    assert README.index("```bash") < README.index("\n## ")          # before any section


def numbers_in(text):
    """[(value, decimals)] of every number printed in ``text``, in order."""
    return [(float(m), len(m.split(".")[1].split("e")[0]) if "." in m else 0)
            for m in re.findall(r"-?\d+(?:\.\d+)?(?:e[-+]?\d+)?", text)]


def test_readme_example_prints_the_numbers_the_readme_shows(tmp_path):
    dn = load_docs_numbers()
    code = dn.examples()["readme"]
    stored = dn.load_numbers()["readme_example"]
    assert stored["code_sha256"] == dn.code_hash(code), (
        "the README example changed since its output was measured: run "
        "`python benchmarks/docs_numbers.py --only readme_example`")
    proc = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=900,
                          env={**os.environ, "MPLBACKEND": "Agg"})
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert (tmp_path / "pressure_profile.csv").is_file()
    live, shown = numbers_in(proc.stdout), numbers_in(stored["stdout"])
    assert len(live) == len(shown) and re.sub(r"[-\d.e+]+", "#", proc.stdout) == re.sub(r"[-\d.e+]+", "#", stored["stdout"])
    for (a, decimals), (b, _) in zip(live, shown):
        # the same run: equal to the printed digits (one unit of the last digit) or to 1e-3 relative
        assert abs(a - b) <= max(1.01 * 10.0**-decimals, 1e-3 * abs(b)), (a, b)
