"""The examples' tables in the docs are what the code computes from stored outputs.

``python -m benchmarks.example_tables`` writes the marked tables of examples/README.md,
docs/incommensurate.md and docs/your-own-interface.md from the run and study files it stored
in docs/measured/examples. Here:

* every marked table in the docs is exactly the rendering of the store (no hand edit, no
  number left from an older version; an example without a stored run is marked as not
  regenerated);
* the stored laws are what the code fits to the stored per-load table (``fit_load_laws`` on
  friction.csv), their grid parts what ``grid_law_components`` gives on its grid columns, and
  the per-load grid columns what analyze.json's grid block used;
* the approximant studies' collapse stresses are what the contact model computes from each
  cell's stored laws at the experiment's conditions.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest
from benchmarks import example_tables as et

from flatcontact.analysis.laws import fit_load_laws
from flatcontact.analysis.uncertainty import grid_law_components
from flatcontact.contact.experiment import model_collapse_stress
from flatcontact.contact.parameters import ContactParameters
from flatcontact.foundation.units import GPA_TO_PA, MPA_TO_PA

STORED = sorted(
    p.name
    for p in et.STORE.iterdir()
    if (p / "04-laws" / "laws.json").is_file() and p.name in (*et.RUN_EXAMPLES, et.WORKED)
)


@pytest.mark.parametrize("doc", et.DOCS, ids=lambda p: p.name)
def test_docs_tables_are_the_rendering_of_the_stored_outputs(doc):
    text = doc.read_text()
    assert et.MARK.search(text), f"{doc.name} has no generated table"
    assert et.render(text) == text, (
        f"{doc.name}: a table differs from the stored outputs; run python -m benchmarks.example_tables"
    )


def test_rows_without_a_stored_run_are_marked_not_regenerated():
    table = et.runs_table()
    for name in et.RUN_EXAMPLES:
        (row,) = [r for r in table.splitlines() if r.startswith(f"| {name}")]
        assert (et.NOT_REGENERATED in row) == (name not in STORED)


@pytest.mark.parametrize("name", STORED)
def test_stored_laws_are_the_fit_of_the_stored_table(name):
    d = et.STORE / name
    laws = json.loads((d / "04-laws" / "laws.json").read_text())
    table = pd.read_csv(d / "03-analyze" / "friction.csv")
    p, tau, sigma = (table[c].to_numpy(float) for c in ("p_gpa", "tau_mpa", "sigma_mss_mpa"))
    fit = fit_load_laws(p, tau, sigma, laws["threshold_gpa"]).to_json()
    for key in ("k_mpa_per_gpa", "tau0_mpa", "mu_mpa_per_gpa", "sigma0_mpa"):
        assert laws[key] == pytest.approx(fit[key], rel=1e-9, abs=1e-9)
    grid = grid_law_components(
        p,
        tau,
        sigma,
        table["tau_grid_error_mpa"].to_numpy(float),
        table["sigma_mss_grid_error_mpa"].to_numpy(float),
        laws["threshold_gpa"],
    )
    for key, part in grid.items():
        stored = laws["intervals"][key]["components"]["grid"]
        assert stored == pytest.approx(part, rel=1e-9, abs=1e-9)
        iv = laws["intervals"][key]
        parts = iv["components"]
        coverage = float(laws["uncertainty"].get("coverage", 1.0))
        want = coverage * math.sqrt(sum((v or 0.0) ** 2 for v in parts.values()))
        assert iv["half_width"] == pytest.approx(want, rel=1e-12)
    analyze = json.loads((d / "03-analyze" / "analyze.json").read_text())
    for column, values in analyze["grid"]["errors"].items():
        np.testing.assert_allclose(
            table[column].to_numpy(float), np.array(values, dtype=float), rtol=1e-12
        )


@pytest.mark.parametrize("study", list(et.STUDIES))
def test_stored_collapse_stresses_are_the_contact_model_of_the_stored_laws(study):
    d = et.STORE / study
    if not (d / "approximants.csv").is_file():
        pytest.skip(f"{study} not stored")
    doc = json.loads((d / "experiment_collapse.json").read_text())
    cells = pd.read_csv(d / "approximants.csv", keep_default_na=False).set_index("label")
    checked = 0
    for cell in doc["cells"]:
        row = cells.loc[cell["label"]]
        for key in ("k_mpa_per_gpa", "tau0_mpa", "mu_mpa_per_gpa", "sigma0_mpa"):
            assert cell[key] == pytest.approx(float(row[key]), rel=1e-12)
        if cell["collapse_stress_mpa"] is None:
            continue
        params = ContactParameters(
            radius_um=doc["radius_um"],
            contact_modulus_gpa=doc["contact_modulus_gpa"],
            shear_modulus_gpa=doc["shear_modulus_gpa"],
            **{
                k: float(row[k])
                for k in ("k_mpa_per_gpa", "tau0_mpa", "mu_mpa_per_gpa", "sigma0_mpa")
            },
        )
        stress = model_collapse_stress(
            doc["p0_gpa"] * GPA_TO_PA, params, fraction=doc["collapse_fraction"]
        )
        assert cell["collapse_stress_mpa"] == pytest.approx(stress / MPA_TO_PA, rel=1e-9)
        checked += 1
    assert checked >= 1
