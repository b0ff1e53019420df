"""Resource limits of the process: the file-size limit (``ulimit -f``) and the memory limit
(``ulimit -v``) are one ``error:`` line naming the limit (and the file), exit 2, no
traceback; the rerun without the limit finishes."""

from __future__ import annotations

import errno
import os
import resource
import subprocess
import sys

import numpy as np
import pytest
from tests.hardening.helpers import TOY_YAML, refused, run_cli


def test_file_size_limit_is_one_line_naming_the_file(tmp_path, monkeypatch, capsys):
    config = tmp_path / "run.yaml"
    config.write_text(TOY_YAML)
    real_replace = os.replace

    def too_large(src, dst, *args, **kwargs):
        if "/01-build/" in str(dst):
            raise OSError(errno.EFBIG, "File too large", str(src))
        return real_replace(src, dst, *args, **kwargs)

    monkeypatch.setattr(os, "replace", too_large)
    code, _, err = run_cli(["run", config, "--out", tmp_path / "run"], capsys)
    refused(code, err, "file size limit", "ulimit -f", "01-build")
    assert not list((tmp_path / "run").rglob("*.part"))
    monkeypatch.setattr(os, "replace", real_replace)
    code, _, err = run_cli(["run", config, "--out", tmp_path / "run"], capsys)
    assert code == 0, err


def test_memory_limit_is_one_line(tmp_path, monkeypatch, capsys):
    from flatcontact.foundation import rundir

    def no_memory(*args, **kwargs):
        return np.empty(1 << 50)  # numpy's _ArrayMemoryError, as under ulimit -v

    monkeypatch.setattr(rundir, "fingerprint", no_memory)
    config = tmp_path / "run.yaml"
    config.write_text(TOY_YAML)
    code, _, err = run_cli(["run", config, "--out", tmp_path / "run"], capsys)
    refused(code, err, "out of memory", "ulimit -v", "Unable to allocate")


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux only")
def test_a_real_file_size_limit_is_one_line(tmp_path):
    """``ulimit -f`` for real, in a child process: the first file over the limit stops it."""
    config = tmp_path / "run.yaml"
    config.write_text(TOY_YAML)

    def limit():
        resource.setrlimit(resource.RLIMIT_FSIZE, (65536, 65536))

    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    argv = ["run", str(config), "--out", str(tmp_path / "run")]
    proc = subprocess.run(
        [sys.executable, "-c", "from flatcontact.cli import main; main()", *argv],
        capture_output=True,
        text=True,
        env=env,
        preexec_fn=limit,
        timeout=300,
    )
    refused(proc.returncode, proc.stderr, "file size limit", "ulimit -f")
    proc = subprocess.run(
        [sys.executable, "-c", "from flatcontact.cli import main; main()", *argv],
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr
