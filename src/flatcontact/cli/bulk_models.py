"""The bulk models of ``validate-potential`` and ``elastic``: a potential name as the bulk
calculators take it (:func:`flatcontact.potentials.engines.bulk_calculator`)."""

from __future__ import annotations

from pathlib import Path

from flatcontact.foundation.errors import InputError


def bulk_potential(potential: str, flag: str) -> str:
    """``potential`` in any spelling of :func:`~flatcontact.potentials.names.normalize_potential_name`
    as the name or ``.snapcoeff`` path that the bulk calculators take (offline teachers of
    :mod:`flatcontact.potentials.teachers` pass through).
    """
    from flatcontact.potentials.names import normalize_potential_name, resolve_intra
    from flatcontact.potentials.teachers import is_teacher

    if is_teacher(potential):
        return potential.strip()
    try:
        resolved = resolve_intra(potential)
    except InputError as exc:
        from flatcontact.potentials.teachers import TEACHERS

        raise InputError(f"{flag}: {exc}; or an offline teacher ({', '.join(TEACHERS)})") from None
    if resolved.style in ("vashishta", "tersoff"):
        return resolved.style
    if resolved.style == "snap":
        name = Path(resolved.files[0]).stem
        bundled = normalize_potential_name(potential) == f"snap:{name}"
        return name if bundled else resolved.files[0]
    raise InputError(
        f"{flag} {potential!r}: expected a LAMMPS model (vashishta, tersoff, a SNAP) or an "
        "offline teacher (chgnet-r2scan, sevennet-0, sevennet-mf-0-r2scan, sevennet-mf-0-pbe)"
    )
