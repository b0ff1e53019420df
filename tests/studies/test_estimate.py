"""The cost estimate of a convergence study (``--estimate``): the extrapolation rules on a
constructed base, and on the toy against what the study then spends."""

from __future__ import annotations

import json

import pytest
from tests.hardening.helpers import run_cli
from tests.studies.columns import chosen, column
from tests.studies.toy import toy_config, toy_data, write_yaml

from flatcontact.studies.convergence import run_convergence
from flatcontact.studies.estimate import estimate_convergence, estimate_lines
from flatcontact.studies.variants import step

#: a base as base_measurements reads it: 3x3 grid, 6 thicknesses (4 requested, 2 the probe
#: added), 27 of 54 points computed (symmetry), 270 force calls, 27 s of scan
BASE = {
    "grid": [3, 3],
    "thicknesses": 6,
    "points_total": 54,
    "points_computed": 27,
    "force_calls": 270,
    "seconds": {"build": 4.0, "scan": 27.0, "analyze": 2.0, "laws": 1.0},
}


def test_the_rules_scale_points_calls_and_seconds_from_the_base():
    cfg = toy_config(settings=["grid", "thicknesses", "layers", "fmax"], max_steps=2)
    ladder = {
        s: [step(cfg, s, i) for i in (1, 2)] for s in ("grid", "thicknesses", "layers", "fmax")
    }
    est = estimate_convergence(cfg, ladder, BASE, workers=2)
    by = {v["name"]: v for v in est["variants"]}
    # grid 3 -> 5 (x1.5, rounded up): 25 lateral points x 6 thicknesses; half computed as in
    # the base; 10 force calls per computed point; 0.1 s per call; build shared
    g1 = by["grid1"]
    assert g1["grid"] == [5, 5] and g1["points"] == 150
    assert g1["points_computed"] == 75 and g1["force_calls"] == 750
    assert g1["seconds"] == pytest.approx(75.0 + 2.0 + 1.0)
    # thicknesses 4 -> 6 requested: the base's 6 (the probe's 2 included) span 5 spacings of
    # the requested 3; at 5/3 the density, 1 + 5 * 5/3 = 9.33 -> 9
    t1 = by["thicknesses1"]
    assert t1["thicknesses"] == 9 and t1["points"] == 81 and t1["force_calls"] == 405
    # layers 3 -> 4: the same points and calls, each call 4/3 the atoms; rebuilt
    l1 = by["layers1"]
    assert l1["points"] == 54 and l1["force_calls"] == 270
    assert l1["seconds"] == pytest.approx(4.0 + 27.0 * 4 / 3 + 3.0)
    # fmax: the same calls per point, a lower bound for a relaxing scan
    assert by["fmax2"]["force_calls"] == 270 and by["fmax2"]["lower_bound"]
    assert not g1["lower_bound"]
    total = 270 + sum(v["force_calls"] for v in est["variants"])
    assert est["force_calls_study"] == total
    assert est["force_calls_from_scratch"] == total + 3 * 270
    rounds = [[v["seconds"] for v in est["variants"] if v["level"] == k] for k in (1, 2)]
    wall = 34.0 + sum(max(sum(r) / 2, max(r)) for r in rounds)
    assert est["wall_seconds"] == pytest.approx(wall)
    assert est["serial_seconds"] == pytest.approx(34.0 + sum(sum(r) for r in rounds))
    text = "\n".join(estimate_lines(est))
    assert "grid1 (grid 5x5): 150 points, ~75 computed, ~750 force calls" in text
    # a thickness rung names the scan's thicknesses beside the requested count (the base's
    # 6 include the probe's; "6 thicknesses" alone read as fewer than Ni(111)'s base of 18)
    assert "thicknesses1 (6 thicknesses; ~9 scanned): 81 points" in text
    assert f"all 8 variants: ~{total} force calls" in text


@pytest.mark.slow
def test_estimate_runs_only_the_base_and_predicts_what_the_study_spends(tmp_path, capsys):
    """The toy (3x3, full relaxation): ``--estimate`` runs the base alone and prints each
    rung; the study then reuses the base, and each variant's points are within 15 % of the
    estimate (the probe adds a thickness or two more for another grid or spacing: 250 vs 275
    for grid 5x5 measured) and its force calls within 50 % (calls per point vary with the
    relaxation's starting point)."""
    conf = write_yaml(
        tmp_path / "toy.yaml",
        toy_data(refine={"settings": ["grid", "thicknesses"], "max_steps": 1}),
    )
    code, out, err = run_cli(
        ["study", "convergence", conf, "--out", tmp_path / "s", "--estimate"], capsys
    )
    assert code == 0, err
    text = " ".join(out.split())
    assert "estimate from the base (3x3" in text and "grid1 (grid 5x5)" in text
    assert "all 2 variants" in text
    assert (tmp_path / "s" / "runs" / "base").is_dir()
    assert not (tmp_path / "s" / "runs" / "grid1").exists()
    assert not (tmp_path / "s" / "study.json").exists()
    doc = run_convergence(toy_config(settings=["grid", "thicknesses"], max_steps=1), tmp_path / "s")
    by = {v["name"]: v for v in doc["variants"]}
    assert by["base"]["scan_action"] == "skipped"  # the estimate's base is the study's
    for est in doc["estimate"]["variants"]:
        scan = json.loads(
            (tmp_path / "s" / "runs" / est["name"] / "02-scan" / "scan.json").read_text()
        )
        got = (scan["points_total"], by[est["name"]]["force_calls"])
        print(
            est["name"], "points", est["points"], got[0], "force calls", est["force_calls"], got[1]
        )
        assert est["points"] == pytest.approx(got[0], rel=0.15), est["name"]
        assert est["force_calls"] == pytest.approx(got[1], rel=0.5), est["name"]


def test_a_thickness_rung_below_the_minimum_spacing_is_estimated_as_the_scan_merges_it():
    """A stiff interface (the Morse-like columns of tests/studies/columns.py: 25 GPa/Å, a
    repulsive stacking 0.3 Å out): the scan's own chooser gives the base's thicknesses for
    n = 4 and the rungs' for n = 6 and 9; the estimate from the base's count and range is
    within 15 % of each (Ni(111): the rule without the merge said 29 for 16 scanned)."""
    stiff = [column(14.2, 12.5, 2.0), column(14.5, 12.5, 2.0, (2 / 3, 1 / 3))]
    z = {n: chosen(stiff, 2.0, n)["thickness_angstrom"] for n in (4, 6, 9)}
    cfg = toy_config(settings=["thicknesses"], max_steps=2)  # p_range_gpa n = 4
    base = {
        **BASE,
        "thicknesses": len(z[4]),
        "thickness_range_angstrom": max(z[4]) - min(z[4]),
    }
    ladder = {"thicknesses": [step(cfg, "thicknesses", i) for i in (1, 2)]}
    est = {v["name"]: v for v in estimate_convergence(cfg, ladder, base, 1)["variants"]}
    for name, n in (("thicknesses1", 6), ("thicknesses2", 9)):
        assert est[name]["thicknesses"] == pytest.approx(len(z[n]), rel=0.15), name
