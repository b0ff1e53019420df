"""Searches that never end or allocate without bound: every structure search has a bound on
its cells checked before it starts (atoms: FLATCONTACT_MAX_ATOMS) and a deadline
(FLATCONTACT_MAX_SEARCH_SECONDS), and its one line says which setting to change."""

from __future__ import annotations

import time

import numpy as np
import pytest
from tests.hardening.helpers import refused, run_cli

from flatcontact.foundation.errors import InputError
from flatcontact.foundation.limits import SearchTimeout
from flatcontact.structures.match import coincidence_match, twist_match

#: graphene (2.46 Å) and h-BN (2.504 Å): a 1.8 % mismatch; at 0.01 % strain the search runs
#: through every area up to its bound (16 s for 2000 atoms on the loaded machine)
GRAPHENE = 2.46 * np.array([[1.0, 0.0], [-0.5, np.sqrt(3) / 2]])
HBN = 2.504 * np.array([[1.0, 0.0], [-0.5, np.sqrt(3) / 2]])

SHEETS = """\
structure:
  kind: sheets
  sheet: graphene
  layers: 1
  stacking: AB
  {extra}
potential: {{preset: graphene-rebo-kc}}
scan: {{grid: [3, 3], relax_mode: rigid-layers, executor: serial}}
contact: {{contact_modulus_gpa: 40.0, shear_modulus_gpa: 30.0}}
"""


@pytest.mark.parametrize(
    ("extra", "names"),
    [
        (
            "slab2: {sheet: h-BN}\n  match: {slab1_supercell: [[100001, 0], [0, 1]], "
            "slab2_supercell: [[100001, 0], [0, 1]]}",
            ["slab1_supercell", "100001", "FLATCONTACT_MAX_ATOMS"],
        ),
        (
            "slab2: {sheet: h-BN}\n  match: {slab1_supercell: [[10000000000000000000, 0], "
            "[0, 1]], slab2_supercell: [[1, 0], [0, 1]]}",
            ["slab1_supercell", "FLATCONTACT_MAX_ATOMS"],
        ),
        (
            "slab2: {sheet: h-BN}\n  match: {max_atoms: 1000000000}",
            ["structure.match.max_atoms", "FLATCONTACT_MAX_ATOMS"],
        ),
        ("twist: [30000000000, 30000000001]", ["structure.twist", "FLATCONTACT_MAX_ATOMS"]),
    ],
)
def test_a_cell_beyond_the_atom_bound_is_one_line_before_anything_is_built(
    tmp_path, capsys, extra, names
):
    """Before: a 224 GiB allocation attempt (100001), an OverflowError traceback (10^19), a
    search without end (max_atoms 10^9), a million-atom twist built."""
    conf = tmp_path / "run.yaml"
    conf.write_text(SHEETS.format(extra=extra))
    t0 = time.perf_counter()
    code, _, err = run_cli(["config", "--check", conf], capsys)
    line = refused(code, err, *names)
    assert "Value error" not in line and "Overflow" not in line
    assert time.perf_counter() - t0 < 30


def test_a_coincidence_search_past_its_deadline_says_which_setting_to_change(monkeypatch):
    monkeypatch.setenv("FLATCONTACT_MAX_SEARCH_SECONDS", "1")
    t0 = time.perf_counter()
    with pytest.raises(SearchTimeout) as info:
        coincidence_match(GRAPHENE, HBN, 2, 2, max_strain=1e-4, max_atoms=4000, field="f")
    elapsed = time.perf_counter() - t0
    text = str(info.value)
    assert elapsed < 20, elapsed
    for name in ("no answer within 1 s", "match.max_atoms", "FLATCONTACT_MAX_SEARCH_SECONDS=4"):
        assert name in text, text


def test_an_approximant_ladder_past_its_deadline_is_not_called_no_cell(monkeypatch):
    """The approximant ladder turned the search's "nothing found" into its own message; a
    deadline is another thing and passes through."""
    from flatcontact.config.approximants import ApproximantSettings
    from flatcontact.structures.approximants import approximant_sequence

    monkeypatch.setenv("FLATCONTACT_MAX_SEARCH_SECONDS", "1")
    structure = {
        "kind": "sheets",
        "sheet": "graphene",
        "layers": 1,
        "stacking": "AB",
        "slab2": {"sheet": "h-BN"},
    }
    settings = ApproximantSettings(max_atoms=20_000, strain_percent=[0.01])
    with pytest.raises(SearchTimeout, match="no answer within 1 s"):
        approximant_sequence(structure, settings)


def test_a_search_within_its_bounds_still_finds_the_cell():
    """3 % strain: the smallest graphene/h-BN cell is the 1x1 one strained by 1.8 %."""
    match = coincidence_match(GRAPHENE, HBN, 2, 2, max_strain=0.03, max_atoms=400, field="f")
    assert abs(round(np.linalg.det(match.p1))) == 1
    _, theta = twist_match(GRAPHENE, 1, 2)
    assert theta == pytest.approx(21.786789, abs=1e-5)


def test_the_search_bound_itself_must_be_a_positive_integer(monkeypatch):
    monkeypatch.setenv("FLATCONTACT_MAX_SEARCH_SECONDS", "soon")
    with pytest.raises(InputError, match="FLATCONTACT_MAX_SEARCH_SECONDS='soon'"):
        coincidence_match(GRAPHENE, HBN, 2, 2, max_strain=0.03, max_atoms=400, field="f")
