"""Comparing two variants: the per-load change of τ and σ_MSS, the change of the laws.

A refinement step converges when it moves every per-load τ and σ_MSS by less than the
tolerance: ``|x_fine − x_coarse| < tol_pct/100 · max(|x_fine|, |x_coarse|, floor_mpa)``
(the floor keeps a value near zero from failing on round-off). A load that one variant
reaches and the other does not (NaN in one of them) is a change without bound.

A step of the thicknesses setting refines only if the scanned thicknesses come out closer
together (:func:`thickness_step_refines`): the scan chooses them from ``p_range_gpa.n`` and
then adds thicknesses to bracket the extreme stackings and drops those closer than the
minimum spacing (:mod:`flatcontact.ispes.thicknesses`), so a larger ``n`` can give a coarser
list (Ni(111), Foiles EAM: n 4 → 6 took the median spacing from 0.024 to 0.031 Å).
"""

from __future__ import annotations

import math

import numpy as np

from flatcontact.analysis.uncertainty import LAW_COEFFICIENTS
from flatcontact.ispes.thicknesses import MIN_THICKNESS_SPACING_ANGSTROM

QUANTITIES = ("tau_mpa", "sigma_mss_mpa")


def relative_change_pct(a: float, b: float, floor: float) -> float:
    """``100·|b − a| / max(|a|, |b|, floor)``; 0 when both are NaN, inf when one is."""
    if math.isnan(a) and math.isnan(b):
        return 0.0
    if math.isnan(a) or math.isnan(b):
        return math.inf
    return 100.0 * abs(b - a) / max(abs(a), abs(b), floor, 1e-300)


def paired_loads(coarse: dict, fine: dict):
    """``(coarse row, fine row)`` for each load both variants list (matched to 1e-9 GPa), in
    ``fine``'s order."""
    by_p = {round(r["p_gpa"], 9): r for r in coarse["loads"]}
    for row in fine["loads"]:
        other = by_p.get(round(row["p_gpa"], 9))
        if other is not None:
            yield other, row


def largest_change(coarse: dict, fine: dict, floor_mpa: float) -> dict:
    """The largest per-load relative change (%) of τ and σ_MSS from ``coarse`` to ``fine``.

    Returns ``{"max_pct", "quantity", "p_gpa"}`` (the load and quantity where it is largest)
    over the loads both variants list.
    """
    worst = {"max_pct": 0.0, "quantity": None, "p_gpa": None}
    for other, row in paired_loads(coarse, fine):
        for q in QUANTITIES:
            pct = relative_change_pct(other[q], row[q], floor_mpa)
            if pct > worst["max_pct"] or worst["quantity"] is None:
                worst = {"max_pct": pct, "quantity": q, "p_gpa": row["p_gpa"]}
    return worst


def law_changes(coarse: dict, fine: dict, form: str) -> dict[str, float]:
    """|Δc| of each law coefficient of energy form ``form`` (NaN where either lacks it)."""
    a, b = coarse["laws"].get(form, {}), fine["laws"].get(form, {})
    out = {}
    for key in LAW_COEFFICIENTS:
        va, vb = a.get(key), b.get(key)
        out[key] = abs(float(vb) - float(va)) if va is not None and vb is not None else math.nan
    return out


def median_spacing_angstrom(thickness_angstrom) -> float:
    """The median distance (Å) between neighbouring scanned thicknesses (NaN for fewer than two)."""
    z = np.unique(np.asarray(thickness_angstrom, dtype=float))
    return float(np.median(np.diff(z))) if z.size >= 2 else math.nan


def thickness_step_refines(
    coarse: dict, fine: dict, fine_name: str, coarse_name: str
) -> str | None:
    """``None`` when ``fine``'s scan samples z more finely than ``coarse``'s, else why not (one line).

    Finer = a smaller median spacing of the scans' thicknesses (``thickness_angstrom`` of
    :func:`flatcontact.studies.runner.run_variant`), to 1e-9 Å. A step that leaves the spacing
    as it is or widens it measures nothing about the spacing: its change is no evidence of
    convergence.
    """
    a = median_spacing_angstrom(coarse["thickness_angstrom"])
    b = median_spacing_angstrom(fine["thickness_angstrom"])
    if b < a - 1e-9:
        return None
    return (
        f"{fine_name} did not refine the thicknesses: its scan's are {b:.4g} Å apart (median, "
        f"{len(fine['thickness_angstrom'])} thicknesses) against {a:.4g} Å for {coarse_name} "
        f"({len(coarse['thickness_angstrom'])}); the spacing is set by the bracket of the "
        f"extreme stackings and the minimum spacing {MIN_THICKNESS_SPACING_ANGSTROM} Å, not by "
        "scan.p_range_gpa.n; a finer scan.thickness_angstrom list needs energies converged "
        "for their derivative at its spacing (a tighter scan.fmax_ev_per_angstrom)"
    )


def counts_in_delta(state: dict) -> bool:
    """Whether a setting's ladder enters δ_conv (its ``measured_step``, base → finest level).

    Converged and not-converged settings count; a ``not refined`` thicknesses step never does
    (its change is no evidence). A ``failed`` setting counts with its last *analysable* level
    when it had one (e.g. thicknesses 19 → 29 when 29 → 43 was refused): that change is a
    measured lower bound of what refinement moves, and dropping it would understate the
    interval. A setting failed at its first step has no measured change and does not count.
    """
    if state.get("state") == "not refined":
        return False
    if state.get("state") == "failed":
        return "last_change" in state
    return True


#: A finer variant whose landscape is this many times noisier than the coarser one's
#: (median over the loads of the analysis's ``energy_noise_mev_per_a2``) is flagged.
NOISIER_FACTOR = 2.0


def noise_ratio(coarse: dict, fine: dict) -> float:
    """Median over the loads both list of ``fine``'s energy noise over ``coarse``'s (NaN if none).

    The noise is the analysis's own per-load estimate of the landscape's relaxation noise
    (``energy_noise_mev_per_a2`` of friction.csv). A refinement that makes it grow — more
    free atoms relaxed to the same force tolerance: the energy a relaxation stopped at force
    F leaves above its minimum grows like N·F²/k — changes τ by relaxation error, not by the
    setting. Measured on quartz (docs/convergence.md, "Slab layers at high load"): 9 → 12
    layers at fmax 0.005 eV/Å made the noise 5× larger and the step's internal-form τ change
    at 3 GPa mostly relaxation error.
    """
    ratios = []
    for other, row in paired_loads(coarse, fine):
        a = other.get("energy_noise_mev_per_a2", math.nan)
        b = row.get("energy_noise_mev_per_a2", math.nan)
        if math.isfinite(a) and math.isfinite(b) and a > 0:
            ratios.append(b / a)
    return float(np.median(ratios)) if ratios else math.nan
