"""The asperity builder (shape, registry, counts, refusal) and the binning on constructed fields."""

import numpy as np
import pytest

from flatcontact.asperity import binning
from flatcontact.asperity import builder as b
from flatcontact.foundation.errors import InputError
from flatcontact.structures.construct import build_interface
from flatcontact.structures.recipe import parse_recipe

RECIPE = parse_recipe({"kind": "fcc111", "element": "Cu", "a_angstrom": 3.615, "layers": 3})


@pytest.fixture(scope="module", params=["cylinder", "sphere"])
def built(request):
    atoms, sizes = b.build_asperity(RECIPE, request.param, 60.0, 1.0, 70.0)
    return atoms, sizes


def test_counts_shape_and_blocks(built):
    atoms, sizes = built
    slab = atoms.arrays["slab"]
    n1, n2 = sizes.repeats
    # Cu(111): one atom per primitive cell and plane; the flat is complete
    assert np.sum(slab == 1) == n1 * n2 * sizes.flat_layers
    assert np.sum(slab == 2) <= n1 * n2 * sizes.tip_layers
    # every tip atom lies inside the cap: (z - z_c)^2 + d^2 <= R^2
    z = atoms.positions[:, 2]
    spacing = atoms.info["plane_spacing_angstrom"]
    z_c = z[slab == 2].min() - 0.5 * spacing + sizes.radius_angstrom
    d = atoms.arrays["contact_coordinate"]
    tip = slab == 2
    assert np.all((z[tip] - z_c) ** 2 + d[tip] ** 2 <= sizes.radius_angstrom**2 + 1e-6)
    # and the removed ones were outside: the tip's lowest plane spans √(R² − (R − s/2)²)
    lowest = tip & (z < z[tip].min() + 0.3)
    half = np.sqrt(sizes.radius_angstrom**2 - (sizes.radius_angstrom - 0.5 * spacing) ** 2)
    assert np.max(np.abs(d[lowest])) <= half + 1e-6
    assert np.max(np.abs(d[lowest])) > half - 2.6  # within one lattice spacing of the edge
    block = atoms.arrays["block"]
    assert np.all(slab[block == 1] == 1) and np.all(slab[block == 2] == 2)
    assert z[block == 1].max() < z[(slab == 1) & (block == 0)].min()
    assert z[block == 2].min() > z[(slab == 2) & (block == 0)].max()


def test_registry_is_the_ispes_at_zero_shift(built):
    atoms, _ = built
    small, _ = build_interface(RECIPE)
    s = small.arrays["slab"]
    zs = small.positions[:, 2]
    top1 = small.positions[(s == 1) & (zs == zs[s == 1].max())][0]
    bot2 = small.positions[(s == 2) & (zs == zs[s == 2].min())][0]
    want = bot2 - top1
    slab = atoms.arrays["slab"]
    z = atoms.positions[:, 2]
    apex = np.asarray(atoms.info["apex"])
    low = np.flatnonzero((slab == 2) & (z < z[slab == 2].min() + 0.3))
    apex_atom = atoms.positions[
        low[np.argmin(np.linalg.norm(atoms.positions[low, :2] - apex, axis=1))]
    ]
    tops = atoms.positions[(slab == 1) & (z > z[slab == 1].max() - 0.3)]
    delta = apex_atom - tops
    cell = small.cell.array[:2, :2]
    frac = np.linalg.solve(cell.T, (delta[:, :2] - want[:2]).T).T
    assert np.min(np.linalg.norm(frac - np.round(frac), axis=1)) < 1e-8
    assert delta[0, 2] == pytest.approx(want[2], abs=1e-9)


def test_sizes_follow_from_the_hertz_half_width():
    s = b.plan_sizes("cylinder", 500.0, 2.0, 80.0, np.array([[2.556, 0], [-1.278, 2.214]]), 2.087)
    assert s.hertz_half_width_angstrom == pytest.approx(2 * 500.0 * 2.0 / 80.0)
    assert s.repeats[1] * 2.214 >= 4.0 * 2 * s.hertz_half_width_angstrom
    assert (s.flat_layers - 1) * 2.087 >= 2.0 * s.hertz_half_width_angstrom


