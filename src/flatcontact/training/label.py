"""Labelling configurations with a reference ("teacher") model.

Teachers are named in :mod:`flatcontact.potentials.teachers` (their one home; the default is
CHGNet's r2SCAN model, ``sevennet-mf-0-r2scan`` the stiffer alternative). They are optional
extras imported only when asked. Any ASE calculator can label instead.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from ase import Atoms

from flatcontact.potentials.teachers import (  # noqa: F401 - re-exported for callers of .label
    TEACHERS,
    teacher_calculator,
    teacher_info,
)
from flatcontact.training.dataset import labelled


def label_frames(
    frames: Sequence[Atoms],
    calc,
    progress: Callable[[int, int], None] | None = None,
) -> list[Atoms]:
    """Label every frame with ``calc`` (energy, forces, stress); return new labelled Atoms."""
    out = []
    for k, atoms in enumerate(frames):
        a = atoms.copy()
        a.calc = calc
        energy = a.get_potential_energy()
        forces = a.get_forces()
        stress = a.get_stress(voigt=True)
        res = labelled(atoms, energy, forces, stress)
        res.info.update(atoms.info)
        out.append(res)
        if progress is not None:
            progress(k + 1, len(frames))
    return out
