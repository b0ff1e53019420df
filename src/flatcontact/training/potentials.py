"""Resolve a potential name or path to a single-body (bulk/slab) ASE calculator.

Accepted forms (every one goes through :class:`flatcontact.potentials.InteractionModel`,
so training, validation and the elastic stage use the same model as the scan):

* a bundled SNAP name, e.g. ``sio2-snap``
  (``flatcontact/data/potentials/<name>/<name>.snapcoeff``);
* a path to a ``.snapcoeff`` file (its ``.snapparam`` beside it) or to a
  directory holding exactly one ``.snapcoeff``;
* ``vashishta`` (Vashishta et al. 1990, LAMMPS ``SiO.1990.vashishta``) or ``tersoff``
  (Munetoh et al. 2007, LAMMPS ``SiO.tersoff``);
* a preset name (``cu-eam``, ``graphene-rebo-kc``, ...; the intra model of the preset);
* an offline teacher of :mod:`flatcontact.training.teachers` (``chgnet`` = ``chgnet-r2scan``,
  ``sevennet-0``, ``sevennet-mf-0-r2scan``, ``sevennet-mf-0-pbe``; optional extras).
"""

from __future__ import annotations

from pathlib import Path

from flatcontact.errors import InputError
from flatcontact.potentials.files import BUNDLED_DIR, bundled_snap_names
from flatcontact.training.teachers import ALIASES, TEACHERS, is_teacher, teacher_calculator

CLASSICAL = ("vashishta", "tersoff")


def bundled_dir() -> Path:
    """Directory of the bundled potentials."""
    return BUNDLED_DIR


def bundled_names() -> list[str]:
    """Names of the bundled SNAP potentials."""
    return bundled_snap_names()


def snapcoeff_path(name_or_path: str) -> Path | None:
    """The ``.snapcoeff`` a name or path refers to, or None for a non-SNAP name."""
    from flatcontact.potentials.model import normalize_potential_name, resolve_intra

    if name_or_path in CLASSICAL or is_teacher(name_or_path):
        return None
    try:
        resolved = resolve_intra(normalize_potential_name(name_or_path))
    except InputError:
        resolved = None
    if resolved is None or resolved.style != "snap":
        raise InputError(
            f"potential '{name_or_path}': not a bundled SNAP ({bundled_names()}), "
            f"not one of {[*CLASSICAL, *TEACHERS, *ALIASES]}, and not a .snapcoeff file or directory"
        )
    return Path(resolved.files[0])


def bulk_calculator(name_or_path: str, atoms=None):
    """A single-body ASE calculator for ``name_or_path`` (see the module docstring)."""
    from flatcontact.potentials import InteractionModel

    if is_teacher(name_or_path):
        return teacher_calculator(name_or_path)
    if name_or_path not in CLASSICAL:
        coeff = None
        try:
            coeff = snapcoeff_path(name_or_path)
        except InputError:
            from flatcontact.potentials.presets import PRESETS

            if name_or_path not in PRESETS:
                raise
        if coeff is not None:
            param = coeff.with_suffix(".snapparam")
            if not param.is_file():
                raise InputError(f"{param}: the .snapparam beside {coeff.name} is missing")
            name_or_path = f"snap:{coeff}"
    return InteractionModel(intra=name_or_path).bulk_calculator(atoms)
