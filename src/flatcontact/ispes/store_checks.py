"""The contract of a ``points.db``'s contents, and the repair of rows that break it.

:class:`flatcontact.ispes.store.PointStore` opens a store only through these checks:

- the file: :func:`quick_check` refuses a file whose pages fail SQLite's
  ``PRAGMA quick_check``, in one line naming it and the defect;
- the metadata: :func:`settings_difference` names the first difference between the stored
  and the current settings; :func:`resolved_defect` what is wrong with ``resolved``
  (finite, positive, distinct thicknesses in Å, finite in-plane vectors ``a1``, ``a2``,
  a potential label);
- every row (:func:`row_defect`): the keys ``i_a``, ``i_b``, ``i_z`` present and integers
  inside the grid (a negative index is out of range), the record keys :data:`ROW_KEYS`
  present, ``shift_a``, ``shift_b`` (fractions of ``a1``, ``a2``) and ``thickness`` (Å)
  equal to the grid's values at that index, finite energy (eV), stresses (GPa) and
  positions (Å), the reference's atom count, a warm start that is an index of the grid,
  and one row per index.

:func:`repair_rows` deletes the rows that fail; one warning (:class:`PointStoreRepaired`)
names the file, the count and the first defect, and the scan recomputes exactly those
points. The other rows are kept (each was final when it was stored: a later change to
another row does not alter it). Identical duplicates are collapsed to one row without a
warning.
"""

from __future__ import annotations

import json
import math
import sqlite3
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from flatcontact.foundation.errors import InputError
from flatcontact.ispes.relax import Index

#: Keys every row must hold (the index and the record :meth:`PointStore._record` reads).
ROW_KEYS = (
    "i_a",
    "i_b",
    "i_z",
    "shift_a",
    "shift_b",
    "thickness",
    "normal_stress_gpa",
    "force_calls",
    "converged",
)
#: Row keys that must be finite numbers.
FINITE_KEYS = ("shift_a", "shift_b", "thickness", "normal_stress_gpa")
_SHIFT_ATOL = 1e-9
_THICKNESS_ATOL = 1e-6


class PointStoreRepaired(UserWarning):
    """Rows of a ``points.db`` failed validation, were deleted and will be recomputed."""


def quick_check(path: Path) -> None:
    """Refuse a file whose pages SQLite finds damaged (``PRAGMA quick_check``): InputError."""
    with sqlite3.connect(str(path)) as con:
        found = [r[0] for r in con.execute("PRAGMA quick_check(3)")]
    con.close()
    if found != ["ok"]:
        said = " ".join("; ".join(map(str, found)).replace("*** in database main ***", "").split())
        raise InputError(
            f"{path}: damaged points database ({said[:200]}); remove it to recompute the scan"
        )


def _flatten(d: Any, prefix: str = "") -> dict[str, Any]:
    if isinstance(d, dict):
        out: dict[str, Any] = {}
        for k, v in d.items():
            out.update(_flatten(v, f"{prefix}.{k}" if prefix else str(k)))
        return out
    return {prefix: d}


#: The model's part of the store's settings (the scan's ``potential`` key holds
#: :meth:`flatcontact.potentials.engines.ModelFactory.fingerprint`, ``{"potential": {"model":
#: ..., "files_sha256": ...}}``) -> how a difference names it: the model's fields as the run
#: settings name them (``potential.calculator.kwargs.x``), a potential file by its name.
_FINGERPRINT_NAMES = (
    ("potential.potential.model.", "potential."),
    ("potential.potential.files_sha256.", "the content (SHA-256) of potential file "),
)


def _setting_name(key: str) -> str:
    """The flattened settings key ``key`` as the run settings name it (:data:`_FINGERPRINT_NAMES`)."""
    for inner, shown in _FINGERPRINT_NAMES:
        if key.startswith(inner):
            return shown + key.removeprefix(inner)
    return key


