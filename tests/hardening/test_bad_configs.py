"""Bad run configurations: `config --check` and `run` refuse each in one line, before work.

Every case is a file a user could write (wrong bytes, encoding, nesting, repeated keys, a
value out of range or beyond a size bound, a file field naming a bad file). Both doors must
refuse it with exit 2 and one ``error:`` line naming the field or file; `run` must not
start a stage nor write anything outside its --out (nor the --out itself).
"""

from __future__ import annotations

from pathlib import Path

import pytest
from tests.hardening.helpers import TOY_YAML, assert_refused_cleanly


def _yaml(text: str):
    return lambda d: _write(d / "c.yaml", text.encode())


def _write(path: Path, data: bytes) -> Path:
    path.write_bytes(data)
    return path


def _deep(d: Path) -> Path:
    return _write(d / "c.yaml", ("scan: " + "[" * 5000 + "]" * 5000 + "\n").encode())


def _deep_mapping(d: Path) -> Path:
    return _write(d / "c.yaml", ("a: {" * 200 + "b: 1" + "}" * 200 + "\n").encode())


def _with_file(field_section: str, name: str, data: bytes, extra: str = ""):
    def make(d: Path) -> Path:
        _write(d / name, data)
        if field_section == "structure":
            body = f"structure: {{kind: file, file: {name}}}\n{extra}"
        else:
            body = f"contact: {{experiment: {{csv: {name}}}}}\n{extra}"
        return _write(d / "c.yaml", body.encode())

    return make


def _iface_without_slab(d: Path) -> Path:
    from ase.io import write

    from flatcontact.structures.toy import toy_interface

    atoms = toy_interface(layers=3)
    del atoms.arrays["slab"]
    write(d / "iface.extxyz", atoms, format="extxyz")
    return _write(d / "c.yaml", b"structure: {kind: file, file: iface.extxyz}\n")


def _dir_config(d: Path) -> Path:
    (d / "conf.yaml").mkdir()
    return d / "conf.yaml"


def _structure_dir(d: Path) -> Path:
    (d / "sub").mkdir()
    return _write(d / "c.yaml", b"structure: {kind: file, file: sub}\n")


