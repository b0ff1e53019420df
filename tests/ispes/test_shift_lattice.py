"""The shift lattice Λ_1 + Λ_2 of a coincidence cell: closed forms, the scan's own group,
an independent energy check, and the re-indexing of a supercell grid onto one period."""

from __future__ import annotations

import math

import numpy as np
import pytest
import xarray as xr

from flatcontact.foundation.errors import InputError
from flatcontact.ispes.contract import fractional_shifts, symmetry_attrs
from flatcontact.ispes.shift_lattice import (
    grid_size_for,
    reindex,
    scan_grid,
    shift_cell_operations,
    shift_lattice,
    shift_lattice_of,
    to_shift_cell,
)
from flatcontact.ispes.shift_symmetry import shift_space_group
from flatcontact.structures.construct import build_interface
from flatcontact.structures.interface_contract import in_plane_vectors, thickness
from flatcontact.structures.match import twist_match
from flatcontact.structures.placement import place_slab2

HEX = np.array([[2.46, 0.0], [-1.23, 2.46 * math.sqrt(3) / 2]])


def _twisted(m: int, n: int):
    atoms, _ = build_interface(
        {"kind": "sheets", "sheet": "graphene", "layers": 1, "twist": [m, n]}
    )
    return atoms


@pytest.mark.parametrize("mn", [(1, 2), (2, 3), (1, 3), (3, 4), (2, 5), (1, 4)])
def test_twist_index_is_n_squared_and_the_cell_is_the_supercell_over_n(mn):
    """Λ_1 ∩ Λ_2 = Λ_S (N cells per layer) gives [Λ_1 + Λ_2 : Λ_S] = N², Λ_1 + Λ_2 = Λ_S/N;
    when m − n is a multiple of 3 the built cell is 3 coincidence cells: index N²/3."""
    m, n = mn
    match, _ = twist_match(HEX, m, n)
    cells = m * m + m * n + n * n
    assert round(abs(np.linalg.det(match.p1))) == cells
    lat = shift_lattice(match.p1, match.p2, match.cell)
    expected = cells * cells // (3 if (m - n) % 3 == 0 else 1)
    assert lat.index == expected
    assert abs(1.0 / abs(np.linalg.det(lat.basis)) - expected) < 1e-9
    if (m - n) % 3:
        np.testing.assert_allclose(lat.basis, np.eye(2) / cells)
        np.testing.assert_array_equal(lat.to_shift_cell, np.eye(2, dtype=int) * cells)


def test_an_untwisted_cell_has_index_one():
    lat = shift_lattice(np.eye(2), np.eye(2))
    assert lat.index == 1
    np.testing.assert_array_equal(lat.to_shift_cell, np.eye(2, dtype=int))


def test_the_atoms_give_the_translations_of_the_scans_own_shift_group():
    """The (1, 2) cell: the shift lattice read from the atoms has index 49, and the scan's
    shift-space group of the same interface holds exactly 49 pure translations, all of them
    on the lattice."""
    atoms = _twisted(1, 2)
    lat = shift_lattice_of(atoms)
    assert lat.index == 49
    group = shift_space_group(atoms)
    translations = [op for op in group.operations if op.matrix == ((1, 0), (0, 1))]
    assert len(translations) == 49
    for op in translations:
        u = lat.to_shift_cell @ np.asarray(op.translation)
        np.testing.assert_allclose(u, np.round(u), atol=1e-6)


def _cross_lj_ev(atoms, sigma=3.4, epsilon=0.0028, rc=10.0) -> float:
    """Lennard-Jones energy between slab 1 and slab 2 only (plain numpy, periodic images)."""
    slab = np.asarray(atoms.arrays["slab"])
    p1, p2 = atoms.positions[slab == 1], atoms.positions[slab == 2]
    cell = atoms.cell.array
    total = 0.0
    for i in range(-3, 4):
        for j in range(-3, 4):
            d = p2[None, :, :] + i * cell[0] + j * cell[1] - p1[:, None, :]
            r = np.linalg.norm(d, axis=-1)
            r = r[r < rc]
            total += float(np.sum(4 * epsilon * ((sigma / r) ** 12 - (sigma / r) ** 6)))
    return total


