"""``contact.experiment.compare`` followed from the YAML to the report, on a cheap toy run.

The toy interface (``toy-lj``, the toy calculator, 3×3 grid) runs every stage; the test then
reads the run's own files: the collapse stress in ``summary.json["experiment_comparison"]`` is
the one read off the stiffness curve at p0 = 1.77 GPa in ``contact.nc`` (first amplitude stress
with d⟨Q⟩/d⟨u⟩ < 0.2·k0, interpolated here: no root finding), its laws are ``laws.json``'s, and
the report's table shows those numbers next to the measured 26.7 and 145 MPa. Without the flag
the same run's contact stage reruns without the comparison and the report without the section.
"""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest
import xarray as xr

from flatcontact.config import build_config
from flatcontact.pipeline import Pipeline
from flatcontact.report.format import fmt

TOY = {
    "structure": {"kind": "toy-lj", "layers": 3},
    "potential": {"calculator": {"target": "flatcontact.ispes.toy:toy_calculator"}},
    "scan": {
        "grid": [3, 3],
        "p_range_gpa": {"lo_gpa": -0.2, "hi_gpa": 1.5, "n": 4},
        "executor": "serial",
    },
    "analysis": {"p_gpa": [0.0, 0.5, 1.0]},
    "contact": {
        "p0_gpa": [1.0, 1.77],
        # the toy's 3×3 surface fires these gates; the file wiring is what is tested here
        "accept_untrusted": [
            "broken_symmetry",
            "negative_slope",
            "in_slab_slip",
            "degenerate_minima",
        ],
        "experiment": {"compare": "passivated-tip", "p0_gpa": 1.77},
    },
    "report": {"svg": False, "title": "toy interface"},
}


@pytest.fixture(scope="module")
def toy_run(tmp_path_factory):
    root = tmp_path_factory.mktemp("tip") / "toy"
    with Pipeline(build_config(TOY), root) as pipe:
        pipe.run()
    return root


def _collapse_from_contact_nc(path, p0_gpa: float, fraction: float = 0.2) -> float:
    ds = xr.open_dataset(path, engine="h5netcdf")
    row = ds.sel(p0=p0_gpa)
    k = row["lateral_stiffness"].values
    s = row["stress_amplitude"].values
    ok = np.isfinite(k) & np.isfinite(s)
    k, s = k[ok], s[ok]
    ratio = k / float(row["initial_lateral_stiffness"])
    i = int(np.nonzero(ratio < fraction)[0][0])
    ds.close()
    return float(
        s[i - 1] + (fraction - ratio[i - 1]) * (s[i] - s[i - 1]) / (ratio[i] - ratio[i - 1])
    )


def test_the_comparison_comes_from_the_runs_own_files(toy_run):
    summary = json.loads((toy_run / "06-contact" / "summary.json").read_text())
    laws = json.loads((toy_run / "04-laws" / "laws.json").read_text())
    doc = summary["experiment_comparison"]
    run = doc["run"]
    assert doc["p0_gpa"] == 1.77 and doc["collapse_fraction"] == 0.2
    assert doc["measured_mpa"] == {"graphene-passivated SiOx": 26.7, "bare SiOx": 145.0}
    for key in ("k_mpa_per_gpa", "tau0_mpa", "mu_mpa_per_gpa", "sigma0_mpa"):
        assert run[key] == pytest.approx(laws[key], rel=1e-12)
    from_curve = _collapse_from_contact_nc(toy_run / "06-contact" / "contact.nc", 1.77)
    assert run["collapse_stress_mpa"] == pytest.approx(from_curve, rel=5e-3)
    # the collapse lies just below the peak's mean stress Q_peak/πa² of the same p0
    peak = next(r for r in summary["results"] if r["p0_gpa"] == 1.77)[
        "effective_shear_strength_mpa"
    ]
    assert 0.98 * peak < run["collapse_stress_mpa"] <= peak
    assert run["ratio_to_measured"]["graphene-passivated SiOx"] == pytest.approx(
        run["collapse_stress_mpa"] / 26.7
    )
    labels = [r["label"] for r in doc["references"]]
    assert labels == [
        "quartz, the paper's laws (SNAP + TS-vdW LJ)",
        "quartz, flatcontact quick preset (make run)",
    ]
    report = (toy_run / "report.html").read_text()
    assert "collapse stress against the measurement" in report
    assert "toy interface (this run)" in report
    for row in (run, *doc["references"]):
        assert f"<td>{fmt(row['collapse_stress_mpa'])}</td>" in report
    assert "<td>26.7</td>" in report and "<td>145</td>" in report


def test_without_the_flag_there_is_no_comparison(toy_run, tmp_path):
    """The same run with the flag removed: the contact stage and the report rerun (the flag is
    part of their inputs), the scan does not, and neither file has the comparison."""
    cfg = json.loads(json.dumps(TOY))
    del cfg["contact"]["experiment"]
    root = tmp_path / "plain"
    shutil.copytree(toy_run, root)
    with Pipeline(build_config(cfg), root) as pipe:
        pipe.run()
        actions = {name: res.action for name, res in pipe.results.items()}
    assert actions["scan"] != "ran" and actions["contact"] == "ran"
    assert "experiment_comparison" not in json.loads(
        (root / "06-contact" / "summary.json").read_text()
    )
    assert "collapse stress against the measurement" not in (root / "report.html").read_text()
