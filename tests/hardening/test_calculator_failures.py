"""A user's ASE calculator that cannot evaluate the interface (ASE's EMT has no Si or O, a model
that returns NaN forces) is refused by ``config --check``, ``run`` and ``scan`` in one ``error:``
line naming the config file, the settings path, the target, the elements and the exception,
before anything is written; one that fails only at a point mid-scan is one line naming the
calculator and the point, on the serial executor and across worker processes."""

from __future__ import annotations

import pickle

import numpy as np
import pytest
from tests.hardening.failing_calculators import NanForces
from tests.hardening.helpers import assert_refused_cleanly, refused, run_cli, stored_rows

from flatcontact.ispes.geometry import thickness
from flatcontact.ispes.toy import toy_calculator
from flatcontact.potentials.guarded import CalculatorFailure, failing_at, guard_calculator
from flatcontact.structures.interface_io import write_interface
from flatcontact.structures.toy import toy_interface

EMT = "ase.calculators.emt:EMT"
HERE = "tests.hardening.failing_calculators"
#: what ASE's EMT raises on α-quartz (its type and first line)
EMT_SAYS = "(NotImplementedError: No EMT-potential for Si)"
#: the toy recipe with its parameters given, so the calculator's keyword arguments (which
#: the toy recipe otherwise takes as its own) may be the failing calculator's
TOY_STRUCTURE = "structure: {kind: toy-lj, layers: 3, params: {eps_cross_ev: 0.02}}\n"


@pytest.fixture(scope="module")
def quartz(tmp_path_factory):
    """The default quartz interface, as ``flatcontact build`` writes it (default preset)."""
    from flatcontact.config import load_config
    from flatcontact.stages.build import BuildInputs, build_stage

    folder = tmp_path_factory.mktemp("quartz")
    build_stage(load_config(None, None), BuildInputs(), folder)
    return folder / "interface.extxyz"


@pytest.fixture(scope="module")
def toy(tmp_path_factory):
    folder = tmp_path_factory.mktemp("toy")
    return write_interface(toy_interface(layers=3), folder / "interface.extxyz")


def _config(tmp_path, text: str):
    path = tmp_path / "conf" / "run.yaml"
    path.parent.mkdir()
    path.write_text(text)
    return path


# ---- ASE's EMT on the default quartz interface ----------------------------------------


