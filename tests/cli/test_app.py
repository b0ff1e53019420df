"""The CLI application: ``version`` and the one-line error path (exit code 2)."""

import pytest
from typer.testing import CliRunner

from flatcontact.cli import app
from flatcontact.foundation.errors import InputError


def test_cli_version():
    result = CliRunner().invoke(app, ["version"])
    assert result.exit_code == 0
    assert result.stdout.strip()


def test_input_error_is_one_line_exit_2(capsys):
    from flatcontact.cli import main
    from flatcontact.cli.app import app as the_app

    @the_app.command("_raise-input-error", hidden=True)
    def _raise() -> None:
        raise InputError("--radius-um: expected a positive number, got -1")

    with pytest.raises(SystemExit) as exit_info:
        main(["_raise-input-error"])
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert err.strip() == "error: --radius-um: expected a positive number, got -1"
    assert "Traceback" not in err
