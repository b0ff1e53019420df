"""Convergence of per-load friction quantities under one refinement of a numerical setting.

A setting (lateral grid, thickness spacing, force tolerance, slab layers, LJ cutoff) is
*converged* at a reference value when one more refinement moves every per-load quantity
of interest by less than a tolerance. For each load ``P`` and quantity ``q`` (τ, σ_MSS
of the paper's Eqs. for the shear strength and the minimal-scale-sliding friction):

.. math::

    Δq(P) = q_{\\rm refined}(P) - q_{\\rm ref}(P), \\qquad
    {\\rm bound}(P) = \\max\\bigl(r\\,|q_{\\rm ref}(P)|,\\; n\\,\\sqrt{ν_{\\rm ref}^2 + ν_{\\rm refined}^2}\\bigr)

with ``r`` the relative tolerance (default 5 %), ``ν`` the force-noise scale that the
analysis reports with each load (``force_noise_mpa``, :mod:`flatcontact.analysis.noise`)
and ``n`` its multiple (default 1). A load passes when ``|Δq| ≤ bound``. Quantities
without a noise estimate (G_int) use the relative tolerance alone.

The load laws are compared in units of their combined standard error,
``z = Δc / sqrt(se_ref² + se_refined²)`` for c in (k, τ0, μ, σ0).

All functions are pure: rows in (mappings with ``p_gpa`` and the quantities, as in
``friction.csv``), tables out (:class:`pandas.DataFrame`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd

from flatcontact.foundation.errors import InputError, require

#: Quantities compared per load, with the column holding their noise estimate (or None).
QUANTITIES: dict[str, str | None] = {
    "tau_mpa": "force_noise_mpa",
    "sigma_mss_mpa": "force_noise_mpa",
    "shear_stiffness_gpa_per_nm": None,
}
#: The law coefficients and their standard-error keys in ``laws.json``.
LAW_KEYS: dict[str, str] = {
    "k_mpa_per_gpa": "k_stderr_mpa_per_gpa",
    "tau0_mpa": "tau0_stderr_mpa",
    "mu_mpa_per_gpa": "mu_stderr_mpa_per_gpa",
    "sigma0_mpa": "sigma0_stderr_mpa",
}


def _frame(rows: Sequence[Mapping] | pd.DataFrame, what: str) -> pd.DataFrame:
    table = pd.DataFrame(rows).copy()
    require(
        "p_gpa" in table.columns, f"{what}: expected rows with 'p_gpa', got {list(table.columns)}"
    )
    return table.set_index(np.round(table["p_gpa"].to_numpy(float), 6))


def per_load_changes(
    reference: Sequence[Mapping] | pd.DataFrame,
    refined: Sequence[Mapping] | pd.DataFrame,
    *,
    rel_tol: float = 0.05,
    noise_multiple: float = 1.0,
    quantities: Mapping[str, str | None] = QUANTITIES,
) -> pd.DataFrame:
    """Per-load change of each quantity between a reference and a refined run.

    Parameters
    ----------
    reference, refined
        Rows with ``p_gpa`` and the quantities (``friction.csv`` of each run). Only the
        loads present in both are compared.
    rel_tol
        Relative tolerance ``r`` (0.05 = 5 %).
    noise_multiple
        ``n``: a change within ``n`` combined noise scales passes (module docstring).
    quantities
        Quantity column -> its noise column (or ``None``).

    Returns
    -------
    pandas.DataFrame
        One row per (load, quantity): ``p_gpa, quantity, reference, refined, change,
        rel_change, noise, bound, within``.
    """
    require(rel_tol >= 0, f"rel_tol={rel_tol}: expected >= 0")
    require(noise_multiple >= 0, f"noise_multiple={noise_multiple}: expected >= 0")
    ref = _frame(reference, "reference")
    new = _frame(refined, "refined")
    loads = sorted(set(ref.index) & set(new.index))
    if not loads:
        raise InputError("reference and refined runs have no load p_gpa in common")
    out = []
    for p in loads:
        for q, noise_col in quantities.items():
            if q not in ref.columns or q not in new.columns:
                continue
            a, b = float(ref.at[p, q]), float(new.at[p, q])
            noise = 0.0
            if noise_col is not None and noise_col in ref.columns and noise_col in new.columns:
                na, nb = float(ref.at[p, noise_col]), float(new.at[p, noise_col])
                noise = float(np.hypot(np.nan_to_num(na), np.nan_to_num(nb)))
            bound = max(rel_tol * abs(a), noise_multiple * noise)
            change = b - a
            out.append(
                {
                    "p_gpa": float(p),
                    "quantity": q,
                    "reference": a,
                    "refined": b,
                    "change": change,
                    "rel_change": change / abs(a) if a != 0 else np.inf * np.sign(change),
                    "noise": noise,
                    "bound": bound,
                    "within": bool(np.isfinite(change) and abs(change) <= bound),
                }
            )
    return pd.DataFrame(out)


def law_changes(reference: Mapping, refined: Mapping) -> pd.DataFrame:
    """Change of each load-law coefficient in units of the combined standard error.

    Parameters
    ----------
    reference, refined
        ``laws.json`` documents (:meth:`flatcontact.analysis.laws.LoadLaws.to_json`).

    Returns
    -------
    pandas.DataFrame
        One row per coefficient: ``coefficient, reference, reference_stderr, refined,
        refined_stderr, change, z`` (``z = change / sqrt(se_ref² + se_refined²)``; NaN when
        a coefficient or error is missing).
    """
    rows = []
    for key, err in LAW_KEYS.items():
        a, b = reference.get(key), refined.get(key)
        ea, eb = reference.get(err), refined.get(err)
        vals = [np.nan if v is None else float(v) for v in (a, ea, b, eb)]
        combined = float(np.hypot(vals[1], vals[3]))
        change = vals[2] - vals[0]
        rows.append(
            {
                "coefficient": key,
                "reference": vals[0],
                "reference_stderr": vals[1],
                "refined": vals[2],
                "refined_stderr": vals[3],
                "change": change,
                "z": change / combined if combined > 0 else np.nan,
            }
        )
    return pd.DataFrame(rows)


def summarize(changes: pd.DataFrame) -> dict:
    """Largest relative change per quantity and whether every load is within its bound.

    Parameters
    ----------
    changes
        Output of :func:`per_load_changes`.

    Returns
    -------
    dict
        ``{quantity: {"max_abs_rel_change", "at_p_gpa", "max_abs_change", "all_within",
        "failing_p_gpa"}}``.
    """
    out = {}
    for q, part in changes.groupby("quantity", sort=False):
        rel = part["rel_change"].abs().to_numpy(float)
        i = int(np.nanargmax(rel)) if np.isfinite(rel).any() else 0
        out[str(q)] = {
            "max_abs_rel_change": float(rel[i]),
            "at_p_gpa": float(part["p_gpa"].iloc[i]),
            "max_abs_change": float(part["change"].abs().max()),
            "all_within": bool(part["within"].all()),
            "failing_p_gpa": [float(p) for p in part.loc[~part["within"], "p_gpa"]],
        }
    return out


def monotonic_violations(
    p_gpa: Sequence[float], values: Sequence[float], noise: Sequence[float] | float = 0.0
) -> list[dict]:
    """Loads where a quantity expected to grow with load falls by more than its noise.

    A drop from load ``P_i`` to ``P_{i+1}`` counts when
    ``q_i - q_{i+1} > sqrt(ν_i² + ν_{i+1}²)`` (ν the per-load noise).

    Returns
    -------
    list of dict
        ``{"from_p_gpa", "to_p_gpa", "drop", "noise"}`` per violation, in load order.
    """
    p = np.asarray(p_gpa, float)
    v = np.asarray(values, float)
    nu = np.broadcast_to(np.nan_to_num(np.asarray(noise, float)), p.shape)
    require(p.shape == v.shape, "p_gpa and values: expected the same length")
    order = np.argsort(p)
    p, v, nu = p[order], v[order], nu[order]
    out = []
    for i in range(len(p) - 1):
        drop = v[i] - v[i + 1]
        bound = float(np.hypot(nu[i], nu[i + 1]))
        if drop > bound:
            out.append(
                {
                    "from_p_gpa": float(p[i]),
                    "to_p_gpa": float(p[i + 1]),
                    "drop": float(drop),
                    "noise": bound,
                }
            )
    return out
