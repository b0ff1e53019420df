"""Validity gates: what the scan and the analysis say about whether the load laws can be
trusted, checked before the contact stage takes them.

Each gate is a pure function of what the earlier stages wrote (plain dicts and arrays) and
returns the :class:`Finding` it fired with (one line: the cause, the points or loads, the
remedy) or nothing. :data:`GATES` names them; a user who insists lists the names in
``contact.accept_untrusted`` and the report then says, above the figures, which numbers are
not to be trusted and why.

``in_slab_slip``
    A plane inside a slab (not the interface) moved sideways against its neighbour by more
    than the scan's threshold (``scan.json["layer_slip"]``, :mod:`flatcontact.ispes.slip`):
    the slab slid inside itself, and the energies and loads are those of another sliding
    plane.
``broken_symmetry``
    The constant-pressure ISPES breaks an operation of the interface's shift-space group
    (the stage passes it from :func:`flatcontact.ispes.shift_symmetry.shift_space_group`,
    slab swaps included, as plain ``(M, t)``) by more than :data:`SYMMETRY_GATE_TOLERANCE`
    of the map's range at some load (:mod:`.operation_deviation`).
``load_fold``
    A column's load p(z) folds (not monotonic), so loads beyond the fold were refused
    (``scan.json["load_folds"]``, absent = none).
``negative_slope``
    k or μ is *significantly* negative: the whole interval c ± h_c of ``laws.json``
    (:mod:`.uncertainty`) lies below 0. A negative slope whose interval reaches 0 is used
    as fitted, with a note (:func:`negative_slope_notes`).
``degenerate_minima``
    The slider's rest position is not one minimum through the loads: the reported start
    jumps between loads to a minimum that no symmetry of the landscape relates to the
    previous one, or at one load inequivalent minima within the degeneracy tolerance give
    τ differing by more than :data:`DEGENERATE_TAU_SPREAD`. A jump is not counted when the
    previous rest site, relaxed on the new load's landscape, is itself one of that load's
    starts within the degeneracy tolerance and gives τ within :data:`DEGENERATE_TAU_SPREAD`
    of the reported one: the slider could rest at either, the analysis chose between them by
    a rule, and τ(P) is the same interface's whichever it took. Without that exception the
    gate was decided by differences inside the relaxation's tolerance (measured: the quick
    preset's two minima 0.25 Å either side of one site at 3 GPa, 0.0097 meV/Å² apart
    against a tolerance of 0.027, equal τ, fired it with one optimiser and not another).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from flatcontact.analysis.operation_deviation import operation_deviation
from flatcontact.analysis.periodic import PeriodicSurface
from flatcontact.analysis.symmetry import lattice_point_operations

#: The gates, in the order they are checked and reported.
GATES: tuple[str, ...] = (
    "in_slab_slip",
    "broken_symmetry",
    "load_fold",
    "negative_slope",
    "degenerate_minima",
)
#: An operation of the shift-space group that the constant-pressure ISPES breaks by more
#: than this fraction of the map's range (largest |E(g·s) − E(s)|, :mod:`.operation_deviation`)
#: fires ``broken_symmetry``. Measured (largest over operations and loads): toy LJ 3×3 full
#: relaxation 0.11 %; quartz quick preset (12×12, full, its slab-swapping two-fold axis,
#: P = 0 … 3.5 GPa) 0.9–3.5 %; scans reduced by symmetry (the examples) 1e-8 (filled by
#: the group, checked by the scan's verified points instead); 3 + 3 graphene sheets with
#: ``full`` relaxation (planes slipping at 24 of 180 points) 12.5–17.4 %, the largest
#: operation 15.9 % or more at every load.
SYMMETRY_GATE_TOLERANCE = 0.10
#: Two minima are the same site when closer than this fraction of the shortest lattice vector.
SAME_SITE_FRACTION = 0.05
#: Landscape operations relating two minima are kept below this deviation.
LANDSCAPE_SYMMETRY_TOLERANCE = 0.05
#: Inequivalent degenerate starts whose τ differ by more than this fraction of the largest
#: fire ``degenerate_minima``.
DEGENERATE_TAU_SPREAD = 0.05
#: At most this many points or loads are named in one line.
MAX_NAMED = 4


@dataclass(frozen=True)
class Finding:
    """A gate that fired: its name and one line (cause, points or loads, remedy)."""

    gate: str
    message: str


def _listed(items: Sequence[str], total: int | None = None) -> str:
    shown = ", ".join(items[:MAX_NAMED])
    more = (total if total is not None else len(items)) - min(len(items), MAX_NAMED)
    return shown + (f" and {more} more" if more > 0 else "")


def in_slab_slip(layer_slip: Mapping | None) -> Finding | None:
    """``in_slab_slip`` from ``scan.json["layer_slip"]`` (None: not measured, no finding)."""
    if not layer_slip or not layer_slip.get("n_slipped_points"):
        return None
    thr = float(layer_slip["threshold_angstrom"])
    gaps = [g for g in layer_slip["gaps"] if g["max_slip_angstrom"] > thr]
    planes = _listed(
        [
            f"layers {g['lower_layer']}-{g['upper_layer']} of slab {g['slab']} "
            f"(up to {g['max_slip_angstrom']:.2f} Å)"
            for g in gaps
        ]
    )
    points = _listed(
        [
            f"shift ({p['shift'][0]:.3g}, {p['shift'][1]:.3g}) z = {p['thickness_angstrom']:.3f} Å"
            for p in layer_slip["slipped_points"]
        ],
        int(layer_slip["n_slipped_points"]),
    )
    return Finding(
        "in_slab_slip",
        f"planes inside a slab slid sideways by more than {thr:g} Å at "
        f"{layer_slip['n_slipped_points']} of {layer_slip['points_checked']} points: {planes}; "
        f"at {points}. The slab slid inside itself, so those energies and loads are not the "
        "interface's; use scan.relax_mode: normal (every plane held laterally) or hold more "
        "layers (structure.held_layers)",
    )


def _refused(loads_gpa) -> str:
    """``"loads refused: 2.5, 3 GPa"``, or that none of the requested loads lies above the
    fold (the fold is gated all the same: docs/scan.md, *Folds*)."""
    if not loads_gpa:
        return "none of the requested loads above it"
    return "loads refused: " + ", ".join(f"{p:g}" for p in loads_gpa) + " GPa"


def load_fold(scan: Mapping) -> Finding | None:
    """``load_fold`` from ``scan.json["load_folds"]`` (absent or empty: none)."""
    folds = scan.get("load_folds") or []
    if not folds:
        return None
    parts = [
        f"column {f['column']} at z = {f['z_angstrom']:.3f} Å (p = {f['p_gpa']:.3g} GPa; "
        + _refused(f.get("loads_refused_gpa", []))
        + ")"
        for f in folds
    ]
    return Finding(
        "load_fold",
        f"the load p(z) folds in {len(folds)} column(s): {_listed(parts)}; the loads beyond a "
        "fold are not on one branch of the interface, so the laws miss them; scan finer "
        "thicknesses around the fold, or lower analysis.p_gpa below it",
    )


_SLOPES = (("k_mpa_per_gpa", "k", "τ"), ("mu_mpa_per_gpa", "μ", "σ_MSS"))
#: The intercept of each slope's law (same order as :data:`_SLOPES`).
_INTERCEPTS = {"k_mpa_per_gpa": "tau0_mpa", "mu_mpa_per_gpa": "sigma0_mpa"}

#: A significantly negative slope is gated only when the law falls by more than this fraction
#: of its intercept over the fitted loads, |slope|·p_max/|intercept|. Below it the slope is
#: statistically resolved but immaterial to the contact stage and is used as fitted, with a
#: note. Measured: Cu(111) EAM (examples/cu111-eam.yaml, internal form) μ = −0.49
#: (−0.54 .. −0.44) MPa/GPa against σ0 = 1100 MPa, 0.07 % over 0–1.5 GPa (used); H-diamond(111)
#: on graphene (internal form) k = −3.66 (−4.27 .. −3.05) against τ0 = 295 MPa, 1.9 %
#: (gated); the issue's H-diamond case μ = −1.31 ± 0.37 against σ0 ≈ 90 MPa, 2 % (gated).
NEGATIVE_SLOPE_MIN_RELATIVE_DROP = 0.01


def _interval(laws: Mapping, key: str) -> tuple[float, float, float] | None:
    """(value, low, high) of a coefficient: ``laws["intervals"]``, else value ± stderr. A fit
    without a standard error (two loads) has no interval whatever its other parts (the grid's,
    a study's): its slope's sign is not significant, so it stays zero-width here."""
    err = {"k_mpa_per_gpa": "k_stderr_mpa_per_gpa", "mu_mpa_per_gpa": "mu_stderr_mpa_per_gpa"}
    se = laws.get(err[key])
    # laws.json writes a missing standard error as null; a document without the key is judged
    # by its interval alone
    fitted = err[key] not in laws or (se is not None and math.isfinite(float(se)))
    iv = (laws.get("intervals") or {}).get(key)
    if iv is not None:
        v = float(iv["value"])
        return (v, float(iv["low"]), float(iv["high"])) if fitted else (v, v, v)
    value = laws.get(key)
    if value is None:
        return None
    se = float(se) if fitted and se is not None else 0.0
    return float(value), float(value) - se, float(value) + se


def _relative_drop(laws: Mapping, key: str, slope: float) -> float:
    """|slope|·p_max/|intercept|: how far the law falls over the fitted loads (inf when the
    intercept or the load range is not known, so the gate then judges by the interval only)."""
    intercept = laws.get(_INTERCEPTS[key])
    p_max = laws.get("p_max_gpa")
    try:
        intercept, p_max = abs(float(intercept)), float(p_max)
    except (TypeError, ValueError):
        return math.inf
    if not (math.isfinite(intercept) and math.isfinite(p_max)) or intercept == 0 or p_max <= 0:
        return math.inf
    return abs(slope) * p_max / intercept


def _resolved(iv: tuple[float, float, float]) -> bool:
    """The interval has a width: a fit through two loads has no standard error, so its
    slope's sign is not significant either way (it is used as fitted, with a note)."""
    return iv[2] > iv[1]


def _material(laws: Mapping, key: str, iv: tuple[float, float, float]) -> bool:
    """Whole (resolved) interval below 0 and a fall beyond
    :data:`NEGATIVE_SLOPE_MIN_RELATIVE_DROP`."""
    return (
        _resolved(iv)
        and iv[2] < 0
        and _relative_drop(laws, key, iv[0]) > NEGATIVE_SLOPE_MIN_RELATIVE_DROP
    )


def negative_slope(laws: Mapping) -> Finding | None:
    """``negative_slope``: k or μ whose whole interval of ``laws.json`` is below 0 and whose
    law falls by more than :data:`NEGATIVE_SLOPE_MIN_RELATIVE_DROP` of its intercept over the
    fitted loads."""
    bad, grid = [], []
    for key, name, what in _SLOPES:
        iv = _interval(laws, key)
        if iv is not None and _material(laws, key, iv):
            drop = _relative_drop(laws, key, iv[0])
            fall = f"{what} falls" + (f" {100 * drop:.2g} %" if math.isfinite(drop) else "")
            bad.append(f"{name} = {iv[0]:.3g} MPa/GPa ({iv[1]:.3g} .. {iv[2]:.3g}): {fall}")
            grid += _grid_remedy(laws, key, name, iv[0])
    if not bad:
        return None
    return Finding(
        "negative_slope",
        "significantly negative load slope, the whole interval below 0: "
        + "; ".join(bad)
        + f" with load on P <= {laws.get('threshold_gpa', float('nan')):g} GPa; check τ and "
        "σ_MSS per load in 03-analyze/friction.csv (a fold, slip, a change of minimum"
        + (" or the lateral grid" if grid else "")
        + " usually causes it)"
        + "".join(f"; {g}" for g in grid)
        + ", or give contact.k_mpa_per_gpa / contact.mu_mpa_per_gpa",
    )


#: The grid part of a slope (``intervals.<c>.components.grid``) at or above this fraction of
#: the slope makes a finer grid one of the negative-slope gate's remedies.
GRID_REMEDY_FRACTION = 0.1


def _grid_remedy(laws: Mapping, key: str, name: str, slope: float) -> list[str]:
    """The grid among the remedies of a negative slope, where it applies: the run's own grid
    estimate of the slope (:mod:`flatcontact.analysis.grid_error`) is at least
    :data:`GRID_REMEDY_FRACTION` of it, or could not be made. Nothing for a ``laws.json``
    without a grid part (written before it existed)."""
    parts = ((laws.get("intervals") or {}).get(key) or {}).get("components") or {}
    if "grid" not in parts:
        return []
    g = parts["grid"]
    if g is None:
        return [
            f"the grid's error in {name} could not be estimated (03-analyze/analyze.json "
            "grid.unavailable): check the slope on a finer scan.grid"
        ]
    if float(g) >= GRID_REMEDY_FRACTION * abs(slope):
        return [
            f"the grid's own estimate of its error in {name} is ±{float(g):.3g} MPa/GPa "
            f"({100 * float(g) / abs(slope):.2g} % of it; 03-analyze/analyze.json grid): a "
            "finer scan.grid (its recommended_grid where the grid does not resolve τ) "
            "shows whether the slope is the grid's"
        ]
    return []


def negative_slope_notes(laws: Mapping) -> list[str]:
    """Notes for negative slopes used as fitted: an interval reaching 0, or a significant
    slope whose fall stays under :data:`NEGATIVE_SLOPE_MIN_RELATIVE_DROP`."""
    notes = []
    for key, name, what in _SLOPES:
        iv = _interval(laws, key)
        if iv is not None and iv[0] < 0 and not _resolved(iv):
            notes.append(
                f"{name} = {iv[0]:.3g} MPa/GPa is negative, from a fit without an interval "
                "(too few loads for a standard error; give 3 or more): used as fitted"
            )
            continue
        if iv is not None and iv[2] < 0 and not _material(laws, key, iv):
            drop = _relative_drop(laws, key, iv[0])
            notes.append(
                f"{name} = {iv[0]:.3g} MPa/GPa is significantly negative (interval "
                f"{iv[1]:.3g} .. {iv[2]:.3g}) but {what} falls only {100 * drop:.2g} % over "
                f"0–{float(laws['p_max_gpa']):g} GPa (under "
                f"{100 * NEGATIVE_SLOPE_MIN_RELATIVE_DROP:g} %): used as fitted"
            )
        if iv is not None and iv[0] < 0 <= iv[2]:
            notes.append(
                f"{name} = {iv[0]:.3g} MPa/GPa is negative but not significantly "
                f"(interval {iv[1]:.3g} .. {iv[2]:.3g} reaches 0): used as fitted; the "
                "contact model takes it where τ > 0 and σ >= 0 on the whole contact"
            )
    return notes


def operation_name(
    matrix: np.ndarray, translation: np.ndarray, a1: np.ndarray, a2: np.ndarray
) -> str:
    """The shift-space map ``s ↦ M s + t`` in words: "rotation by 120°", "mirror at 90°"
    (the Cartesian ``L M L⁻¹``; angle of the mirror line from x), with ``+ (t_a, t_b)`` when
    it also translates."""
    lat = np.column_stack([np.asarray(a1, float)[:2], np.asarray(a2, float)[:2]])
    r = lat @ np.asarray(matrix, float) @ np.linalg.inv(lat)
    if np.linalg.det(r) > 0:
        angle = float(np.degrees(np.arctan2(r[1, 0], r[0, 0]))) % 360
        name = "translation" if round(angle) % 360 == 0 else f"rotation by {angle:.0f}°"
    else:
        name = f"mirror at {float(np.degrees(0.5 * np.arctan2(r[1, 0], r[0, 0]))) % 180:.0f}°"
    t = np.asarray(translation, float) % 1.0
    t[np.isclose(t, 1.0, atol=1e-9)] = 0.0
    if np.any(t > 1e-9):
        name += f" + ({t[0]:.3g}, {t[1]:.3g})"
    return name


def _is_lattice_vector(t: np.ndarray) -> bool:
    return bool(np.allclose(t - np.round(t), 0.0, atol=1e-9))


def broken_symmetry(
    maps: np.ndarray,
    p_gpa: Sequence[float],
    a1: np.ndarray,
    a2: np.ndarray,
    operations: Sequence[tuple[np.ndarray, np.ndarray]],
    tolerance: float = SYMMETRY_GATE_TOLERANCE,
) -> Finding | None:
    """``broken_symmetry``: the constant-pressure maps against the interface's shift-space
    group.

    Parameters
    ----------
    maps
        Constant-pressure landscapes on the scan's grid of fractional shifts, shape
        (n_p, n_a, n_b), any energy unit.
    p_gpa
        The loads (GPa).
    a1, a2
        Lattice vectors (Å), for the names of the operations.
    operations
        ``(M, t)`` per operation, fractional basis, ``E(M s + t) = E(s)``
        (:func:`flatcontact.ispes.shift_symmetry.shift_space_group`, a slab swap's sign
        inside ``M``); the identity is skipped.
    tolerance
        Largest accepted :func:`.operation_deviation.operation_deviation` (fraction of the
        map's range).
    """
    ops = [
        (np.asarray(m, float), np.asarray(t, float))
        for m, t in operations
        if not (np.allclose(m, np.eye(2)) and _is_lattice_vector(np.asarray(t, float)))
    ]
    broken: dict[str, list[tuple[float, float]]] = {}
    for p, values in zip(p_gpa, maps, strict=True):
        if not np.all(np.isfinite(values)):
            continue
        surface = PeriodicSurface(values, a1, a2)
        for m, t in ops:
            dev = operation_deviation(surface, m, t)
            if dev > tolerance:
                broken.setdefault(operation_name(m, t, a1, a2), []).append((float(p), dev))
    if not broken:
        return None
    worst = sorted(broken.items(), key=lambda item: -max(d for _, d in item[1]))
    parts = [
        f"{name} deviates {100 * max(d for _, d in rows):.0f} % (P = "
        + ", ".join(f"{p:g}" for p, _ in rows)
        + " GPa)"
        for name, rows in worst
    ]
    return Finding(
        "broken_symmetry",
        f"the ISPES breaks a symmetry of the interface (tolerance {100 * tolerance:g} % of "
        "the map's range): "
        + _listed(parts)
        + ". Equivalent stackings relaxed into different states (planes slipping, or a "
        "relaxation branch that depends on the scan order); use scan.relax_mode: normal, "
        "or a smaller scan.fmax_ev_per_angstrom",
    )


def _min_image(surface: PeriodicSurface, d: np.ndarray) -> float:
    s = surface.fractional(np.asarray(d, float))
    s -= np.round(s)
    return float(np.linalg.norm(surface.cartesian(s)))


def _equivalent(surface: PeriodicSurface, x: np.ndarray, y: np.ndarray, tol_xy: float) -> bool:
    """Whether a lattice point operation, kept by ``surface``, maps minimum ``x`` onto ``y``."""
    if _min_image(surface, y - x) < tol_xy:
        return True
    for r, m in lattice_point_operations(surface.a1, surface.a2):
        t = surface.fractional(np.asarray(y) - r @ np.asarray(x))
        if operation_deviation(surface, m, t) < LANDSCAPE_SYMMETRY_TOLERANCE:
            return True
    return False


def _tau_spread(tau_a: float, tau_b: float) -> float:
    """|τ_a − τ_b| over the larger |τ| (NaN when either is NaN: compares as neither)."""
    return abs(tau_a - tau_b) / max(abs(tau_a), abs(tau_b), 1e-300)


def degenerate_minima(
    p_gpa: Sequence[float],
    maps: np.ndarray,
    a1: np.ndarray,
    a2: np.ndarray,
    start_xy: np.ndarray,
    selected: Sequence[int],
    tau_by_start: np.ndarray,
    above_lowest: np.ndarray,
    tolerance: Sequence[float],
) -> Finding | None:
    """``degenerate_minima`` from the analysis's per-load starts (``friction.nc``).

    Parameters
    ----------
    p_gpa
        The loads (GPa), increasing.
    maps
        Constant-pressure landscapes, shape (n_p, n_a, n_b).
    a1, a2
        Lattice vectors (Å).
    start_xy
        Start positions (Å), shape (n_p, n_start, 2), NaN-padded.
    selected
        Index of the reported start per load.
    tau_by_start
        τ (MPa) per load and start, NaN-padded.
    above_lowest
        Each start's energy above the lowest minimum (meV/Å²), NaN-padded.
    tolerance
        Degeneracy tolerance per load (meV/Å²).
    """
    scale = float(min(np.linalg.norm(a1), np.linalg.norm(a2)))
    tol_xy = SAME_SITE_FRACTION * scale
    reasons = []
    prev = None
    for i, p in enumerate(p_gpa):
        if not np.all(np.isfinite(maps[i])):
            prev = None
            continue
        surface = PeriodicSurface(maps[i], a1, a2)
        xy = np.asarray(start_xy[i], float)
        ok = np.all(np.isfinite(xy), axis=1)
        k = int(selected[i])
        here = xy[k]
        # the previous rest position, relaxed on this landscape (a minimum that drifts with
        # the load stays one site)
        taus = np.asarray(tau_by_start[i], float)
        near = np.flatnonzero(ok & (np.asarray(above_lowest[i], float) <= float(tolerance[i])))
        if prev is not None:
            continued = surface.local_minimum(prev[1])[0]
            if not _equivalent(surface, continued, here, tol_xy) and not any(
                _equivalent(surface, continued, xy[j], tol_xy)
                and _tau_spread(taus[j], taus[k]) <= DEGENERATE_TAU_SPREAD
                for j in near
            ):
                reasons.append(f"the rest position moves between P = {prev[0]:g} and {p:g} GPa")
        prev = (float(p), here)
        for a in near:
            for b in near:
                if b <= a:
                    continue
                if _tau_spread(taus[a], taus[b]) > DEGENERATE_TAU_SPREAD and not _equivalent(
                    surface, xy[a], xy[b], tol_xy
                ):
                    reasons.append(
                        f"at P = {p:g} GPa two inequivalent minima within "
                        f"{float(tolerance[i]):.2g} meV/Å² give τ = {taus[a]:.4g} and "
                        f"{taus[b]:.4g} MPa"
                    )
    if not reasons:
        return None
    return Finding(
        "degenerate_minima",
        "the minimum the slider rests in is not one site through the loads: "
        + _listed(list(dict.fromkeys(reasons)))
        + "; τ(P) mixes different stackings, so the load law is not one interface's; "
        "analyse fewer or lower loads (analysis.p_gpa), or refine the grid (scan.grid)",
    )


@dataclass
class GateReport:
    """The findings of every gate, the notes, and which gates had no data to check."""

    findings: list[Finding]
    notes: list[str]
    not_checked: list[str]

    @property
    def fired(self) -> list[str]:
        """Names of the gates that fired."""
        return [f.gate for f in self.findings]

    def refused(self, accepted: Sequence[str]) -> list[Finding]:
        """The findings not in ``accepted`` (they stop the run)."""
        return [f for f in self.findings if f.gate not in accepted]

    def to_json(self, accepted: Sequence[str] = ()) -> dict:
        """``summary.json["gates"]``: every finding with ``overridden``, the overridden names,
        the notes and the gates left unchecked."""
        return {
            "fired": [
                {"gate": f.gate, "message": f.message, "overridden": f.gate in accepted}
                for f in self.findings
            ],
            "overridden": [f.gate for f in self.findings if f.gate in accepted],
            "notes": list(self.notes),
            "not_checked": list(self.not_checked),
        }
