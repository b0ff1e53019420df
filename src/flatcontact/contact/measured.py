"""Measured stiffness curves: the CSV formats, their units, and reading them into SI arrays.

Two-column CSV (one load; :func:`load_stiffness_csv`)
----------------------------------------------------
Two columns, one a stress and one a lateral stiffness, each with its unit in the
header, either in brackets or as a snake-case suffix, e.g.::

    mean shear stress [MPa],lateral stiffness [N/m]
    mean_shear_stress_mpa,lateral_stiffness_n_per_m

Stress units: Pa, kPa, MPa, GPa. Stiffness units: <force>/<length> with force in
N, mN, µN (uN), nN, kN and length in m, mm, µm (um), nm (e.g. N/m, mN/m, µN/nm).
Lines starting with ``#`` are comments. Which column is which is decided by its
unit.

Cells and rows
--------------
A cell is a plain decimal number (``12``, ``-0.5``, ``1.2e3``): no digit separators
(``1_0``), no hex, no NaN or inf, no subnormal magnitude. Stresses (at most 100 GPa) and
stiffnesses (at most 1e12 N/m) are >= 0 (0: gross sliding); loads are > 0 (p0 at most
1 TPa, a normal load at most 1e4 N). The rows are put in one canonical order (by load,
stress, stiffness), so a shuffled file reads as the sorted one; a row repeated exactly is
kept once; two rows with the same stress (and load) but different stiffnesses are refused,
as is a curve whose stresses or stiffnesses are all equal. Every refusal names the file
and the data line.

Several loads (:func:`load_fit_data`)
-------------------------------------
Either one two-column CSV per load (the p0 of each file given alongside) or one CSV
with a third, load column: ``p0 [GPa]`` / ``p0_gpa`` (peak Hertz pressure, any pressure
unit) or ``normal load [uN]`` / ``normal_load_un`` (converted to p0 with the tip radius and
E* of the parameters, Hertz: p0 = (6 P E*²/(π³ R²))^(1/3)). A load column is recognised by
its name (containing ``p0``, ``peak`` or ``load``).

The stress is in whatever measure the experiment used (amplitude or rms); the model side
(:mod:`flatcontact.contact.experiment`, :mod:`flatcontact.contact.fit`) says which.
"""

from __future__ import annotations

import math
import re
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from flatcontact.contact.parameters import ContactParameters
from flatcontact.foundation import units
from flatcontact.foundation.errors import InputError, require
from flatcontact.foundation.fileio import read_text_file

FloatArray = NDArray[np.float64]

_PRESSURE_TO_PA = {"pa": 1.0, "kpa": 1.0e3, "mpa": units.MPA_TO_PA, "gpa": units.GPA_TO_PA}
_FORCE_TO_N = {"n": 1.0, "kn": 1.0e3, "mn": 1.0e-3, "un": units.UN_TO_N, "nn": 1.0e-9}
_LENGTH_TO_M = {"m": 1.0, "mm": 1.0e-3, "um": units.UM_TO_M, "nm": units.NM_TO_M}
_BRACKET = re.compile(r"^(?P<name>.*?)\s*[\[(](?P<unit>[^\])]+)[\])]\s*$")
_SNAKE_STIFF = re.compile(r"^(?P<name>.+?)_(?P<f>kn|mn|un|nn|n)_per_(?P<l>mm|um|nm|m)$")
_SNAKE_PRESS = re.compile(r"^(?P<name>.+?)_(?P<u>kpa|mpa|gpa|pa)$")
_LOAD_NAME = re.compile(r"p0|peak|load", re.IGNORECASE)
#: Largest measured stress (100 GPa, the settings' bound on τ0 and σ0) and lateral stiffness
#: (1e12 N/m, beyond any contact) a row may hold; larger is a unit error, not a measurement.
MAX_STRESS_PA = 1.0e11
MAX_STIFFNESS_N_PER_M = 1.0e12
#: Largest load of a load column: p0 1 TPa (the settings' bound), normal load 1e4 N.
MAX_P0_PA = 1.0e12
MAX_LOAD_N = 1.0e4
#: A plain decimal number: what a CSV cell may hold (no ``1_0``, ``0x1p3``, ``inf``).
_DECIMAL = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")