def settings_difference(stored: dict, current: dict) -> str | None:
    """The first difference between two settings dicts as ``key: stored vs current``, or None.

    The key is the flattened path (``grid.n_a``), the model's part named as the run settings
    name it (``potential.calculator.kwargs.x``, not the fingerprint's nesting).
    """
    a, b = _flatten(json.loads(json.dumps(stored))), _flatten(json.loads(json.dumps(current)))
    for key in sorted(set(a) | set(b)):
        if a.get(key, "<absent>") != b.get(key, "<absent>"):
            sa, sb = json.dumps(a.get(key, "<absent>")), json.dumps(b.get(key, "<absent>"))
            if len(sa) > 60:
                sa = sa[:57] + "..."
            if len(sb) > 60:
                sb = sb[:57] + "..."
            return f"{_setting_name(key)}: {sa} in the store vs {sb} now"
    return None


def _finite_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


def resolved_defect(resolved: Any) -> str | None:
    """What is wrong with the ``resolved`` metadata (None if absent or sound)."""
    if resolved is None:
        return None
    if not isinstance(resolved, dict):
        return "is not a map"
    z = resolved.get("thickness_angstrom")
    if not isinstance(z, list) or not z or not all(_finite_number(v) and v > 0 for v in z):
        return "'thickness_angstrom' is not a non-empty list of positive finite numbers"
    if len(set(z)) != len(z):
        return "'thickness_angstrom' repeats a thickness"
    for key in ("a1", "a2"):
        v = resolved.get(key)
        if not isinstance(v, list) or len(v) < 2 or not all(_finite_number(x) for x in v):
            return f"{key!r} is not a vector of finite numbers"
    if not isinstance(resolved.get("potential_label"), str):
        return "'potential_label' is not text"
    return None


def row_defect(
    row: Any, shape: tuple[int | None, ...], z: list[float] | None, n_atoms: int
) -> str | None:
    """What is wrong with one stored row (None if it keeps the contract).

    ``shape`` holds the grid's size along each axis, ``None`` where it is not known (then
    the index along it need only be non-negative); ``z`` the thicknesses (Å) or ``None``.
    """
    where = f"row {row.id}"
    missing = [k for k in ROW_KEYS if k not in row.key_value_pairs]
    if missing:
        return f"{where} has no {', '.join(missing)}"
    index = [row.get(k) for k in ("i_a", "i_b", "i_z")]
    if not all(isinstance(i, int) and not isinstance(i, bool) for i in index):
        return f"{where}: index {index} is not three integers"
    if not all(0 <= i and (n is None or i < n) for i, n in zip(index, shape, strict=True)):
        return f"{where}: index {tuple(index)} is outside the grid {_shown(shape)}"
    for key in FINITE_KEYS:
        if not _finite_number(row.get(key)):
            return f"{where}: {key} = {row.get(key)!r} is not a finite number"
    energy = row.get("energy")
    if not _finite_number(energy):
        return f"{where}: energy = {energy!r} is not a finite number"
    reaction = row.get("reaction_stress_gpa")
    if reaction is not None and not _finite_number(reaction):
        return f"{where}: reaction_stress_gpa = {reaction!r} is not a finite number"
    if not _finite_number(row.get("force_calls")) or row.get("force_calls") < 0:
        return f"{where}: force_calls = {row.get('force_calls')!r} is not a count"
    ia, ib, iz = index
    if (
        (shape[0] is not None and abs(row.get("shift_a") - ia / shape[0]) > _SHIFT_ATOL)
        or (shape[1] is not None and abs(row.get("shift_b") - ib / shape[1]) > _SHIFT_ATOL)
        or (z is not None and abs(row.get("thickness") - z[iz]) > _THICKNESS_ATOL)
    ):
        return f"{where}: shift or thickness differs from the grid's at index {tuple(index)}"
    start = row.get("start", "")
    if start and not _start_index(start, shape):
        return f"{where}: start {start!r} is not an index of the grid"
    positions = row.get("positions")
    if positions is None or np.shape(positions) != (n_atoms, 3):
        return f"{where}: positions are not {n_atoms} × 3"
    if not np.all(np.isfinite(positions)):
        return f"{where}: positions are not finite"
    return None


