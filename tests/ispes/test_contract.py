"""ispes/contract.py: the ISPES file contract (round trip, refused grids, declared units)."""

import numpy as np
import pytest

from flatcontact.foundation.errors import InputError
from flatcontact.ispes import contract


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


def test_a_file_without_mapped_points_or_group_reads_as_every_point_relaxed(tmp_path):
    """ispes.nc written before irreducible registries (no ``mapped``, no ``symmetry_*``,
    ``grid_points``, ``computed_points``) still reads, with the identity as its group, and a
    scan's file with them round-trips."""
    a1, a2 = _hex_vectors()
    ds = contract.empty_grid(3, 3, [8.0, 9.0], a1, a2, potential="old")
    ds["energy"][:] = np.random.default_rng(1).normal(size=ds.energy.shape)
    ds["normal_stress"][:] = 0.0
    assert "mapped" not in ds and "symmetry_order" not in ds.attrs
    back = contract.open_ispes(contract.write_ispes(ds, tmp_path / "old.nc"))
    ops = contract.symmetry_operations(back)
    assert len(ops) == 1 and np.array_equal(ops[0][0], np.eye(2)) and not ops[0][1].any()
    np.testing.assert_array_equal(back.energy.values, ds.energy.values)

    c3 = [
        {"matrix": [[1, 0], [0, 1]], "translation": [0.0, 0.0]},
        {"matrix": [[0, -1], [1, -1]], "translation": [0.0, 0.0]},
        {"matrix": [[-1, 1], [-1, 0]], "translation": [0.0, 0.0]},
    ]
    new = ds.assign_attrs(grid_points=18, computed_points=8, **contract.symmetry_attrs(c3))
    new["mapped"] = (contract.DIMS, np.arange(18).reshape(3, 3, 2) % 2 == 0)
    back = contract.open_ispes(contract.write_ispes(new, tmp_path / "new.nc"))
    assert back["mapped"].dtype == bool
    np.testing.assert_array_equal(back["mapped"].values, new["mapped"].values)
    ops = contract.symmetry_operations(back)
    assert [m.tolist() for m, _ in ops] == [op["matrix"] for op in c3]
    with pytest.raises(InputError, match=r"new\.nc: symmetry attributes"):
        broken = new.assign_attrs(symmetry_translations=np.zeros(4))
        contract.open_ispes(contract.write_ispes(broken, tmp_path / "new.nc"))


def test_the_measured_energy_floor_round_trips_and_a_bad_one_is_refused(tmp_path):
    a1, a2 = _hex_vectors()
    ds = contract.empty_grid(3, 3, [8.0, 9.0], a1, a2, potential="test")
    assert np.isnan(contract.energy_floor_mev_per_a2(ds))  # not measured
    ds.attrs[contract.ENERGY_FLOOR_ATTR] = 2.7e-4
    back = contract.open_ispes(contract.write_ispes(ds, tmp_path / "ispes.nc"))
    assert contract.energy_floor_mev_per_a2(back) == 2.7e-4
    for bad in (-1e-4, "small", [1e-4, 2e-4]):
        ds.attrs[contract.ENERGY_FLOOR_ATTR] = bad
        with pytest.raises(InputError, match="energy_floor_mev_per_a2"):
            contract.energy_floor_mev_per_a2(ds, "ispes.nc")
