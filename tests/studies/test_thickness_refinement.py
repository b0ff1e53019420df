"""A thicknesses step of ``flatcontact study convergence`` counts only if the scan's thicknesses
come out closer together. Found on Ni(111)/Ni(111) with the Foiles EAM: ``p_range_gpa.n`` 4 → 6
gave 16 thicknesses 0.031 Å apart (median) against the base's 18 at 0.024 Å, because the
thicknesses added to bracket the repulsive stacking at the finer step fell below the minimum
spacing and every other one was dropped; the study called the setting converged on a coarser
scan."""

from __future__ import annotations

import pytest
from tests.studies.columns import chosen as _chosen
from tests.studies.columns import column as _column

from flatcontact.config.load import build_config
from flatcontact.ispes.thicknesses import MIN_THICKNESS_SPACING_ANGSTROM
from flatcontact.studies.compare import median_spacing_angstrom, thickness_step_refines


def test_a_larger_n_can_coarsen_a_stiff_interface_and_the_step_says_so():
    """Stiff (25 GPa/Å at P = 0, like Ni(111)) with a repulsive stacking 0.3 Å further out: the
    thicknesses added to bracket it are spaced as the first column's, which for n = 6 is below
    the minimum spacing, so the merge keeps about every other one. The step is refused as a
    refinement in one line naming both spacings; a soft single column refines and passes."""
    stiff = [_column(14.2, 12.5, 2.0), _column(14.5, 12.5, 2.0, (2 / 3, 1 / 3))]
    coarse, fine = _chosen(stiff, 2.0, 4), _chosen(stiff, 2.0, 6)
    a = median_spacing_angstrom(coarse["thickness_angstrom"])
    b = median_spacing_angstrom(fine["thickness_angstrom"])
    assert b > a >= MIN_THICKNESS_SPACING_ANGSTROM
    why = thickness_step_refines(coarse, fine, "thicknesses1", "base")
    assert why is not None and "\n" not in why
    assert why.startswith("thicknesses1 did not refine the thicknesses")
    assert f"{b:.4g} Å apart" in why and f"against {a:.4g} Å for base" in why
    soft = [_column(14.2, 1.0, 1.0)]
    coarse, fine = _chosen(soft, 0.2, 4), _chosen(soft, 0.2, 6)
    assert median_spacing_angstrom(fine["thickness_angstrom"]) < median_spacing_angstrom(
        coarse["thickness_angstrom"]
    )
    assert thickness_step_refines(coarse, fine, "thicknesses1", "base") is None
    # the same list is no refinement either
    assert thickness_step_refines(coarse, coarse, "thicknesses1", "base") is not None


@pytest.mark.slow
def test_the_study_reports_a_thickness_step_that_did_not_refine(tmp_path):
    """Ni(111), 4 + 4 planes (the example of docs/studies.md), 3x3 grid, normal relaxation, n 4 → 6: the study reports the
    setting 'not refined' with the spacings of the two scans (their scan.json), not converged,
    and keeps its change out of δ_conv."""
    import json

    from flatcontact.studies.convergence import run_convergence

    cfg = build_config(
        {
            "structure": {"kind": "fcc111", "element": "Ni", "a_angstrom": 3.52, "layers": 4},
            "potential": {"preset": "ni-eam"},
            "scan": {
                "grid": [3, 3],
                "p_range_gpa": {"lo_gpa": 0.0, "hi_gpa": 2.0, "n": 4},
                "relax_mode": "normal",
                "executor": "serial",
            },
            "analysis": {"p_gpa": [0.0, 0.5, 1.0, 1.5]},
            "contact": {"contact_modulus_gpa": 115.0, "shear_modulus_gpa": 94.0},
            "refine": {"settings": ["thicknesses"], "max_steps": 2},
        },
        None,
        "ni",
    )
    doc = run_convergence(cfg, tmp_path)
    st = doc["settings"]["thicknesses"]
    z = {
        name: json.loads((tmp_path / "runs" / name / "02-scan" / "scan.json").read_text())[
            "thickness_angstrom"
        ]
        for name in ("base", "thicknesses1")
    }
    a, b = (median_spacing_angstrom(z[n]) for n in ("base", "thicknesses1"))
    assert b >= a
    assert st["state"] == "not refined" and st["steps"] == 1
    assert f"{b:.4g} Å apart" in st["reason"]
    assert doc["converged"] is False
    assert all(v == 0.0 for v in doc["delta"]["internal"].values())
