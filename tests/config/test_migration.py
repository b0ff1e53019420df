"""Old forms of a configuration still load, each with a dated deprecation naming the new key."""

import warnings

import pytest

from flatcontact.config import build_config, load_config
from flatcontact.config.migration import CONTACT_KEYS
from flatcontact.errors import InputError


def test_flat_contact_keys_load_into_the_sub_sections_with_a_dated_warning(tmp_path):
    (tmp_path / "m.csv").write_text("mean shear stress [MPa],lateral stiffness [N/m]\n1,2\n")
    path = tmp_path / "old.yaml"
    path.write_text(
        "contact:\n"
        "  cycle: true\n"
        "  model: classical\n"
        "  cycle_amplitude_fractions: [0.3, 0.7]\n"
        "  fit_free: [tau0_mpa, k_mpa_per_gpa]\n"
        "  fit_stiffness: paper\n"
        "  experiment_csv: m.csv\n"
        "  experiment_p0_gpa: 1.5\n"
    )
    with pytest.warns(DeprecationWarning, match=r"2026-11-25: use contact\.cycle\.enabled"):
        old = load_config(path)
    new = build_config(
        {
            "contact": {
                "cycle": {"enabled": True, "model": "classical", "amplitude_fractions": [0.3, 0.7]},
                "fit": {"free": ["tau0_mpa", "k_mpa_per_gpa"], "stiffness": "paper"},
                "experiment": {"csv": str((tmp_path / "m.csv").resolve()), "p0_gpa": 1.5},
            }
        }
    )
    assert old.contact == new.contact


@pytest.mark.parametrize("old", sorted(CONTACT_KEYS))
def test_each_flat_contact_key_names_its_date_and_new_key(old):
    sub, key = CONTACT_KEYS[old]
    value = {
        "cycle": True,
        "model": "classical",
        "cycle_amplitude_fractions": [0.5],
        "cycle_amplitudes_un": [1.0],
        "fit_csv": [],
        "fit_p0_gpa": [1.0],
        "fit_free": ["tau0_mpa"],
        "fit_fixed": [],
        "fit_stiffness": "paper",
        "experiment_csv": None,
        "experiment_p0_gpa": 1.5,
        "experiment_stress_measure": "rms",
    }[old]
    with pytest.warns(DeprecationWarning) as record:
        cfg = build_config({"contact": {old: value}})
    assert f"contact.{old} is deprecated since 2026-11-25: use contact.{sub}.{key}" in str(
        record[0].message
    )
    assert getattr(getattr(cfg.contact, sub), key) == value


def test_a_key_given_flat_and_nested_is_refused():
    with pytest.raises(
        InputError, match=r"c\.yaml: contact\.fit_csv: given beside contact\.fit\.csv"
    ):
        build_config({"contact": {"fit_csv": [], "fit": {"csv": []}}}, source="c.yaml")


def test_the_nested_form_raises_no_warning():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        build_config({"contact": {"cycle": {"enabled": True}, "fit": {"stiffness": "paper"}}})


def test_the_top_level_calculator_section_becomes_the_models():
    cfg = build_config({"calculator": {"target": "flatcontact.ispes.toy:toy_calculator"}})
    assert cfg.potential.calculator.target == "flatcontact.ispes.toy:toy_calculator"
    assert cfg.potential.calculator.scope == "interface"
