"""The validity gates (flatcontact.analysis.gates, .shift_symmetry, flatcontact.ispes.slip):
each fires on a constructed case and not on a clean one.

The structure's shift-space symmetry is checked against an energy computed independently in
the test: a pair sum between the two slabs evaluated by brute force on the grid of shifts,
which must keep every operation :func:`shift_operations` finds (E(s) = E(R s + t_B − t_T))."""

from __future__ import annotations

import numpy as np
import pytest
from ase import Atoms

from flatcontact.analysis import gates
from flatcontact.analysis.periodic import PeriodicSurface
from flatcontact.analysis.shift_symmetry import operation_deviation, shift_operations
from flatcontact.config.contact import GATE_NAMES
from flatcontact.ispes.slip import SLIP_THRESHOLD_ANGSTROM, slip_table

A = 2.5
A1 = np.array([A, 0.0])
A2 = np.array([-A / 2, A * np.sqrt(3) / 2])


def test_the_settings_name_the_gates_of_the_analysis():
    assert GATE_NAMES == gates.GATES


def _pair_energy(bottom: np.ndarray, top: np.ndarray, shifts: np.ndarray) -> np.ndarray:
    """Σ exp(-r²) between the slabs over lattice images, per shift (independent of the code)."""
    lat = np.column_stack([A1, A2])
    images = np.array([lat @ [i, j] for i in range(-3, 4) for j in range(-3, 4)])
    out = []
    for s in shifts:
        e = 0.0
        for x in bottom:
            for y in top:
                d = (y[:2] + s)[None, :] + images - x[:2]
                r2 = np.sum(d**2, axis=1) + (y[2] - x[2]) ** 2
                e += float(np.sum(np.exp(-r2)))
        out.append(e)
    return np.array(out)


def _grid_energy(bottom, top, n=12):
    sa, sb = np.meshgrid(np.arange(n) / n, np.arange(n) / n, indexing="ij")
    shifts = np.stack([sa.ravel(), sb.ravel()], -1) @ np.vstack([A1, A2])
    return _pair_energy(bottom, top, shifts).reshape(n, n)


@pytest.mark.parametrize(
    ("top_xy", "n_ops"),
    [
        ([(1 / 3, 2 / 3)], 11),  # one atom per layer: the whole hexagonal point group
        # a second atom at a1/2: only the mirror normal to a1 keeps both top atoms
        ([(1 / 3, 2 / 3), (0.5, 0.0)], 1),
    ],
)
def test_every_structure_operation_is_kept_by_an_independent_pair_energy(top_xy, n_ops):
    lat = np.column_stack([A1, A2])
    bottom = np.array([[0.0, 0.0, 0.0]])
    top = np.array([[*(lat @ f), 1.5 + 0.4 * k] for k, f in enumerate(top_xy)])
    pos = np.vstack([bottom, top])
    numbers = np.full(len(pos), 6)
    slab = np.array([1] * len(bottom) + [2] * len(top))
    ops = shift_operations(pos, numbers, slab, A1, A2)
    assert ops, "a structure of atoms on the hexagonal sites has some symmetry"
    surface = PeriodicSurface(_grid_energy(bottom, top), A1, A2)
    for op in ops:
        assert operation_deviation(surface, op) < 1e-6, op.name
    assert len(ops) == n_ops
    if n_ops == 1:  # the operations the structure lacks, the energy breaks
        names = {op.name for op in ops}
        assert names == {"mirror at 90°"}
        full = shift_operations(pos[:2], numbers[:2], slab[:2], A1, A2)
        lacking = [op for op in full if op.name not in names]
        assert lacking and all(operation_deviation(surface, op) > 1e-3 for op in lacking)


