"""The command line's bad-input behaviour: one verbatim ``error:`` line, exit 2, before any work."""

import pytest

from flatcontact.cli import main


def _run(argv, capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(argv)
    out, err = capsys.readouterr()
    return exit_info.value.code, out, err


def _one_error_line(code, err):
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), err
    assert "Traceback" not in err
    return lines[0]


# ---- 1: messages are printed verbatim (no rich markup eats '[...]') ----------------------


def test_error_keeps_square_brackets(tmp_path, capsys):
    csv = tmp_path / "nounit.csv"
    csv.write_text("stress,stiffness\n1,2\n")
    line = _one_error_line(*_run(["contact", "--experiment", str(csv)], capsys)[::2])
    assert "'name [unit]'" in line and "'mean shear stress [MPa]'" in line


def test_error_keeps_lowercase_markup_lookalikes(capsys):
    from flatcontact.cli.app import print_error, print_warning

    print_error("got [nan] and [bold]x[/bold] in [/tmp/a b]")
    print_warning("[dim]kept[/dim]")
    err = capsys.readouterr().err
    assert "error: got [nan] and [bold]x[/bold] in [/tmp/a b]" in err
    assert "warning: [dim]kept[/dim]" in err
