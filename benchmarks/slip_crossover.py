"""Where concurrent slip stops, measured: the bonded Cu(111) asperities in atoms against the
critical size of the contact stage (issue 36 checked against issue 35).

    python -m benchmarks.slip_crossover           # print the table
    python -m benchmarks.slip_crossover --write   # rewrite the marked table in docs/contact.md

Inputs, all stored in the repository (no run needed):

- ``docs/measured/asperity/cu-eam-R*/asperity.json``: the direct atomistic cylinders
  (``flatcontact asperity examples/asperity-cu111-eam.yaml``, EAM across the interface) at
  p0 = 1 GPa: the atoms' contact half-width a and their peak mean shear stress Q'/2a, and the
  pointwise model's concurrent-slip number on the Hertz pressure (the contact stage's);
- ``docs/measured/examples/cu111-eam``: the run of ``examples/cu111-eam.yaml`` the asperities
  took their laws from: G* (``06-contact/summary.json``) and the barrier of the γ-surface along
  the sliding direction, γ_us (``03-analyze/friction.csv`` at the lowest load).

Per radius it gives τ_dis(a) = √(8 G* γ_us/(π a)) (:func:`flatcontact.contact.slip_size.
dislocation_strength`) at the atoms' a and the critical size a_c = 8 G* γ_us/(π τ_c²) with τ_c
the concurrent number; the prediction is min(τ_c, τ_dis(a)). The estimate is written for a
sphere's contact radius; here it is applied to the cylinder's half-width, an O(1) change of
geometry the table does not correct for.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pandas as pd

from flatcontact.contact.slip_size import critical_radius, dislocation_strength

ROOT = Path(__file__).resolve().parents[1]
ASPERITIES = ROOT / "docs" / "measured" / "asperity"
FLAT_RUN = ROOT / "docs" / "measured" / "examples" / "cu111-eam"
DOC = ROOT / "docs" / "contact.md"
BEGIN, END = "<!-- slip-crossover:begin -->", "<!-- slip-crossover:end -->"


def interface() -> dict:
    """G* (Pa) and γ_us (J/m²) of the flat Cu(111) run the asperities used."""
    summary = json.loads((FLAT_RUN / "06-contact" / "summary.json").read_text())
    friction = pd.read_csv(FLAT_RUN / "03-analyze" / "friction.csv").sort_values("p_gpa")
    barrier = float(friction["barrier_along_direction_mev_per_a2"].iloc[0])
    return {
        "shear_modulus_pa": summary["parameters"]["shear_modulus_gpa"] * 1e9,
        "unstable_stacking_j_per_m2": barrier * 1e-3 * 1.602176634e-19 / 1e-20,
    }


def rows() -> list[dict]:
    """One row per bonded asperity radius, ascending."""
    facts = interface()
    out = []
    for path in sorted(ASPERITIES.glob("cu-eam-R*/asperity.json")):
        doc = json.loads(path.read_text())
        load = doc["loads"][0]
        atoms = load["atoms"]
        a_m = atoms["contact_half_width_angstrom"] * 1e-10
        tau_c = load["model_hertz"]["peak_shear_stress_mpa"] * 1e6
        tau_dis = float(dislocation_strength(a_m, **facts))
        a_c = float(critical_radius(tau_c, **facts))
        predicted = min(tau_c, tau_dis)
        out.append(
            {
                "radius_nm": doc["radius_angstrom"] / 10.0,
                "n_atoms": doc["n_atoms"],
                "a_nm": a_m * 1e9,
                "a_c_nm": a_c * 1e9,
                "atoms_mpa": atoms["peak_shear_stress_mpa"],
                "peak_reached": bool(atoms.get("peak_reached", True)),
                "concurrent_mpa": tau_c / 1e6,
                "tau_dis_mpa": tau_dis / 1e6,
                "predicted_mpa": predicted / 1e6,
                "regime": "concurrent" if tau_c <= tau_dis else "size-limited",
            }
        )
    return sorted(out, key=lambda r: r["radius_nm"])


def table() -> str:
    """The markdown table of :func:`rows`."""
    facts = interface()
    lines = [
        f"G* = {facts['shear_modulus_pa'] / 1e9:.1f} GPa, γ_us = "
        f"{facts['unstable_stacking_j_per_m2'] * 1e3:.0f} mJ/m² (the flat run of "
        "`examples/cu111-eam.yaml`); cylinders at p0 = 1 GPa, bonded (EAM across).",
        "",
        "| R (nm) | atoms | a atoms (nm) | a_c (nm) | Q'/2a atoms (MPa) | concurrent model (MPa) "
        "| τ_dis(a) (MPa) | predicted (regime) | atoms / predicted |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows():
        atoms = f"{r['atoms_mpa']:.0f}" + ("" if r["peak_reached"] else " (≥, peak not reached)")
        lines.append(
            f"| {r['radius_nm']:.0f} | {r['n_atoms']} | {r['a_nm']:.2f} | {r['a_c_nm']:.2f} | "
            f"{atoms} | {r['concurrent_mpa']:.0f} | {r['tau_dis_mpa']:.0f} | "
            f"{r['predicted_mpa']:.0f} ({r['regime']}) | "
            f"{r['atoms_mpa'] / r['predicted_mpa']:.2f} |"
        )
    return "\n".join(lines) + "\n"


def write(doc: Path = DOC) -> None:
    """Replace the marked block of ``doc`` with :func:`table`."""
    text = doc.read_text(encoding="utf-8")
    head, rest = text.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    doc.write_text(f"{head}{BEGIN}\n{table()}{END}{tail}", encoding="utf-8")


if __name__ == "__main__":
    if "--write" in sys.argv[1:]:
        write()
    print(table(), end="")
