"""Faults, in real child processes: SIGTERM in a standalone command leaves no temporary file
(it left .fig4_traction.png.<random>.part), a memory limit (ulimit -v) is one line (it was an
ImportError stack), a file-size limit (ulimit -f) under LAMMPS's MPI is one line naming it
(it was an MPI_Init abort with a multi-line stack, exit 143), and a control character in a
name cannot split the one error line."""

from __future__ import annotations

import os
import resource
import signal
import subprocess
import sys
import time

import pytest
from tests.hardening.helpers import refused, run_cli, stored_rows

from flatcontact.cli.app import one_line


def _env() -> dict:
    return {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}


def _flatcontact(*args) -> list[str]:
    return [sys.executable, "-m", "flatcontact", *map(str, args)]


def test_sigterm_in_a_standalone_contact_leaves_no_temporary_file(tmp_path):
    """SIGTERM the moment a .part file appears (a figure being written): before, the file
    stayed; now the command unwinds, removes it, and says so in one line (status 143)."""
    out = tmp_path / "contact"
    proc = subprocess.Popen(
        _flatcontact("contact", "--out", out),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        env=_env(),
        cwd=tmp_path,
    )
    seen = []
    t0 = time.monotonic()
    while proc.poll() is None and time.monotonic() - t0 < 240:
        seen = [p.name for p in out.glob(".*.part")] if out.is_dir() else []
        if seen:
            proc.send_signal(signal.SIGTERM)
            break
        time.sleep(0.0005)
    code = proc.wait(timeout=240)
    err = proc.stderr.read()
    if not seen:
        pytest.skip("the command finished before a temporary file was seen")
    assert code == 128 + signal.SIGTERM, err
    assert [p.name for p in out.glob(".*.part")] == [], "a temporary file survived SIGTERM"
    refused(2, err, "terminated (SIGTERM)", "temporary files removed")


def _limited(kind: int, limit: int):
    def apply():
        resource.setrlimit(kind, (limit, resource.getrlimit(kind)[1]))

    return apply


@pytest.mark.parametrize("kb", [60_000, 200_000])
def test_a_memory_limit_too_low_to_load_the_libraries_is_one_line(tmp_path, kb):
    """60 MB: numpy's own library did not map (an ImportError stack); 200 MB: SciPy's."""
    proc = subprocess.run(
        _flatcontact("config", "--show-default"),
        capture_output=True,
        text=True,
        env=_env(),
        cwd=tmp_path,
        preexec_fn=_limited(resource.RLIMIT_AS, kb * 1024),
        timeout=120,
    )
    refused(proc.returncode, proc.stderr, "ulimit -v", f"{kb} kB")


def test_a_file_size_limit_below_what_mpi_writes_is_one_line_before_any_stage(tmp_path):
    """1 MB: MPI_Init aborted the process (exit 143, a multi-line MPI stack). Now the preflight
    (which sets LAMMPS up) refuses it in one line naming ulimit -f; no stage ran."""
    conf = tmp_path / "cu.yaml"
    conf.write_text(
        "structure: {kind: fcc111, element: Cu, layers: 3}\n"
        "potential: {preset: cu-eam}\n"
        "scan: {grid: [3, 3], p_range_gpa: {lo_gpa: 0.0, hi_gpa: 1.0, n: 3}, executor: serial}\n"
        "contact: {contact_modulus_gpa: 100, shear_modulus_gpa: 40}\n"
    )
    out = tmp_path / "run"
    proc = subprocess.run(
        _flatcontact("run", conf, "--out", out),
        capture_output=True,
        text=True,
        env=_env(),
        cwd=tmp_path,
        preexec_fn=_limited(resource.RLIMIT_FSIZE, 1024 * 1024),
        timeout=300,
    )
    refused(proc.returncode, proc.stderr, "ulimit -f", "1048576 bytes", "MPI")
    assert not any(out.glob("0*-*")), "a stage started"


def test_a_control_character_in_a_name_cannot_split_the_error_line(tmp_path, capsys):
    conf = tmp_path / "bad\tkind\nname.yaml"
    conf.write_text("structure: {kind: nonsense}\n")
    code, _, err = run_cli(["config", "--check", conf], capsys)
    line = refused(code, err, "bad\\tkind\\nname.yaml", "structure.kind")
    assert "\t" not in line
    assert one_line("a\x1b[31mred\x7f") == "a\\x1b[31mred\\x7f"


def test_sigterm_in_a_forked_child_of_a_command_still_kills_it():
    """The command's handler is the main process's: a process forked from it (a pool
    worker) dies of SIGTERM as it did, instead of unwinding someone else's stack."""
    code = (
        "import os, signal, sys, time\n"
        "from flatcontact.cli import sigterm_unwinds\n"
        "with sigterm_unwinds():\n"
        "    pid = os.fork()\n"
        "    if pid == 0:\n"
        "        time.sleep(30); os._exit(0)\n"
        "    time.sleep(0.5); os.kill(pid, signal.SIGTERM)\n"
        "    _, status = os.waitpid(pid, 0)\n"
        "    print(os.WIFSIGNALED(status) and os.WTERMSIG(status) == signal.SIGTERM)\n"
    )
    proc = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=_env(), timeout=60
    )
    assert proc.stdout.strip() == "True", proc.stderr


