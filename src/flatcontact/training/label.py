"""Labelling configurations with a reference ("teacher") model.

The default teacher is CHGNet's r2SCAN model (Deng et al., Nat. Mach. Intell. 5,
1031 (2023); r2SCAN weights of CHGNet 0.4), the closest packaged model to the
SCAN level of the paper's DFT data. CHGNet is an optional extra
(``pip install torch==2.13.0 && pip install 'flatcontact[teacher]'``); this
module imports it only when asked. Any ASE calculator can label instead.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from ase import Atoms

from flatcontact.errors import InputError
from flatcontact.training.dataset import labelled

#: Teacher names understood by :func:`teacher_calculator`.
TEACHERS = ("chgnet",)


def chgnet_available() -> bool:
    """Whether CHGNet (and torch) can be imported."""
    from flatcontact.potentials.chgnet import chgnet_available as available

    return available()


def teacher_calculator(name: str = "chgnet", model_name: str = "r2scan", threads: int = 1):
    """An ASE calculator for the teacher ``name`` (``"chgnet"``: CHGNet ``model_name``)."""
    from flatcontact.potentials.chgnet import chgnet_calculator

    if name not in TEACHERS:
        raise InputError(f"--label {name!r}: expected one of {list(TEACHERS)}")
    return chgnet_calculator(model_name, threads=threads)


def teacher_info(name: str = "chgnet", model_name: str = "r2scan") -> dict:
    """Name and version of the teacher, for provenance."""
    import importlib.metadata as md

    info = {"teacher": name, "model_name": model_name}
    for pkg in ("chgnet", "torch"):
        try:
            info[f"{pkg}_version"] = md.version(pkg)
        except md.PackageNotFoundError:
            info[f"{pkg}_version"] = None
    return info


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
