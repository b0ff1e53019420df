"""Comparing two variants: the per-load change of τ and σ_MSS, the change of the laws.

A refinement step converges when it moves every per-load τ and σ_MSS by less than the
tolerance: ``|x_fine − x_coarse| < tol_pct/100 · max(|x_fine|, |x_coarse|, floor_mpa)``
(the floor keeps a value near zero from failing on round-off). A load that one variant
reaches and the other does not (NaN in one of them) is a change without bound.
"""

from __future__ import annotations

import math

from flatcontact.analysis.uncertainty import LAW_COEFFICIENTS

QUANTITIES = ("tau_mpa", "sigma_mss_mpa")


def relative_change_pct(a: float, b: float, floor: float) -> float:
    """``100·|b − a| / max(|a|, |b|, floor)``; 0 when both are NaN, inf when one is."""
    if math.isnan(a) and math.isnan(b):
        return 0.0
    if math.isnan(a) or math.isnan(b):
        return math.inf
    return 100.0 * abs(b - a) / max(abs(a), abs(b), floor, 1e-300)


def largest_change(coarse: dict, fine: dict, floor_mpa: float) -> dict:
    """The largest per-load relative change (%) of τ and σ_MSS from ``coarse`` to ``fine``.

    Returns ``{"max_pct", "quantity", "p_gpa"}`` (the load and quantity where it is largest)
    over the loads both variants list.
    """
    by_p = {round(r["p_gpa"], 9): r for r in coarse["loads"]}
    worst = {"max_pct": 0.0, "quantity": None, "p_gpa": None}
    for row in fine["loads"]:
        other = by_p.get(round(row["p_gpa"], 9))
        if other is None:
            continue
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