def _signal_once(argv, cwd, ready, sig, seconds=240.0):
    """Start ``flatcontact argv`` and send ``sig`` the moment ``ready()`` holds; (status,
    stderr, whether the signal was sent). SIGINT is restored to its default in the child, as
    in a terminal (a background shell would have it ignored)."""
    proc = subprocess.Popen(
        _flatcontact(*argv),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        env=_env(),
        cwd=cwd,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    sent = False
    t0 = time.monotonic()
    while proc.poll() is None and time.monotonic() - t0 < seconds:
        if ready():
            proc.send_signal(sig)
            sent = True
            break
        time.sleep(0.001)
    code = proc.wait(timeout=seconds)
    return code, proc.stderr.read(), sent


@pytest.mark.parametrize("command", ["run", "scan"])
@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_a_signal_in_the_scan_is_one_error_line(tmp_path, finished_toy, command, sig):
    """SIGTERM (or Ctrl-C) once the scan has stored points: before, ``flatcontact run`` printed
    its own "interrupted; ..." line and then the "error: terminated (SIGTERM)" line, and a
    Ctrl-C outside the scan's points printed nothing (typer turns it into status 130 without
    a word); now exactly one line, naming what was kept where the command knows it."""
    conf, run = finished_toy
    out = tmp_path / "out"
    if command == "run":
        argv, db = ["run", conf / "run.yaml", "--out", out], out / "02-scan" / "points.db"
    else:
        interface = run / "01-build" / "interface.extxyz"
        argv = ["scan", conf / "run.yaml", "--interface", interface, "--out", out]
        db = out / "points.db"
    code, err, sent = _signal_once(argv, tmp_path, lambda: db.exists() and stored_rows(db) > 0, sig)
    if not sent:
        pytest.skip("the scan finished before a point was seen")
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert "Traceback" not in err
    if sig == signal.SIGTERM:
        assert code == 128 + signal.SIGTERM, err
        assert lines[0].startswith("error: terminated (SIGTERM); temporary files removed"), err
    else:
        assert code == 130, err
        assert "interrupted;" in lines[0], err
    assert "rerun the same command" in lines[0]


def test_a_file_size_limit_under_the_point_stores_log_is_one_line_and_the_rerun_resumes(
    tmp_path, finished_toy
):
    """1000 kB: the toy run's point store grows its write-ahead log past that before a
    checkpoint (4 MB in ASE's layout, where ``python -m benchmarks limits`` measured the toy run
    passing at 3.94 MiB and failing at 3.88; between 1000 and 2000 kB in the compact store,
    store_schema.py); SQLite reported the write past the limit as "disk I/O error", a traceback
    (exit 1). Now one line naming ulimit -f and the limit, and the rerun without it resumes to
    the finished run's grid."""
    import numpy as np
    import xarray as xr

    conf, finished = finished_toy
    out = tmp_path / "run"
    limit = 1_000 * 1024
    proc = subprocess.run(
        _flatcontact("run", conf / "run.yaml", "--out", out),
        capture_output=True,
        text=True,
        env=_env(),
        cwd=tmp_path,
        preexec_fn=_limited(resource.RLIMIT_FSIZE, limit),
        timeout=600,
    )
    refused(proc.returncode, proc.stderr, "ulimit -f", f"{limit} bytes")
    assert (out / "02-scan" / "points.db").is_file()
    again = subprocess.run(
        _flatcontact("run", conf / "run.yaml", "--out", out),
        capture_output=True,
        text=True,
        env=_env(),
        cwd=tmp_path,
        timeout=600,
    )
    assert again.returncode == 0, again.stderr
    with (
        xr.open_dataset(out / "02-scan" / "ispes.nc", engine="h5netcdf") as resumed,
        xr.open_dataset(finished / "02-scan" / "ispes.nc", engine="h5netcdf") as whole,
    ):
        for name in ("energy", "normal_stress"):
            assert np.array_equal(resumed[name].values, whole[name].values), name


def test_the_floors_are_what_their_measurement_says():
    """The floors against ``benchmarks/limits_measured.json`` (``python -m benchmarks limits``):
    the address-space floor lies above the libraries' need and above every limit at which a
    command ended in more than one line (MPI_Init's abort, numpy's and OpenBLAS's), and below
    what a run needs; the file-size floor above MPI_Init's measured pool; and
    docs/measured/resource-floors.md shows the record's tables."""
    import json
    from pathlib import Path

    from benchmarks.bench_limits import RECORD, table

    from flatcontact.cli.memory_floor import MIN_ADDRESS_SPACE_BYTES
    from flatcontact.potentials.lammps_runtime import MPI_MIN_FILE_BYTES

    record = json.loads(RECORD.read_text())
    mib = 1024 * 1024
    assert record["floors_bytes"] == {
        "ulimit -v": MIN_ADDRESS_SPACE_BYTES,
        "ulimit -f": MPI_MIN_FILE_BYTES,
    }
    assert record["libraries"]["ulimit -v"]["passes_at_bytes"] < MIN_ADDRESS_SPACE_BYTES
    many_lines = [
        int(limit)
        for seen in record["modes"].values()
        for limit, said in seen.items()
        if not said.startswith(("exit 0", "exit 2, 1 stderr line"))
    ]
    assert many_lines and max(many_lines) * mib < MIN_ADDRESS_SPACE_BYTES
    for run in ("toy", "lammps"):
        assert record[run]["ulimit -v"]["passes_at_bytes"] > MIN_ADDRESS_SPACE_BYTES
    pool = record["libraries"]["ulimit -f"]["passes_at_bytes"]
    assert pool == record["lammps"]["ulimit -f"]["passes_at_bytes"] < MPI_MIN_FILE_BYTES
    doc = (Path(__file__).parents[2] / "docs" / "measured" / "resource-floors.md").read_text()
    for part in table(record).split("\n\n"):
        assert part in doc