def parse_cell(cell: str, where: str) -> float:
    """The number in one CSV cell: a plain decimal, finite and not subnormal.

    Raises
    ------
    InputError
        One line naming ``where`` (file and data line) and the cell.
    """
    text = cell.strip()
    if text.lower().lstrip("+-") in ("nan", "inf", "infinity"):
        raise InputError(f"{where} has NaN or inf: {text!r}")
    if not _DECIMAL.fullmatch(text):
        raise InputError(f"{where} is not numeric: {text!r} is not a plain decimal number")
    value = float(text)
    if not math.isfinite(value):
        raise InputError(f"{where} has a number out of range: {text!r}")
    if value != 0.0 and abs(value) < sys.float_info.min:
        raise InputError(f"{where} has a subnormal number: {text!r}")
    return value


def _canonical_rows(
    rows: list[tuple[int, list[float]]], key: Sequence[int], name: str
) -> list[list[float]]:
    """``rows`` ((data line, values)) sorted by the columns ``key`` then the rest, exact
    repeats dropped; two rows equal on ``key[:-1]`` + stress but not otherwise are refused.

    ``key`` lists the column indices in sort order, ending with the stress column; the
    remaining column is the stiffness.
    """
    width = len(rows[0][1]) if rows else 0
    order = list(key) + [i for i in range(width) if i not in key]
    ranked = sorted(rows, key=lambda r: ([r[1][i] for i in order], r[0]))
    out: list[list[float]] = []
    prev: tuple[int, list[float]] | None = None
    for line, vals in ranked:
        if prev is not None and [prev[1][i] for i in key] == [vals[i] for i in key]:
            if prev[1] == vals:
                continue  # an exact repeat
            first, second = sorted(((prev[0], prev[1]), (line, vals)))
            raise InputError(
                f"{name}: data lines {first[0]} and {second[0]} give the same stress with "
                f"different values ({first[1]} and {second[1]}): merge or remove one"
            )
        out.append(vals)
        prev = (line, vals)
    return out


def _check_curve(stress: FloatArray, stiff: FloatArray, name: str, at: str = "") -> None:
    """Refuse a curve without a range: all stresses or all stiffnesses equal."""
    require(
        np.ptp(stress) > 0.0,
        f"{name}: every row{at} has the same stress ({stress[0]:g} Pa): a stiffness curve "
        "needs a range of stresses",
    )
    require(
        np.ptp(stiff) > 0.0,
        f"{name}: every row{at} has the same stiffness ({stiff[0]:g} N/m): the curve has no "
        "collapse to compare with",
    )


def _data_rows(lines: list[str], name: str, n_cells: int):
    """(line number, ``"<name>: data line N"``, parsed cells, line) for each data line after
    the header; a line without exactly ``n_cells`` cells or with a cell :func:`parse_cell`
    refuses is one InputError naming the file and line."""
    for n, ln in enumerate(lines[1:], start=2):
        where = f"{name}: data line {n}"
        cells = [c.strip() for c in ln.split(",")]
        require(len(cells) == n_cells, f"{where} has {len(cells)} cells, expected {n_cells}")
        yield n, where, [parse_cell(c, where) for c in cells], ln


def _check_row(stress_pa: float, stiffness_n_per_m: float, where: str, line: str) -> None:
    """Refuse a physically impossible row (SI values): stress outside 0..:data:`MAX_STRESS_PA`
    or stiffness outside 0..:data:`MAX_STIFFNESS_N_PER_M` (0 is a contact in gross sliding)."""
    require(
        0.0 <= stress_pa <= MAX_STRESS_PA,
        f"{where}: the stress must be in 0..{MAX_STRESS_PA / units.MPA_TO_PA:g} MPa, got {line!r}",
    )
    require(
        0.0 <= stiffness_n_per_m <= MAX_STIFFNESS_N_PER_M,
        f"{where}: the stiffness must be in 0..{MAX_STIFFNESS_N_PER_M:g} N/m, got {line!r}",
    )