@pytest.fixture
def emt_config(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    return _config(tmp_path, f'potential:\n  calculator:\n    target: "{EMT}"\n')


def _emt_line(line: str, source: str, field: str = "potential.calculator.target") -> None:
    assert line.startswith(f"error: {source}: {field}: ")
    assert f"{EMT} cannot evaluate the elements Si, O of " in line
    assert line.endswith(EMT_SAYS)


def test_config_check_refuses_emt_on_quartz(emt_config, tmp_path, capsys):
    line = assert_refused_cleanly(["config", "--check", emt_config], capsys, tmp_path, [])
    _emt_line(line, str(emt_config))


@pytest.mark.parametrize(
    ("section", "field", "named"),
    [
        (f'{{calculator: {{target: "{EMT}", scope: slab}}, coupling: lj}}', None, EMT),
        (f'{{intra: "ase:{EMT}"}}', "potential.intra", f"ase:{EMT}"),
    ],
    ids=["per-slab", "intra"],
)
def test_config_check_refuses_emt_per_slab_and_as_intra(
    section, field, named, tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(tmp_path)
    config = _config(tmp_path, f"potential: {section}\n")
    line = assert_refused_cleanly(["config", "--check", config], capsys, tmp_path, [])
    field = field or "potential.calculator.target"
    assert line == (
        f"error: {config}: {field}: {named} cannot evaluate the elements Si, O of this "
        f"interface's alpha-quartz {EMT_SAYS}"
    )


def test_run_refuses_emt_on_quartz_before_the_run_directory(emt_config, tmp_path, capsys):
    out = tmp_path / "run"
    line = assert_refused_cleanly(["run", emt_config, "--out", out], capsys, tmp_path, [])
    _emt_line(line, str(emt_config))
    assert not out.exists()


@pytest.mark.parametrize("structure", ["quartz", "toy"])
def test_build_config_refuses_in_the_line_of_config_check(
    structure, emt_config, tmp_path, capsys, monkeypatch
):
    """``build --config`` evaluates the model once before building, as ``config --check``,
    ``run`` and ``scan`` do: EMT on quartz (which the build relaxes with it) and NaN forces
    on the toy interface (which the build does not relax) are refused in the same line,
    naming the file and the settings path, with nothing written and no relaxation run."""
    from flatcontact.stages import build as build_module

    config = emt_config
    if structure == "toy":
        config.write_text(
            TOY_STRUCTURE + f"potential: {{calculator: {{target: '{HERE}:NanForces'}}}}\n"
        )
    expected = assert_refused_cleanly(["config", "--check", config], capsys, tmp_path, [])
    monkeypatch.setattr(build_module, "build_stage", _must_not_run)
    out = tmp_path / "b"
    line = assert_refused_cleanly(["build", "--config", config, "--out", out], capsys, tmp_path, [])
    assert line == expected
    assert line.startswith(f"error: {config}: potential.calculator.target: ")
    assert not out.exists()


def test_build_names_the_potential_flag_that_set_emt(tmp_path, capsys, monkeypatch):
    from flatcontact.stages import build as build_module

    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(build_module, "build_stage", _must_not_run)
    out = tmp_path / "b"
    argv = ["build", "--potential", f"ase:{EMT}", "--out", out]
    line = assert_refused_cleanly(argv, capsys, tmp_path, [])
    assert line == (
        f"error: --potential: ase:{EMT} cannot evaluate the elements Si, O of this "
        f"interface's alpha-quartz {EMT_SAYS}"
    )


def _must_not_run(*args, **kwargs):
    raise AssertionError("the build stage ran: the pre-run check did not refuse")


def test_scan_refuses_emt_on_a_quartz_interface_before_writing(
    emt_config, quartz, tmp_path, capsys
):
    out = tmp_path / "scan"
    argv = ["scan", emt_config, "--interface", quartz, "--grid", "2", "2", "--out", out]
    line = assert_refused_cleanly(argv, capsys, tmp_path, [])
    _emt_line(line, str(emt_config))
    assert f"of {quartz} (" in line
    assert not out.exists()


def test_scan_names_the_calculator_flag_that_set_emt(quartz, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "scan"
    argv = ["scan", "--calculator", EMT, "--interface", quartz, "--out", out]
    line = assert_refused_cleanly(argv, capsys, tmp_path, [])
    assert line.startswith(f"error: --calculator: {EMT} cannot evaluate the elements Si, O")
    assert line.endswith(EMT_SAYS) and not out.exists()


def test_a_factory_that_fails_is_refused_naming_the_field_or_the_flag(
    toy, tmp_path, capsys, monkeypatch
):
    """The pre-run evaluation builds the calculator: a factory that raises is refused by
    ``config --check`` (which only imported it before) under ``potential.calculator.target``
    and by ``scan`` under ``--calculator``, the flag that set it."""
    monkeypatch.chdir(tmp_path)
    config = _config(
        tmp_path, TOY_STRUCTURE + f"potential: {{calculator: {{target: '{HERE}:boom'}}}}\n"
    )
    said = f"calculator '{HERE}:boom' failed: ValueError: sigma must be positive see the manual"
    line = assert_refused_cleanly(["config", "--check", config], capsys, tmp_path, [])
    assert line == f"error: {config}: potential.calculator.target: {said}"
    argv = ["scan", "--interface", toy, "--calculator", f"{HERE}:boom", "--out", tmp_path / "s"]
    line = assert_refused_cleanly([*argv, "--thickness-angstrom", "11"], capsys, tmp_path, [])
    assert line == f"error: --calculator: {said}"


# ---- a calculator that returns NaN forces -----------------------------------------------


@pytest.mark.parametrize("command", ["config", "run"])
def test_nan_forces_are_refused_before_any_work(command, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    config = _config(
        tmp_path, TOY_STRUCTURE + f"potential: {{calculator: {{target: '{HERE}:NanForces'}}}}\n"
    )
    out = tmp_path / "run"
    argv = ["config", "--check", config] if command == "config" else ["run", config, "--out", out]
    line = assert_refused_cleanly(argv, capsys, tmp_path, [])
    assert line == (
        f"error: {config}: potential.calculator.target: {HERE}:NanForces cannot evaluate the "
        "element Ar of this interface (non-finite forces on 1 of 6 atoms)"
    )
    assert not out.exists()


def test_scan_refuses_nan_forces_before_writing(toy, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "scan"
    argv = ["scan", "--interface", toy, "--calculator", f"{HERE}:NanForces", "--out", out]
    argv += ["--thickness-angstrom", "11"]
    line = assert_refused_cleanly(argv, capsys, tmp_path, ["--calculator", "non-finite forces"])
    assert not out.exists(), line


# ---- a calculator that fails at one point in the middle of a scan ----------------------


def _scan(toy, out, executor, *extra, capsys):
    argv = ["scan", "--interface", toy, "--calculator", f"{HERE}:FailsWhenPressed", *extra]
    argv += ["--p-range-gpa", "0", "1", "3", "--grid", "2", "2", "--executor", executor]
    argv += ["--workers", "2", "--out", out, "--json"]
    return run_cli(argv, capsys)


def test_a_calculator_class_scans_on_worker_processes_as_in_one_process(
    toy, tmp_path, capsys, monkeypatch
):
    """An ASE Calculator class as the target (``ase.calculators.emt:EMT`` style) attaches
    itself to the atoms it is built with; built on the driver's reference, it made every
    task sent to the workers unpicklable (``Can't pickle local object``, a traceback). The
    pressure-range scan on two worker processes now gives the serial scan's numbers."""
    import xarray as xr

    monkeypatch.chdir(tmp_path)
    energies = {}
    # processes first: the driver's calculator (cached per thread and model) is then built
    # on this run's reference, as in a fresh command
    for executor in ("processes", "serial"):
        code, _, err = _scan(toy, tmp_path / executor, executor, capsys=capsys)
        assert code == 0, err
        with xr.open_dataset(tmp_path / executor / "ispes.nc") as ds:
            energies[executor] = ds["energy"].values.copy()
    assert np.all(np.isfinite(energies["serial"]))
    np.testing.assert_allclose(energies["processes"], energies["serial"], rtol=0, atol=1e-9)


def test_a_failure_in_a_rigid_single_point_names_its_stacking():
    """The probe's single points (one per lateral shift at the reference thickness)."""
    from flatcontact.ispes.grid import GridSpec
    from flatcontact.ispes.probe import rigid_rows

    reference = toy_interface(layers=3)
    calc = guard_calculator(NanForces(), "calculator 'nan'")
    grid = GridSpec(2, 2, thickness_angstrom=(11.0,))
    with pytest.raises(CalculatorFailure) as info:
        rigid_rows(reference, calc, grid, [1])
    z = thickness(reference)
    assert str(info.value) == (
        f"rigid single point at shift (0.5, 0), thickness {z:.4g} Å: calculator 'nan' failed "
        "on the element Ar (non-finite forces on 1 of 6 atoms)"
    )


def test_a_failure_in_the_probe_on_workers_names_the_probe_point(toy, tmp_path, capsys):
    """The pressure-range probe's compression reaches the gap the model refuses, in a worker
    process: one line naming the scan's probe and the point (not a pickling traceback)."""
    reference = toy_interface(layers=3)
    z = reference.positions[:, 2]
    slab = reference.arrays["slab"]
    gap = float(z[slab == 2].min() - z[slab == 1].max())
    kwarg = ["--calculator-kwarg", f"fail_gap_angstrom={gap - 0.15:.4f}"]
    code, _, err = _scan(toy, tmp_path / "p", "processes", *kwarg, capsys=capsys)
    line = refused(code, err, f"calculator '{HERE}:FailsWhenPressed' failed on the element Ar")
    assert line.startswith("error: scan: probe: point at shift (0, 0), thickness ")
    assert line.endswith("outside the fitted range)")


@pytest.mark.parametrize("executor", ["serial", "processes"])
def test_a_failure_mid_scan_names_the_calculator_and_the_point(
    executor, toy, tmp_path, capsys, monkeypatch
):
    """The reference passes the pre-run check; the compressed thickness makes the model raise
    in a worker: one line with the stage, the point's shift and thickness, the target and
    the exception's first line. The points relaxed before it stay in the store (resumable)."""
    from flatcontact.structures.interface_io import read_interface

    monkeypatch.chdir(tmp_path)
    reference = read_interface(toy)
    z_ref = thickness(reference)
    z = reference.positions[:, 2]
    slab = reference.arrays["slab"]
    gap = float(z[slab == 2].min() - z[slab == 1].max())
    pressed = round(z_ref - 0.6, 3)
    target = f"{HERE}:FailsWhenPressed"
    argv = ["scan", "--interface", toy, "--calculator", target]
    argv += ["--calculator-kwarg", f"fail_gap_angstrom={gap - 0.15:.4f}"]
    argv += ["--thickness-angstrom", f"{z_ref + 0.3:.3f},{z_ref:.3f},{pressed}"]
    argv += ["--grid", "2", "2", "--executor", executor, "--out", tmp_path / "scan"]
    if executor == "processes":
        argv += ["--workers", "1"]
    code, _, err = run_cli(argv, capsys)
    line = refused(code, err, target, "failed on the element Ar (RuntimeError: gap ")
    assert line.startswith("error: scan: point at shift (")
    assert f"thickness {pressed:.4g} Å: calculator '{target}'" in line
    assert line.endswith("outside the fitted range)")
    assert stored_rows(tmp_path / "scan" / "points.db") >= 1  # the points before it, kept


@pytest.mark.parametrize("command", ["build", "run"])
def test_a_failure_in_the_build_relaxation_names_the_stage(command, tmp_path, capsys, monkeypatch):
    """A calculator that passes the pre-run check (one evaluation) and fails in the build's
    relaxation of a slab recipe (ASE's EMT on Cu, diverging at its third evaluation)."""
    from ase.build import fcc111

    monkeypatch.chdir(tmp_path)
    slab = fcc111("Cu", (1, 1, 3), vacuum=5.0, a=3.615)
    slab.info.clear()
    target = f"{HERE}:FailsAfter"
    config = _config(
        tmp_path,
        "structure: {kind: slab, file: slab.extxyz}\n"
        f"potential: {{calculator: {{target: '{target}', kwargs: {{after: 3}}}}}}\n"
        "elastic: {enabled: false}\ncontact: {contact_modulus_gpa: 70, shear_modulus_gpa: 55}\n",
    )
    slab.write(config.parent / "slab.extxyz")
    out = tmp_path / "out"
    argv = ["build", "--config", config] if command == "build" else ["run", config]
    code, _, err = run_cli([*argv, "--out", out], capsys)
    line = refused(code, err)
    assert line == (
        f"error: build: calculator '{target}' failed on the element Cu "
        "(RuntimeError: evaluation 3: the model diverged)"
    )
    assert not (out / "interface.extxyz").exists() and not any(out.glob("01-build/*.extxyz"))
    if command == "run":  # the console has one line; the run log keeps the traceback
        log = (out / "run.log").read_text()
        assert "the calculator's traceback:\nTraceback (most recent call last):" in log
        assert "in calculate\n" in log and "RuntimeError: evaluation 3: the model diverged" in log


# ---- the guard itself ---------------------------------------------------------------------


def test_a_guarded_calculator_gives_the_same_numbers():
    atoms = toy_interface(layers=3)
    atoms.positions[7 % len(atoms), 0] += 0.1  # off the symmetric reference: forces ≠ 0
    plain = toy_calculator()
    guarded = guard_calculator(toy_calculator(), "calculator 'toy'")
    results = []
    for calc in (plain, guarded):
        work = atoms.copy()
        work.calc = calc
        results.append((work.get_potential_energy(), work.get_forces()))
    assert results[0][0] == results[1][0]
    np.testing.assert_array_equal(results[0][1], results[1][1])
    assert type(guarded) is type(plain)
    assert guard_calculator(guarded, "another name") is guarded


def test_nan_and_exceptions_become_one_line_and_cross_processes():
    atoms = toy_interface(layers=3)
    atoms.calc = guard_calculator(NanForces(), "calculator 'nan'")
    with pytest.raises(CalculatorFailure) as info:
        atoms.get_forces()
    failure = info.value
    assert (
        str(failure)
        == "calculator 'nan' failed on the element Ar (non-finite forces on 1 of 6 atoms)"
    )
    placed = failure.at("point at shift (0.5, 0), thickness 11 Å").at("scan")
    back = pickle.loads(pickle.dumps(placed))
    assert type(back) is CalculatorFailure and str(back) == str(placed)
    assert str(back).startswith("scan: point at shift (0.5, 0), thickness 11 Å: calculator 'nan'")
    assert back.reason == "non-finite forces on 1 of 6 atoms" and back.elements == ("Ar",)


def test_a_nan_stress_is_refused_only_when_asked_for():
    """A scan asks for energy and forces: a NaN stress beside them is dropped, the forces are
    the toy's; the elastic stage asks for the stress: refused in one line."""
    from tests.hardening.failing_calculators import NanStress

    atoms = toy_interface(layers=3)
    atoms.calc = guard_calculator(NanStress(), "calculator 'nan-stress'")
    plain = atoms.copy()
    plain.calc = toy_calculator()
    np.testing.assert_array_equal(atoms.get_forces(), plain.get_forces())
    with pytest.raises(
        CalculatorFailure, match=r"failed on the element Ar \(non-finite stress \(nan"
    ):
        atoms.get_stress()


def test_a_duck_typed_calculator_is_guarded_at_its_getters():
    from tests.hardening.failing_calculators import broken

    atoms = toy_interface(layers=3)
    atoms.calc = guard_calculator(broken(), "calculator 'broken'")
    assert atoms.get_potential_energy() == 0.0
    with pytest.raises(CalculatorFailure, match=r"\(IndexError: index 11 is out of bounds"):
        atoms.get_forces()
    detail = pickle.loads(pickle.dumps(info_of(atoms.get_forces))).detail
    assert detail.startswith("Traceback (most recent call last):")
    assert "in get_forces\n" in detail and detail.rstrip().endswith("with size 7")


def info_of(call) -> CalculatorFailure:
    """The CalculatorFailure ``call()`` raises."""
    with pytest.raises(CalculatorFailure) as info:
        call()
    return info.value


def test_a_calculator_class_given_atoms_leaves_them_alone():
    from flatcontact.potentials.loader import call_factory

    atoms = toy_interface(layers=3)
    calc = call_factory(f"{HERE}:FailsWhenPressed", atoms, {})
    assert atoms.calc is None and calc.atoms is not atoms
    pickle.dumps(atoms)  # what the scan sends to its workers


def test_flatcontacts_own_errors_are_not_renamed():
    """Only a failure inside the user's calculator is converted; an error of the code around
    it (here a KeyError in the block) keeps its type and traceback."""
    with pytest.raises(KeyError), failing_at("scan"):
        {}["missing"]
