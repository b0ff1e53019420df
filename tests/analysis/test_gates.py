"""The validity gates (flatcontact.analysis.gates, .operation_deviation, flatcontact.ispes.slip):
each fires on a constructed case and not on a clean one.

The interface's shift-space group (:func:`flatcontact.ispes.shift_symmetry.shift_space_group`,
the one finder the scan and the gate share) is checked against an energy computed
independently in the test: a pair sum between the two slabs evaluated by brute force on the
grid of shifts, which must keep every operation of the group (E(M s + t) = E(s)), slab swaps
included."""

from __future__ import annotations

import numpy as np
import pytest
from ase import Atoms

from flatcontact.analysis import gates
from flatcontact.analysis.operation_deviation import maps_grid, operation_deviation
from flatcontact.analysis.periodic import PeriodicSurface
from flatcontact.config.contact import GATE_NAMES
from flatcontact.ispes.shift_symmetry import shift_space_group
from flatcontact.ispes.slip import SLIP_THRESHOLD_ANGSTROM, slip_table

A = 2.5
A1 = np.array([A, 0.0])
A2 = np.array([-A / 2, A * np.sqrt(3) / 2])
LAT = np.column_stack([A1, A2])


def test_the_settings_name_the_gates_of_the_analysis():
    assert GATE_NAMES == gates.GATES


def _pair_energy(bottom, top, shifts, weight=None):
    """Σ w(Z_i, Z_j) exp(-r²) between the slabs over lattice images, per Cartesian shift of
    the top slab (independent of the code); ``bottom``, ``top``: (x, y, z, Z) rows."""
    images = np.array([LAT @ [i, j] for i in range(-3, 4) for j in range(-3, 4)])
    weight = weight or (lambda zi, zj: 1.0)
    out = []
    for s in shifts:
        e = 0.0
        for x in bottom:
            for y in top:
                d = (np.asarray(y[:2]) + s)[None, :] + images - np.asarray(x[:2])
                r2 = np.sum(d**2, axis=1) + (y[2] - x[2]) ** 2
                e += weight(x[3], y[3]) * float(np.sum(np.exp(-r2)))
        out.append(e)
    return np.array(out)


def _grid_energy(bottom, top, n=12, weight=None):
    sa, sb = np.meshgrid(np.arange(n) / n, np.arange(n) / n, indexing="ij")
    shifts = np.stack([sa.ravel(), sb.ravel()], -1) @ LAT.T
    return _pair_energy(bottom, top, shifts, weight).reshape(n, n)


def _interface(bottom, top) -> Atoms:
    """Two one-layer slabs (every atom held, as rigid sheets) in the interface contract."""
    rows = [*bottom, *top]
    atoms = Atoms(
        numbers=[int(r[3]) for r in rows],
        positions=[r[:3] for r in rows],
        cell=[[*A1, 0], [*A2, 0], [0, 0, 30.0]],
        pbc=(True, True, False),
    )
    n1 = len(bottom)
    atoms.arrays["slab"] = np.array([1] * n1 + [2] * len(top))
    atoms.arrays["surface"] = np.array([2] * n1 + [3] * len(top))
    atoms.arrays["layer"] = np.array([1] * n1 + [2] * len(top))
    atoms.arrays["held"] = np.ones(len(rows), bool)
    return atoms


def _ops(atoms):
    return [
        (np.array(op.matrix), np.array(op.translation))
        for op in shift_space_group(atoms).operations
    ]


def _keys(ops):
    return {(tuple(m.ravel()), tuple(np.round(t % 1, 6) % 1)) for m, t in ops}


@pytest.mark.parametrize(
    ("top_xy", "order"),
    [
        ([(1 / 3, 2 / 3)], 12),  # one atom per layer: the whole hexagonal point group
        # a second atom at a1/2: only the identity and the mirror normal to a1 keep both
        ([(1 / 3, 2 / 3), (0.5, 0.0)], 2),
    ],
)
def test_every_structure_operation_is_kept_by_an_independent_pair_energy(top_xy, order):
    bottom = [(0.0, 0.0, 0.0, 6)]
    top = [(*(LAT @ f), 1.5 + 0.4 * k, 6) for k, f in enumerate(top_xy)]
    ops = _ops(_interface(bottom, top))
    assert len(ops) == order
    surface = PeriodicSurface(_grid_energy(bottom, top), A1, A2)
    for m, t in ops:
        assert maps_grid((12, 12), m, t)
        assert operation_deviation(surface, m, t) < 1e-9, (m, t)
    if order == 2:  # the operations the structure lacks, the energy breaks
        assert gates.operation_name(*ops[1], A1, A2) == "mirror at 90°"
        full = _ops(_interface(bottom, top[:1]))
        lacking = [op for op in full if _keys([op]) - _keys(ops)]
        assert len(lacking) == 10
        assert all(operation_deviation(surface, m, t) > 1e-2 for m, t in lacking)


