"""The settings paths and what an unknown key is told it probably meant."""

import pytest

from flatcontact.config import build_config
from flatcontact.config.paths import field_at, settings_paths, suggestion
from flatcontact.config.run import RunConfig
from flatcontact.foundation.errors import InputError


@pytest.mark.parametrize(
    ("old", "meant"),
    [
        ("contact.fit_csv", "contact.fit.csv"),  # a key of the drafts' flat contact section
        ("contact.cycle_amplitudes_un", "contact.cycle.amplitudes_un"),
        ("contact.work_of_adhesion_j_m2", "contact.work_of_adhesion_j_per_m2"),  # the unit
        ("calculator", "potential.calculator"),  # the drafts' top-level section
        ("scan.fmax_ev_per_a", "scan.fmax_ev_per_angstrom"),
        ("analysis.energy_from", "analysis.energy_form"),  # a typo
        ("structure.layers", None),  # a key of another recipe kind: nothing closer
        ("contact.no_such_thing", None),
    ],
)
def test_an_unknown_key_names_the_setting_it_probably_meant(old, meant):
    assert suggestion(old) == meant
    section, _, key = old.rpartition(".")
    data = {key: 1} if not section else {section: {key: 1}}
    if old.startswith("structure."):
        return  # the recipe's own one line (tests/pipeline/test_interfaces.py)
    with pytest.raises(InputError) as info:
        build_config(data, source="c.yaml")
    hint = f" (did you mean {meant}?)" if meant else ""
    assert str(info.value) == f"c.yaml: {old}: unknown field{hint}"


def test_every_path_names_its_field():
    paths = settings_paths()
    assert set(RunConfig.model_fields) <= set(paths)
    for path in ("contact.fit.csv", "scan.symmetry.verify_points", "potential.lj.cutoff_angstrom"):
        model, info = field_at(path)
        assert path.rpartition(".")[2] in model.model_fields and info.description
