"""Tests of clutchocp.analyses (the static analyses behind ``clutchocp validate``)."""

import csv
import json
import math
import time

import numpy as np
import pytest

from clutchocp.analyses import chen2021, cui2019, liao2021, run_validation
from clutchocp.errors import ModelError
from clutchocp.scene import load_scene


@pytest.fixture(scope="module")
def validation(tmp_path_factory):
    out = tmp_path_factory.mktemp("validate")
    start = time.perf_counter()
    summary = run_validation(out, quiet=True)
    return out, summary, time.perf_counter() - start


def read_csv(path):
    with path.open(newline="", encoding="utf-8") as fh:
        rows = list(csv.reader(fh))
    return rows[0], rows[1:]


def test_run_validation_writes_summary_csv_png(validation):
    out, summary, elapsed = validation
    assert elapsed < 20.0
    on_disk = json.loads((out / "summary.json").read_text())
    flat = {f"{a}.{k}": v for a, block in on_disk.items() for k, v in block.items()}
    assert flat == pytest.approx(summary)
    for key in ("table3_max_rel_deviation", "bench_max_rel_error"):
        assert isinstance(on_disk["chen2021"][key], float) and math.isfinite(on_disk["chen2021"][key])
    for value in flat.values():
        assert isinstance(value, (str, bool)) or math.isfinite(value)
    csvs = sorted(out.glob("*.csv"))
    pngs = sorted(out.glob("*.png"))
    prefixes = {p.name.split("_")[0] for p in csvs + pngs}
    assert prefixes == {"chen2021", "cui2019", "liao2021"}
    for path in csvs:
        header, rows = read_csv(path)
        assert rows and all(len(r) == len(header) for r in rows)
        numbers = [float(c) for r in rows for c in r if c and c[0] in "-.0123456789"]
        assert numbers and all(math.isfinite(x) for x in numbers), path.name
    for path in pngs:
        data = path.read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10_000, path.name


def test_chen_table3_all_ten_entries_within_0p1_percent(validation):
    out, summary, _ = validation
    header, rows = read_csv(out / "chen2021_table3.csv")
    col = {name: k for k, name in enumerate(header)}
    assert len(rows) == 10
    for r in rows:
        ours, paper = float(r[col["torque [N m]"]]), float(r[col["torque_chen_table3 [N m]"]])
        assert ours == pytest.approx(paper, rel=1e-3)
    assert summary["chen2021.table3_max_rel_deviation"] < 1e-3


def test_chen_bench_error_matches_papers_own_error_column(validation):
    """Chen Table 3 lists a largest relative error of 10.3 % (0.8 MPa, mu_fs = 0.1)."""
    _, summary, _ = validation
    assert summary["chen2021.bench_max_rel_error"] == pytest.approx(0.103, abs=1e-3)


def test_chen_first_pair_ratio_with_eq5_cof(validation):
    """Chen Sec. 5: p2/p1 = 96.7 % at 0.2 MPa (spline COF 0.15, interface COF of Eq. 5)."""
    _, summary, _ = validation
    assert summary["chen2021.fig7_first_pair_ratio_eq5"] == pytest.approx(0.967, abs=5e-4)


def test_chen_attenuation_figure_data():
    kw = chen2021.from_scene(load_scene("chen2021"))
    res = chen2021.compute(**kw)
    p = res["fig_pressures"]
    assert p.shape == (16, 5)
    assert np.all(np.diff(p, axis=0) < 0)                  # decreasing along the pack
    # Eq. 9: without spline friction the m-pair torque is linear in m
    m = np.arange(1, 17)
    np.testing.assert_allclose(res["fig_torque_none"] / m[:, None],
                               np.broadcast_to(res["fig_torque_none"][0], (16, 5)), rtol=1e-14)
    assert np.all(res["fig_torque"] < res["fig_torque_none"] + 1e-12)


