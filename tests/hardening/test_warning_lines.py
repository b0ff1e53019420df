"""Numerical warnings of the libraries never reach the user as extra lines.

A calculator factory (a user module, as ``calculator:`` allows) whose calculator triggers
numpy's overflow warning and a third-party ``UserWarning`` on every call: ``flatcontact run``
finishes with exit 0 and prints one summary ``warning:`` line for all of them (no
``RuntimeWarning: overflow`` line per point); the run's ``run.log`` has each. flatcontact's
own dated deprecations stay one line each (an old settings key is an error line), and a refused command prints only its error line.
Outside the command line (library callers, these tests) the warnings are raised as Python
raises them.
"""

from __future__ import annotations

import textwrap
import warnings

import numpy as np
import pytest
from tests.hardening.helpers import TOY_YAML, run_cli

from flatcontact.cli.warning_lines import WarningLines, captured_warnings

NOISY = textwrap.dedent(
    """
    import warnings

    import numpy as np

    from flatcontact.ispes.toy import toy_calculator


    def factory(atoms=None, **params):
        np.exp(np.array([1000.0]))  # RuntimeWarning: overflow encountered in exp
        warnings.warn("a third-party note", UserWarning)
        return toy_calculator(atoms, **params)
    """
)


@pytest.fixture
def noisy_run(tmp_path, monkeypatch):
    (tmp_path / "noisy_calc_h3.py").write_text(NOISY)
    monkeypatch.syspath_prepend(str(tmp_path))
    config = tmp_path / "run.yaml"
    config.write_text(
        TOY_YAML.replace("flatcontact.ispes.toy:toy_calculator", "noisy_calc_h3:factory")
    )
    return config


def test_a_run_with_library_warnings_prints_one_summary_line(noisy_run, tmp_path, capsys):
    out = tmp_path / "run"
    code, _, err = run_cli(["run", noisy_run, "--out", out], capsys)
    assert code == 0, err
    lines = [ln for ln in err.splitlines() if "Warning" in ln or ln.startswith("warning: ")]
    summary = [ln for ln in lines if "numerical warning" in ln]
    assert len(summary) == 1, err
    assert "overflow encountered in exp" in summary[0] or "third-party note" in summary[0]
    assert not [ln for ln in lines if ln not in summary and "RuntimeWarning" in ln], err
    assert "third-party note" not in err.replace(summary[0], "")
    log = (out / "run.log").read_text()
    assert "overflow encountered in exp" in log and "a third-party note" in log


def test_a_refused_command_prints_only_its_error(noisy_run, tmp_path, capsys):
    text = noisy_run.read_text().replace("grid: [3, 3]", "grid: [3, 3]\n  max_steps: 0")
    noisy_run.write_text(text)
    code, _, err = run_cli(["run", noisy_run, "--out", tmp_path / "run"], capsys)
    assert code == 2
    assert len(err.strip().splitlines()) == 1 and "scan.max_steps" in err, err


def test_an_old_key_is_one_error_line_naming_the_setting_it_became(tmp_path, capsys):
    old = tmp_path / "old.yaml"
    old.write_text("contact:\n  experiment_p0_gpa: 1.5\n")
    code, _, err = run_cli(["config", "--check", old], capsys)
    assert code == 2, err
    assert err.strip().splitlines() == [
        f"error: {old}: contact.experiment_p0_gpa: unknown field "
        "(did you mean contact.experiment.p0_gpa?)"
    ]


def test_the_capture_restores_python_warnings_for_callers():
    shown = []
    with captured_warnings(shown.append) as lines:
        with np.errstate(over="warn"):
            np.exp(np.array([1000.0]))
        warnings.warn("x is deprecated since 2026-01-01: use y", DeprecationWarning, stacklevel=1)
    assert lines.library and "overflow" in lines.library[0]
    assert shown == ["DeprecationWarning: x is deprecated since 2026-01-01: use y"]
    # outside the block a library warning is raised again, as Python raises it
    with pytest.warns(RuntimeWarning, match="overflow"):
        np.exp(np.array([1000.0]))


def test_show_all_prints_each_library_warning():
    shown = []
    lines = WarningLines(shown.append, show_all=True)
    lines.show(RuntimeWarning("overflow"), RuntimeWarning, "x.py", 1)
    assert shown == ["RuntimeWarning: overflow"] and lines.summary() is None
