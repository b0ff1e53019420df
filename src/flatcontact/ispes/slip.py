"""Lateral slip inside a slab: how far each plane of a relaxed point moved sideways against
its neighbour in the same slab.

A scan point holds slab 1's held layers at the reference and slab 2's at the grid shift
(:mod:`flatcontact.ispes.geometry`); in ``full`` relaxation every other atom is free in 3D.
The interface is where the slabs are meant to slide. If the weakest plane of a slab is not
the interface (graphite: any plane between two sheets), a free plane inside a slab can slide
with the other slab instead, and the point's energy and load are then those of a different
sliding plane: the ISPES is no longer the interface's.

Definitions (Å, Cartesian, in-plane):

- ``d_i`` = relaxed lateral position of atom ``i`` − its rigidly placed position
  (reference + the grid shift for slab 2), with the periodic minimum image of the in-plane
  cell;
- ``D_L`` = mean of ``d_i`` over the atoms of layer ``L`` (``arrays["layer"]``): the lateral
  displacement of the plane's centre of mass (0 for a held layer);
- an **in-slab gap** is a pair of layers of one slab adjacent in z (the gap between the two
  slabs, the interface, is not one); its **slip** at a point is ``|D_upper − D_lower|``.

Elastic shear of a slab under the interface's lateral stress τ displaces neighbouring planes
by about τ·h/G (h the plane spacing, G the shear modulus: 10⁻³ Å for quartz at 100 MPa);
the atomic planes of a covalent network also move against each other as bond angles relax
(quartz quick preset, ``full``: at most 0.136 Å between an O and an Si plane over its 2160
points). A plane that slips moves by a sizeable fraction of the lattice constant (graphite
sheets: 0.4–0.65 Å). :data:`SLIP_THRESHOLD_ANGSTROM` lies between.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import numpy as np

from flatcontact.ispes.store_schema import stored_rows

#: A gap whose slip exceeds this at some point is reported (Å).
SLIP_THRESHOLD_ANGSTROM = 0.25
#: At most this many slipped points are listed in ``scan.json`` (the count is always given).
MAX_LISTED_POINTS = 20


@dataclass(frozen=True)
class Gap:
    """Two layers of one slab adjacent in z (``lower`` below ``upper``)."""

    slab: int
    lower: int
    upper: int


@dataclass
class SlipTable:
    """Per in-slab gap the slip at every stored point (see the module docstring)."""

    gaps: tuple[Gap, ...]
    indices: list[tuple[int, int, int]] = field(default_factory=list)  #: (i_a, i_b, i_z)
    shifts: list[tuple[float, float]] = field(default_factory=list)
    thicknesses: list[float] = field(default_factory=list)
    slip_angstrom: list[np.ndarray] = field(default_factory=list)  #: one array per point
    threshold_angstrom: float = SLIP_THRESHOLD_ANGSTROM

    def max_by_gap(self) -> np.ndarray:
        """Largest slip of each gap over the points (Å); zeros with no point."""
        if not self.slip_angstrom:
            return np.zeros(len(self.gaps))
        return np.max(np.array(self.slip_angstrom), axis=0)

    def slipped(self) -> list[int]:
        """Positions (in :attr:`indices`) of the points where some gap exceeds the threshold."""
        return [k for k, s in enumerate(self.slip_angstrom) if np.any(s > self.threshold_angstrom)]

    def to_json(self) -> dict:
        """``scan.json["layer_slip"]``: the gaps, their largest slip, the threshold and the
        slipped points (at most :data:`MAX_LISTED_POINTS`, with their count)."""
        worst = self.max_by_gap()
        slipped = self.slipped()
        listed = sorted(slipped, key=lambda k: -float(np.max(self.slip_angstrom[k])))
        return {
            "threshold_angstrom": self.threshold_angstrom,
            "points_checked": len(self.indices),
            "gaps": [
                {
                    "slab": g.slab,
                    "lower_layer": g.lower,
                    "upper_layer": g.upper,
                    "max_slip_angstrom": float(w),
                }
                for g, w in zip(self.gaps, worst, strict=True)
            ],
            "n_slipped_points": len(slipped),
            "slipped_points": [
                {
                    "index": list(self.indices[k]),
                    "shift": list(self.shifts[k]),
                    "thickness_angstrom": self.thicknesses[k],
                    "slip_angstrom": {
                        f"{g.lower}-{g.upper}": float(s)
                        for g, s in zip(self.gaps, self.slip_angstrom[k], strict=True)
                        if s > self.threshold_angstrom
                    },
                }
                for k in listed[:MAX_LISTED_POINTS]
            ],
        }


def in_slab_gaps(reference) -> tuple[Gap, ...]:
    """The in-slab gaps of an interface (``arrays["slab"]``, ``arrays["layer"]``), bottom up."""
    slab = np.asarray(reference.arrays["slab"])
    layer = np.asarray(reference.arrays["layer"])
    z = reference.positions[:, 2]
    gaps = []
    for s in np.unique(slab):
        layers = sorted(np.unique(layer[slab == s]), key=lambda k: float(z[layer == k].mean()))
        gaps += [Gap(int(s), int(a), int(b)) for a, b in itertools.pairwise(layers)]
    return tuple(gaps)


def layer_displacements(
    reference, positions: np.ndarray, shift: tuple[float, float]
) -> dict[int, np.ndarray]:
    """``D_L`` (Å, 2-vector) per layer of a relaxed point (module docstring)."""
    cell = reference.cell.array
    a1, a2 = cell[0, :2], cell[1, :2]
    placed = reference.positions[:, :2].copy()
    upper = np.asarray(reference.arrays["slab"]) == 2
    placed[upper] += shift[0] * a1 + shift[1] * a2
    lat = np.column_stack([a1, a2])
    frac = np.linalg.solve(lat, (np.asarray(positions)[:, :2] - placed).T).T
    frac -= np.round(frac)
    d = frac @ lat.T
    layer = np.asarray(reference.arrays["layer"])
    return {int(k): d[layer == k].mean(axis=0) for k in np.unique(layer)}


def slip_table(reference, points, threshold_angstrom: float = SLIP_THRESHOLD_ANGSTROM) -> SlipTable:
    """The slip of every in-slab gap at every point.

    Parameters
    ----------
    reference
        The reference interface (ASE Atoms with ``slab`` and ``layer`` arrays).
    points
        Iterable of ``(index, (shift_a, shift_b), thickness, positions)``: the relaxed
        points (:func:`store_points`).
    threshold_angstrom
        Slip above which a point is listed (Å).
    """
    gaps = in_slab_gaps(reference)
    table = SlipTable(gaps, threshold_angstrom=float(threshold_angstrom))
    for index, shift, thickness, positions in points:
        disp = layer_displacements(reference, positions, shift)
        table.indices.append(tuple(int(i) for i in index))
        table.shifts.append((float(shift[0]), float(shift[1])))
        table.thicknesses.append(float(thickness))
        table.slip_angstrom.append(
            np.array([float(np.linalg.norm(disp[g.upper] - disp[g.lower])) for g in gaps])
        )
    return table


def store_points(path):
    """``(index, shift, thickness, positions)`` of every point of a closed point store
    (``points.db``, :mod:`flatcontact.ispes.store`), read only."""
    for row in stored_rows(path):
        yield (row.i_a, row.i_b, row.i_z), (row.shift_a, row.shift_b), row.thickness, row.positions
