"""A fold of the energy-derived load can be the relaxation's, not a plane's: measured on the
quartz convergence study's 12-layer scan (docs/convergence.md, "Slab layers at high load").

The column at shift (0.8333, 0.6667) of that scan (α-quartz (0001) dense, 12 O-Si-O layers per
slab, sio2-snap + LJ 18 Å, 20.93 Å² cell) folded at 4.29 -> 4.54 GPa. Its points at
z = 37.39 ... 38.07 Å as the scan stored them (fmax 0.005 eV/Å, warm-started along the column,
4-17 force calls each near the fold) and the same points relaxed again from there to
0.0005 eV/Å with the scan's own relaxation: energy (eV) and stored load (GPa). No in-slab plane
slipped in that scan (largest slip 0.14 Å).
"""

from __future__ import annotations

import numpy as np

from flatcontact.foundation.units import EV_PER_A3_TO_GPA
from flatcontact.ispes.grid_bracket import check_grid
from flatcontact.ispes.thicknesses import FOLD_REMEDY

AREA_ANGSTROM2 = 20.929284430681143
SHIFT = (0.8333333333333334, 0.6666666666666666)
#: z (Å), stored energy (eV), stored load (GPa), re-relaxed energy (eV), re-relaxed load (GPa)
COLUMN = np.array(
    [
        (37.391357, -712.602451, 5.002, -712.602604, 5.030),
        (37.483024, -712.661196, 4.765, -712.661410, 4.778),
        (37.576004, -712.711474, 4.817, -712.717942, 4.531),
        (37.670512, -712.767962, 4.474, -712.772242, 4.266),
        (37.766923, -712.821582, 4.156, -712.824335, 4.002),
        (37.865552, -712.872339, 3.802, -712.874075, 3.717),
        (37.966855, -712.920252, 3.489, -712.921319, 3.422),
        (38.071147, -712.965186, 3.109, -712.965842, 3.115),
    ]
)
Z = COLUMN[:, 0]


def _check(energy, stress):
    return check_grid(Z, energy[None, :], stress[None, :], AREA_ANGSTROM2, [SHIFT], (3.0, 5.0, 5))


def _finite_difference_loads_gpa(energy: np.ndarray) -> np.ndarray:
    """-(1/A) ΔU/Δz between neighbouring nodes (GPa), independent of any spline."""
    return -np.diff(energy) / np.diff(Z) / AREA_ANGSTROM2 * EV_PER_A3_TO_GPA


def test_the_stored_column_folds_and_the_note_names_the_relaxation_as_a_cause():
    stored = _check(COLUMN[:, 1], COLUMN[:, 2])
    assert len(stored.folds) == 1
    fold = stored.folds[0]
    # the fold sits where the points stopped shortest of their minimum (6.5 meV at 37.58 Å)
    assert 37.5 < fold.z_angstrom < 37.7 and fold.p_gpa > fold.below_p_gpa
    line = fold.message()
    assert "\n" not in line and FOLD_REMEDY in line
    assert "scan.fmax_ev_per_angstrom" in line and "scan.relax_mode: normal" in line
    # the independent finite differences of the same energies rise too (the data, not the spline)
    assert np.any(np.diff(_finite_difference_loads_gpa(COLUMN[:, 1])) > 0)


def test_relaxed_to_its_minimum_the_same_column_does_not_fold():
    tight = _check(COLUMN[:, 3], COLUMN[:, 4])
    assert tight.folds == []
    assert np.all(np.diff(_finite_difference_loads_gpa(COLUMN[:, 3])) < 0)
    # every re-relaxed energy is lower: the stored points were above their minima
    assert np.all(COLUMN[:, 3] < COLUMN[:, 1])
