"""The validity gates between the laws and the contact stage (:mod:`flatcontact.analysis.gates`).

:func:`evaluate_gates` reads what the earlier stages wrote (:class:`GateInputs`: the
interface, ``scan.json``, ``friction.nc``, ``laws.json``) and runs every gate;
:func:`check_gates` stops the run, before the contact stage touches its folder, with one
line per gate that fired and is not in ``contact.accept_untrusted``. The contact stage
records the report in ``summary.json["gates"]`` and the report puts a box above the figures.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from flatcontact.foundation.errors import InputError
from flatcontact.foundation.result_json import read_result_json
from flatcontact.ispes.shift_symmetry import DEFAULT_TOLERANCE_ANGSTROM


@dataclass(frozen=True)
class GateInputs:
    """The files the gates read (any may be None: that gate is not checked), and how the
    scan defines the interface's shift-space group (its structural tolerance, Å, and whether
    it spread the compression over the stack: false in ``rigid`` mode)."""

    interface: Path | None = None
    scan_json: Path | None = None
    friction_nc: Path | None = None
    laws_json: Path | None = None
    symmetry_tolerance_angstrom: float = DEFAULT_TOLERANCE_ANGSTROM
    spread_compression: bool = True


def evaluate_gates(inputs: GateInputs):
    """Every gate of :data:`flatcontact.analysis.gates.GATES` on ``inputs``
    (a :class:`flatcontact.analysis.gates.GateReport`)."""
    from flatcontact.analysis import gates

    findings, notes, not_checked = [], [], []
    scan = _read_json(inputs.scan_json)
    laws = _read_json(inputs.laws_json)
    if scan is None or "layer_slip" not in scan:
        not_checked.append("in_slab_slip")
    else:
        findings.append(gates.in_slab_slip(scan["layer_slip"]))
    if scan is None:
        not_checked.append("load_fold")
    else:
        findings.append(gates.load_fold(scan))
    if laws is None:
        not_checked.append("negative_slope")
    else:
        findings.append(gates.negative_slope(laws))
        notes += gates.negative_slope_notes(laws)
    friction = _read_friction(inputs.friction_nc)
    if friction is None:
        not_checked += ["broken_symmetry", "degenerate_minima"]
    else:
        findings += _landscape_gates(inputs, friction, not_checked)
    kept = [f for f in findings if f is not None]
    kept.sort(key=lambda f: gates.GATES.index(f.gate))
    return gates.GateReport(kept, notes, not_checked)


def _read_json(path: Path | None) -> dict | None:
    if path is None or not Path(path).exists():
        return None
    return read_result_json(path)


def _read_friction(path: Path | None):
    if path is None or not Path(path).is_file():
        return None
    import xarray as xr

    with xr.open_dataset(path, engine="h5netcdf") as ds:
        return ds.load()


def shift_group_operations(inputs: GateInputs) -> list[tuple[np.ndarray, np.ndarray]]:
    """The interface's shift-space group as plain ``(M, t)`` (fractional basis, a slab swap's
    sign inside ``M``), found on ``inputs.interface`` the way the scan finds it
    (:func:`flatcontact.ispes.shift_symmetry.shift_space_group`), every operation, not only
    those that map the grid onto itself.

    A coincidence or twist cell (shift-lattice index > 1) has its landscape stated on one
    period of the shift lattice (:mod:`flatcontact.stages.scan`): the group is found modulo
    its pure translations and restated on that period
    (:func:`flatcontact.ispes.shift_lattice.shift_cell_operations`)."""
    from flatcontact.ispes.shift_lattice import shift_cell_operations, shift_lattice_of
    from flatcontact.ispes.shift_symmetry import shift_space_group
    from flatcontact.structures.interface_io import read_interface

    reference = read_interface(inputs.interface)
    lattice = shift_lattice_of(reference, inputs.symmetry_tolerance_angstrom)
    group = shift_space_group(
        reference,
        inputs.symmetry_tolerance_angstrom,
        spread_compression=inputs.spread_compression,
        modulo_translations=lattice.index > 1,
    )
    ops = [(np.array(op.matrix, int), np.array(op.translation, float)) for op in group.operations]
    return ops if lattice.index == 1 else shift_cell_operations(lattice, ops)


def _landscape_gates(inputs: GateInputs, ds, not_checked: list[str]) -> list:
    from flatcontact.analysis import gates

    interface = inputs.interface

    a1, a2 = np.asarray(ds.attrs["a1"], float), np.asarray(ds.attrs["a2"], float)
    p = [float(v) for v in ds["p_gpa"].values]
    maps = np.asarray(ds["energy_map"].values, float)
    out = []
    if interface is None or not Path(interface).is_file():
        not_checked.append("broken_symmetry")
    else:
        out.append(gates.broken_symmetry(maps, p, a1, a2, shift_group_operations(inputs)))
    start_xy = np.stack([ds["start_x"].values, ds["start_y"].values], axis=-1)
    out.append(
        gates.degenerate_minima(
            p,
            maps,
            a1,
            a2,
            start_xy,
            [int(k) for k in ds["selected_start"].values],
            np.asarray(ds["tau_by_start_mpa"].values, float),
            np.asarray(ds["start_energy_above_lowest_mev_per_a2"].values, float),
            [float(v) for v in ds["degeneracy_tolerance_mev_per_a2"].values],
        )
    )
    return out


def check_gates(settings, report) -> None:
    """Stop (:class:`~flatcontact.foundation.errors.InputError`, one line per gate) on every finding of
    ``report`` whose gate is not in ``settings.contact.accept_untrusted``."""
    refused = report.refused(settings.contact.accept_untrusted)
    if not refused:
        return
    names = ", ".join(f.gate for f in refused)
    lines = [f"{f.gate}: {f.message}" for f in refused]
    raise InputError(
        "; ".join(lines)
        + f". The contact stage did not run (the stages before it are kept); to continue "
        f"with these numbers anyway set contact.accept_untrusted: [{names}]"
    )