def test_the_rigid_energy_repeats_with_the_shift_lattice_and_not_in_between():
    """Independent check with a plain cross-slab Lennard-Jones sum (no flatcontact model): the
    rigid stack's energy at s and at s + b1 (a shift-lattice vector, 1/7 of the supercell
    vector) agree to round-off; half of b1 gives another energy."""
    atoms = _twisted(1, 2)
    lat = shift_lattice_of(atoms)
    z = thickness(atoms)

    def energy(s):
        return _cross_lj_ev(
            place_slab2(atoms, float(s[0]), float(s[1]), z, spread_compression=False)
        )

    s = np.array([0.013, 0.029])
    b1 = lat.basis[0]
    e0, e1, e_half = energy(s), energy(s + b1), energy(s + b1 / 2)
    assert abs(e1 - e0) < 1e-11
    assert abs(e_half - e0) > 1e-8


def test_a_coprime_supercell_grid_visits_one_period_once():
    match, _ = twist_match(HEX, 1, 2)
    lat = shift_lattice(match.p1, match.p2, match.cell)
    assert grid_size_for(6, 49) == 6
    assert grid_size_for(7, 49) == 8
    ta, tb = reindex(lat, 6, 6)
    assert len(set(zip(ta.ravel(), tb.ravel(), strict=True))) == 36
    with pytest.raises(InputError, match=r"scan.grid \[7, 7\]: .*gcd\(n, 49\) = 1 \(n = 8\)"):
        reindex(lat, 7, 7)


def test_the_scan_grid_keeps_a_one_by_one_cell_and_squares_a_coprime_grid_otherwise():
    """Index 1: ``scan.grid`` as given (quartz, the AB bilayer); index 49: the square grid of
    the larger side raised to coprime with 49, which visits one period once."""
    assert scan_grid([6, 8], 1) == (6, 8)
    assert scan_grid([6, 6], 49) == (6, 6)
    assert scan_grid([7, 7], 49) == (8, 8)
    assert scan_grid([6, 7], 49) == (8, 8)
    assert scan_grid([5, 3], 3) == (5, 5)
    match, _ = twist_match(HEX, 1, 2)
    lat = shift_lattice(match.p1, match.p2, match.cell)
    for grid in ([7, 7], [6, 9], [13, 2]):
        n_a, n_b = scan_grid(grid, lat.index)
        ta, tb = reindex(lat, n_a, n_b)
        assert len(set(zip(ta.ravel(), tb.ravel(), strict=True))) == n_a * n_b


def _synthetic_ispes(n: int, lattice, f) -> xr.Dataset:
    """A scan file over the supercell whose energy is ``index · f(u)``, u = K s mod 1."""
    s = np.stack(np.meshgrid(fractional_shifts(n), fractional_shifts(n), indexing="ij"))
    u = np.tensordot(lattice.to_shift_cell.astype(float), s, axes=1) % 1.0
    z = np.array([3.0, 3.2])
    energy = lattice.index * f(u)[..., None] + z
    a1, a2 = np.array([6.5, 0.0]), np.array([-3.25, 5.629165])
    ops = [
        {"matrix": [[1, 0], [0, 1]], "translation": [0, 0]},
        {"matrix": [[0, -1], [1, -1]], "translation": [0, 0]},
    ]
    return xr.Dataset(
        {
            "energy": (("shift_a", "shift_b", "thickness"), energy),
            "normal_stress": (("shift_a", "shift_b", "thickness"), np.ones_like(energy)),
        },
        coords={"shift_a": fractional_shifts(n), "shift_b": fractional_shifts(n), "thickness": z},
        attrs={
            "a1": a1,
            "a2": a2,
            "area": float(abs(a1[0] * a2[1] - a1[1] * a2[0])),
            **symmetry_attrs(ops),
        },
    )