def test_slab_swapping_operations_act_on_the_shift_with_their_sign():
    """A two-atom (B, N) sheet of no symmetry of its own, and slab 2 its image under the
    two-fold axis along x in the interface plane, (x, y, z) ↦ (x, −y, h − z): that axis swaps
    the slabs and is the structure's only operation. The group carries the swap's sign in M
    (s ↦ −M' s + t, M' the mirror y ↦ −y), and the independent pair energy keeps exactly
    that map, not M' s + t."""
    b, n = 5, 7
    bottom = [(0.0, 0.0, 0.0, b), (*(LAT @ (0.3, 0.1)), 0.0, n)]
    top = [(x, -y, 1.6, z) for x, y, _, z in bottom]

    def weight(zi, zj):
        return {frozenset([b]): 1.0, frozenset([n]): 0.3, frozenset([b, n]): 2.0}[
            frozenset([zi, zj])
        ]

    group = shift_space_group(_interface(bottom, top))
    swaps = [op for op in group.operations if op.swaps_slabs]
    assert group.order == 2 and len(swaps) == 1
    surface = PeriodicSurface(_grid_energy(bottom, top, weight=weight), A1, A2)
    ops = [(np.array(op.matrix), np.array(op.translation)) for op in group.operations]
    assert gates.broken_symmetry(np.array([surface.values]), [0.0], A1, A2, ops) is None
    for op in swaps:
        m, t = np.array(op.matrix), np.array(op.translation)
        assert operation_deviation(surface, m, t) < 1e-9
        # the space operation's in-plane part without the swap's sign is not a symmetry
        assert operation_deviation(surface, -m, t) > 1e-2


def test_a_symmetric_landscape_on_a_coarse_grid_reads_symmetric():
    """On a 3×3 grid C3 maps the edge frequencies of the square index set outside it; the
    samples obey the group exactly, and so does the measure (grid comparison). On a grid the
    translation (1/3, 2/3) does not map onto itself, the interpolant is compared on the
    frequencies that stay inside: small for a smooth symmetric landscape, large when the
    landscape leans."""
    bottom = [(0.0, 0.0, 0.0, 6)]
    top = [(*(LAT @ (1 / 3, 2 / 3)), 2.2, 6)]
    ops = _ops(_interface(bottom, top))
    coarse = PeriodicSurface(_grid_energy(bottom, top, n=3), A1, A2)
    assert max(operation_deviation(coarse, m, t) for m, t in ops) < 1e-9
    off = [(m, t) for m, t in ops if not maps_grid((8, 8), m, t)]
    assert off, "translation (1/3, 2/3) is not on an 8×8 grid"
    smooth = _grid_energy(bottom, top, n=8)
    assert max(operation_deviation(PeriodicSurface(smooth, A1, A2), m, t) for m, t in off) < 0.01
    lean = np.cos(2 * np.pi * np.arange(8) / 8)[:, None] * np.ones(8)[None, :]
    leaning = PeriodicSurface(smooth + 0.5 * np.ptp(smooth) * lean, A1, A2)
    assert min(operation_deviation(leaning, m, t) for m, t in off) > 0.2


def test_the_symmetry_gate_names_the_broken_operation_and_the_loads():
    bottom = [(0.0, 0.0, 0.0, 6)]
    top = [(*(LAT @ (1 / 3, 2 / 3)), 1.5, 6)]
    ops = _ops(_interface(bottom, top))
    clean = _grid_energy(bottom, top)
    assert gates.broken_symmetry(np.array([clean, clean]), [0.0, 1.0], A1, A2, ops) is None
    # a landscape that leans along x at the second load only: every rotation breaks there
    n = clean.shape[0]
    lean = np.cos(2 * np.pi * np.arange(n) / n)[:, None] * np.ones(n)[None, :]
    broken = clean + 2.0 * np.ptp(clean) * lean
    found = gates.broken_symmetry(np.array([clean, broken]), [0.0, 1.0], A1, A2, ops)
    assert found is not None and found.gate == "broken_symmetry"
    assert "rotation by" in found.message and "P = 1 GPa" in found.message
    assert " more" in found.message  # at most four operations named, the count of the rest
    assert "P = 0," not in found.message and "relax_mode: normal" in found.message
    # one point out of 144 off by a tenth of the range: the max norm sees it
    spot = clean.copy()
    spot[5, 2] += 0.1 * np.ptp(clean)
    assert gates.broken_symmetry(np.array([spot]), [0.0], A1, A2, ops, tolerance=0.05)


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
    # a fold above every requested load (a new user's Ag(111) in mode full, p 0-2 GPa, folding
    # at 2.36 GPa) is gated all the same (docs/scan.md) and says that it refuses none of them
    scan["load_folds"][0].update(p_gpa=2.36, loads_refused_gpa=[])
    found = gates.load_fold(scan)
    assert found.gate == "load_fold"
    assert "(p = 2.36 GPa; none of the requested loads above it)" in found.message
    assert "loads refused:  GPa" not in found.message


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


