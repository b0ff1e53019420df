"""Foundation: unit constants, the ISPES file contract, the CLI error path."""

import numpy as np
import pytest
from typer.testing import CliRunner

from flatcontact import units
from flatcontact.cli import app
from flatcontact.errors import InputError
from flatcontact.ispes import contract


def test_unit_constants_against_definitions():
    # 1 eV/Å^3 = 1.602176634e-19 J / 1e-30 m^3 = 160.2176634 GPa
    assert units.EV_PER_A3_TO_GPA == pytest.approx(160.2176634, rel=1e-9)
    assert units.EV_PER_A2_TO_J_PER_M2 == pytest.approx(16.02176634, rel=1e-9)
    assert units.EV_PER_A3_TO_MPA == pytest.approx(1e3 * units.EV_PER_A3_TO_GPA)


def _hex_vectors(a=4.916):
    return np.array([a, 0.0]), np.array([-a / 2, a * np.sqrt(3) / 2])


def test_contract_round_trip(tmp_path):
    a1, a2 = _hex_vectors()
    ds = contract.empty_grid(3, 4, [9.0, 8.0, 8.5], a1, a2, potential="test")
    assert ds.thickness.values.tolist() == [8.0, 8.5, 9.0]
    assert ds.attrs["area"] == pytest.approx(4.916**2 * np.sqrt(3) / 2)
    ds["energy"][:] = np.random.default_rng(0).normal(size=ds.energy.shape)
    path = contract.write_ispes(ds, tmp_path / "ispes.nc")
    back = contract.open_ispes(path)
    np.testing.assert_array_equal(back.energy.values, ds.energy.values)
    assert back.energy.attrs["units"] == "eV"
    assert back.normal_stress.attrs["units"] == "GPa"
    np.testing.assert_allclose(back.attrs["a2"], a2)
    assert not list(tmp_path.glob("*.part"))


def test_contract_rejects_bad_grids(tmp_path):
    a1, a2 = _hex_vectors()
    ds = contract.empty_grid(2, 2, [8.0, 9.0], a1, a2, potential="test")
    with pytest.raises(InputError, match="missing variable 'normal_stress'"):
        contract.validate_ispes(ds.drop_vars("normal_stress"))
    with pytest.raises(InputError, match="area"):
        contract.validate_ispes(ds.assign_attrs(area=1.0))
    with pytest.raises(InputError, match="shift_a"):
        contract.validate_ispes(ds.assign_coords(shift_a=[0.0, 0.7]))
    with pytest.raises(InputError, match="no such ISPES file"):
        contract.open_ispes(tmp_path / "missing.nc")
    (tmp_path / "junk.nc").write_text("not netcdf")
    with pytest.raises(InputError, match="not a readable netCDF"):
        contract.open_ispes(tmp_path / "junk.nc")


def test_contract_converts_declared_units_and_refuses_unknown_ones(tmp_path):
    a1, a2 = _hex_vectors()
    ds = contract.empty_grid(2, 2, [8.0, 9.0], a1, a2, potential="test")
    rng = np.random.default_rng(1)
    ds["energy"][:] = rng.normal(size=ds.energy.shape)
    ds["normal_stress"][:] = rng.normal(size=ds.energy.shape)
    foreign = ds.copy(deep=True)
    foreign["normal_stress"] = foreign.normal_stress * 1000.0
    foreign["normal_stress"].attrs["units"] = "MPa"
    foreign["energy"] = foreign.energy * 1000.0
    foreign["energy"].attrs["units"] = "meV"
    foreign = foreign.assign_coords(thickness=foreign.thickness / 10.0)
    foreign["thickness"].attrs["units"] = "nm"
    foreign.to_netcdf(tmp_path / "foreign.nc", engine="h5netcdf")
    back = contract.open_ispes(tmp_path / "foreign.nc")
    np.testing.assert_allclose(back.normal_stress.values, ds.normal_stress.values, rtol=1e-12)
    np.testing.assert_allclose(back.energy.values, ds.energy.values, rtol=1e-12)
    np.testing.assert_allclose(back.thickness.values, ds.thickness.values, rtol=1e-12)
    assert (
        back.normal_stress.attrs["units"] == "GPa" and back.thickness.attrs["units"] == "angstrom"
    )
    odd = ds.copy(deep=True)
    odd["energy"].attrs["units"] = "kJ/mol"
    with pytest.raises(InputError, match="'energy' has units 'kJ/mol'"):
        contract.validate_ispes(odd)


def test_cli_version():
    result = CliRunner().invoke(app, ["version"])
    assert result.exit_code == 0
    assert result.stdout.strip()


def test_input_error_is_one_line_exit_2(capsys):
    from flatcontact.cli import main
    from flatcontact.cli.app import app as the_app

    @the_app.command("_raise-input-error", hidden=True)
    def _raise() -> None:
        raise InputError("--radius-um: expected a positive number, got -1")

    with pytest.raises(SystemExit) as exit_info:
        main(["_raise-input-error"])
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert err.strip() == "error: --radius-um: expected a positive number, got -1"
    assert "Traceback" not in err


def test_atomic_write_leaves_usual_permissions_and_no_partial_file(tmp_path):
    import os
    import stat

    from flatcontact.fileio import atomic_path, write_text_atomic

    mask = os.umask(0o022)
    try:
        path = write_text_atomic(tmp_path / "out.txt", "x")
        assert stat.S_IMODE(path.stat().st_mode) == 0o644
        with pytest.raises(RuntimeError), atomic_path(tmp_path / "never.txt") as tmp:
            tmp.write_text("half")
            raise RuntimeError("interrupted")
    finally:
        os.umask(mask)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.txt"]