def _normalise_unit(text: str) -> str:
    return text.strip().replace("µ", "u").replace("μ", "u").replace(" ", "").lower()


def parse_unit(unit: str) -> tuple[str, float]:
    """('stress', factor to Pa) or ('stiffness', factor to N/m) for a unit string.

    Raises
    ------
    InputError
        For a unit that is neither a pressure nor a force per length.
    """
    u = _normalise_unit(unit)
    if u in _PRESSURE_TO_PA:
        return "stress", _PRESSURE_TO_PA[u]
    if "/" in u:
        f, _, ln = u.partition("/")
        if f in _FORCE_TO_N and ln in _LENGTH_TO_M:
            return "stiffness", _FORCE_TO_N[f] / _LENGTH_TO_M[ln]
    raise InputError(
        f"unknown unit {unit!r}: expected a stress (Pa, kPa, MPa, GPa) or a stiffness "
        "(force/length, e.g. N/m, mN/m, µN/nm)"
    )


def parse_column(header: str) -> tuple[str, str, float]:
    """(name, kind, factor) from a header like 'mean shear stress [MPa]' or 'stress_mpa'."""
    h = header.strip()
    m = _BRACKET.match(h)
    if m:
        kind, factor = parse_unit(m.group("unit"))
        return m.group("name").strip(), kind, factor
    low = h.lower()
    m = _SNAKE_STIFF.match(low)
    if m:
        return m.group("name"), "stiffness", _FORCE_TO_N[m.group("f")] / _LENGTH_TO_M[m.group("l")]
    m = _SNAKE_PRESS.match(low)
    if m:
        return m.group("name"), "stress", _PRESSURE_TO_PA[m.group("u")]
    raise InputError(
        f"column {header!r} has no unit: write it as 'name [unit]' or 'name_<unit>' "
        "(e.g. 'mean shear stress [MPa]', 'lateral_stiffness_n_per_m')"
    )


@dataclass(frozen=True)
class MeasuredStiffness:
    """Measured stiffness curve in SI, sorted by stress.

    Attributes
    ----------
    stress_pa : mean shear stress (Pa), in the measure the experiment used
    stiffness_n_per_m : lateral stiffness (N/m)
    source : file name
    stress_column, stiffness_column : the header cells as read
    """

    stress_pa: FloatArray
    stiffness_n_per_m: FloatArray
    source: str
    stress_column: str
    stiffness_column: str


def load_stiffness_csv(path: str | Path) -> MeasuredStiffness:
    """Read a two-column stress/stiffness CSV with units in the header (see module doc).

    Raises
    ------
    InputError
        Missing file, not two columns, a column without a unit or with an unknown
        one, two columns of the same kind, a non-numeric or NaN/inf cell, a
        negative stress, fewer than 4 rows.
    """
    p = Path(path)
    require(p.exists(), f"experiment file {str(p)!r} does not exist")
    text = read_text_file(p, "measured stiffness CSV", 50_000_000)
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    require(len(lines) > 0, f"{p.name}: empty file, expected a header and data rows")
    header = [c.strip() for c in lines[0].split(",")]
    require(
        len(header) == 2,
        f"{p.name}: expected 2 columns (mean shear stress, lateral stiffness), got {len(header)}: {header}",
    )
    cols = []
    for h in header:
        try:
            cols.append(parse_column(h))
        except InputError as exc:
            raise InputError(f"{p.name}: {exc}") from None
    kinds = [c[1] for c in cols]
    require(
        sorted(kinds) == ["stiffness", "stress"],
        f"{p.name}: need one stress column and one stiffness column, got kinds {kinds} from {header}",
    )
    i_stress = kinds.index("stress")
    rows = []
    for n, where, vals, ln in _data_rows(lines, p.name, 2):
        _check_row(
            vals[i_stress] * cols[i_stress][2],
            vals[1 - i_stress] * cols[1 - i_stress][2],
            where,
            ln.strip(),
        )
        rows.append((n, vals))
    data = np.array(_canonical_rows(rows, [i_stress], p.name)).reshape(-1, 2)
    require(len(data) >= 4, f"{p.name}: need at least 4 distinct data rows, got {len(data)}")
    stress = data[:, i_stress] * cols[i_stress][2]
    stiff = data[:, 1 - i_stress] * cols[1 - i_stress][2]
    _check_curve(stress, stiff, p.name)
    return MeasuredStiffness(
        stress_pa=stress,
        stiffness_n_per_m=stiff,
        source=p.name,
        stress_column=header[i_stress],
        stiffness_column=header[1 - i_stress],
    )


