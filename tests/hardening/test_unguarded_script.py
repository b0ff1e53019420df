"""The Python API from a plain script without ``if __name__ == "__main__":`` (issue 32), and a
run-directory lock that outlived its writer.

Local scan workers are spawned and import the main script again; a script that calls
flatcontact at its top level would run the study again in every worker. Such a script runs its
points serially, with one warning naming the guard (:mod:`flatcontact.ispes.main_guard`), and
the same script with the guard gets its workers. A lock whose writer was killed while a process
forked from it still holds the open lock file is recognised as stale and taken over
(:class:`flatcontact.foundation.rundir.RunLock`).
"""

from __future__ import annotations

import logging
import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from flatcontact.foundation.errors import InputError
from flatcontact.foundation.rundir import RunLock, stale_holder
from flatcontact.ispes.main_guard import guarded_lines

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux only")

TOY = """\
from flatcontact import Pipeline, build_config

cfg = build_config({
    "structure": {"kind": "toy-lj", "layers": 3},
    "potential": {"calculator": {"target": "flatcontact.ispes.toy:toy_calculator"}},
    "scan": {"grid": [3, 3], "p_range_gpa": {"lo_gpa": -0.2, "hi_gpa": 1.5, "n": 4},
             "executor": "processes", "workers": 2},
    "analysis": {"p_gpa": [0.0, 0.5, 1.0]},
    "report": {"svg": False},
})
"""
CALLS = """\
pipe = Pipeline(cfg, "run")
ispes = pipe.scan()
print("converged", int(ispes["converged"].sum()), ispes["energy"].size)
pipe.close()
"""


def _env() -> dict:
    return {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}


def _run_script(folder: Path, source: str, timeout: float = 300) -> subprocess.CompletedProcess:
    (folder / "script.py").write_text(source)
    return subprocess.run(
        [sys.executable, "script.py"],
        cwd=folder,
        env=_env(),
        capture_output=True,
        text=True,
        timeout=timeout,
    )


def test_a_script_without_the_guard_completes_serially_with_one_warning(tmp_path):
    done = _run_script(tmp_path, TOY + CALLS)
    assert done.returncode == 0, done.stderr
    assert "BrokenProcessPool" not in done.stderr and "another flatcontact" not in done.stderr
    # every grid point relaxed (the toy's 3 x 3 x thicknesses grid), all converged
    converged, size = (int(v) for v in done.stdout.split()[-2:])
    assert converged == size > 0
    warned = [line for line in done.stderr.splitlines() if "SerialFallback" in line]
    assert len(warned) == 1 and "__name__" in warned[0] and "serially" in warned[0]
    assert "run serially" in (tmp_path / "run" / "run.log").read_text()


def test_the_same_script_with_the_guard_gets_its_workers(tmp_path):
    guarded = TOY + 'if __name__ == "__main__":\n' + textwrap.indent(CALLS, "    ")
    done = _run_script(tmp_path, guarded)
    assert done.returncode == 0, done.stderr
    assert "SerialFallback" not in done.stderr
    assert "run serially" not in (tmp_path / "run" / "run.log").read_text()


PROBE = """\
from flatcontact.ispes.main_guard import unguarded_script

def inner():
    return unguarded_script()

print("top", unguarded_script() is not None)
print("top-function", inner() is not None)
if __name__ == "__main__":
    print("guarded", unguarded_script() is not None)
    print("guarded-function", inner() is not None)
"""


def test_only_calls_from_the_scripts_top_level_outside_the_guard_are_unguarded(tmp_path):
    done = _run_script(tmp_path, PROBE, timeout=60)
    assert done.returncode == 0, done.stderr
    seen = dict(line.split() for line in done.stdout.splitlines())
    assert seen == {
        "top": "True",
        "top-function": "True",
        "guarded": "False",
        "guarded-function": "False",
    }
    # no main file (python -c, a notebook kernel's __main__): nothing for a worker to import
    code = "from flatcontact.ispes.main_guard import unguarded_script; print(unguarded_script())"
    out = subprocess.run([sys.executable, "-c", code], env=_env(), capture_output=True, text=True)
    assert out.stdout.strip() == "None", out.stderr


