"""Error renaming: core parameter -> settings path -> flag, whole names only."""

from flatcontact.stages._common import rename

CORE_TO_SETTINGS = {"p_gpa": "analysis.p_gpa", "form": "analysis.energy_form"}
SETTINGS_TO_FLAG = {"analysis.p_gpa": "--p-gpa", "analysis.energy_form": "--energy-form"}


def test_a_core_parameter_becomes_the_settings_path_then_the_flag():
    core = "form: expected one of internal, enthalpy, got 'gibbs'"
    settings = rename(core, CORE_TO_SETTINGS)
    assert settings == "analysis.energy_form: expected one of internal, enthalpy, got 'gibbs'"
    assert rename(settings, SETTINGS_TO_FLAG) == (
        "--energy-form: expected one of internal, enthalpy, got 'gibbs'"
    )
    # a message naming no parameter is unchanged by both
    other = "P = 90 GPa is outside the data of ispes.nc"
    assert rename(rename(other, CORE_TO_SETTINGS), SETTINGS_TO_FLAG) == other


def test_only_whole_names_outside_paths_and_longer_names_are_renamed():
    names = {"p_gpa": "analysis.p_gpa", "allow_missing": "analysis.allow_missing"}
    text = (
        "runs/p_gpa/ispes.nc: p_gpa: 1 missing; p0_gpa and contact.p_gpa stay, "
        "p_gpa.nc stays (allow_missing)"
    )
    assert rename(text, names) == (
        "runs/p_gpa/ispes.nc: analysis.p_gpa: 1 missing; p0_gpa and contact.p_gpa stay, "
        "p_gpa.nc stays (analysis.allow_missing)"
    )
    assert rename(text, {}) == text
