"""The quartz laws the experiment comparison quotes as ``make run``'s
(``data/measured/quartz_quick_laws.json``, a data file with its provenance) are what
``flatcontact run`` on the built-in default gives: a fresh run of the quick preset, compared to
the stored digits. Slow (the whole quick run: ~1.5 min idle)."""

import json

import pytest
from tests.cli.cli_helpers import run_cli

from flatcontact.foundation.reference import PAPER_LAW_KEYS
from flatcontact.stages.contact import quartz_quick_laws


def test_the_data_file_names_its_source_and_form():
    quoted = quartz_quick_laws()
    assert quoted["energy_form"] in ("internal", "enthalpy")
    assert "flatcontact run" in quoted["source"]
    assert all(quoted[k] > 0 for k in PAPER_LAW_KEYS)


@pytest.mark.slow
def test_the_quoted_quick_preset_laws_are_a_fresh_make_run(tmp_path, capsys):
    code, _, err = run_cli(["run", "--out", str(tmp_path / "run")], capsys)
    assert code == 0, err
    laws = json.loads((tmp_path / "run" / "04-laws" / "laws.json").read_text())
    quoted = quartz_quick_laws()
    assert laws.get("energy_form", "internal") == quoted["energy_form"]
    law = laws[quoted["energy_form"]]
    for key in PAPER_LAW_KEYS:
        # the file carries 6-7 significant digits (the run's laws.json rounded)
        assert law[key] == pytest.approx(quoted[key], rel=2e-6), key
