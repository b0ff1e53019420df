"""The command line's bad-input behaviour: one verbatim ``error:`` line, exit 2, before any work."""

import pytest
from tests.cli.cli_helpers import one_error_line, run_cli

_run = run_cli
_one_error_line = one_error_line


# ---- 1: messages are printed verbatim (no rich markup eats '[...]') ----------------------


def test_error_keeps_square_brackets(tmp_path, capsys):
    csv = tmp_path / "nounit.csv"
    csv.write_text("stress,stiffness\n1,2\n")
    line = _one_error_line(*_run(["contact", "--experiment-csv", str(csv)], capsys)[::2])
    assert "'name [unit]'" in line and "'mean shear stress [MPa]'" in line


def test_error_keeps_lowercase_markup_lookalikes(capsys):
    from flatcontact.cli.app import print_error, print_warning

    print_error("got [nan] and [bold]x[/bold] in [/tmp/a b]")
    print_warning("[dim]kept[/dim]")
    err = capsys.readouterr().err
    assert "error: got [nan] and [bold]x[/bold] in [/tmp/a b]" in err
    assert "warning: [dim]kept[/dim]" in err


# ---- 2: --out checked before any work, by one helper -----------------------------------


@pytest.mark.parametrize(
    "argv",
    [
        ["contact", "--p0-gpa", "1"],
        ["build", "--potential", "vashishta"],
        ["run"],
        ["scan", "--potential", "vashishta", "--interface", "missing.extxyz"],
        ["train-snap", "--data", "missing.extxyz"],
    ],
)
@pytest.mark.parametrize("bad", ["proc", "file"])
def test_unusable_out_is_one_line_before_work(tmp_path, monkeypatch, capsys, argv, bad):
    monkeypatch.chdir(tmp_path)
    if bad == "file":
        target = tmp_path / "afile"
        target.write_text("keep me\n")
        expected = "exists and is not a directory"
    else:
        target = "/proc/flatcontact-forbidden/x"
        expected = "cannot write there"
    line = _one_error_line(*_run([*argv, "--out", str(target)], capsys)[::2])
    assert line.startswith(f"error: --out '{target}'") and expected in line
    if bad == "file":
        assert (tmp_path / "afile").read_text() == "keep me\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == (["afile"] if bad == "file" else [])


def test_check_out_dir_creates_nothing(tmp_path):
    from flatcontact.cli.app import check_out_dir
    from flatcontact.foundation.errors import InputError

    assert check_out_dir(tmp_path / "a" / "b") == tmp_path / "a" / "b"
    assert list(tmp_path.iterdir()) == []
    (tmp_path / "f").write_text("")
    with pytest.raises(InputError, match=r"'.*f' is not a directory"):
        check_out_dir(tmp_path / "f" / "sub")


@pytest.mark.parametrize(
    ("flag", "value"),
    [
        ("--lj-cutoff-angstrom", "-3"),
        ("--lj-cutoff-angstrom", "nan"),
        ("--gap-angstrom", "0"),
        ("--fmax-ev-per-angstrom", "0"),
        ("--fmax-ev-per-angstrom", "-1"),
        ("--fmax-ev-per-angstrom", "nan"),
    ],
)
def test_build_refuses_bad_numbers_naming_the_flag(tmp_path, capsys, flag, value):
    argv = ["build", "--potential", "vashishta", "--out", str(tmp_path / "b"), flag, value]
    line = _one_error_line(*_run(argv, capsys)[::2])
    # the bounds of the setting the flag sets (structure.gap_angstrom, ..., lj.cutoff_angstrom)
    assert line.startswith(f"error: {flag}: expected ") and "<= value <=" in line
    assert not (tmp_path / "b").exists()


# ---- 3: an unconverged build relaxation is said on the console --------------------------


def test_build_warns_when_relaxation_does_not_converge(tmp_path, monkeypatch, capsys):
    from flatcontact.structures import build as builder
    from flatcontact.structures import dense

    def few_steps(atoms, calc, fmax_ev_per_angstrom=0.01):
        return dense.relax(atoms, calc, fmax_ev_per_angstrom, steps=3)

    monkeypatch.setattr(builder, "relax", few_steps)
    out = tmp_path / "b"
    code, _, err = _run(["build", "--potential", "vashishta", "--out", str(out)], capsys)
    assert code in (0, None)
    warnings = [ln for ln in err.splitlines() if ln.startswith("warning: ")]
    assert len(warnings) == 2 and all("did not converge" in w for w in warnings)
    assert "slab relaxation" in warnings[0] and "interface relaxation" in warnings[1]
    assert (out / "interface.extxyz").is_file()


def test_relax_refuses_non_positive_fmax():
    from flatcontact.foundation.errors import InputError
    from flatcontact.structures.dense import relax

    for bad in (0.0, -1.0, float("nan")):
        with pytest.raises(InputError, match="fmax_ev_per_angstrom"):
            relax(None, None, bad)


# ---- 5: one resolver for every command ---------------------------------------------------


@pytest.fixture()
def snap_copy(tmp_path):
    import shutil

    from flatcontact.potentials.files import BUNDLED_DIR

    src = BUNDLED_DIR / "sio2-snap"
    if not (src / "sio2-snap.snapcoeff").is_file():
        pytest.skip("no bundled SNAP")
    d = tmp_path / "p"
    d.mkdir()
    for ext in ("snapcoeff", "snapparam"):
        shutil.copy(src / f"sio2-snap.{ext}", d / f"X.{ext}")
    return d / "X.snapcoeff"


