"""Resolve a potential name or path to a single-body (bulk/slab) ASE calculator.

Accepted forms:

* a bundled SNAP name, e.g. ``sio2-snap``
  (``flatcontact/data/potentials/<name>/<name>.snapcoeff``);
* a path to a ``.snapcoeff`` file (its ``.snapparam`` beside it) or to a
  directory holding exactly one ``.snapcoeff``;
* ``vashishta`` (Vashishta et al. 1990, LAMMPS ``SiO.1990.vashishta``) or ``tersoff``
  (Munetoh et al. 2007, LAMMPS ``SiO.tersoff``);
* ``chgnet`` (the r2SCAN CHGNet teacher; optional extra).
"""

from __future__ import annotations

from importlib.resources import files
from pathlib import Path

from flatcontact.errors import InputError

CLASSICAL = ("vashishta", "tersoff")
TEACHERS = ("chgnet",)


def bundled_dir() -> Path:
    """Directory of the bundled potentials."""
    return Path(str(files("flatcontact") / "data" / "potentials"))


def bundled_names() -> list[str]:
    """Names of the bundled SNAP potentials."""
    root = bundled_dir()
    if not root.is_dir():
        return []
    return sorted(p.name for p in root.iterdir() if (p / f"{p.name}.snapcoeff").is_file())


def snapcoeff_path(name_or_path: str) -> Path | None:
    """The ``.snapcoeff`` a name or path refers to, or None for a non-SNAP name."""
    if name_or_path in CLASSICAL or name_or_path in TEACHERS:
        return None
    bundled = bundled_dir() / name_or_path / f"{name_or_path}.snapcoeff"
    if bundled.is_file():
        return bundled
    path = Path(name_or_path)
    if path.is_dir():
        found = sorted(path.glob("*.snapcoeff"))
        if len(found) != 1:
            raise InputError(f"{path}: expected exactly one .snapcoeff file, found {len(found)}")
        return found[0]
    if path.suffix == ".snapcoeff" and path.is_file():
        return path
    raise InputError(
        f"potential '{name_or_path}': not a bundled SNAP ({bundled_names()}), "
        f"not one of {list(CLASSICAL + TEACHERS)}, and not a .snapcoeff file or directory"
    )


def bulk_calculator(name_or_path: str):
    """A single-body ASE calculator for ``name_or_path`` (see the module docstring)."""
    from flatcontact.training.lammps_bulk import (
        LammpsBulkCalculator,
        snap_calculator,
        tersoff_pair_commands,
        vashishta_calculator,
    )

    if name_or_path == "vashishta":
        return vashishta_calculator()
    if name_or_path == "tersoff":
        return LammpsBulkCalculator(tersoff_pair_commands(), ["Si", "O"])
    if name_or_path == "chgnet":
        from flatcontact.training.label import teacher_calculator

        return teacher_calculator("chgnet")
    coeff = snapcoeff_path(name_or_path)
    param = coeff.with_suffix(".snapparam")
    if not param.is_file():
        raise InputError(f"{param}: the .snapparam beside {coeff.name} is missing")
    return snap_calculator(coeff, param)
