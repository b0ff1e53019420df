"""Per-load tables of the slab-thickness steps in both energy forms.

Two series (:data:`SERIES`), each made by ``study.py`` into ``results/<name>.json`` and
``results/enthalpy/<name>.json``: 6 → 9 → 12 layers at the presets' force tolerance
(0.005 eV/Å), and 9 → 12 → 15 layers at half of it (0.0025 eV/Å), where a thick stack's
relaxation noise is resolved. Per load: τ, σ_MSS and G_int of each thickness with the
relative change of each step and whether it is within the study's bound (5 % or the combined
force-noise scale, :func:`flatcontact.analysis.convergence.per_load_changes`, the function
``table.py`` uses); a variant not yet run is left out::

    python -m benchmarks.convergence.layers_table      # Markdown on stdout
"""

from __future__ import annotations

import itertools
import json

from benchmarks.convergence.study import HERE

#: series title -> (variant, layers) from thin to thick; each step compares neighbours.
SERIES = {
    "fmax 0.005 eV/Å": (("layers6_g8", 6), ("layers9_g8", 9), ("layers12_g8", 12)),
    "fmax 0.0025 eV/Å": (
        ("layers9_f25_g8", 9),
        ("layers12_f25_g8", 12),
        ("layers15_f25_g8", 15),
    ),
}
QUANTITIES = (
    ("tau_mpa", "τ (MPa)"),
    ("sigma_mss_mpa", "σ_MSS (MPa)"),
    ("shear_stiffness_gpa_per_nm", "G_int (GPa/nm)"),
)


def table(form: str, series: str) -> str:
    """The Markdown table of one energy form (``internal`` or ``enthalpy``) and series."""
    from flatcontact.analysis.convergence import per_load_changes

    folder = HERE / "results" if form == "internal" else HERE / "results" / form
    members = [(n, k) for n, k in SERIES[series] if (folder / f"{n}.json").exists()]
    if not members:
        return ""
    docs = {n: json.loads((folder / f"{n}.json").read_text()) for n, _ in members}
    steps = list(itertools.pairwise(members))
    changes = {}
    for (a, _), (b, _) in steps:
        ch = per_load_changes(docs[a]["loads"], docs[b]["loads"], rel_tol=0.05, noise_multiple=1.0)
        for row in ch.to_dict(orient="records"):
            changes[(a, b, row["quantity"], round(row["p_gpa"], 6))] = row
    head = [f"{k} layers" for _, k in members] + [f"{ka}→{kb}" for (_, ka), (_, kb) in steps]
    out = [
        f"| P (GPa) | quantity ({form}, {series}) | " + " | ".join(head) + " |",
        "|---|---|" + "---|" * len(head),
    ]
    for p in [r["p_gpa"] for r in docs[members[0][0]]["loads"]]:
        for q, label in QUANTITIES:
            cells = []
            for name, _ in members:
                v = {round(r["p_gpa"], 6): r[q] for r in docs[name]["loads"]}.get(round(p, 6))
                cells.append("–" if v is None else f"{v:.3g}")
            for (a, _), (b, _) in steps:
                row = changes.get((a, b, q, round(p, 6)))
                mark = "" if row is None or row["within"] else " ✗"
                cells.append("–" if row is None else f"{row['rel_change']:+.1%}{mark}")
            out.append(f"| {p:g} | {label} | " + " | ".join(cells) + " |")
    w = [docs[n]["work_of_separation_j_per_m2"] for n, _ in members]
    cells = [f"{x:.4f}" for x in w] + [f"{b / a - 1:+.1%}" for a, b in itertools.pairwise(w)]
    out.append("| – | W (J/m²) | " + " | ".join(cells) + " |")
    return "\n".join(out) + "\n"


def main() -> None:
    for series in SERIES:
        for form in ("internal", "enthalpy"):
            print(table(form, series))


if __name__ == "__main__":
    main()
