"""The contact's range for every example: adhesion regime and the size of concurrent slip.

``python -m benchmarks.contact_range_examples RUNS_DIR`` reads ``RUNS_DIR/NAME/06-contact/
summary.json`` of every run under RUNS_DIR (made with ``flatcontact run examples/NAME.yaml
--out RUNS_DIR/NAME``) and prints the markdown table of examples/README.md's section "The
contact's range": per example the structure kind, γ_us and b of the sliding path, the Tabor
parameter and adhesion regime, and at each p0 the contact radius a against the critical size
(a_c, commensurate; a_el, twisted/approximant) with the regime the example's 5 µm tip is in.
Nothing is recomputed: the numbers are the runs' own.

``python -m benchmarks.contact_range_examples --approximants`` prints the second table: the
elastic bound of superlubricity of the approximant cells of
``passivated-tip-*-approximants.yaml`` (``flatcontact study approximants`` writes no contact
stage per cell), from the cells' laws as measured in examples/README.md's approximant table
(:data:`APPROXIMANT_LAWS`, inputs copied with their source), the experiment's moduli and
radius, w = 0 (the Hertz radius, a lower bound on the contact), and b = 2.46 Å, graphene's
period (the sheet's lattice is what the interfacial stress varies on): a_el with the cell's
own concurrent strength (the upper estimate of its rigid range) and with its lock's.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path


def _list(values, fmt="{:.3g}") -> str:
    return ", ".join("—" if v is None else fmt.format(v) for v in values)


def row(name: str, summary: dict) -> str:
    """One markdown row of the table from a run's contact ``summary.json`` (lists over the
    run's p0)."""
    adh = summary.get("adhesion_regime") or {}
    slip = summary.get("slip_size") or {}
    res = adh.get("results") or []
    p0 = _list((r["p0_gpa"] for r in summary["results"]), "{:g}")
    regimes = "/".join(dict.fromkeys(r["regime"] for r in res)) or "—"
    if adh.get("contact_radius") == "hertz":
        regimes += " (Hertz radius used)"
    tabor = f"{adh['tabor_parameter']:.3g} ({adh['equilibrium_separation_angstrom']:.3g} Å)"
    ratio = _list(r["radius_over_hertz"] for r in res)
    pull = _list(r["pull_off_over_load"] for r in res)
    a = _list((r["contact_radius_nm"] for r in summary["results"]), "{:.0f}")
    conc = _list((r["effective_shear_strength_mpa"] for r in summary["results"]), "{:.4g}")
    if not slip:
        return (
            f"| {name} | {p0} | — | — | — | {tabor} | {regimes} | {ratio} | {pull} | {a} | — | "
            f"{conc} | — |"
        )
    rows = slip["results"]
    crit = _list(r["critical_radius_nm"] for r in rows)
    reported = ", ".join(
        f"{r['reported_strength_mpa']:.4g} ({r['reported']})"
        if r["size_limited_strength_mpa"] is not None or not r["exceeded"]
        else "≥ concurrent (past a_el)"
        for r in rows
    )
    gus, b = slip.get("unstable_stacking_j_per_m2"), slip.get("burgers_angstrom")
    return (
        f"| {name} | {p0} | {slip['structure']} | {1e3 * gus:.3g} | {b:.3g} | {tabor} | "
        f"{regimes} | {ratio} | {pull} | {a} | {crit} | {conc} | {reported} |"
    )


HEADER = (
    "| example | p0 (GPa) | structure | γ_us (mJ/m²) | b (Å) | Tabor μ_T (z0) | adhesion "
    "regime | a / a_Hertz | pull-off / load | a (nm) | a_c or a_el (nm) | Q_peak/πa² "
    "concurrent (MPa) | reported for the 5 µm tip (MPa) |\n"
    "|---|---|---|---|---|---|---|---|---|---|---|---|---|"
)


#: examples/README.md, "approximant" table (2026-11-26, scan fmax 0.0005): k, τ0, μ, σ0 per cell.
APPROXIMANT_LAWS = {
    "(b) H-diamond, zsl-3pct (lock)": (150.4, 293.4, 47.7, 92.1),
    "(b) H-diamond, zsl-1pct": (0.0076, 0.0274, 0.0034, 0.0063),
    "(b) H-diamond, zsl-0.3pct": (-0.0035, 0.0127, -0.0018, 0.0040),
    "(a) bare diamond, zsl-3pct (lock)": (130.2, 345.8, 20.6, 96.2),
    "(a) bare diamond, zsl-1pct": (-0.94, 2.71, -0.14, 0.60),
    "(a) bare diamond, zsl-0.3pct": (-0.037, 1.22, -0.047, 0.40),
}
#: The experiment's bodies (passivated-tip-*.yaml): E*, G* (GPa), R (µm), p0 (GPa); b (Å).
EXPERIMENT = {"contact_modulus_gpa": 69.64, "shear_modulus_gpa": 63.40, "radius_um": 5.0}
P0_GPA = (0.5, 1.0, 1.77)
GRAPHENE_PERIOD_ANGSTROM = 2.46


def approximant_rows() -> None:
    """The second table (see the module)."""
    from flatcontact.config.load import build_config
    from flatcontact.stages.contact import ContactInputs, contact_stage

    keys = ("k_mpa_per_gpa", "tau0_mpa", "mu_mpa_per_gpa", "sigma0_mpa")
    facts = {
        "structure": "approximant",
        "path": {"burgers_angstrom": GRAPHENE_PERIOD_ANGSTROM, "source": "b = graphene's period"},
    }
    locks = {}
    print(
        "| cell | τ_c at 0.5, 1, 1.77 GPa (MPa) | a (nm) | a_el, own τ_c | a_el, the lock's "
        "τ_c | 5 µm tip |\n|---|---|---|---|---|---|"
    )
    for name, laws in APPROXIMANT_LAWS.items():
        contact = {
            **EXPERIMENT,
            **dict(zip(keys, laws, strict=True)),
            "p0_gpa": list(P0_GPA),
            "work_of_adhesion_j_per_m2": 0.0,
        }
        doc = contact_stage(
            build_config({"contact": contact}), ContactInputs(interface=facts), None
        )
        rows = doc.to_json()["slip_size"]["results"]
        tau = [r["concurrent_strength_mpa"] for r in rows]
        if "lock" in name:
            locks[name[:3]] = rows
        lock = locks[name[:3]]
        a = [r["contact_radius_nm"] for r in rows]
        fmt = lambda xs: ", ".join(f"{x:.3g}" for x in xs)  # noqa: E731
        own = [r["critical_radius_nm"] for r in rows]
        by_lock = [r["critical_radius_nm"] for r in lock]
        if "lock" in name:
            print(
                f"| {name} | {fmt(tau)} | {fmt(a)} | — | {fmt(by_lock)} | commensurate: its a_c "
                "is in the table above (passivated-tip examples) |"
            )
            continue
        verdict = (
            "rigid (concurrent)"
            if a[-1] < by_lock[-1]
            else (
                "past the lock's a_el: the cell's number is a lower bound"
                if a[-1] < own[-1]
                else "past its own a_el: lower bound"
            )
        )
        print(f"| {name} | {fmt(tau)} | {fmt(a)} | {fmt(own)} | {fmt(by_lock)} | {verdict} |")


def main(runs: Path) -> None:
    print(HEADER)
    for summary in sorted(runs.glob("*/06-contact/summary.json")):
        print(row(summary.parent.parent.name, json.loads(summary.read_text())))


if __name__ == "__main__":
    if sys.argv[1:] == ["--approximants"]:
        approximant_rows()
    else:
        main(Path(sys.argv[1]))
