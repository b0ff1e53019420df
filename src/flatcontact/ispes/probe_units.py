"""The probe's finished units in ``probe.json``: a scan interrupted in its probe resumes it.

The probe of a pressure-range grid (:mod:`flatcontact.ispes.probe`) is a set of independent
units of work, each a function of the interface, the potential, the relaxation settings
and its own inputs only:

- ``rigid``: the rigid single points of one lateral row of the grid
  (:func:`~flatcontact.ispes.probe.rigid_rows`), keyed by the row's ``shift_a`` and every
  ``shift_b`` of the grid;
- ``compress``: a probed column's compression (:func:`~flatcontact.ispes.probe.compress_chain`),
  keyed by the shift and ``p_hi_gpa``;
- ``segment``: one compression segment (:func:`~flatcontact.ispes.probe.compress_segment`),
  keyed by the shift, ``p_hi_gpa``, its index and its number of steps;
- ``stretch``: a column's stretching (:func:`~flatcontact.ispes.probe.stretch_chain`), keyed
  by the shift, the load at the reference thickness (GPa, or null) and ``stop_at_gpa``;
- ``work``: the ideal work of separation
  (:func:`~flatcontact.ispes.work_of_separation.ideal_work_of_separation`), keyed by the shift.

Each unit is written to ``probe.json`` as soon as the driver has it (the whole file replaced
atomically, :func:`flatcontact.foundation.fileio.write_json_atomic`), beside ``points.db`` and not in
it. The file's ``settings`` are the scan fingerprint without the grid (the interface hash,
the potential, the relaxation settings): a file made with other settings is set aside and
its units recomputed; within it a unit is reused only under exactly its key, so a unit whose
inputs differ is recomputed. Floats are stored with ``repr`` precision (JSON round trip is
exact), NaN (the slabs overlap) as null: a resumed probe is bit for bit the finished one.
A file that is not a probe record of this format is refused as ``points.db`` is.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import warnings
from collections import Counter
from pathlib import Path
from typing import Any

import numpy as np

from flatcontact.foundation.errors import InputError
from flatcontact.foundation.fileio import refuse_link, write_json_atomic
from flatcontact.ispes.probe import ColumnChain
from flatcontact.ispes.work_of_separation import WorkOfSeparation

FORMAT = "flatcontact.probe/1"
#: the unit kinds, in the order the progress line names them
KINDS = ("rigid", "compress", "segment", "stretch", "work")


class ProbeUnitsReused(UserWarning):
    """A resumed scan reused finished probe units from ``probe.json`` (the count per kind)."""


class ProbeUnitsRepaired(UserWarning):
    """Units of a ``probe.json`` failed validation and are recomputed."""


def probe_settings(scan_settings: dict) -> dict:
    """The fingerprint the probe's units depend on: the scan's without its ``grid`` and
    ``symmetry`` (the grid's inputs a unit uses are in the unit's key)."""
    return {k: v for k, v in scan_settings.items() if k not in ("grid", "symmetry")}


def _floats(values) -> list:
    return [None if not math.isfinite(v) else float(v) for v in np.asarray(values, float).ravel()]


def _array(values, shape) -> np.ndarray:
    return np.array([np.nan if v is None else v for v in values], dtype=float).reshape(shape)


def _encode(kind: str, value: Any) -> dict:
    if kind == "rigid":
        energy, load = value
        return {"energy_ev": _floats(energy), "normal_stress_gpa": _floats(load)}
    if kind == "work":
        return {
            k: (
                list(map(float, v))
                if isinstance(v, tuple)
                else v.item()
                if hasattr(v, "item")
                else v
            )
            for k, v in dataclasses.asdict(value).items()
        }
    return {  # a ColumnChain
        "thickness_angstrom": [float(v) for v in value.thickness_angstrom],
        "energy_ev": [float(v) for v in value.energy_ev],
        "normal_stress_gpa": [float(v) for v in value.normal_stress_gpa],
        "force_calls": [int(n) for n in value.force_calls],
        "overlap": value.overlap,
    }


def _decode(kind: str, record: dict) -> Any:
    if kind == "rigid":
        n = len(record["energy_ev"])
        return (
            _array(record["energy_ev"], (1, n)),
            _array(record["normal_stress_gpa"], (1, n)),
        )
    if kind == "work":
        return WorkOfSeparation(**{**record, "zero_load_shift": tuple(record["zero_load_shift"])})
    return ColumnChain(
        *(tuple(record[f]) for f in ("thickness_angstrom", "energy_ev", "normal_stress_gpa")),
        tuple(int(n) for n in record["force_calls"]),
        overlap=record["overlap"],
    )


def _defect(kind: str, value: Any) -> str | None:
    """What is wrong with a decoded unit, or None: chains of equal lengths with finite
    thicknesses, energies and loads and non-negative call counts; a row's energy and load
    both finite or both NaN (overlap); a work of separation with finite numbers."""
    if kind == "rigid":
        e, p = value
        if e.shape != p.shape or np.any(np.isfinite(e) != np.isfinite(p)):
            return "energy and load of a row differ in length or overlap"
        return None
    if kind == "work":
        numbers = [v for v in dataclasses.astuple(value) if not isinstance(v, bool | str)]
        numbers = np.asarray([x for v in numbers for x in np.atleast_1d(v)], dtype=float)
        return None if np.all(np.isfinite(numbers)) else "a number of W is not finite"
    fields = (value.thickness_angstrom, value.energy_ev, value.normal_stress_gpa)
    if len({len(f) for f in (*fields, value.force_calls)}) != 1:
        return "a chain's fields differ in length"
    if not np.all(np.isfinite(np.asarray(fields, dtype=float))):
        return "a chain holds a value that is not finite"
    if any(n < 0 for n in value.force_calls):
        return "a chain holds a negative force-call count"
    if value.overlap is not None and not isinstance(value.overlap, str):
        return "a chain's overlap is not text"
    return None


def unit_key(kind: str, *inputs: Any) -> str:
    """The key of a unit: its kind and inputs as compact JSON (floats with ``repr`` digits)."""
    if kind not in KINDS:
        raise ValueError(f"unknown probe unit kind {kind!r}")
    return json.dumps([kind, *(_plain(v) for v in inputs)], separators=(",", ":"))


def _plain(value: Any) -> Any:
    """Inputs as JSON values: numpy scalars as Python numbers, sequences as lists."""
    if isinstance(value, (list, tuple, np.ndarray)):
        return [_plain(v) for v in value]
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value)
    return value


class ProbeUnits:
    """The finished probe units of one scan folder (see the module).

    Parameters
    ----------
    path
        ``<scan folder>/probe.json`` (created with the first unit).
    settings
        :func:`probe_settings` of the scan.
    """

    def __init__(self, path: str | os.PathLike[str], settings: dict):
        self.path = Path(path)
        self.settings = json.loads(json.dumps(settings))
        self.units: dict[str, dict] = {}
        #: units reused by this run, per kind
        self.reused: Counter = Counter()
        #: units of the file that failed validation (dropped, recomputed), the first defect
        self.dropped: list[str] = []
        if self.path.exists() or self.path.is_symlink():
            refuse_link(self.path, "probe record")
            try:
                data = json.loads(self.path.read_text())
            except (OSError, UnicodeDecodeError, ValueError) as exc:
                raise InputError(
                    f"{self.path}: not a readable probe record ({exc.__class__.__name__}); "
                    "remove it to recompute the probe"
                ) from None
            if not isinstance(data, dict) or data.get("format") != FORMAT:
                raise InputError(
                    f"{self.path}: expected a probe record of format {FORMAT}; "
                    "remove it to recompute the probe"
                )
            if data.get("settings") == self.settings and isinstance(data.get("units"), dict):
                self.units = data["units"]

    def get(self, kind: str, *inputs: Any) -> Any:
        """The finished unit ``kind`` with these inputs, or None (counted in :attr:`reused`)."""
        key = unit_key(kind, *inputs)
        record = self.units.get(key)
        if record is None:
            return None
        try:
            value = _decode(kind, record)
            defect = _defect(kind, value)
        except (KeyError, TypeError, ValueError, AttributeError) as exc:
            defect = f"unreadable ({exc.__class__.__name__}: {exc})"
        if defect is not None:
            del self.units[key]
            self.dropped.append(f"{key}: {defect}")
            warnings.warn(
                f"{self.path}: a probe unit failed validation and is recomputed ({key}: {defect})",
                ProbeUnitsRepaired,
                stacklevel=2,
            )
            return None
        self.reused[kind] += 1
        return value

    def put(self, kind: str, inputs: tuple, value: Any) -> Any:
        """Record a finished unit (the file rewritten atomically) and return ``value``."""
        self.units[unit_key(kind, *inputs)] = _encode(kind, value)
        write_json_atomic(
            self.path, {"format": FORMAT, "settings": self.settings, "units": self.units}
        )
        return value

    def cached(self, kind: str, inputs: tuple, compute) -> Any:
        """The unit from the file if it is there, else ``compute()`` recorded."""
        value = self.get(kind, *inputs)
        return value if value is not None else self.put(kind, inputs, compute())

    def report(self) -> str | None:
        """One line naming the reused units per kind, or None if none was reused."""
        if not self.reused:
            return None
        parts = ", ".join(f"{kind} {self.reused[kind]}" for kind in KINDS if self.reused[kind])
        return f"probe resumed from {self.path.name}: reused finished units ({parts})"

    def announce(self) -> None:
        """Warn (:class:`ProbeUnitsReused`, one ``warning:`` line on the CLI) if units were reused."""
        line = self.report()
        if line is not None:
            warnings.warn(line, ProbeUnitsReused, stacklevel=2)
