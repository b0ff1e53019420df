"""``--potential NAME`` over a configuration's model: the named model with a coupling across
the interface, never the file's ``coupling: none`` of a calculator that covered both slabs;
``build --config`` and ``scan`` resolve the same model; an error names the model asked for."""

import json
from pathlib import Path

import pytest
import xarray as xr
from tests.cli.cli_helpers import one_error_line, run_cli

from flatcontact.cli.build import _config_settings
from flatcontact.cli.scan import potential_flag, resolve_config
from flatcontact.config import load_config

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
CU = EXAMPLES / "cu111-eam.yaml"
#: An ASE calculator that knows every element (a plain Lennard-Jones), over the whole interface.
LJ_CALCULATOR = (
    '{target: "ase.calculators.lj:LennardJones", kwargs: {sigma: 2.5, epsilon: 0.01, rc: 6.0}}'
)


def _config(tmp_path, potential: str, name: str = "run.yaml", scan: str = "") -> Path:
    path = tmp_path / name
    path.write_text(f"potential:\n{potential}{scan}")
    return path


def _build_settings(config: Path, potential: str):
    recipe = {k: None for k in ("layers", "source", "gap_angstrom", "fmax_ev_per_angstrom")}
    return _config_settings(config, None, potential, None, recipe, False)


def _scan_settings(config: Path, potential: str):
    # what `flatcontact scan CONFIG --potential NAME` lays over the file
    return resolve_config(config, None, {"potential": potential_flag(potential)})


def test_the_flag_over_a_whole_interface_calculator_is_the_model_the_file_would_name(tmp_path):
    """The file's calculator saw both slabs (its coupling ``none`` is the calculator's): the
    flag's model is exactly what ``potential: {intra: vashishta}`` gives, with the default LJ
    across; scan and build --config agree."""
    calc = _config(tmp_path, f"  calculator: {LJ_CALCULATOR}\n")
    assert load_config(calc).potential.coupling == "none"
    written = load_config(_config(tmp_path, "  intra: vashishta\n", "intra.yaml")).potential
    scan = _scan_settings(calc, "vashishta").potential
    build = _build_settings(calc, "vashishta").potential
    assert scan == written == build
    assert scan.coupling == "lj" and scan.calculator is None and scan.lj.hamaker_zj is not None


def test_the_flag_keeps_a_coupling_the_file_states(tmp_path):
    """Beside a per-slab calculator the coupling is the file's choice: its LJ (cutoff 12 Å)
    stays, and so does an explicit ``coupling: none``; over a plain intra model the LJ stays."""
    per_slab = f"  calculator: {LJ_CALCULATOR[:-1]}, scope: slab}}\n"
    lj = _config(tmp_path, per_slab + "  coupling: lj\n  lj: {cutoff_angstrom: 12.0}\n")
    for settings in (_scan_settings, _build_settings):
        model = settings(lj, "vashishta").potential
        assert (model.intra, model.coupling, model.lj.cutoff_angstrom) == ("vashishta", "lj", 12)
    none = _config(tmp_path, per_slab + "  coupling: none\n", "none.yaml")
    assert _scan_settings(none, "vashishta").potential.coupling == "none"
    assert _build_settings(none, "vashishta").potential.coupling == "none"
    plain = _config(tmp_path, "  intra: tersoff\n  lj: {cutoff_angstrom: 9.0}\n", "plain.yaml")
    assert _scan_settings(plain, "vashishta").potential.lj.cutoff_angstrom == 9.0


def test_the_flag_over_a_preset_drops_the_preset_name_keeps_its_coupling():
    """cu-eam with vashishta inside is no longer cu-eam: the model is named vashishta, with the
    preset's coupling (the same potential across) kept, from scan and from build --config."""
    for settings in (_scan_settings, _build_settings):
        model = settings(CU, "vashishta").potential
        assert model.preset is None and model.name == "vashishta"
        assert model.coupling == "same" and "cu-eam" not in model.label


@pytest.mark.parametrize("command", ["build", "scan"])
def test_an_element_the_flag_model_lacks_names_that_model(command, tmp_path, capsys):
    argv = [command, *(["--config"] if command == "build" else []), str(CU)]
    if command == "scan":  # the model meets the atoms on the interface, before the scan
        built = tmp_path / "b"
        code, _, err = run_cli(
            ["build", "--config", str(CU), "--no-svg", "--out", str(built)], capsys
        )
        assert code in (0, None), err
        argv += ["--interface", str(built / "interface.extxyz")]
    argv += ["--potential", "vashishta", "--out", str(tmp_path / "o")]
    line = one_error_line(*run_cli(argv, capsys)[::2])
    assert line.startswith("error: --potential 'vashishta' has no parameters for element(s) ['Cu']")
    assert "cu-eam" not in line


def test_a_preset_given_an_intra_is_named_by_that_intra(tmp_path, capsys):
    """``{preset: cu-eam, intra: vashishta}`` written in a file: the refusal names vashishta
    (cu-eam knows Cu) and no flag the user did not give."""
    path = tmp_path / "pv.yaml"
    path.write_text(
        "structure: {kind: fcc111, element: Cu, a_angstrom: 3.615, layers: 4}\n"
        "potential: {preset: cu-eam, intra: vashishta}\n"
    )
    argv = ["build", "--config", str(path), "--out", str(tmp_path / "o")]
    line = one_error_line(*run_cli(argv, capsys)[::2])
    assert line.startswith(  # build --config names the file, as config --check does
        f"error: {path}: potential 'vashishta' has no parameters for element(s) ['Cu']"
    )


def test_a_spec_file_with_a_calculator_is_the_model_scanned(tmp_path):
    """``--potential spec.json`` holding a calculator replaces the file's model (it was nulled)."""
    spec = tmp_path / "spec.json"
    spec.write_text(json.dumps({"calculator": {"target": "ase.calculators.emt:EMT"}}))
    model = resolve_config(CU, None, {"potential": potential_flag(str(spec))}).potential
    assert model.calculator is not None and model.calculator.target == "ase.calculators.emt:EMT"


def test_scan_with_the_flag_over_a_calculator_file_feels_the_other_slab(tmp_path, capsys):
    """The real CLI: a quartz interface, a file whose model is an ASE calculator over the whole
    interface, ``--potential vashishta``. 0.25 Å wider than built, the slabs attract (van der
    Waals across: every normal stress < 0, a positive work of separation); a model without
    coupling across would give exactly zero stress and a flat ISPES."""
    interface = tmp_path / "b"
    code, _, err = run_cli(
        ["build", "--potential", "vashishta", "--layers", "5", "--no-svg", "--out", str(interface)],
        capsys,
    )
    assert code in (0, None), err
    z = json.loads((interface / "build.json").read_text())["thickness_angstrom"] + 0.25
    scan = f"scan:\n  grid: [2, 2]\n  thickness_angstrom: [{z:.4f}]\n"
    calc = _config(tmp_path, f"  calculator: {LJ_CALCULATOR}\n", scan=scan)
    out = tmp_path / "s"
    argv = ["scan", str(calc), "--interface", str(interface / "interface.extxyz")]
    argv += ["--potential", "vashishta", "--executor", "serial", "--json", "--out", str(out)]
    code, _, err = run_cli(argv, capsys)
    assert code in (0, None), err
    with xr.open_dataset(out / "ispes.nc") as ds:
        assert ds.attrs["potential"].startswith("vashishta+LJ(")
        assert (ds["normal_stress"].values < -0.05).all()
        assert ds.attrs["work_of_separation_j_per_m2"] > 0