def test_every_command_reads_every_spelling(snap_copy):
    from flatcontact.cli.build import _potential_spec
    from flatcontact.cli.bulk_models import bulk_potential as _bulk_potential
    from flatcontact.cli.scan import _potential_section, resolve_config

    groups = {
        "snap:sio2-snap": ["sio2-snap", "snap:sio2-snap"],
        f"snap:{snap_copy}": [str(snap_copy), f"snap:{snap_copy}"],
        "vashishta": ["vashishta"],
    }
    for canonical, spellings in groups.items():
        for name in spellings:
            scan_cfg = resolve_config(None, None, {"potential": _potential_section(name)})
            assert scan_cfg.potential.intra == canonical, name
            assert _potential_spec(name, 10.0).intra == canonical, name
            bulk = _bulk_potential(name, "--potential")
            expected = {"snap:sio2-snap": "sio2-snap", "vashishta": "vashishta"}
            assert bulk == expected.get(canonical, str(snap_copy)), name


def test_elastic_refuses_an_ase_factory(capsys):
    code, _, err = _run(["elastic", "--potential", "ase:flatcontact.ispes.toy:toy"], capsys)
    line = _one_error_line(code, err)
    assert "--potential" in line and "expected a LAMMPS model" in line


# ---- 6: build and scan chain with the run's model ----------------------------------------


def test_build_then_scan_chain_with_the_run_model(tmp_path, monkeypatch, capsys):
    import json

    from flatcontact.config import load_config
    from flatcontact.structures.interface_contract import thickness
    from flatcontact.structures.interface_io import read_interface

    monkeypatch.chdir(tmp_path)
    code, _, err = _run(["build"], capsys)
    assert code in (0, None) and "warning" not in err
    reference = read_interface("build/interface.extxyz")
    recipe = json.loads(reference.info["recipe"])
    run_model = load_config(None).potential
    assert recipe["potential_spec"] == json.loads(run_model.model_dump_json())
    z = f"{thickness(reference) - 0.5:.3f}"  # compressed: p > 0, no repulsive-branch warning
    argv = ["scan", "--grid", "1", "1", "--thickness-angstrom", z, "--executor", "serial", "--json"]
    code, out, err = _run(argv, capsys)
    assert code in (0, None) and "warning" not in err
    assert json.loads(out)["points_done"] == 1 and (tmp_path / "ispes" / "ispes.nc").is_file()
    # another model than the interface's: one warning line, the scan still runs
    code, out, err = _run([*argv, "--potential", "vashishta", "--out", "iv"], capsys)
    assert code in (0, None)
    built = [ln for ln in err.splitlines() if "was built with" in ln]
    assert len(built) == 1 and built[0].startswith("warning: build/interface.extxyz was built")
    assert "this scan uses vashishta+LJ" in built[0]


# ---- 7: a scan that fails before storing a point leaves nothing that blocks the rerun -----


@pytest.mark.parametrize("existing_dir", [False, True])
def test_failed_scan_leaves_no_store(tmp_path, monkeypatch, capsys, existing_dir):
    from flatcontact.foundation.errors import InputError
    from flatcontact.ispes import executors
    from flatcontact.structures.interface_contract import thickness
    from flatcontact.structures.interface_io import write_interface
    from flatcontact.structures.toy import toy_interface

    reference = toy_interface(layers=3)
    iface = str(write_interface(reference, tmp_path / "interface.extxyz"))
    out = tmp_path / "os11"
    if existing_dir:
        out.mkdir()
    z = f"{thickness(reference):.4f}"
    argv = ["scan", "--interface", iface, "--calculator", "flatcontact.ispes.toy:toy_calculator"]
    argv += ["--thickness-angstrom", z, "--out", str(out)]
    make_executor = executors.make_executor

    def unreachable(**options):  # what a dead --dask-address gives, without its 5 s timeout
        raise InputError("dask-address tcp://127.0.0.1:1: no Dask scheduler reachable (OSError)")

    monkeypatch.setattr(executors, "make_executor", unreachable)
    line = _one_error_line(*_run([*argv, "--grid", "1", "1"], capsys)[::2])
    assert "no Dask scheduler reachable" in line
    monkeypatch.setattr(executors, "make_executor", make_executor)
    assert out.is_dir() == existing_dir
    assert not out.exists() or list(out.iterdir()) == []
    code, _, err = _run([*argv, "--grid", "2", "1", "--executor", "serial", "--json"], capsys)
    assert code in (0, None), err
    assert (out / "ispes.nc").is_file()


# ---- 8: a scan with no compressed thickness says so ---------------------------------------


def test_scan_warns_without_repulsive_branch(tmp_path, capsys):
    from flatcontact.structures.interface_contract import thickness
    from flatcontact.structures.interface_io import write_interface
    from flatcontact.structures.toy import toy_interface

    reference = toy_interface(layers=3)
    iface = str(write_interface(reference, tmp_path / "interface.extxyz"))
    z0 = thickness(reference)
    argv = ["scan", "--interface", iface, "--calculator", "flatcontact.ispes.toy:toy_calculator"]
    argv += ["--grid", "1", "1", "--executor", "serial", "--json"]
    separated = [*argv, "--thickness-angstrom", f"{z0 + 1.0:.4f},{z0 + 1.5:.4f}", "--out", "far"]
    code, _, err = _run([*separated[:-1], str(tmp_path / "far")], capsys)
    assert code in (0, None)
    assert err.strip().startswith("warning: no scanned thickness reached p > 0")
    compressed = [
        *argv,
        "--thickness-angstrom",
        f"{z0 - 0.3:.4f},{z0:.4f}",
        "--out",
        str(tmp_path / "n"),
    ]
    code, _, err = _run(compressed, capsys)
    assert code in (0, None) and "warning" not in err
