"""Tables of the convergence study from ``results/<variant>.json`` (see ``study.py``).

For every variant against the reference (:func:`flatcontact.analysis.convergence.per_load_changes`,
5 % or one combined force-noise scale): per-load τ, σ_MSS, G_int of both runs and their
change, the largest change per quantity, the work of separation and the fitted laws with
their change in combined standard errors. Writes ``convergence.csv`` (long form, every load
and quantity), ``convergence_summary.csv`` and ``convergence.md`` (the tables of
``docs/convergence.md``).
"""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd

from flatcontact.analysis.convergence import law_changes, per_load_changes, summarize

REFERENCE = "ref"


def _load(results: Path) -> dict[str, dict]:
    docs = {}
    for path in sorted(results.glob("*.json")):
        doc = json.loads(path.read_text())
        if isinstance(doc, dict) and "loads" in doc and "laws" in doc and "setting" in doc:
            docs[doc["name"]] = doc
    return docs


def _fmt(v, digits=3) -> str:
    if v is None or (isinstance(v, float) and v != v):
        return "–"
    return f"{v:.{digits}g}" if isinstance(v, float) else str(v)


def write_tables(results: Path, rel_tol: float = 0.05, noise_multiple: float = 1.0) -> str:
    """Write the tables into ``results`` and return the Markdown text."""
    docs = _load(results)
    if REFERENCE not in docs:
        raise SystemExit(f"error: {results}/{REFERENCE}.json missing: run the reference first")
    ref = docs[REFERENCE]
    long_rows, summary_rows = [], []
    md = []
    md.append("### Per-load values of the reference (paper preset)\n")
    md.append(
        "| P (GPa) | τ (MPa) | σ_MSS (MPa) | G_int (GPa/nm) | τ limited by | jumps | force noise (MPa) |"
    )
    md.append("|---|---|---|---|---|---|---|")
    for r in ref["loads"]:
        md.append(
            f"| {r['p_gpa']:g} | {r['tau_mpa']:.1f} | {r['sigma_mss_mpa']:.2f} | "
            f"{r['shear_stiffness_gpa_per_nm']:.3f} | {r['tau_limited_by']} | {r['n_jumps']} | "
            f"{_fmt(r.get('force_noise_mpa'), 2)} |"
        )
    md.append("")
    md.append(
        f"### One refinement of each setting: largest per-load change (bound: {rel_tol:.0%} "
        f"or {noise_multiple:g}× the combined force-noise scale)\n"
    )
    md.append(
        "| variant | vs | setting | change | max |Δτ|/τ (at P) | max |Δσ|/σ (at P) | max |ΔG|/G | "
        "loads outside bound (τ; σ) | W (J/m²) | scan: s (loaded machine) / force calls |"
    )
    md.append("|---|---|---|---|---|---|---|---|---|---|---|")
    for name, doc in docs.items():
        scan_s = (doc.get("stage_timing") or {}).get("scan")
        calls = doc.get("force_calls_total")
        if name == REFERENCE:
            md.append(
                f"| {name} | – | reference | {doc['description']} | – | – | – | – | "
                f"{doc['work_of_separation_j_per_m2']:.4f} | {_fmt(scan_s, 3)} / {_fmt(calls)} |"
            )
            continue
        base = docs.get(doc.get("compare_with", REFERENCE), ref)
        ch = per_load_changes(
            base["loads"], doc["loads"], rel_tol=rel_tol, noise_multiple=noise_multiple
        )
        ch.insert(0, "variant", name)
        long_rows.append(ch)
        s = summarize(ch)
        tau, sig = s.get("tau_mpa", {}), s.get("sigma_mss_mpa", {})
        g = s.get("shear_stiffness_gpa_per_nm", {})
        summary_rows.append(
            {
                "variant": name,
                "compared_with": base["name"],
                "setting": doc["setting"],
                "description": doc["description"],
                **{f"{q}_{k}": v for q, d in s.items() for k, v in d.items()},
                "work_of_separation_j_per_m2": doc["work_of_separation_j_per_m2"],
                "scan_s": scan_s,
            }
        )
        md.append(
            f"| {name} | {base['name']} | {doc['setting']} | {doc['description']} | "
            f"{tau.get('max_abs_rel_change', float('nan')):.1%} ({tau.get('at_p_gpa', float('nan')):g}) | "
            f"{sig.get('max_abs_rel_change', float('nan')):.1%} ({sig.get('at_p_gpa', float('nan')):g}) | "
            f"{g.get('max_abs_rel_change', float('nan')):.1%} | "
            f"{_fmt(tau.get('failing_p_gpa'))}; {_fmt(sig.get('failing_p_gpa'))} | "
            f"{doc['work_of_separation_j_per_m2']:.4f} | {_fmt(scan_s, 3)} / {_fmt(calls)} |"
        )
    md.append("")
    md.append(
        "### Fitted laws (P ≤ 3 GPa, ± one standard error) and change from the reference in combined standard errors z\n"
    )
    md.append(
        "| variant | k (MPa/GPa) | τ0 (MPa) | μ (MPa/GPa) | σ0 (MPa) | z(k) | z(τ0) | z(μ) | z(σ0) |"
    )
    md.append("|---|---|---|---|---|---|---|---|---|")
    for name, doc in docs.items():
        lw = doc["laws"]
        base = docs.get(doc.get("compare_with", REFERENCE), ref)
        z = law_changes(base["laws"], lw).set_index("coefficient")["z"]
        md.append(
            f"| {name} | {lw['k_mpa_per_gpa']:.2f} ± {lw['k_stderr_mpa_per_gpa']:.2f} | "
            f"{lw['tau0_mpa']:.1f} ± {lw['tau0_stderr_mpa']:.1f} | "
            f"{lw['mu_mpa_per_gpa']:.2f} ± {lw['mu_stderr_mpa_per_gpa']:.2f} | "
            f"{lw['sigma0_mpa']:.2f} ± {lw['sigma0_stderr_mpa']:.2f} | "
            + " | ".join(_fmt(z[k], 2) if base is not doc else "–" for k in z.index)
            + " |"
        )
    md.append("")
    md.append("### τ (MPa) per load and variant\n")
    loads = [r["p_gpa"] for r in ref["loads"]]
    md.append("| variant | " + " | ".join(f"{p:g}" for p in loads) + " |")
    md.append("|---|" + "---|" * len(loads))
    for q, title in (("tau_mpa", "τ"), ("sigma_mss_mpa", "σ_MSS")):
        if q == "sigma_mss_mpa":
            md.append("")
            md.append("### σ_MSS (MPa) per load and variant\n")
            md.append("| variant | " + " | ".join(f"{p:g}" for p in loads) + " |")
            md.append("|---|" + "---|" * len(loads))
        for name, doc in docs.items():
            by_p = {round(r["p_gpa"], 6): r[q] for r in doc["loads"]}
            md.append(
                f"| {name} | " + " | ".join(_fmt(by_p.get(round(p, 6)), 4) for p in loads) + " |"
            )
        del title
    text = "\n".join(md) + "\n"
    if long_rows:
        pd.concat(long_rows, ignore_index=True).to_csv(results / "convergence.csv", index=False)
        pd.DataFrame(summary_rows).to_csv(results / "convergence_summary.csv", index=False)
    (results / "convergence.md").write_text(text)
    print(text)
    return text
