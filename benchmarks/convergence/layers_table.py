"""Per-load table of the slab-thickness steps (6 → 9 → 12 layers) in both energy forms.

Reads ``results/layers{6,9,12}_g8.json`` and ``results/enthalpy/...`` (made by ``study.py``)
and prints, per load, τ, σ_MSS and G_int of each thickness with the relative change of each
step and whether it is within the study's bound (5 % or the combined force-noise scale,
:func:`flatcontact.analysis.convergence.per_load_changes`, the function ``table.py`` uses)::

    python -m benchmarks.convergence.layers_table      # Markdown on stdout
"""

from __future__ import annotations

import json

from benchmarks.convergence.study import HERE

STEPS = (("layers6_g8", "layers9_g8"), ("layers9_g8", "layers12_g8"))
QUANTITIES = (
    ("tau_mpa", "τ (MPa)"),
    ("sigma_mss_mpa", "σ_MSS (MPa)"),
    ("shear_stiffness_gpa_per_nm", "G_int (GPa/nm)"),
)


def table(form: str) -> str:
    """The Markdown table of one energy form (``internal`` or ``enthalpy``)."""
    from flatcontact.analysis.convergence import per_load_changes

    folder = HERE / "results" if form == "internal" else HERE / "results" / form
    docs = {
        name: json.loads((folder / f"{name}.json").read_text())
        for name in ("layers6_g8", "layers9_g8", "layers12_g8")
    }
    changes = {}
    for a, b in STEPS:
        ch = per_load_changes(docs[a]["loads"], docs[b]["loads"], rel_tol=0.05, noise_multiple=1.0)
        for row in ch.to_dict(orient="records"):
            changes[(a, b, row["quantity"], round(row["p_gpa"], 6))] = row
    out = [
        f"| P (GPa) | quantity ({form}) | 6 layers | 9 layers | 12 layers | 6→9 | 12 vs 9 |",
        "|---|---|---|---|---|---|---|",
    ]
    loads = [r["p_gpa"] for r in docs["layers6_g8"]["loads"]]
    for p in loads:
        for q, label in QUANTITIES:
            vals = []
            for name in ("layers6_g8", "layers9_g8", "layers12_g8"):
                by_p = {round(r["p_gpa"], 6): r[q] for r in docs[name]["loads"]}
                v = by_p.get(round(p, 6))
                vals.append("–" if v is None else f"{v:.3g}")
            steps = []
            for a, b in STEPS:
                row = changes.get((a, b, q, round(p, 6)))
                if row is None:
                    steps.append("–")
                else:
                    mark = "" if row["within"] else " ✗"
                    steps.append(f"{row['rel_change']:+.1%}{mark}")
            out.append(f"| {p:g} | {label} | " + " | ".join(vals + steps) + " |")
    w = [
        docs[n]["work_of_separation_j_per_m2"] for n in ("layers6_g8", "layers9_g8", "layers12_g8")
    ]
    out.append(
        f"| – | W (J/m²) | {w[0]:.4f} | {w[1]:.4f} | {w[2]:.4f} | {w[1] / w[0] - 1:+.1%} | "
        f"{w[2] / w[1] - 1:+.1%} |"
    )
    return "\n".join(out) + "\n"


def main() -> None:
    for form in ("internal", "enthalpy"):
        print(table(form))


if __name__ == "__main__":
    main()
