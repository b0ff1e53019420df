"""Γ-point displacement frames of a teacher's zero-stress α-quartz, labelled by the teacher.

Every atom of the 9-atom cell displaced by ±AMPLITUDE along x, y, z (54 frames,
``config_type = "quartz_phonon"``): the force constants that, with the strain coupling,
make the relaxed-ion elastic constants. Used as an added group in
``benchmarks.refit_weights --add`` (docs/teachers.md). Teacher venv::

    python -m benchmarks.gamma_displacements sevennet-mf-0-r2scan phonon_0.01.extxyz 0.01
"""

from __future__ import annotations

import sys
import time

import numpy as np

from flatcontact.elastic import relax_cell
from flatcontact.potentials.teachers import teacher_calculator
from flatcontact.structures.bulk import alpha_quartz
from flatcontact.training.dataset import write_dataset
from flatcontact.training.label import label_frames


def main(argv: list[str] | None = None) -> None:
    teacher, out, amplitude = (sys.argv[1:] if argv is None else argv)[:3]
    amp = float(amplitude)
    t0 = time.perf_counter()
    calc = teacher_calculator(teacher)
    q0 = relax_cell(alpha_quartz(), calc, fmax=1e-4)
    frames = []
    for i in range(len(q0)):
        for axis in range(3):
            for sign in (1, -1):
                a = q0.copy()
                a.calc = None
                a.positions[i, axis] += sign * amp
                a.info["config_type"] = "quartz_phonon"
                frames.append(a)
    labelled = label_frames(frames, calc)
    write_dataset(labelled, out)
    fmax = max(np.abs(f.get_forces()).max() for f in labelled)
    print(f"{len(labelled)} frames in {time.perf_counter() - t0:.0f} s; max |F| {fmax:.3f} eV/Å")


if __name__ == "__main__":
    main()
