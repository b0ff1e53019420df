"""``flatcontact elastic CONFIG --out DIR`` is the run's elastic stage: the same elastic.json."""

import json

from tests.cli.cli_helpers import one_error_line, run_cli

from flatcontact.config import load_config
from flatcontact.pipeline import Pipeline

CU = """\
structure: {kind: fcc111, element: Cu}
potential: {preset: cu-eam}
elastic: {enabled: true, strain: 0.005}
"""


def test_the_elastic_command_writes_the_runs_elastic_json(tmp_path, capsys):
    config = tmp_path / "cu.yaml"
    config.write_text(CU)
    code, out, err = run_cli(["elastic", str(config), "--out", str(tmp_path / "cli")], capsys)
    assert code in (0, None), err
    assert "fcc Cu" in out
    with Pipeline(load_config(config), tmp_path / "run") as pipe:
        run_doc = pipe.elastic()
    cli_doc = json.loads((tmp_path / "cli" / "elastic.json").read_text())
    assert cli_doc == run_doc
    # Mishin et al. (2001), Cu: C11 = 169.9, C12 = 122.6, C44 = 76.2 GPa
    c = cli_doc["tensor_gpa"]
    assert abs(c[0][0] - 169.9) < 2 and abs(c[0][1] - 122.6) < 2 and abs(c[3][3] - 76.2) < 2
    assert "C11 170.2" in out


def test_out_without_config_is_one_line(tmp_path, capsys):
    code, _, err = run_cli(["elastic", "--out", str(tmp_path / "x")], capsys)
    assert "--out" in one_error_line(code, err)
    assert not (tmp_path / "x").exists()
