"""Bad flags and files of every command: one ``error:`` line naming the flag or file, exit 2,
before any work (no --out created, nothing written in the working directory)."""

from __future__ import annotations

from pathlib import Path

import pytest
from tests.hardening.helpers import assert_refused_cleanly

TOY = ["--calculator", "flatcontact.ispes.toy:toy_calculator"]


def _files(d: Path) -> dict[str, Path]:
    from flatcontact.structures.interface_io import write_interface
    from flatcontact.structures.toy import toy_interface

    (d / "adir").mkdir()
    (d / "binary.csv").write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(range(256)))
    (d / "binary.nc").write_bytes(b"\x00\x01garbage" * 50)
    (d / "empty.extxyz").write_bytes(b"")
    return {
        "iface": write_interface(toy_interface(layers=3), d / "iface.extxyz"),
        "adir": d / "adir",
        "binary_csv": d / "binary.csv",
        "binary_nc": d / "binary.nc",
        "empty_extxyz": d / "empty.extxyz",
    }


# (argv with {placeholders} for the files above, strings the line must contain)
CASES = {
    "scan-grid-huge": (
        ["scan", "--interface", "{iface}", *TOY, "--grid", "100000", "100000"],
        ["--grid", "FLATCONTACT_MAX_GRID_AXIS"],
    ),
    "scan-points": (
        [
            "scan",
            "--interface",
            "{iface}",
            *TOY,
            "--grid",
            "200",
            "200",
            "--p-range-gpa",
            "0",
            "4",
            "20",
        ],
        ["FLATCONTACT_MAX_SCAN_POINTS"],
    ),
    "scan-p-range-n": (
        ["scan", "--interface", "{iface}", *TOY, "--p-range-gpa", "0", "4", "10000000"],
        ["--p-range-gpa", "FLATCONTACT_MAX_THICKNESSES"],
    ),
    "scan-workers": (
        ["scan", "--interface", "{iface}", *TOY, "--workers", "100000"],
        ["--workers", "FLATCONTACT_MAX_WORKERS"],
    ),
    "scan-repeated-thickness": (
        ["scan", "--interface", "{iface}", *TOY, "--thickness-angstrom", "7,7.5,7"],
        ["--thickness-angstrom", "distinct"],
    ),
    "scan-bad-calculator": (
        ["scan", "--interface", "{iface}", "--calculator", "nosuchmodule_xyz:make"],
        ["--calculator", "nosuchmodule_xyz"],
    ),
    "scan-calculator-attribute": (
        ["scan", "--interface", "{iface}", "--calculator", "flatcontact.ispes.toy:nothing_here"],
        ["--calculator", "nothing_here"],
    ),
    "scan-interface-binary": (["scan", "--interface", "{binary_nc}", *TOY], ["binary.nc"]),
    "scan-interface-dir": (["scan", "--interface", "{adir}", *TOY], ["adir"]),
    "scan-interface-empty": (["scan", "--interface", "{empty_extxyz}", *TOY], ["empty.extxyz"]),
    "contact-radius-huge": (["contact", "--radius-um", "1e300"], ["--radius-um", "<="]),
    "contact-radius-zero": (["contact", "--radius-um", "0"], ["--radius-um"]),
    "contact-experiment-binary": (
        ["contact", "--experiment-csv", "{binary_csv}"],
        ["binary.csv", "UTF-8"],
    ),
    "contact-experiment-dir": (["contact", "--experiment-csv", "{adir}"], ["adir"]),
    "contact-experiment-proc": (
        ["contact", "--experiment-csv", "/proc/self/mem"],
        ["/proc/self/mem"],
    ),
    "elastic-strain-zero": (["elastic", "--potential", "vashishta", "--strain", "0"], ["--strain"]),
    "elastic-strain-negative": (
        ["elastic", "--potential", "vashishta", "--strain", "-0.01"],
        ["--strain"],
    ),
    "elastic-strain-large": (
        ["elastic", "--potential", "vashishta", "--strain", "0.5"],
        ["--strain"],
    ),
    "train-name-traversal": (
        ["train-snap", "--data", "{iface}", "--name", "../../evil", "--out", "{out}"],
        ["--name", "../../evil"],
    ),
    "train-name-slash": (
        ["train-snap", "--data", "{iface}", "--name", "a/b", "--out", "{out}"],
        ["--name", "a/b"],
    ),
    "train-name-hidden": (
        ["train-snap", "--data", "{iface}", "--name", ".hidden", "--out", "{out}"],
        ["--name", ".hidden"],
    ),
    "train-name-absolute": (
        ["train-snap", "--data", "{iface}", "--name", "/tmp/evil", "--out", "{out}"],
        ["--name", "/tmp/evil"],
    ),
    "train-scale-negative": (
        ["train-snap", "--data", "{iface}", "--scale", "-1", "--out", "{out}"],
        ["--scale", "-1"],
    ),
    "train-scale-nan": (
        ["train-snap", "--data", "{iface}", "--scale", "nan", "--out", "{out}"],
        ["--scale"],
    ),
    "train-active-rounds-negative": (
        ["train-snap", "--data", "{iface}", "--active-rounds", "-1", "--out", "{out}"],
        ["--active-rounds", "-1"],
    ),
    "build-layers-huge": (
        ["build", "--layers", "100000000", "--out", "{out}"],
        ["--layers", "FLATCONTACT_MAX_LAYERS"],
    ),
    "analyze-binary-nc": (
        ["analyze", "{binary_nc}", "--p-gpa", "0.5", "1", "--out", "{out}"],
        ["binary.nc"],
    ),
    "analyze-dir": (["analyze", "{adir}", "--p-gpa", "0.5", "1", "--out", "{out}"], ["adir"]),
    "run-out-is-a-file": (["run", "--out", "{binary_csv}"], ["--out", "binary.csv"]),
    "run-config-dir": (["run", "{adir}", "--out", "{out}"], ["adir", "directory"]),
    "config-proc": (["config", "--check", "/proc/self/mem"], ["/proc/self/mem"]),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_bad_flag_is_one_line_before_work(case, tmp_path, monkeypatch, capsys):
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    files = {k: str(v) for k, v in _files(work).items()}
    out = work / "out"
    argv, names = CASES[case]
    argv = [a.format(out=out, **files) for a in argv]
    assert_refused_cleanly(argv, capsys, work, names, out)
    assert not out.exists()
    assert not list(tmp_path.glob("evil*")) and not Path("/tmp/evil.snapcoeff").exists()


@pytest.mark.parametrize(
    "kwargs, field",
    [
        ({"name": "../../evil"}, "name"),
        ({"name": "sub/evil"}, "name"),
        ({"scale": -1.0}, "scale"),
        ({"active_rounds": -1}, "active_rounds"),
    ],
)
def test_train_snap_library_refuses_before_reading(tmp_path, kwargs, field):
    """The library door checks the same arguments as the CLI, before reading any data."""
    from flatcontact.foundation.errors import InputError
    from flatcontact.training.train import train_snap

    with pytest.raises(InputError, match=field):
        train_snap(tmp_path / "out", data=tmp_path / "never-read.extxyz", **kwargs)
    assert not (tmp_path / "out").exists() and not list(tmp_path.parent.glob("evil*"))