@dataclass(frozen=True)
class LoadCurve:
    """One measured stiffness curve at one load (SI)."""

    p0_gpa: float
    stress_pa: FloatArray
    stiffness_n_per_m: FloatArray
    source: str


def _load_column(header: str) -> tuple[str, float] | None:
    """('p0', factor to Pa) or ('load', factor to N) for a load column header, else None."""
    h = header.strip()
    m = re.match(r"^(?P<name>.*?)\s*[\[(](?P<unit>[^\])]+)[\])]\s*$", h)
    if m:
        name, unit = m.group("name"), _normalise_unit(m.group("unit"))
    else:
        low = h.lower()
        parts = low.rsplit("_", 1)
        if len(parts) != 2:
            return None
        name, unit = parts
    if not _LOAD_NAME.search(name):
        return None
    if unit in _PRESSURE_TO_PA:
        return "p0", _PRESSURE_TO_PA[unit]
    if unit in _FORCE_TO_N:
        return "load", _FORCE_TO_N[unit]
    return None


def _p0_from_load_pa(load_n: FloatArray, params: ContactParameters) -> FloatArray:
    """Hertz peak pressure (Pa) from the normal load (N): p0 = (6 P E*²/(π³ R²))^(1/3)."""
    e, r = params.contact_modulus_pa, params.radius_m
    return np.cbrt(6.0 * load_n * e**2 / (np.pi**3 * r**2))