def test_impossible_sizes_are_refused_in_one_line(monkeypatch):
    monkeypatch.setenv("FLATCONTACT_MAX_ASPERITY_ATOMS", str(10**12))
    with pytest.raises(InputError, match=r"atoms need ~.* GB, more than 50%"):
        b.check_machine(10**9, 100)
    monkeypatch.setenv("FLATCONTACT_MAX_ASPERITY_ATOMS", "1000")
    with pytest.raises(InputError, match="FLATCONTACT_MAX_ASPERITY_ATOMS") as err:
        b.build_asperity(RECIPE, "sphere", 1.0e4, 2.0, 70.0)
    assert "\n" not in str(err.value)
    with pytest.raises(InputError, match="geometry"):
        b.plan_sizes("cone", 1.0, 1.0, 1.0, np.eye(2), 2.0)


def test_tractions_and_slip_of_a_constructed_field():
    # a square lattice of "flat atoms" (spacing 0.5 Å, axis length 2 Å) loaded by a Hertz
    # line pressure p0 √(1 − y²/a²) and a Cattaneo-like shear; slip zero inside |y| < c
    h, axis, a, c, p0 = 0.5, 2.0, 10.0, 6.0, 3.0
    y = np.arange(-20, 20, h) + h / 2
    area = h * axis / 2  # two atoms per (y, axis) cell
    ys = np.repeat(y, 2)
    p = p0 * np.sqrt(np.clip(1 - ys**2 / a**2, 0, None))
    q = 0.2 * p
    force = np.zeros((len(ys), 3))
    force[:, 2] = -p * area / binning.EV_PER_A3_GPA
    force[:, 1] = q * area / binning.EV_PER_A3_GPA
    edges = np.arange(-20, 20.01, 2.0)
    areas = binning.bin_areas(edges, "cylinder", axis)
    pb, qb = binning.traction_profiles(ys, force, edges, areas)
    centres = 0.5 * (edges[1:] + edges[:-1])
    exact = [
        np.mean(p0 * np.sqrt(np.clip(1 - ((lo + h * (np.arange(4) + 0.5)) ** 2) / a**2, 0, None)))
        for lo in edges[:-1]
    ]
    assert pb == pytest.approx(exact, rel=1e-12, abs=1e-12)
    assert qb == pytest.approx(0.2 * np.asarray(exact), rel=1e-12, abs=1e-12)
    # total force round trip
    assert np.sum(pb * areas) / binning.EV_PER_A3_GPA == pytest.approx(-force[:, 2].sum())
    thr = 0.05 * p0 * area / binning.EV_PER_A3_GPA
    a_meas = binning.contact_half_width(ys, force[:, 2], thr)
    assert a - h <= a_meas <= a
    slip = np.where(np.abs(ys) < c, 0.001, 0.3 * (np.abs(ys) - c) + 0.05)
    sb = binning.binned_mean(ys, slip, edges)
    assert binning.stick_half_width(edges, sb, a_meas, 0.02) == pytest.approx(c)
    assert binning.stick_half_width(edges, np.zeros_like(sb), a_meas, 0.02) == a_meas
    assert centres.size == pb.size


def test_sphere_coordinate_uses_the_minimum_image():
    cell = np.array([[10.0, 0.0], [5.0, 8.660254037844386]])
    pts = np.array([[9.5, 0.0], [0.5, 0.0], [5.0 + 0.2, 8.66]])
    r = binning.contact_coordinate(pts, np.zeros(2), cell, "sphere")
    assert r == pytest.approx([0.5, 0.5, np.hypot(0.2, 0.000254037844386)], abs=1e-9)
    areas = binning.bin_areas(np.array([0.0, 1.0, 2.0]), "sphere", 0.0)
    assert areas == pytest.approx([np.pi, 3 * np.pi])