def test_the_symmetry_gate_names_the_broken_operation_and_the_loads():
    lat = np.column_stack([A1, A2])
    bottom = np.array([[0.0, 0.0, 0.0]])
    top = np.array([[*(lat @ [1 / 3, 2 / 3]), 1.5]])
    pos = np.vstack([bottom, top])
    ops = shift_operations(pos, [6, 6], [1, 2], A1, A2)
    clean = _grid_energy(bottom, top)
    assert gates.broken_symmetry(np.array([clean, clean]), [0.0, 1.0], A1, A2, ops) is None
    # a landscape that leans along x at the second load only: every rotation breaks there
    n = clean.shape[0]
    lean = np.cos(2 * np.pi * np.arange(n) / n)[:, None] * np.ones(n)[None, :]
    broken = clean + 2.0 * np.ptp(clean) * lean
    found = gates.broken_symmetry(np.array([clean, broken]), [0.0, 1.0], A1, A2, ops)
    assert found is not None and found.gate == "broken_symmetry"
    assert "rotation by 120°" in found.message and "P = 1 GPa" in found.message
    assert "P = 0," not in found.message and "relax_mode: normal" in found.message


def _stack(layers_per_slab=3):
    """Two slabs of flat triangular sheets (one atom per cell), layers numbered bottom up."""
    pos, slab, layer = [], [], []
    z = 0.0
    for s in (1, 2):
        for _ in range(layers_per_slab):
            pos.append([0.0, 0.0, z])
            slab.append(s)
            layer.append(len(layer) + 1)
            z += 3.4
    atoms = Atoms("C" * len(pos), positions=pos, cell=[[*A1, 0], [*A2, 0], [0, 0, z + 10]])
    atoms.pbc = True
    atoms.arrays["slab"] = np.array(slab)
    atoms.arrays["layer"] = np.array(layer)
    return atoms


def test_slip_is_measured_between_neighbouring_planes_of_one_slab():
    ref = _stack()
    shift = (0.25, 0.5)
    placed = ref.positions.copy()
    placed[ref.arrays["slab"] == 2, :2] += shift[0] * A1 + shift[1] * A2
    # the interface planes (3 and 4) move together with an elastic 0.02 Å: no slip
    elastic = placed.copy()
    elastic[2, 0] += 0.02
    elastic[3, 0] += 0.02
    # plane 2 (inside slab 1) slides 0.5 Å along y (one lattice vector away: minimum image)
    slipped = placed.copy()
    slipped[1, :2] += np.array([0.0, 0.5]) + A1
    table = slip_table(ref, [((0, 0, 0), shift, 6.8, elastic), ((1, 0, 0), shift, 6.8, slipped)])
    assert [(g.lower, g.upper) for g in table.gaps] == [(1, 2), (2, 3), (4, 5), (5, 6)]
    assert table.slip_angstrom[0] == pytest.approx([0.0, 0.02, 0.02, 0.0], abs=1e-12)
    assert table.slip_angstrom[1] == pytest.approx([0.5, 0.5, 0.0, 0.0], abs=1e-12)
    doc = table.to_json()
    assert doc["n_slipped_points"] == 1 and doc["points_checked"] == 2
    found = gates.in_slab_slip(doc)
    assert found is not None and found.gate == "in_slab_slip"
    assert "layers 1-2 of slab 1 (up to 0.50 Å)" in found.message
    assert "1 of 2 points" in found.message and "relax_mode: normal" in found.message
    clean = slip_table(ref, [((0, 0, 0), shift, 6.8, elastic)]).to_json()
    assert gates.in_slab_slip(clean) is None and gates.in_slab_slip(None) is None
    assert SLIP_THRESHOLD_ANGSTROM > 0.136  # the quartz quick preset's largest plane motion


def test_load_folds_of_a_synthetic_scan_json():
    assert gates.load_fold({}) is None and gates.load_fold({"load_folds": []}) is None
    scan = {
        "load_folds": [
            {"column": "0,0", "z_angstrom": 25.51, "p_gpa": 2.343, "loads_refused_gpa": [2.5, 3]}
        ]
    }
    found = gates.load_fold(scan)
    assert found.gate == "load_fold"
    assert "column 0,0 at z = 25.510 Å (p = 2.34 GPa; loads refused: 2.5, 3 GPa)" in found.message


