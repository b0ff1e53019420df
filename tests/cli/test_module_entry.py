"""``python -m flatcontact`` is the ``flatcontact`` command: same help, same one-line user error."""

import subprocess
import sys


def _run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "flatcontact", *args], capture_output=True, text=True, timeout=120
    )


def test_module_entry_prints_the_commands_help():
    done = _run("--help")
    assert done.returncode == 0
    assert "Usage: flatcontact" in done.stdout and "study" in done.stdout


def test_module_entry_reports_a_user_mistake_in_one_line_without_traceback(tmp_path):
    done = _run("analyze", str(tmp_path / "missing.nc"), "--p-gpa", "1")
    assert done.returncode == 2
    assert "Traceback" not in done.stderr + done.stdout
    assert "missing.nc" in done.stderr + done.stdout
