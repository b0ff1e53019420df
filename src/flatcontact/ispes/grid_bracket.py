"""Whether the scanned grid itself brackets the requested loads, and what to add if not.

The thicknesses of a pressure-range grid are chosen from a few probed columns
(:mod:`flatcontact.ispes.thicknesses`); the grid's own relaxed points differ from the
probe's (other warm starts, other stackings), so a column can end a few MPa short of
P = 0 (Au(111) with ``Au_u3.eam``: 4.3 MPa). This module reads every column of the grid
the way the analysis does (:mod:`flatcontact.analysis.constant_pressure`): the load at
the nodes is ``p = -(1/A) dU/dz`` of the cubic spline of U(z) clamped at the end nodes
by the stored stress (``"energy"``), or the stored stress (``"stress"``); the repulsive
branch runs from the first node to the node of lowest p. A column brackets the loads
when, for both load sources, its branch falls strictly, its first node is at or above
the loads the analysis reads (HI when the scan does not know them) and its lowest node is
at or below ``min(0, LO)`` (and those loads) or is an interior node (the
column's tensile maximum lies inside the data: loads below it are not carried).
Loads in GPa (> 0 pressed), thicknesses in Å, energies in eV.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np
from scipy.interpolate import CubicSpline

from flatcontact.foundation.units import EV_PER_A3_TO_GPA
from flatcontact.ispes.thicknesses import MIN_THICKNESS_SPACING_ANGSTROM, LoadFold

#: Grid extensions a scan makes at most before it names the columns still short.
MAX_EXTENSIONS = 3
#: A new largest thickness is placed where the short column's load, extrapolated
#: linearly from its last node, is this fraction of one requested load step (HI - LO)/(N - 1)
#: below the target (at least ``BRACKET_MARGIN_MIN_GPA``), so the relaxed point lands past it.
BRACKET_MARGIN_FRACTION = 0.1
BRACKET_MARGIN_MIN_GPA = 0.02
#: The shortest step to a new thickness: the minimum spacing, rounded up so that the
#: difference of the two floats is not below it.
MIN_STEP = MIN_THICKNESS_SPACING_ANGSTROM * (1 + 1e-9)


def node_loads_gpa(
    z: np.ndarray, energy_ev: np.ndarray, stress_gpa: np.ndarray, area_angstrom2: float
) -> np.ndarray:
    """``-(1/A) dU/dz`` (GPa) at the nodes of the cubic spline of each column's U(z),
    clamped at the first and last node by the stored stress (the analysis's ``"energy"``
    load). ``energy_ev`` and ``stress_gpa`` have shape ``(n_col, n_z)``."""
    e = np.atleast_2d(np.asarray(energy_ev, dtype=float)) / area_angstrom2
    p = np.atleast_2d(np.asarray(stress_gpa, dtype=float)) / EV_PER_A3_TO_GPA
    spline = CubicSpline(z, e.T, axis=0, bc_type=((1, -p[:, 0]), (1, -p[:, -1])))
    return -spline(z, 1).T * EV_PER_A3_TO_GPA


@dataclasses.dataclass(frozen=True)
class GridBracket:
    """The verdict on a grid: ``z_above`` (``z_below``) a thickness (Å) to add beyond the
    largest (below the smallest), or None; ``folds`` columns whose load rises with z on
    the branch; ``short`` one line per column whose first node is below HI (what to say
    if no thickness below can be added)."""

    z_above: float | None
    z_below: float | None
    folds: list[LoadFold]
    short: list[str]


def bracket_margin_gpa(lo_gpa: float, hi_gpa: float, n: int) -> float:
    """How far past a short column's target load a new thickness is aimed (GPa)."""
    return max(BRACKET_MARGIN_FRACTION * (hi_gpa - lo_gpa) / max(n - 1, 1), BRACKET_MARGIN_MIN_GPA)


