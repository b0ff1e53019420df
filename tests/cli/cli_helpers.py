"""Helpers shared by the CLI tests: run ``flatcontact`` in-process, check the one-line error."""

import pytest

from flatcontact.cli import main


def run_cli(argv, capsys):
    """Run the CLI with ``argv``; return (exit code, stdout, stderr)."""
    with pytest.raises(SystemExit) as exit_info:
        main(argv)
    out, err = capsys.readouterr()
    return exit_info.value.code, out, err


def one_error_line(code, err):
    """Assert exit 2 and exactly one ``error:`` line (no traceback, no rich box); return it."""
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), err
    assert "Traceback" not in err and "╭" not in err
    return lines[0]