def read_table(path: str | Path, params: ContactParameters) -> list[LoadCurve] | None:
    """Curves of a CSV with a load column, one per distinct load; None if it has none.

    Raises
    ------
    InputError
        Unreadable file, columns without units, non-numeric cells (one line, naming the file).
    """
    p = Path(path)
    require(p.is_file(), f"fit file {str(p)!r} does not exist")
    lines = [
        ln for ln in p.read_text().splitlines() if ln.strip() and not ln.lstrip().startswith("#")
    ]
    require(len(lines) > 1, f"{p.name}: expected a header and data rows")
    header = [c.strip() for c in lines[0].split(",")]
    load_idx = [i for i, h in enumerate(header) if _load_column(h) is not None]
    if not load_idx:
        return None
    require(len(load_idx) == 1, f"{p.name}: more than one load column in {header}")
    require(
        len(header) == 3,
        f"{p.name}: with a load column expected 3 columns (stress, stiffness, load), got {header}",
    )
    li = load_idx[0]
    kind_load, f_load = _load_column(header[li])  # type: ignore[misc]
    others = [i for i in range(3) if i != li]
    cols = {}
    for i in others:
        try:
            _, kind, factor = parse_column(header[i])
        except InputError as exc:
            raise InputError(f"{p.name}: {exc}") from None
        cols[kind] = (i, factor)
    require(
        sorted(cols) == ["stiffness", "stress"],
        f"{p.name}: need one stress and one stiffness column besides the load, got {header}",
    )
    i_stress, i_stiff = cols["stress"][0], cols["stiffness"][0]
    rows = []
    load_max = MAX_P0_PA if kind_load == "p0" else MAX_LOAD_N
    top, unit = (MAX_P0_PA / units.GPA_TO_PA, "GPa") if kind_load == "p0" else (MAX_LOAD_N, "N")
    for n, where, vals, ln in _data_rows(lines, p.name, 3):
        require(
            0.0 < vals[li] * f_load <= load_max,
            f"{where}: the load must be in (0, {top:g}] {unit}, got {ln.strip()!r}",
        )
        _check_row(
            vals[i_stress] * cols["stress"][1],
            vals[i_stiff] * cols["stiffness"][1],
            where,
            ln.strip(),
        )
        rows.append((n, vals))
    data = np.array(_canonical_rows(rows, [li, i_stress], p.name)).reshape(-1, 3)
    load = data[:, li] * f_load
    p0_pa = load if kind_load == "p0" else _p0_from_load_pa(load, params)
    stress = data[:, cols["stress"][0]] * cols["stress"][1]
    stiff = data[:, cols["stiffness"][0]] * cols["stiffness"][1]
    require(bool(np.all(p0_pa > 0)), f"{p.name}: loads must be > 0 (column {header[li]!r})")
    require(bool(np.all(stress >= 0)), f"{p.name}: stress must be >= 0")
    out = []
    for p0 in np.unique(np.round(p0_pa / units.GPA_TO_PA, 9)):
        sel = np.isclose(p0_pa / units.GPA_TO_PA, p0, rtol=1e-9, atol=0)
        order = np.lexsort((stiff[sel], stress[sel]))
        require(int(sel.sum()) >= 4, f"{p.name}: need at least 4 rows at p0 = {p0:g} GPa")
        _check_curve(stress[sel], stiff[sel], p.name, f" at p0 = {p0:g} GPa")
        out.append(
            LoadCurve(
                p0_gpa=float(p0),
                stress_pa=stress[sel][order],
                stiffness_n_per_m=stiff[sel][order],
                source=p.name,
            )
        )
    return out


def load_fit_data(
    paths: Sequence[str | Path],
    params: ContactParameters,
    p0_gpa: Sequence[float] | None = None,
) -> list[LoadCurve]:
    """The curves to fit: from CSVs with a load column, or one two-column CSV per load with
    its p0 in ``p0_gpa`` (same order as ``paths``).

    Raises
    ------
    InputError
        (one line) no file; ``p0_gpa`` not one per file; a file without a load column when
        several loads are fitted and no p0 is given for it; a p0 given for a file that has
        a load column.
    """
    paths = [Path(x) for x in paths]
    require(len(paths) > 0, "fit: give at least one stiffness CSV file")
    if p0_gpa is not None:
        p0s = list(p0_gpa)
        require(
            len(p0s) == len(paths),
            f"fit_p0_gpa: {len(p0s)} values for {len(paths)} files; give one p0 per file "
            "(or none, with a load column 'p0 [GPa]' in the files)",
        )
    curves: list[LoadCurve] = []
    for i, path in enumerate(paths):
        table = read_table(path, params)
        if table is not None:
            require(
                p0_gpa is None,
                f"{path.name} has a load column; do not also give fit_p0_gpa for it",
            )
            curves.extend(table)
            continue
        if p0_gpa is None:
            raise InputError(
                f"{path.name} has no load column ('p0 [GPa]' or 'normal load [uN]'): "
                + (f"with {len(paths)} files (several loads) " if len(paths) > 1 else "")
                + "give fit_p0_gpa (one p0 per file) or add a load column"
            )
        p0 = params.check_p0_gpa(p0s[i], "fit_p0_gpa")[0]
        m = load_stiffness_csv(path)
        curves.append(LoadCurve(p0, m.stress_pa, m.stiffness_n_per_m, m.source))
    return curves