CASES = {
    # bytes and encoding
    "latin-1": (
        lambda d: _write(d / "c.yaml", "report: {title: caf\xe9}\n".encode("latin-1")),
        ["c.yaml", "UTF-8"],
    ),
    "binary": (lambda d: _write(d / "c.yaml", bytes(range(256)) * 4), ["c.yaml", "UTF-8"]),
    "not-yaml": (_yaml("scan: [1, 2\n"), ["c.yaml", "not valid YAML"]),
    "not-a-mapping": (_yaml("- 1\n- 2\n"), ["c.yaml", "mapping"]),
    "deep-lists": (_deep, ["c.yaml", "nested deeper"]),
    "deep-mappings": (_deep_mapping, ["c.yaml", "nested deeper"]),
    "duplicate-section": (
        _yaml("scan: {grid: [4, 4]}\nscan: {grid: [6, 6]}\n"),
        ["c.yaml", '"scan" given twice'],
    ),
    "duplicate-field": (
        _yaml("contact: {radius_um: 1, radius_um: 2}\n"),
        ["c.yaml", '"radius_um" given twice'],
    ),
    "too-big": (
        lambda d: _write(d / "c.yaml", b"# " + b"x" * 2_000_000 + b"\n"),
        ["c.yaml", "larger than"],
    ),
    "directory": (_dir_config, ["conf.yaml", "directory"]),
    # a grid the analysis cannot interpolate: refused before the scan, not after it
    "grid-2x2": (
        _yaml(TOY_YAML.replace("grid: [3, 3]", "grid: [2, 2]")),
        ["scan.grid", "2×2", "at least 3 per axis"],
    ),
    "missing": (lambda d: d / "nope.yaml", ["nope.yaml", "no such config file"]),
    "unreadable": (lambda d: Path("/proc/self/mem"), ["/proc/self/mem", "cannot read"]),
    # values
    "unknown-field": (_yaml("scan: {gird: [4, 4]}\n"), ["scan.gird", "unknown field"]),
    "zero-grid": (_yaml("scan: {grid: [0, 4]}\n"), ["scan.grid", "positive integers"]),
    "float-grid": (_yaml("scan: {grid: [1e18, 2]}\n"), ["scan.grid", "positive integers"]),
    "nan": (_yaml("contact: {radius_um: .nan}\n"), ["contact.radius_um", "finite"]),
    "radius-huge": (_yaml("contact: {radius_um: 1e300}\n"), ["contact.radius_um", "<="]),
    "repeated-thickness": (
        _yaml("scan: {thickness_angstrom: [5.0, 6.0, 5.0]}\n"),
        ["scan.thickness_angstrom", "distinct", "5.0"],
    ),
    "lo-above-hi": (
        _yaml("scan: {p_range_gpa: {lo_gpa: 2, hi_gpa: 1, n: 4}}\n"),
        ["scan.p_range_gpa", "lo_gpa < hi_gpa"],
    ),
    "negative-strain": (_yaml("elastic: {strain: -0.01}\n"), ["elastic.strain"]),
    "bad-preset": (_yaml("preset: fast\n"), ["preset", "quick or paper"]),
    # sizes
    "grid-axis": (
        _yaml("scan: {grid: [100000, 100000]}\n"),
        ["scan.grid", "FLATCONTACT_MAX_GRID_AXIS"],
    ),
    "scan-points": (
        _yaml("scan: {grid: [200, 200], p_range_gpa: {lo_gpa: 0, hi_gpa: 4, n: 20}}\n"),
        ["scan.grid", "FLATCONTACT_MAX_SCAN_POINTS"],
    ),
    "p-range-n": (
        _yaml("scan: {p_range_gpa: {lo_gpa: 0, hi_gpa: 4, n: 10000000}}\n"),
        ["scan.p_range_gpa.n", "FLATCONTACT_MAX_THICKNESSES"],
    ),
    "thickness-count": (
        _yaml(
            "scan: {thickness_angstrom: ["
            + ", ".join(f"{5 + i / 100:.2f}" for i in range(600))
            + "]}\n"
        ),
        ["scan.thickness_angstrom", "FLATCONTACT_MAX_THICKNESSES"],
    ),
    "workers": (_yaml("scan: {workers: 100000}\n"), ["scan.workers", "FLATCONTACT_MAX_WORKERS"]),
    "layers": (
        _yaml("structure: {layers: 100000000}\n"),
        ["structure.layers", "FLATCONTACT_MAX_LAYERS"],
    ),
    "loads": (
        _yaml("analysis: {p_gpa: [" + ", ".join(str(i / 100) for i in range(2000)) + "]}\n"),
        ["analysis.p_gpa", "FLATCONTACT_MAX_LOADS"],
    ),
    # files named by fields
    "structure-missing": (
        _yaml("structure: {kind: file, file: none.extxyz}\n"),
        ["structure.file", "none.extxyz"],
    ),
    "structure-directory": (_structure_dir, ["structure.file", "sub", "not a regular file"]),
    "structure-binary": (
        _with_file("structure", "iface.extxyz", b"\x00\xff" * 300),
        ["structure.file", "iface.extxyz"],
    ),
    "structure-no-slab": (_iface_without_slab, ["structure.file", "iface.extxyz", "slab"]),
    "csv-binary": (
        _with_file("contact", "m.csv", b"\x89PNG\r\n\x1a\n" + bytes(range(256))),
        ["m.csv", "UTF-8"],
    ),
    "csv-latin-1": (
        _with_file(
            "contact", "m.csv", "contrainte [MPa],raideur [N/m]\n1,2\n\xe9\n".encode("latin-1")
        ),
        ["m.csv", "UTF-8"],
    ),
    "csv-not-numeric": (
        _with_file(
            "contact",
            "m.csv",
            b"mean shear stress [MPa],lateral stiffness [N/m]\na,b\n1,2\n3,4\n5,6\n",
        ),
        ["contact.experiment.csv", "m.csv", "not numeric"],
    ),
    "calculator-import": (
        _yaml("potential: {calculator: {target: 'nosuchmodule_xyz:make'}}\n"),
        ["calculator", "nosuchmodule_xyz"],
    ),
    "calculator-attribute": (
        _yaml(TOY_YAML.replace("toy_calculator", "no_such_factory")),
        ["calculator", "no_such_factory"],
    ),
}


@pytest.fixture
def workdir(tmp_path, monkeypatch):
    d = tmp_path / "work"
    d.mkdir()
    monkeypatch.chdir(d)
    return d


@pytest.mark.parametrize("case", sorted(CASES))
def test_config_check_refuses(case, workdir, capsys):
    make, names = CASES[case]
    path = make(workdir)
    assert_refused_cleanly(["config", "--check", path], capsys, workdir, names)


@pytest.mark.parametrize("case", sorted(CASES))
def test_run_refuses_before_any_stage(case, workdir, capsys):
    make, names = CASES[case]
    path = make(workdir)
    out = workdir / "out"
    assert_refused_cleanly(["run", path, "--out", out], capsys, workdir, names, out)
    assert not out.exists()


def test_a_bound_is_raised_by_its_environment_variable(workdir, capsys, monkeypatch):
    from tests.hardening.helpers import run_cli

    path = workdir / "c.yaml"
    path.write_text("scan: {grid: [300, 3]}\n")
    monkeypatch.setenv("FLATCONTACT_MAX_GRID_AXIS", "300")
    code, out, err = run_cli(["config", "--check", path], capsys)
    assert code == 0, err
    assert "grid: [300, 3]" in out
    monkeypatch.setenv("FLATCONTACT_MAX_GRID_AXIS", "lots")
    assert_refused_cleanly(
        ["config", "--check", path],
        capsys,
        workdir,
        ["FLATCONTACT_MAX_GRID_AXIS", "positive integer"],
    )


def test_the_presets_dumped_and_checked_are_within_the_bounds(workdir, capsys):
    """The bounds leave room for every preset: its full dump passes `config --check`."""
    from tests.hardening.helpers import run_cli

    for preset in ("quick", "paper"):
        code, out, err = run_cli(["config", "--show-default", "--preset", preset], capsys)
        assert code == 0, err
        path = workdir / f"{preset}.yaml"
        path.write_text(out)
        code, again, err = run_cli(["config", "--check", path], capsys)
        assert code == 0, err
        assert again == out
