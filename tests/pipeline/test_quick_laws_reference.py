"""The quartz laws the experiment comparison quotes as ``make run``'s
(:data:`flatcontact.stages.contact.QUARTZ_QUICK_LAWS`, copied by hand with their provenance) are
what ``flatcontact run`` on the built-in default gives: a fresh run of the quick preset, compared
to the printed digits. Slow (the whole quick run: ~1.5 min idle)."""

import json

import pytest
from tests.cli.cli_helpers import run_cli

from flatcontact.stages.contact import QUARTZ_QUICK_LAWS

KEYS = ("k_mpa_per_gpa", "tau0_mpa", "mu_mpa_per_gpa", "sigma0_mpa")


@pytest.mark.slow
def test_the_quoted_quick_preset_laws_are_a_fresh_make_run(tmp_path, capsys):
    code, _, err = run_cli(["run", "--out", str(tmp_path / "run")], capsys)
    assert code == 0, err
    laws = json.loads((tmp_path / "run" / "04-laws" / "laws.json").read_text())
    law = laws[laws.get("energy_form", "internal")]
    for key in KEYS:
        # the constant carries 6-7 significant digits (the run's laws.json rounded)
        assert law[key] == pytest.approx(QUARTZ_QUICK_LAWS[key], rel=2e-6), key