def test_chen_from_scene_keys():
    kw = chen2021.from_scene(load_scene("chen2021"))
    assert kw["r1"] == 0.06 and kw["r2"] == 0.073 and kw["n_interfaces"] == 6
    assert kw["pressure_angle_separator"] == pytest.approx(math.radians(27), rel=1e-14)
    np.testing.assert_allclose(kw["mu"], chen2021.TABLE2_MU2, rtol=1e-14)
    with pytest.raises(ModelError, match="spline"):
        chen2021.from_scene(load_scene("cui2019"))


def test_cui_eq18_against_table1(validation):
    """Hand evaluation of Cui Eq. 18 at 0.3 MPa: 0.0432605, i.e. 7.395e-4 below Table 1's 0.044."""
    _, summary, _ = validation
    assert summary["cui2019.eq18_table1_max_abs_deviation"] == pytest.approx(7.395e-4, rel=1e-3)


def test_cui_torques_add_up_and_have_the_papers_shape():
    res = cui2019.compute(**cui2019.from_scene(load_scene("cui2019")))
    np.testing.assert_allclose(res["total_torque"], res["fluid_torque"] + res["asperity_torque"], rtol=1e-15)
    lam = res["film_ratio"]
    assert np.all(np.diff(res["area_ratio"]) < 0)          # Fig. 13: contact area falls with lambda
    assert np.all(np.diff(res["asperity_torque"]) < 0)     # Fig. 15
    assert res["fluid_torque"][0] < 0.05 * res["fluid_torque"].max()   # Fig. 14: from zero
    assert res["asperity_torque"][-1] < 0.02 * res["total_torque"][-1]  # lambda = 3: film only
    # asperity torque = W_a f_a (R1 + R2) / 2 (Cui Eq. 19), f_a at p = W_a / A_a (Eq. 18)
    kw = cui2019.from_scene(load_scene("cui2019"))
    area = 0.78 * math.pi * (kw["r2"] ** 2 - kw["r1"] ** 2)
    p = res["asperity_load"] / area
    fa = 0.073 - 0.1557 * p / 1e6 + 0.233 * (p / 1e6) ** 2 - 0.1595 * (p / 1e6) ** 3 + 0.0379 * (p / 1e6) ** 4
    np.testing.assert_allclose(res["asperity_torque"], res["asperity_load"] * fa * (0.043 + 0.0615) / 2, rtol=1e-12)
    assert lam[0] > 0


def test_cui_greenwood_tripp_variant_runs():
    kw = cui2019.from_scene(load_scene("cui2019"))
    kw.update(contact="greenwood_tripp", contact_kw={"fit": "exact"}, mu=0.05)
    res = cui2019.compute(**kw)
    assert np.all(np.isfinite(res["total_torque"])) and np.all(res["cof"] == 0.05)


def test_liao_cases_and_table3(validation):
    _, summary, _ = validation
    kw = liao2021.from_scene(load_scene("liao2021"))
    assert kw["k3_over_k1"] == pytest.approx(1e5) and kw["first_film"] == pytest.approx(1.3e-4)
    cases = liao2021.film_cases(**kw)
    for cs in cases.values():
        for c in cs:
            assert np.all(np.diff(c["films"]) > 0) and np.all(np.diff(c["torques"]) < 0)   # Figs 4-9
            assert c["total"] == pytest.approx(np.sum(c["torques"]), rel=1e-13)
    # Table 3: revised torque close to the paper's new formula and to the bench
    assert summary["liao2021.table3_new_torque_max_rel_deviation"] < 0.07
    assert summary["liao2021.table3_new_torque_max_rel_error_vs_test"] < 0.05
    assert summary["liao2021.growth_if_k3k1_per_m2"] == pytest.approx(1.0, abs=1e-5)
    assert summary["liao2021.growth_if_k3k1_per_mm2"] > 1.5


def test_liao_without_friction_reduces_to_original_formula():
    kw = liao2021.from_scene(load_scene("liao2021"))
    kw["k3_over_k1"] = 0.0
    for cs in liao2021.film_cases(**kw, sweeps={"groove_depth": liao2021.SWEEPS["groove_depth"]}).values():
        for c in cs:
            np.testing.assert_allclose(c["alpha"], 1.0, rtol=1e-14)
            assert c["total"] == pytest.approx(c["original"], rel=1e-13)