def test_to_shift_cell_puts_each_value_at_its_point_of_the_period():
    match, _ = twist_match(HEX, 1, 2)
    lat = shift_lattice(match.p1, match.p2, match.cell)

    def f(u):
        return np.cos(2 * np.pi * u[0]) + 0.3 * np.sin(2 * np.pi * (u[0] + 2 * u[1]))

    ds = _synthetic_ispes(6, lat, f)
    out = to_shift_cell(ds, lat)
    grid = np.stack(np.meshgrid(fractional_shifts(6), fractional_shifts(6), indexing="ij"))
    np.testing.assert_allclose(out["energy"].values[..., 0], f(grid) + 3.0 / 49, atol=1e-12)
    np.testing.assert_allclose(out["normal_stress"].values, 1.0)
    np.testing.assert_allclose(out.attrs["a1"], ds.attrs["a1"] / 7)
    assert out.attrs["area"] == pytest.approx(ds.attrs["area"] / 49)
    assert out.attrs["shift_lattice_index"] == 49
    # the C3 operation (M, 0) keeps its matrix on the shift cell (K = 7·1 commutes with it)
    assert out.attrs["symmetry_order"] == 2


def test_a_translation_of_the_group_becomes_the_identity_on_the_shift_cell():
    match, _ = twist_match(HEX, 1, 2)
    lat = shift_lattice(match.p1, match.p2, match.cell)
    ops = [(np.eye(2, dtype=int), np.zeros(2)), (np.eye(2, dtype=int), np.array([1 / 7, 3 / 7]))]
    assert len(shift_cell_operations(lat, ops)) == 1


def test_in_plane_vectors_of_the_built_cell_are_the_supercell():
    atoms = _twisted(1, 2)
    a1, a2 = in_plane_vectors(atoms)
    assert np.linalg.norm(a1) == pytest.approx(2.46 * math.sqrt(7), rel=1e-6)
    assert np.linalg.norm(a2) == pytest.approx(2.46 * math.sqrt(7), rel=1e-6)


def test_the_group_modulo_translations_restates_to_the_whole_group_on_the_shift_cell():
    """(1, 2): the whole group is 12 point operations times the 49 translations; keeping one
    operation per point operation loses nothing on the shift cell."""
    atoms = _twisted(1, 2)
    lat = shift_lattice_of(atoms)
    whole = shift_space_group(atoms)
    reduced = shift_space_group(atoms, modulo_translations=True)
    assert whole.order == reduced.order * lat.index

    def restated(group):
        ops = [(np.array(o.matrix), np.array(o.translation)) for o in group.operations]
        return {
            (tuple(m.ravel()), tuple(np.round(t, 6) % 1.0))
            for m, t in shift_cell_operations(lat, ops)
        }

    assert restated(whole) == restated(reduced)
    assert len(restated(reduced)) == reduced.order


def test_a_cell_that_repeats_only_nearly_is_refused_before_the_scan():
    """A build relaxation of a coincidence cell modulates the sheets by 0.05–0.1 Å: the exact
    shift lattice is then the supercell (index 1), the landscape still repeats 49 times in it,
    and a 6×6 grid over the supercell would alias it (τ0 7× too small on the (1, 2) twist).
    The scan stage refuses, in one line, before any point is relaxed; the exact cell passes."""
    from types import SimpleNamespace

    from flatcontact.stages.scan import _shift_lattice_grid

    scan = SimpleNamespace(grid=[6, 6], symmetry=SimpleNamespace(tolerance_angstrom=1e-3))
    atoms = _twisted(1, 2)
    lattice, _, record = _shift_lattice_grid(scan, atoms)
    assert lattice.index == 49 and record["cell"] == "shift_lattice"
    wobbly = atoms.copy()
    rng = np.random.default_rng(7)
    wobbly.positions[:, :2] += rng.uniform(-0.05, 0.05, (len(atoms), 2))
    with pytest.raises(
        InputError,
        match=r"^structure: slab \d of the built cell repeats 7 times .* but 1 times .*index 1\)",
    ) as err:
        _shift_lattice_grid(scan, wobbly)
    assert "\n" not in str(err.value)