def test_a_significant_but_immaterial_negative_slope_is_used_with_a_note():
    """Cu(111) EAM, internal form (measured): μ = −0.486 (−0.535 .. −0.438) MPa/GPa against
    σ0 = 1100 MPa falls 0.066 % over 0–1.5 GPa: used, with a note. The H-diamond/graphene
    example's k = −3.66 (−4.27 .. −3.05) against τ0 = 295 MPa falls 1.9 %: gated."""
    cu = _laws(2.0, 1.0, 3.0, mu=-0.486)
    cu["intervals"]["mu_mpa_per_gpa"] = {"value": -0.486, "low": -0.535, "high": -0.438}
    cu.update(p_max_gpa=1.5, tau0_mpa=3785.0, sigma0_mpa=1100.07)
    assert gates.negative_slope(cu) is None
    (note,) = gates.negative_slope_notes(cu)
    assert "significantly negative" in note and "0.066 %" in note and "used as fitted" in note
    diamond = _laws(-3.66, -4.27, -3.05)
    diamond.update(p_max_gpa=1.5, tau0_mpa=294.8, sigma0_mpa=92.5)
    found = gates.negative_slope(diamond)
    assert found.gate == "negative_slope" and "τ falls 1.9 %" in found.message
    assert gates.negative_slope_notes(diamond) == []
    # the threshold is on the fall, not on the slope: the same slope under a small intercept
    small = dict(cu, sigma0_mpa=20.0)
    assert gates.negative_slope(small).gate == "negative_slope"


def test_a_negative_slope_without_an_interval_is_not_significant():
    """Two loads give a line but no standard error: the interval has no width, so the sign
    of the slope is not significant either way; it is used as fitted, with a note."""
    two_loads = _laws(-8.4, -8.4, -8.4)
    two_loads.update(p_max_gpa=0.6, tau0_mpa=31.0, sigma0_mpa=7.0)
    assert gates.negative_slope(two_loads) is None
    (note,) = gates.negative_slope_notes(two_loads)
    assert "without an interval" in note and "used as fitted" in note


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


def test_a_choice_between_degenerate_sites_of_equal_tau_is_not_a_move():
    """The previous rest site is still a degenerate start at the next load and gives the
    reported τ: the analysis's choice of the other start (its tie rule) mixes no stackings.
    With τ apart by more than the spread it is gated, as a move or as the pair."""
    a1, a2 = np.array([3.0, 0.0]), np.array([0.0, 3.0])
    site_a, site_b = np.array([0.75, 0.75]), np.array([2.25, 1.8])
    maps = np.array([_two_site_map(1.0, 0.6), _two_site_map(1.0, 1.0)])
    nan = np.full(2, np.nan)

    def run(tau_b_mpa, selected_b=True):
        return gates.degenerate_minima(
            [0.0, 1.0],
            maps,
            a1,
            a2,
            np.array([[site_a, nan], [site_a, site_b]]),
            [0, 1 if selected_b else 0],
            np.array([[50.0, np.nan], [50.0, tau_b_mpa]]),
            np.array([[0.0, np.nan], [1e-5, 0.0]]),
            [1e-4, 1e-4],
        )

    assert run(50.0) is None
    assert run(51.0) is None  # 2 % apart: inside DEGENERATE_TAU_SPREAD
    moved = run(80.0)
    assert moved is not None and "moves between P = 0 and 1 GPa" in moved.message
    assert "give τ = 50 and 80 MPa" in moved.message
    # the previous site no longer within the tolerance: a real move, whatever τ says
    far = gates.degenerate_minima(
        [0.0, 1.0],
        maps,
        a1,
        a2,
        np.array([[site_a, nan], [site_a, site_b]]),
        [0, 1],
        np.array([[50.0, np.nan], [50.0, 50.0]]),
        np.array([[0.0, np.nan], [2e-4, 0.0]]),
        [1e-4, 1e-4],
    )
    assert far is not None and "moves between P = 0 and 1 GPa" in far.message


def test_the_report_lists_refused_and_overridden_gates():
    found = [gates.Finding("negative_slope", "x"), gates.Finding("load_fold", "y")]
    report = gates.GateReport(found, ["a note"], [])
    assert [f.gate for f in report.refused(["load_fold"])] == ["negative_slope"]
    doc = report.to_json(["load_fold"])
    assert doc["overridden"] == ["load_fold"] and doc["notes"] == ["a note"]
    assert [f["overridden"] for f in doc["fired"]] == [False, True]
