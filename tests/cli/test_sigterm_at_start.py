"""A SIGTERM while the command line is still importing ends it with the one line a terminated
command prints and status 143, never a silent death by the signal (status -15); a Ctrl-C
(SIGINT) with the one line of an interrupted command and status 130, never a
``KeyboardInterrupt`` traceback.

A real process and a real signal from outside: the child runs the ``flatcontact`` entry point
(the console script's, from pyproject's ``[project.scripts]``, or ``python -m flatcontact``)
and, at the first import of a heavy library (typer, rich, click, numpy: the start-up's slow
part), tells the parent through a pipe and waits; the parent then sends the signal. Ordered by
the pipe, not by timing, so a loaded machine only makes it slower.
"""

import os
import signal
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

#: The child: a meta-path finder that stops at the first heavy import, then the entry point.
CHILD = r"""
import importlib, os, runpy, sys, time

fd = int(sys.argv[1])
HEAVY = {"typer", "rich", "click", "numpy"}


class WaitForSignal:
    def find_spec(self, name, path=None, target=None):
        if name.partition(".")[0] in HEAVY:
            sys.meta_path.remove(self)
            os.write(fd, name.encode() + b"\n")
            os.close(fd)
            time.sleep(300)  # the parent's SIGTERM comes in here
        return None


entry, sys.argv = sys.argv[2], ["flatcontact", *sys.argv[3:]]
sys.meta_path.insert(0, WaitForSignal())
if entry == "-m":
    runpy.run_module("flatcontact", run_name="__main__", alter_sys=True)
else:
    module, _, function = entry.partition(":")
    getattr(importlib.import_module(module), function)()
"""

#: signal -> (the one stderr line, the exit status)
EXPECTED = {
    signal.SIGTERM: (
        "error: terminated (SIGTERM); temporary files removed, finished work kept: rerun the "
        "same command to resume",
        143,
    ),
    signal.SIGINT: (
        "error: interrupted; temporary files removed, finished work kept: rerun the same "
        "command to resume",
        130,
    ),
}


def console_script() -> str:
    """``module:function`` of the ``flatcontact`` console script, as pyproject declares it."""
    with open(ROOT / "pyproject.toml", "rb") as fh:
        return tomllib.load(fh)["project"]["scripts"]["flatcontact"]


def _signals_as_in_a_terminal() -> None:
    """SIGINT at its default in the child, as a terminal's foreground command has it: a suite
    started in the background by a non-interactive shell (``make test &``, ``nohup``) runs
    with SIGINT ignored, which the child inherits, and Python then installs no handler (the
    SIGINT cases hung until their timeout that way)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
@pytest.mark.parametrize("entry", ["console script", "-m"])
def test_a_signal_during_start_up_prints_one_line(tmp_path, entry, sig):
    read, write = os.pipe()
    out = tmp_path / "run"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT / "src"), str(ROOT)])}
    target = console_script() if entry == "console script" else "-m"
    child = subprocess.Popen(
        [sys.executable, "-c", CHILD, str(write), target, "run", "--out", str(out)],
        pass_fds=(write,),
        preexec_fn=_signals_as_in_a_terminal,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
        cwd=tmp_path,
    )
    os.close(write)
    try:
        with os.fdopen(read, "rb") as pipe:
            reached = pipe.readline().decode().strip()
        assert reached, "the child never reached a heavy import"
        child.send_signal(sig)
        stdout, stderr = child.communicate(timeout=240)
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()
    line, status = EXPECTED[sig]
    assert "Traceback" not in stderr + stdout
    assert stderr.splitlines() == [line], (reached, child.returncode, stderr)
    assert child.returncode == status, (reached, stderr)
    assert not out.exists()


def test_the_console_script_is_the_entry_that_installs_the_handler_first():
    """The script's function is the one that installs the start-up handler before it imports
    the command line (a script pointing at ``flatcontact.cli:main`` imports typer first)."""
    assert console_script() == "flatcontact.__main__:main"


def test_the_entry_module_installs_the_handler_before_any_slow_import():
    """What runs before the start-up handler is the window in which SIGTERM still kills
    silently: importing the entry module loads no slow library (the command line's typer, rich,
    numpy; importlib.metadata, ~40 ms, which the package once read its version with)."""
    program = (
        "import signal, sys; import flatcontact.__main__ as entry; "
        "slow = ('typer', 'rich', 'click', 'numpy', 'importlib.metadata', 'flatcontact.cli'); "
        "print(sorted(m for m in slow if m in sys.modules))"
    )
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    done = subprocess.run(
        [sys.executable, "-c", program], capture_output=True, text=True, env=env, timeout=120
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[]", done.stdout


def test_the_version_read_on_first_use_is_the_installed_one():
    from importlib.metadata import PackageNotFoundError, version

    import flatcontact

    try:
        installed = version("flatcontact")
    except PackageNotFoundError:
        installed = "0.0.0+unknown"
    assert flatcontact.__version__ == installed
    assert "__version__" in dir(flatcontact) and "__version__" in flatcontact.__all__