def _start_index(text: Any, shape: tuple[int, int, int]) -> tuple[int, ...] | None:
    """The index ``"i_a,i_b,i_z"`` of a warm start if it is one of the grid, else None."""
    if not isinstance(text, str):
        return None
    try:
        index = tuple(int(s) for s in text.split(","))
    except ValueError:
        return None
    if len(index) != 3 or not all(
        0 <= i and (n is None or i < n) for i, n in zip(index, shape, strict=True)
    ):
        return None
    return index


def _shown(shape: tuple[int | None, ...]) -> str:
    return " × ".join("?" if n is None else str(n) for n in shape)


def _same_point(a: Any, b: Any) -> bool:
    """Whether two rows hold the same point (every record key, energy and positions equal)."""
    keys = (*ROW_KEYS, "reaction_stress_gpa", "steps", "max_force_ev_per_a", "start")
    return (
        all(a.get(k) == b.get(k) for k in keys)
        and a.get("energy") == b.get("energy")
        and np.array_equal(a.positions, b.positions)
    )


def grid_shape(settings: dict, resolved: dict | None) -> tuple[int | None, ...]:
    """The grid's size along ``a1``, ``a2`` and thickness, ``None`` where it is not known.

    The sizes come from ``settings["grid"]`` (``n_a``, ``n_b``) and
    ``resolved["thickness_angstrom"]``; a store of a scan that has rows but no resolved
    thicknesses has lost its grid (size 0 along thickness: every row fails). A store
    without a grid in its settings (a bare store) knows no size along ``a1`` and ``a2``.
    """
    grid = settings.get("grid")
    z = list(resolved["thickness_angstrom"]) if resolved else None
    if isinstance(grid, dict):
        return (int(grid.get("n_a", 0)), int(grid.get("n_b", 0)), len(z or ()))
    return (None, None, None if z is None else len(z))


def repair_rows(
    db: Any, rows: list, settings: dict, resolved: dict | None, n_atoms: int, path: Path
) -> dict[Index, Any]:
    """Check every row against the contract, delete the bad ones and warn; the sound rows.

    Parameters
    ----------
    db
        The open ASE database the rows come from (``db.delete(ids)`` removes rows).
    rows
        Every row of the store.
    settings, resolved
        The store's settings and resolved metadata (the grid, :func:`grid_shape`).
    n_atoms
        The reference interface's atom count.
    path
        The store file, named in the warning.

    Returns
    -------
    dict
        Index ``(i_a, i_b, i_z)`` -> the one sound row stored for it.
    """
    shape = grid_shape(settings, resolved)
    z = list(resolved["thickness_angstrom"]) if resolved else None
    bad: dict[int, str] = {}
    seen: dict[Index, Any] = {}
    for row in rows:
        defect = row_defect(row, shape, z, n_atoms)
        if defect is not None:
            bad[row.id] = defect
            continue
        index = (int(row.i_a), int(row.i_b), int(row.i_z))
        first = seen.get(index)
        if first is None:
            seen[index] = row
        elif _same_point(first, row):
            bad[row.id] = ""  # an identical copy: dropped without loss
        else:
            defect = f"two different rows for point {index}"
            bad[row.id] = bad[first.id] = defect
    kept = {index: row for index, row in seen.items() if row.id not in bad}
    if bad:
        db.delete(list(bad))
        lost = [d for d in bad.values() if d]
        if lost:
            warnings.warn(
                f"{path}: {len(lost)} stored point(s) failed validation (first: "
                f"{lost[0]}); they were deleted and are recomputed",
                PointStoreRepaired,
                stacklevel=3,
            )
    return kept