def test_guarded_lines_are_the_bodies_of_main_blocks_in_either_order():
    src = (
        "x = 1\nif __name__ == '__main__':\n    a()\n    b()\nif '__main__' == __name__:\n    c()\n"
    )
    assert guarded_lines(src) == [(3, 4), (6, 6)]
    assert guarded_lines("if __name__ != '__main__':\n    a()\n") == []
    assert guarded_lines("def (:\n") == []


HOLDER = """\
import os, sys, time
from flatcontact.foundation.rundir import RunLock

lock = RunLock(sys.argv[1]).acquire()
child = os.fork()
if child == 0:  # inherits the open lock file, and with it the lock
    time.sleep(120)
    os._exit(0)
print(child, flush=True)
time.sleep(120)
"""


def test_a_lock_whose_writer_was_killed_is_taken_over_with_a_log_line(tmp_path, caplog):
    run = tmp_path / "run"
    run.mkdir()
    (tmp_path / "holder.py").write_text(HOLDER)
    writer = subprocess.Popen(
        [sys.executable, str(tmp_path / "holder.py"), str(run)],
        env=_env(),
        stdout=subprocess.PIPE,
        text=True,
    )
    child = int(writer.stdout.readline())
    try:
        # while the writer lives, a second writer is refused in one line naming its pid
        with pytest.raises(InputError, match=f"pid {writer.pid}"):
            RunLock(run).acquire()
        recorded = (run / ".flatcontact.lock").read_text().split()
        assert recorded[0] == str(writer.pid) and len(recorded) == 3
        writer.kill()
        writer.wait(timeout=30)
        # the forked child still holds the lock file open: the lock itself is still held
        assert stale_holder(" ".join(recorded)) == f"pid {writer.pid} is not running"
        with caplog.at_level(logging.WARNING, logger="flatcontact"):
            lock = RunLock(run).acquire()
        try:
            assert (run / ".flatcontact.lock").read_text().split()[0] == str(os.getpid())
            said = [r.getMessage() for r in caplog.records if "stale" in r.getMessage()]
            assert len(said) == 1 and f"pid {writer.pid}" in said[0] and "taking it over" in said[0]
            # and the new lock is a real one: a third writer is refused, naming this process
            with pytest.raises(InputError, match=f"pid {os.getpid()}"):
                RunLock(run).acquire()
        finally:
            lock.release()
    finally:
        for pid in (writer.pid, child):
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        writer.stdout.close()


def test_a_holder_on_another_host_or_alive_here_is_not_stale():
    assert stale_holder(f"{os.getpid()} {os.uname().nodename} ?") is None
    assert stale_holder("1 some-other-host 12345") is None
    assert stale_holder("") is None and stale_holder("not-a-pid") is None
    assert stale_holder("999999999") == "pid 999999999 is not running"


def _try_lock(root: str, answer) -> None:
    """In a spawned worker: take the run directory's lock, answer the refusal line."""
    try:
        RunLock(root).acquire()
        answer.put("acquired")
    except InputError as exc:
        answer.put(str(exc))


def test_a_spawned_worker_meeting_its_parents_lock_is_told_about_the_guard(tmp_path):
    """What a worker that re-ran an unguarded script would meet (when the script is not
    recognised, e.g. run through exec): its parent's lock, named as such with the guard."""
    import multiprocessing

    ctx = multiprocessing.get_context("spawn")
    answer = ctx.Queue()
    lock = RunLock(tmp_path).acquire()
    try:
        worker = ctx.Process(target=_try_lock, args=(str(tmp_path), answer))
        worker.start()
        line = answer.get(timeout=120)
        worker.join(timeout=60)
    finally:
        lock.release()
    assert "\n" not in line and f"started by pid {os.getpid()}" in line
    assert 'if __name__ == "__main__":' in line