def _laws(k, k_lo, k_hi, mu=5.0):
    return {
        "threshold_gpa": 3.0,
        "intervals": {
            "k_mpa_per_gpa": {"value": k, "low": k_lo, "high": k_hi},
            "mu_mpa_per_gpa": {"value": mu, "low": mu - 1, "high": mu + 1},
        },
    }


def test_a_slope_is_gated_only_when_its_whole_interval_is_negative():
    found = gates.negative_slope(_laws(-1.31, -1.68, -0.94))
    assert found.gate == "negative_slope" and "k = -1.31 MPa/GPa (-1.68 .. -0.94)" in found.message
    assert gates.negative_slope_notes(_laws(-1.31, -1.68, -0.94)) == []
    # negative, interval reaching 0: used, with a note
    assert gates.negative_slope(_laws(-0.5, -1.2, 0.2)) is None
    (note,) = gates.negative_slope_notes(_laws(-0.5, -1.2, 0.2))
    assert "not significantly" in note and "used as fitted" in note
    assert gates.negative_slope(_laws(14.4, 9.0, 19.7)) is None
    assert gates.negative_slope_notes(_laws(14.4, 9.0, 19.7)) == []
    # a laws.json without intervals: value ± standard error
    old = {"mu_mpa_per_gpa": -3.0, "mu_stderr_mpa_per_gpa": 1.0, "k_mpa_per_gpa": 2.0}
    assert gates.negative_slope(old).message.startswith("significantly negative")


def _two_site_map(depth_a, depth_b, n=16):
    """A square-lattice landscape with minima at (0.25, 0.25) and (0.75, 0.6) (fractions)."""
    s = np.arange(n) / n
    sa, sb = np.meshgrid(s, s, indexing="ij")

    def well(ca, cb, depth, wb):
        return -depth * np.exp(
            -(np.sin(np.pi * (sa - ca)) ** 2) / 0.05 - np.sin(np.pi * (sb - cb)) ** 2 / wb
        )

    # round and elongated: no operation of the lattice maps one well onto the other
    return well(0.25, 0.25, depth_a, 0.05) + well(0.75, 0.6, depth_b, 0.2)


def test_the_rest_position_that_changes_with_load_is_gated():
    a1, a2 = np.array([3.0, 0.0]), np.array([0.0, 3.0])
    low, high = _two_site_map(1.0, 0.6), _two_site_map(0.6, 1.0)
    site_a, site_b = np.array([0.75, 0.75]), np.array([2.25, 1.8])
    nan = np.full(2, np.nan)

    def run(maps, starts):
        return gates.degenerate_minima(
            [0.0, 1.0],
            np.array(maps),
            a1,
            a2,
            np.array([[s, nan] for s in starts]),
            [0, 0],
            np.array([[50.0, np.nan], [50.0, np.nan]]),
            np.array([[0.0, np.nan], [0.0, np.nan]]),
            [1e-4, 1e-4],
        )

    assert run([low, low], [site_a, site_a]) is None
    found = run([low, high], [site_a, site_b])
    assert found.gate == "degenerate_minima"
    assert "moves between P = 0 and 1 GPa" in found.message
    # two inequivalent starts within the tolerance at one load, with different τ
    both = gates.degenerate_minima(
        [0.0],
        np.array([_two_site_map(1.0, 1.0)]),
        a1,
        a2,
        np.array([[site_a, site_b]]),
        [0],
        np.array([[50.0, 80.0]]),
        np.array([[0.0, 1e-5]]),
        [1e-4],
    )
    assert both is not None and "give τ = 50 and 80 MPa" in both.message


def test_the_report_lists_refused_and_overridden_gates():
    found = [gates.Finding("negative_slope", "x"), gates.Finding("load_fold", "y")]
    report = gates.GateReport(found, ["a note"], [])
    assert [f.gate for f in report.refused(["load_fold"])] == ["negative_slope"]
    doc = report.to_json(["load_fold"])
    assert doc["overridden"] == ["load_fold"] and doc["notes"] == ["a note"]
    assert [f["overridden"] for f in doc["fired"]] == [False, True]