def bracket_targets_gpa(
    p_range_gpa: tuple[float, float, int],
    loads_gpa: Sequence[float] | None = None,
    tension_gpa: float | None = None,
) -> tuple[float, float]:
    """``(low, high)`` (GPa) the grid's columns must reach: ``min(0, LO, loads)`` and
    ``max(loads)``, or HI without ``loads_gpa`` (the loads the analysis will read, when the
    scan knows them: ``flatcontact run`` passes ``analysis.p_gpa``). ``tension_gpa``: the
    maximum tension the thickness choice raised LO to (LO below it); loads at or below it
    cannot be carried and are left out of ``low`` (P = 0 always stays)."""
    lo, hi, _ = p_range_gpa
    loads = list(loads_gpa) if loads_gpa is not None and len(loads_gpa) else []
    low = [v for v in (0.0, lo, *loads) if tension_gpa is None or v > tension_gpa]
    return min(low), (max(loads) if loads else hi)


def check_grid(
    z: np.ndarray,
    energy_ev: np.ndarray,
    stress_gpa: np.ndarray,
    area_angstrom2: float,
    shifts: list[tuple[float, float]],
    p_range_gpa: tuple[float, float, int],
    loads_gpa: Sequence[float] | None = None,
    tension_gpa: float | None = None,
) -> GridBracket:
    """Check every column of a finished grid against P = 0 and ``p_range_gpa`` (LO, HI, N).

    The targets are :func:`bracket_targets_gpa` (``loads_gpa``: the loads the analysis
    reads, if known; ``tension_gpa``: the tension LO was raised to, if it was). ``z`` ascending (Å); ``energy_ev``, ``stress_gpa`` of shape ``(n_col, n_z)`` in the
    order of ``shifts`` (fractional lateral shifts, for the names). A column whose lowest
    node is its last and lies above the low target asks for a thickness beyond the largest,
    where its load extrapolated from its last node's slope is a margin
    (:func:`bracket_margin_gpa`) below that target; ``z_above`` is the farthest of those,
    at least ``MIN_THICKNESS_SPACING_ANGSTROM`` beyond the largest thickness (and at
    most the whole range). A column whose first node is below the high target asks, the
    same way along its first slope, for ``z_below`` a margin above it (named in ``short``). A rise on the
    branch is a :class:`LoadFold` (the requested ``linspace(LO, HI, N)`` above the node
    where the tensile side begins are refused).
    """
    lo, hi, n = p_range_gpa
    z = np.asarray(z, dtype=float)
    requested = np.linspace(lo, hi, n)
    target, top = bracket_targets_gpa(p_range_gpa, loads_gpa, tension_gpa)
    margin = bracket_margin_gpa(lo, hi, n)
    stress = np.atleast_2d(np.asarray(stress_gpa, dtype=float))
    sources = {
        "-(1/A) dU/dz": node_loads_gpa(z, energy_ev, stress, area_angstrom2),
        "normal_stress": stress,
    }
    z_above, z_below, folds, short, folded = None, None, [], [], set()
    for j, (a, b) in enumerate(shifts):
        name = f"grid column at shift ({a:.4g}, {b:.4g})"
        for what, loads in sources.items():
            p = loads[j]
            m = int(np.argmin(p))
            rises = np.flatnonzero(np.diff(p[: m + 1]) >= 0)
            if rises.size and j not in folded:
                k = int(rises[0])
                refused = tuple(float(v) for v in requested if v > p[k + 1])
                folds.append(LoadFold(f"{name} ({what})", z[k + 1], p[k + 1], z[k], p[k], refused))
                folded.add(j)
            if p[0] < top:
                short.append(
                    f"p-range-gpa: the {name} reaches only {p[0]:.4g} GPa ({what}) at the "
                    f"smallest thickness z = {z[0]:.4g} Å, below {top:g} GPa; give "
                    "scan.thickness_angstrom below it or lower scan.p_range_gpa.hi_gpa"
                )
                slope = (p[1] - p[0]) / (z[1] - z[0]) if z.size > 1 else -1.0
                step = ((top + margin) - p[0]) / -slope if slope < 0 else np.inf
                step = min(max(step, MIN_STEP), float(np.ptp(z)) or 1.0)
                want = float(z[0] - step)
                z_below = want if z_below is None else min(z_below, want)
            if m == z.size - 1 and p[m] > target:
                slope = (p[-1] - p[-2]) / (z[-1] - z[-2]) if z.size > 1 else -1.0
                step = (p[m] - (target - margin)) / -slope if slope < 0 else np.inf
                step = min(max(step, MIN_STEP), float(np.ptp(z)) or 1.0)
                want = float(z[-1] + step)
                z_above = want if z_above is None else max(z_above, want)
    return GridBracket(z_above, z_below, folds, short)
