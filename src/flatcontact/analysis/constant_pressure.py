"""Constant-pressure ISPES: from columns U(z), p(z) to the lateral landscape at a fixed load.

For each lateral point (a *column* of the grid) the paper links ``U(z)`` and
``p(z)`` at the same thickness ``z`` into the 1-D relation ``Ũ(p)`` and reads it
at the target loads ``P`` (paper, "Interfacial sliding potential energy surface",
Eq. for ``Ũ(p)|_{X,Y}``). Here:

- ``U(z)`` and ``p(z)`` are interpolated with not-a-knot cubic splines
  (fourth-order accurate) on the column's thickness values;
- ``z*(P)`` is the root of ``p(z) = P`` on the *repulsive branch*: from the
  smallest thickness up to the sample of lowest ``p`` (the maximum tension). On
  this branch ``p`` must decrease strictly with ``z``; it is the mechanically
  stable branch under a fixed load, since ``d²(U + P A z)/dz² = -A dp/dz > 0``.
  Where ``p`` rises with ``z`` on the compressed side (a *fold*: a plane slips or
  opens under load), the branch is the falling run that carries ``P = 0`` (the
  scan's rule, :func:`~flatcontact.ispes.contract.branch_run`), splined on its own nodes; loads that the
  compressed side also reaches, or that fall in the segment next to the fold, are
  refused in one line; lower loads are read with a :class:`LoadFoldWarning`.
  Beyond the maximum tension lies the *adhesive tail* (``p`` rises back towards
  0): ``p(z)`` is not invertible there, it is reported and never used;
- a ``P`` outside ``[p_min, p_max]`` of a column's branch is an error naming the
  column and its range: nothing is extrapolated.

Energies are per area of the cell. Two forms are offered:

- ``"internal"`` (the paper's, default): ``ẽ(x, y)|_P = U(z*)/A``;
- ``"enthalpy"``: ``h(x, y)|_P = U(z*)/A + P z*``. By the envelope theorem
  ``∇h|_P = ∇U|_z``: its gradient is the lateral force at constant load,
  including the work done against the load when the gap ``z*`` changes with
  the lateral position. The internal form omits that work (``∇ẽ = ∇U|_z - P∇z*``).

Units: thickness Å, energy eV, stress eV/Å³ inside; pressures in and out of the
public wrapper in GPa (the contract's unit).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
import xarray as xr
from scipy.interpolate import CubicSpline, make_interp_spline

from flatcontact.analysis.diagnostics import (
    LoadFoldWarning,
    StressEnergyMismatchWarning,
    UnconvergedPointsWarning,
)
from flatcontact.analysis.noise import LoadNoise, load_noise
from flatcontact.foundation import units
from flatcontact.foundation.errors import InputError
from flatcontact.ispes import contract

FORMS = ("internal", "enthalpy")
#: Where the load comes from: ``-(1/A) dU/dz`` of the energy spline, or the stored stress.
LOAD_SOURCES = ("energy", "stress")
DEFAULT_LOAD_SOURCE = "energy"
#: Minimum number of thickness values per column (cubic splines, not-a-knot).
MIN_THICKNESS_POINTS = 4
#: Relative stress/energy mismatch (of the column's p range) above which we warn.
MISMATCH_WARN = 0.05
_BISECTION_STEPS = 64


@dataclass(frozen=True)
class ColumnInversion:
    """Result of :func:`invert_columns` for ``n_col`` columns and ``n_p`` loads."""

    thickness_angstrom: np.ndarray  #: z*(P), shape (n_p, n_col)
    energy_ev_per_a2: np.ndarray  #: U(z*)/A, shape (n_p, n_col)
    branch_p_range_ev_per_a3: np.ndarray  #: (n_col, 2): lowest and highest p on the branch
    tail_start_angstrom: np.ndarray  #: (n_col,) z where the branch ends if a tail follows, else NaN
    mismatch: np.ndarray  #: (n_col,) max |p + (1/A)dU/dz| on the branch nodes / p range
    slope_ev_per_a4: np.ndarray  #: dp/dz at z*(P) of the load used, shape (n_p, n_col)
    mismatch_sq_sum: np.ndarray  #: (n_col,) Σ (p + (1/A)dU/dz)² over the interior branch nodes
    derivative_spread_sq_sum: np.ndarray  #: (n_col,) Σ (U'_cubic - U'_quintic)²/A² (NaN if n_z < 6)
    n_branch_nodes: np.ndarray  #: (n_col,) interior branch nodes in those sums (all if n_z < 6)


def invert_columns(
    z: np.ndarray,
    energy_ev_per_a2: np.ndarray,
    stress_ev_per_a3: np.ndarray,
    p_ev_per_a3: np.ndarray,
    labels: list[str] | None = None,
    load_source: str = DEFAULT_LOAD_SOURCE,
) -> ColumnInversion:
    """Energy per area at fixed loads for columns sharing the thickness values ``z``.

    Parameters
    ----------
    z
        Thickness values (Å), strictly increasing, shape ``(n_z,)``, ``n_z >= 4``.
    energy_ev_per_a2
        ``U/A`` per column, shape ``(n_col, n_z)``, finite.
    stress_ev_per_a3
        Normal stress per column (positive when pressed), shape ``(n_col, n_z)``.
    p_ev_per_a3
        Target loads ``P`` (eV/Å³), shape ``(n_p,)``.
    labels
        Names of the columns for error messages.
    load_source
        ``"energy"``: the load is ``p(z) = -(1/A) dU/dz`` of the cubic spline of
        ``U(z)``, clamped at the first and last thickness by the stored stress;
        ``"stress"``: the stored ``normal_stress``, splined. Either way the repulsive branch
        runs up to the node of lowest ``p``; where that load folds on the compressed side,
        the column is splined past the fold only (:func:`~flatcontact.ispes.contract.branch_run`).

    Raises
    ------
    InputError
        Non-monotonic repulsive branch, or a ``P`` outside a column's branch.
    """
    if load_source not in LOAD_SOURCES:
        raise InputError(f"load source: expected one of {LOAD_SOURCES}, got {load_source!r}")
    z = np.asarray(z, dtype=float)
    e = np.atleast_2d(np.asarray(energy_ev_per_a2, dtype=float))
    p = np.atleast_2d(np.asarray(stress_ev_per_a3, dtype=float))
    targets = np.atleast_1d(np.asarray(p_ev_per_a3, dtype=float))
    n_col, n_z = p.shape
    labels = labels or [f"column {j}" for j in range(n_col)]
    if n_z < MIN_THICKNESS_POINTS:
        raise InputError(
            f"{labels[0]}: {n_z} thickness values; at least {MIN_THICKNESS_POINTS} are needed "
            "for the cubic splines of U(z) and p(z)"
        )
    if not np.all(np.diff(z) > 0):
        raise InputError("thickness: values must be strictly increasing")
    # with the stored stress as the load, its folds split the columns before any spline runs
    # through them; the energy-derived load's own folds are found on it below (the stored
    # stress is noisier than the energy's derivative: with 43 thicknesses over 5.5 GPa the
    # 12x12 quartz grid's stress rose between neighbours in 72 columns, its energy load in 1)
    stored_start = np.zeros(n_col, int)
    if load_source == "stress":
        stored_start, _ = _branch(z, p, labels, "normal_stress")
    if np.any(stored_start > 0):
        _above_a_fold(targets, p, stored_start, z, labels, "normal_stress", "")
        _warn_fold(labels, p, stored_start, z, "normal_stress")
        base = None
        if np.any(stored_start == 0):
            keep = stored_start == 0
            base = (
                keep,
                invert_columns(z, e[keep], p[keep], targets, _pick(labels, keep), load_source),
            )
        return _past_the_folds(base, stored_start, z, e, p, targets, labels, load_source)
    if load_source == "energy":
        # clamped at the two end nodes by the stored stress (dU/dz = -A p): the energies
        # alone cannot fix a spline's end slopes, and not-a-knot ends put p wrong by tenths
        # of a GPa at a widely spaced last node (the maximum tension of a coarse scan)
        spline_e = CubicSpline(z, e.T, axis=0, bc_type=((1, -p[:, 0]), (1, -p[:, -1])))
    else:
        spline_e = CubicSpline(z, e.T, axis=0)
    dedz = spline_e(z, 1).T  # (n_col, n_z)
    if load_source == "energy":
        inv = _invert_energy(z, spline_e, targets, labels)
    else:
        inv = _invert_stress(z, p, spline_e, targets, labels)
    zstar, estar, p_lo, p_hi, z_end, slope, start = inv

    # diagnostics: tail and stress/energy consistency on the branch nodes
    last = z_end < z[-1]
    tail = np.where(last, z_end, np.nan)
    span = np.maximum(p_hi - p_lo, np.finfo(float).tiny)
    node_ok = z[None, :] <= z_end[:, None] * (1 + 1e-12)
    diff = np.where(node_ok, p + dedz, 0.0)
    mismatch = np.max(np.abs(diff), axis=1) / span
    # rms estimates on the interior branch nodes: the end derivatives of a spline are its
    # least accurate values and would measure the interpolant, not the data
    inner = node_ok.copy()
    inner[:, [0, -1]] = n_z < 6
    if n_z >= 6:
        quintic = make_interp_spline(z, e.T, k=5, axis=0).derivative()(z).T
        spread = np.sum(np.where(inner, dedz - quintic, 0.0) ** 2, axis=1)
    else:
        spread = np.full(n_col, np.nan)
    result = ColumnInversion(
        thickness_angstrom=zstar,
        energy_ev_per_a2=estar,
        branch_p_range_ev_per_a3=np.column_stack([p_lo, p_hi]),
        tail_start_angstrom=tail,
        mismatch=mismatch,
        slope_ev_per_a4=slope,
        mismatch_sq_sum=np.sum(np.where(inner, diff, 0.0) ** 2, axis=1),
        derivative_spread_sq_sum=spread,
        n_branch_nodes=np.sum(inner, axis=1),
    )
    if np.any(start > 0):
        return _past_the_folds(
            (np.ones(n_col, bool), result), start, z, e, p, targets, labels, load_source
        )
    return result


#: The fields of :class:`ColumnInversion` shaped ``(n_p, n_col)`` (the others lead with ``n_col``).
_PER_LOAD_FIELDS = ("thickness_angstrom", "energy_ev_per_a2", "slope_ev_per_a4")


def _pick(labels: list[str], mask: np.ndarray) -> list[str]:
    return [lab for lab, c in zip(labels, mask, strict=True) if c]


def _past_the_folds(base, start, z, e, p, targets, labels, load_source) -> ColumnInversion:
    """The columns inverted again on the nodes past their fold (``start > 0``) only, so the
    splines of the branch that carries P = 0 do not run through the fold (a cubic spline
    couples every node; the fold's jump would bend the segments next to it), laid over
    ``base`` = ``(mask, result for those columns)`` or None."""
    n_col = start.size
    parts = [] if base is None else [base]
    for s in np.unique(start[start > 0]):
        s, cols = int(s), start == s
        if z.size - s < MIN_THICKNESS_POINTS:
            j = int(np.flatnonzero(cols)[0])
            raise InputError(
                f"{labels[j]}: {z.size - s} thickness values past its fold at z = {z[s]:.4g} Å; "
                f"at least {MIN_THICKNESS_POINTS} are needed for the splines of the branch that "
                "carries P = 0: extend the scan in thickness or hold the slabs' inner planes "
                "laterally (scan.relax_mode: normal)"
            )
        try:
            sub = invert_columns(
                z[s:], e[cols, s:], p[cols, s:], targets, _pick(labels, cols), load_source
            )
        except InputError as exc:
            raise InputError(f"past the fold at z = {z[s]:.4g} Å: {exc}") from None
        parts.append((cols, sub))
    fields = {}
    for name in ColumnInversion.__dataclass_fields__:
        first = np.asarray(getattr(parts[0][1], name))
        shape = (targets.size, n_col) if name in _PER_LOAD_FIELDS else (n_col, *first.shape[1:])
        full = np.empty(shape, first.dtype)
        for cols, part in parts:
            if name in _PER_LOAD_FIELDS:
                full[:, cols] = np.asarray(getattr(part, name))
            else:
                full[cols] = np.asarray(getattr(part, name))
        fields[name] = full
    return ColumnInversion(**fields)


def _warn_fold(labels, p_nodes, start, z, what) -> None:
    folded = np.flatnonzero(start > 0)
    j = int(folded[0])
    more = f" and {folded.size - 1} more column(s)" if folded.size > 1 else ""
    gpa = units.EV_PER_A3_TO_GPA
    warnings.warn(
        f"{labels[j]}{more}: {what} folds on the compressed side (p = "
        f"{p_nodes[j, start[j] - 1] * gpa:.4g} GPa at z = {z[start[j] - 1]:.4g} Å rises to "
        f"{p_nodes[j, start[j]] * gpa:.4g} GPa at z = {z[start[j]]:.4g} Å); every load asked lies "
        "below the fold and is read on the branch that carries P = 0, splined without the "
        "nodes before it",
        LoadFoldWarning,
        stacklevel=5,
    )


def _out_of_range(targets, p_lo, p_hi, z, z_end, labels) -> None:
    outside = (targets[:, None] < p_lo[None, :]) | (targets[:, None] > p_hi[None, :])
    if np.any(outside):
        i, j = (int(v) for v in np.argwhere(outside)[0])
        raise InputError(
            f"P = {targets[i] * units.EV_PER_A3_TO_GPA:.4g} GPa is outside the data of {labels[j]}: "
            f"its repulsive branch spans p = {p_lo[j] * units.EV_PER_A3_TO_GPA:.4g} .. "
            f"{p_hi[j] * units.EV_PER_A3_TO_GPA:.4g} GPa (thickness {z[0]:.4g} .. {z_end[j]:.4g} Å); "
            "extend the scan in thickness or choose P inside that range"
        )


def _above_a_fold(targets, p_nodes, start, z, labels, what, remedy) -> None:
    """InputError unless every load asked lies below each folded column's ceiling.

    The ceiling is the lowest of the nodes before the fold ``s`` and of node ``s + 1``: at or
    above ``min(p[:s])`` a load is also reached on the compressed side (two thicknesses), and
    the segment ``s .. s + 1`` next to the jump is not read (its first node is the fold's own
    sample, whatever made it: a plane that slipped or a bad value; the fold may also be noise
    of the load: ``remedy``)."""
    for j in np.flatnonzero(start > 0):
        s = int(start[j])
        ceiling = float(min(np.min(p_nodes[j, :s]), p_nodes[j, s + 1]))
        if np.max(targets) >= ceiling:
            gpa = units.EV_PER_A3_TO_GPA
            raise InputError(
                f"P = {np.max(targets) * gpa:.4g} GPa is at or above a fold of {labels[j]}: "
                f"{what} = {p_nodes[j, s - 1] * gpa:.4g} GPa at z = {z[s - 1]:.4g} Å rises to "
                f"{p_nodes[j, s] * gpa:.4g} GPa at z = {z[s]:.4g} Å; loads from "
                f"{ceiling * gpa:.4g} GPa up are not read past it (reached on both sides of "
                "it, or next to it): choose loads below that (analysis.p_gpa)" + remedy
            )


#: The remedy named when the energy-derived load is not monotonic: its error is second
#: order in the relaxation residuals but grows with the number of soft modes (thick,
#: compliant slabs), so a tighter force tolerance or the first-order stored load fixes it.
_ENERGY_LOAD_HINT = (
    "; the energies are not converged enough for their derivative: tighten "
    "scan.fmax_ev_per_angstrom or use analysis.load_source: stress"
)


def _branch(z, p, labels, what, remedy=""):
    """``(s, e)`` per column: the branch that carries P = 0 runs from node ``s`` to node ``e``
    (:func:`~flatcontact.ispes.contract.branch_run`, the scan's rule); InputError if the load
    rises from the first node, or if the branch has no segment (``p`` rises where it crosses
    0; ``remedy`` appended)."""
    n_col = p.shape[0]
    start = np.zeros(n_col, int)
    end = np.zeros(n_col, int)
    for j in range(n_col):
        start[j], end[j] = contract.branch_run(p[j])
    m_all = np.argmin(p, axis=1)
    if np.any(m_all == 0):
        j = int(np.flatnonzero(m_all == 0)[0])
        raise InputError(
            f"{labels[j]}: {what} rises with thickness from the first point "
            f"(p = {p[j, 0] * units.EV_PER_A3_TO_GPA:.4g} GPa at z = {z[0]:.4g} Å); "
            "no repulsive branch to invert"
        )
    bad = end - start < 1
    if np.any(bad):
        j = int(np.flatnonzero(bad)[0])
        k = max(int(start[j]) - 1, 0)
        raise InputError(
            f"{labels[j]}: {what} is not monotonic on the repulsive branch: "
            f"p = {p[j, k] * units.EV_PER_A3_TO_GPA:.4g} GPa at z = {z[k]:.4g} Å, "
            f"{p[j, k + 1] * units.EV_PER_A3_TO_GPA:.4g} GPa at z = {z[k + 1]:.4g} Å "
            "(expected p to decrease with thickness up to the maximum tension)" + remedy
        )
    return start, end


def _invert(z, p_nodes, coef_p, spline_e, targets, labels, what, remedy=""):
    """z*(P) on the repulsive branch of a load given at the nodes and as a piecewise cubic.

    The branch runs from the first node to the node ``m`` of lowest ``p`` (the
    maximum tension); on it the nodes must decrease strictly. ``z*`` lies in the
    segment whose end nodes bracket ``P`` and is found there by bisection of the
    piecewise polynomial ``coef_p`` (shape ``(4, n_z - 1, n_col)``, in ``z - z_k``).
    Returns ``(z*, U(z*)/A, p_lo, p_hi, z_m, dp/dz at z*, s)`` (``s``: each column's first
    branch node, > 0 past a fold).
    """
    n_col, n_z = p_nodes.shape
    start, m = _branch(z, p_nodes, labels, what, remedy)
    cols1 = np.arange(n_col)
    p_lo = p_nodes[cols1, m]
    p_hi = p_nodes[cols1, start]
    _above_a_fold(targets, p_nodes, start, z, labels, what, remedy)
    _out_of_range(targets, p_lo, p_hi, z, z[m], labels)
    if np.any(start > 0):
        _warn_fold(labels, p_nodes, start, z, what)
    # segment k with p_k >= P >= p_{k+1}, start <= k < m  (p strictly decreasing there)
    idx = np.arange(n_z)[None, None, :]
    on_branch = (idx >= start[None, :, None]) & (idx <= m[None, :, None])
    count = np.sum((p_nodes[None, :, :] >= targets[:, None, None]) & on_branch, axis=2)
    k = np.clip(start[None, :] + count - 1, start[None, :], np.maximum(m - 1, start)[None, :])
    cols = np.broadcast_to(np.arange(n_col), k.shape)
    coef = coef_p[:, k, cols]  # (4, n_p, n_col), polynomial in (zz - z_k)
    lo = np.zeros(k.shape)
    hi = z[k + 1] - z[k]
    rhs = targets[:, None]
    for _ in range(_BISECTION_STEPS):
        mid = 0.5 * (lo + hi)
        val = ((coef[0] * mid + coef[1]) * mid + coef[2]) * mid + coef[3] - rhs
        above = val > 0  # p still above P: root lies further out
        lo = np.where(above, mid, lo)
        hi = np.where(above, hi, mid)
    dz = 0.5 * (lo + hi)
    ce = spline_e.c[:, k, cols]
    e_star = ((ce[0] * dz + ce[1]) * dz + ce[2]) * dz + ce[3]
    slope = (3 * coef[0] * dz + 2 * coef[1]) * dz + coef[2]
    return z[k] + dz, e_star, p_lo, p_hi, z[m], slope, start


def _invert_stress(z, p, spline_e, targets, labels):
    """Load = the stored stress, splined (not-a-knot cubic)."""
    coef = CubicSpline(z, p.T, axis=0).c
    return _invert(z, p, coef, spline_e, targets, labels, "normal_stress")


def _invert_energy(z, spline_e, targets, labels):
    """Load = -(1/A) dU/dz of the cubic spline of U: a piecewise quadratic."""
    c = spline_e.c  # U/A = c0 x³ + c1 x² + c2 x + c3
    coef = np.stack([np.zeros_like(c[0]), -3 * c[0], -2 * c[1], -c[2]])
    p_nodes = -spline_e(z, 1).T
    return _invert(z, p_nodes, coef, spline_e, targets, labels, "-(1/A) dU/dz", _ENERGY_LOAD_HINT)


@dataclass(frozen=True)
class ConstantPressureISPES:
    """Constant-pressure landscapes on the lateral grid of an ISPES file.

    Arrays are indexed ``[pressure, shift_a, shift_b]``; energies are per area of
    the cell in eV/Å² and keep the file's energy constant (set the zero later).
    """

    p_gpa: np.ndarray
    form: str
    shift_a: np.ndarray
    shift_b: np.ndarray
    a1: np.ndarray
    a2: np.ndarray
    area_angstrom2: float
    energy_ev_per_a2: np.ndarray  #: the chosen form (internal or enthalpy)
    internal_ev_per_a2: np.ndarray  #: U(z*)/A
    thickness_angstrom: np.ndarray  #: z*
    branch_p_range_gpa: np.ndarray  #: (n_a, n_b, 2) invertible load range per column
    tail_start_angstrom: np.ndarray  #: (n_a, n_b), NaN where no adhesive tail is in the data
    stress_energy_mismatch: float  #: max over columns, relative to each column's p range
    load_source: str = DEFAULT_LOAD_SOURCE  #: "energy" or "stress"
    noise: LoadNoise | None = None  #: per-load noise estimate (:mod:`.noise`)

    @property
    def common_p_range_gpa(self) -> tuple[float, float]:
        """Loads that every column can be read at."""
        r = self.branch_p_range_gpa
        return float(np.max(r[..., 0])), float(np.min(r[..., 1]))


def _missing_message(ds: xr.Dataset, bad: np.ndarray, source: str) -> str:
    where = np.argwhere(bad)
    shown = ", ".join(
        f"(shift_a={ds[contract.DIM_A].values[i]:.4g}, shift_b={ds[contract.DIM_B].values[j]:.4g}, "
        f"thickness={ds[contract.DIM_Z].values[k]:.4g} Å)"
        for i, j, k in where[:3]
    )
    more = f" and {len(where) - 3} more" if len(where) > 3 else ""
    return (
        f"{source}: {len(where)} grid points are missing (NaN energy or normal_stress): "
        f"{shown}{more}; finish the scan or allow missing points (allow_missing)"
    )


def _invert_grid(
    z: np.ndarray,
    e_cols: np.ndarray,
    p_cols: np.ndarray,
    fin_cols: np.ndarray,
    targets: np.ndarray,
    labels: list[str],
    load_source: str,
) -> tuple[np.ndarray, ...]:
    """Every column inverted at the loads ``targets`` (eV/Å³): the complete columns together,
    each one with missing points through its remaining points (at least
    :data:`MIN_THICKNESS_POINTS`). Returns, column-wise, z*, the energy there, the branch's load
    range, the tail start, the stress-energy mismatch, dp/dz at z* and the sums behind the
    noise estimates (mismatch Σ², derivative-spread Σ², branch node count)."""
    n_col, n_z = e_cols.shape
    zstar = np.empty((targets.size, n_col))
    estar = np.empty((targets.size, n_col))
    prange = np.empty((n_col, 2))
    tail = np.empty(n_col)
    mismatch = np.empty(n_col)
    slope = np.empty((targets.size, n_col))
    sq = np.empty((3, n_col))

    def store(sel: np.ndarray, res: ColumnInversion) -> None:
        zstar[:, sel] = res.thickness_angstrom
        estar[:, sel] = res.energy_ev_per_a2
        prange[sel] = res.branch_p_range_ev_per_a3
        tail[sel] = res.tail_start_angstrom
        mismatch[sel] = res.mismatch
        slope[:, sel] = res.slope_ev_per_a4
        sq[:, sel] = [res.mismatch_sq_sum, res.derivative_spread_sq_sum, res.n_branch_nodes]

    full = np.all(fin_cols, axis=1)
    if np.any(full):
        sel = np.flatnonzero(full)
        store(
            sel,
            invert_columns(
                z, e_cols[sel], p_cols[sel], targets, [labels[j] for j in sel], load_source
            ),
        )
    for j in np.flatnonzero(~full):
        keep = fin_cols[j]
        if keep.sum() < MIN_THICKNESS_POINTS:
            raise InputError(
                f"{labels[j]}: only {int(keep.sum())} of {n_z} thickness points are present; "
                f"at least {MIN_THICKNESS_POINTS} are needed"
            )
        store(
            np.array([j]),
            invert_columns(
                z[keep], e_cols[j, keep], p_cols[j, keep], targets, [labels[j]], load_source
            ),
        )
    return zstar, estar, prange, tail, mismatch, slope, sq


def constant_pressure(
    ds: xr.Dataset,
    p_gpa: np.ndarray | list[float],
    form: str = "internal",
    allow_missing: bool = False,
    source: str = "ISPES grid",
    load_source: str = DEFAULT_LOAD_SOURCE,
) -> ConstantPressureISPES:
    """Constant-pressure ISPES of a contract grid at the loads ``p_gpa`` (GPa).

    Parameters
    ----------
    ds
        Grid following :mod:`flatcontact.ispes.contract` (validated here).
    p_gpa
        Target loads (GPa), positive when pressed.
    form
        ``"internal"`` (paper, default) or ``"enthalpy"``.
    allow_missing
        If true, a column with missing (NaN) thickness points is interpolated
        through its remaining points (at least 4); otherwise missing points are
        an error listing them.
    source
        Name of the grid in messages (usually the file name).
    load_source
        ``"energy"``: the load is ``-(1/A) dU/dz`` of the energy spline;
        ``"stress"``: the stored ``normal_stress`` (see :func:`invert_columns`).
    """
    if form not in FORMS:
        raise InputError(f"energy form: expected one of {FORMS}, got {form!r}")
    if load_source not in LOAD_SOURCES:
        raise InputError(f"load source: expected one of {LOAD_SOURCES}, got {load_source!r}")
    targets_gpa = np.atleast_1d(np.asarray(p_gpa, dtype=float))
    if targets_gpa.size == 0 or not np.all(np.isfinite(targets_gpa)):
        raise InputError(f"p_gpa: expected finite pressures in GPa, got {targets_gpa.tolist()}")
    ds = contract.validate_ispes(ds, source=source)
    energy = ds[contract.VAR_ENERGY].values.astype(float)
    stress = ds[contract.VAR_STRESS].values.astype(float)
    z = ds[contract.DIM_Z].values.astype(float)
    area = float(ds.attrs["area"])
    n_a, n_b, n_z = energy.shape
    finite = np.isfinite(energy) & np.isfinite(stress)
    if not np.all(finite) and not allow_missing:
        raise InputError(_missing_message(ds, ~finite, source))
    converged = ds[contract.VAR_CONVERGED].values.astype(bool)
    unconverged = finite & ~converged
    if np.any(unconverged):
        warnings.warn(
            f"{source}: {int(unconverged.sum())} finite grid points are marked converged=False "
            "and are used as they are",
            UnconvergedPointsWarning,
            stacklevel=2,
        )
    targets = targets_gpa / units.EV_PER_A3_TO_GPA
    e_cols = (energy / area).reshape(n_a * n_b, n_z)
    p_cols = (stress / units.EV_PER_A3_TO_GPA).reshape(n_a * n_b, n_z)
    fin_cols = finite.reshape(n_a * n_b, n_z)
    sa, sb = ds[contract.DIM_A].values, ds[contract.DIM_B].values
    labels = [
        f"{source} column (shift_a={sa[i]:.4g}, shift_b={sb[j]:.4g})"
        for i in range(n_a)
        for j in range(n_b)
    ]
    zstar, estar, prange, tail, mismatch, slope, sq = _invert_grid(
        z, e_cols, p_cols, fin_cols, targets, labels, load_source
    )
    worst = float(np.max(mismatch))
    if worst > MISMATCH_WARN:
        j = int(np.argmax(mismatch))
        warnings.warn(
            f"{labels[j]}: normal_stress differs from -(1/A) dU/dz by {100 * worst:.1f}% of its "
            "range; energy and stress may come from different calculations",
            StressEnergyMismatchWarning,
            stacklevel=2,
        )
    gpa = units.EV_PER_A3_TO_GPA
    n_nodes = np.sum(sq[2])
    mismatch_rms = float(np.sqrt(np.sum(sq[0]) / n_nodes)) * gpa
    spread_rms = float(np.sqrt(np.sum(sq[1]) / n_nodes)) * gpa  # NaN if any column < 6 points
    a1 = np.asarray(ds.attrs["a1"], dtype=float).ravel()[:2]
    a2 = np.asarray(ds.attrs["a2"], dtype=float).ravel()[:2]
    spacing = min(np.linalg.norm(a1) / n_a, np.linalg.norm(a2) / n_b)
    noise = load_noise(
        targets_gpa,
        delta_p_gpa=spread_rms if load_source == "energy" else mismatch_rms,
        mismatch_rms_gpa=mismatch_rms,
        slope_gpa_per_angstrom=np.median(np.abs(slope), axis=1) * gpa,
        grid_spacing_angstrom=spacing,
        form=form,
        load_source=load_source,
    )
    internal = estar.reshape(targets.size, n_a, n_b)
    zmap = zstar.reshape(targets.size, n_a, n_b)
    chosen = internal + targets[:, None, None] * zmap if form == "enthalpy" else internal
    return ConstantPressureISPES(
        p_gpa=targets_gpa,
        form=form,
        shift_a=sa.astype(float),
        shift_b=sb.astype(float),
        a1=a1,
        a2=a2,
        area_angstrom2=area,
        energy_ev_per_a2=chosen,
        internal_ev_per_a2=internal,
        thickness_angstrom=zmap,
        branch_p_range_gpa=prange.reshape(n_a, n_b, 2) * units.EV_PER_A3_TO_GPA,
        tail_start_angstrom=tail.reshape(n_a, n_b),
        stress_energy_mismatch=worst,
        load_source=load_source,
        noise=noise,
    )
