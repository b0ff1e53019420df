"""The examples' tables in the docs, regenerated from the code's own output files.

``python -m benchmarks.example_tables [--runs DIR] [--studies DIR]``

1. With ``--runs DIR`` (finished ``flatcontact run`` directories ``DIR/<example>``, e.g.
   ``DIR/cu111-eam`` for ``examples/cu111-eam.yaml``, ``DIR/al111`` for the worked example of
   docs/your-own-interface.md) and ``--studies DIR`` (finished ``flatcontact study
   approximants`` directories ``DIR/appx-bare``, ``DIR/appx-h``), the small output files the
   tables are read from are copied into :data:`STORE` (``docs/measured/examples``), replacing
   that example's earlier copy. Nothing is run: the runs are the expensive part.
2. Every table between ``<!-- example-table: NAME -->`` and ``<!-- /example-table: NAME -->``
   in :data:`DOCS` is rewritten from :data:`STORE`. An example with no stored run gets the row
   "not regenerated in this version" instead of numbers from an older version.

``tests/examples/test_example_tables.py`` checks that the docs hold exactly what this module
renders from the store, and that the stored laws are what the code computes from the stored
per-load table (so no hand-copied number can go stale).
"""

from __future__ import annotations

import argparse
import json
import re
import shutil
from pathlib import Path

import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
STORE = ROOT / "docs" / "measured" / "examples"
DOCS = (
    ROOT / "examples" / "README.md",
    ROOT / "docs" / "incommensurate.md",
    ROOT / "docs" / "your-own-interface.md",
)
#: The run examples of examples/README.md's "Measured results", in the table's order.
RUN_EXAMPLES = (
    "graphene-bilayer-kc",
    "graphene-bilayer-ilp",
    "hbn-bilayer-ilp",
    "mos2-bilayer-ilp",
    "cu111-eam",
    "au111-cif-eam",
    "graphene-hbn-ilp",
    "diamond111-h-graphene-airebo",
    "quartz-paper",
)
#: The experiment's interfaces of examples/README.md (example, row label).
PASSIVATED = (
    ("passivated-tip-bare-diamond-graphene", "(a) bare diamond(111) / graphene, AIREBO"),
    ("passivated-tip-h-diamond-graphene", "(b) H-diamond(111) / graphene, AIREBO"),
    ("passivated-tip-graphene-ab", "(c) AB graphene / graphene, REBO + KC"),
)
#: Rows of that table measured with a configuration that is no example file.
PASSIVATED_OTHER = ("(c) twisted 21.787° (`twist: [1, 2]`, 28 atoms), REBO + KC, rigid layers",)
#: The worked example of docs/your-own-interface.md (its YAML is in that page).
WORKED = "al111"
#: The approximant studies (examples/passivated-tip-{bare,h}-diamond-graphene-approximants.yaml).
STUDIES = {"appx-bare": "(a) bare diamond", "appx-h": "(b) H-diamond"}
#: Files of a run directory the tables are read from.
RUN_FILES = (
    "01-build/build.json",
    "02-scan/scan.json",
    "03-analyze/friction.csv",
    "03-analyze/analyze.json",
    "04-laws/laws.json",
    "05-elastic/elastic.json",
    "06-contact/summary.json",
)
#: Also stored for the worked example: its 6×6 scan (the file-lattice pair that
#: tests/analysis/test_grid_error.py analyses is stored apart, ``al111-file-lattice-*``).
WORKED_FILES = ("02-scan/ispes.nc",)
STAGES = ("build", "scan", "analyze", "laws", "elastic", "contact", "report")
STUDY_FILES = ("approximants.csv", "experiment_collapse.json")
NOT_REGENERATED = "not regenerated in this version"
MARK = re.compile(
    r"(<!-- example-table: (?P<name>[\w-]+) -->\n)(?P<body>.*?)(<!-- /example-table: (?P=name) -->)",
    re.S,
)


# ------------------------------------------------------------------------------------ store
def store_run(run: Path, name: str, store: Path = STORE) -> Path:
    """Copy the table files of run directory ``run`` into ``store/name`` (replacing that
    example's copies); the stage wall times (``stage.json`` ``seconds``) go to
    ``timings.json``."""
    dest = store / name
    for rel in RUN_FILES + (WORKED_FILES if name == WORKED else ()):
        (dest / rel).unlink(missing_ok=True)
    for rel in RUN_FILES + (WORKED_FILES if name == WORKED else ()):
        src = run / rel
        if src.is_file():
            (dest / rel).parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(src, dest / rel)
    timings = {}
    for i, stage in enumerate(STAGES, start=1):
        rec = run / f"{i:02d}-{stage}" / "stage.json"
        if rec.is_file():
            timings[stage] = json.loads(rec.read_text()).get("seconds")
    dest.mkdir(parents=True, exist_ok=True)
    (dest / "timings.json").write_text(json.dumps(timings, indent=1) + "\n")
    return dest


def store_study(study: Path, name: str, store: Path = STORE) -> Path:
    """Copy an approximant study's table files into ``store/name`` (replacing it)."""
    dest = store / name
    if dest.exists():
        shutil.rmtree(dest)
    dest.mkdir(parents=True)
    for rel in STUDY_FILES:
        shutil.copyfile(study / rel, dest / rel)
    return dest


# ------------------------------------------------------------------------------------ reading
def _json(path: Path) -> dict:
    return json.loads(path.read_text()) if path.is_file() else {}


def _g(v: float | None, digits: int = 4) -> str:
    """A number in ``digits`` significant figures, Unicode minus; — for none."""
    if v is None or v != v:
        return "—"
    text = re.sub(
        r"e([+-])0*(\d)", lambda m: "e" + m.group(1).strip("+") + m.group(2), f"{v:.{digits}g}"
    )
    return text.replace("-", "−") if text.startswith("-") else text


def _pm(v: float | None, e: float | None, digits: int = 4) -> str:
    return _g(v, digits) if e is None else f"{_g(v, digits)} ± {_g(e, 2)}"


def _stackings(row: pd.Series) -> str:
    text = str(row.get("stacking_energies_mev_per_a2") or "")
    parts = []
    for item in filter(None, text.split(";")):
        name, value = item.split("=")
        parts.append((float(value), name))
    return ", ".join(f"{name} {_g(0.0 if abs(v) < 1e-9 else v)}" for v, name in sorted(parts))


def _law(laws: dict, slope: str, intercept: str, se_slope: str, se_intercept: str) -> str:
    return (
        f"({_pm(laws.get(slope), laws.get(se_slope), 3)})·P + "
        f"{_pm(laws.get(intercept), laws.get(se_intercept))}"
    )


def _grid_part(laws: dict, analyze: dict) -> str:
    """``τ0 ± g, k ± g; resolves τ (x %)`` or ``does not resolve τ (x %): ~N×N``."""
    iv = laws.get("intervals") or {}
    parts = [
        f"{label} ± {_g(((iv.get(key) or {}).get('components') or {}).get('grid'), 2)}"
        for key, label in (("tau0_mpa", "τ0"), ("k_mpa_per_gpa", "k"))
    ]
    grid = analyze.get("grid") or {}
    rel = [v for v in grid.get("relative_tau_error") or [] if v is not None]
    worst = f"{100 * max(rel):.2g} %" if rel else "—"
    if not grid:
        verdict = "—"
    elif grid.get("resolved", True):
        verdict = f"resolves τ ({worst})"
    else:
        rec = grid.get("recommended_grid") or ["?", "?"]
        verdict = f"**does not resolve τ** ({worst}; ~{rec[0]}×{rec[1]})"
    return f"{', '.join(parts)}; {verdict}"


def _wall(timings: dict) -> str:
    total = sum(v for v in timings.values() if v)
    return f"{total:.0f} s (scan {timings.get('scan') or 0:.0f} s)"


def _contact(summary: dict) -> str:
    """Q_peak/πa² at every p0 with its interval over the laws' intervals."""
    rows = (summary.get("intervals") or {}).get("results") or []
    if rows:
        return "; ".join(
            f"{_g(r['effective_shear_strength_mpa']['value'])} "
            f"[{_g(r['effective_shear_strength_mpa']['low'])}, "
            f"{_g(r['effective_shear_strength_mpa']['high'])}]"
            for r in rows
        )
    return ", ".join(_g(r.get("effective_shear_strength_mpa")) for r in summary.get("results", []))


def _moduli(summary: dict) -> str:
    prm, prov = summary.get("parameters") or {}, summary.get("provenance") or {}
    return (
        f"{_g(prm.get('contact_modulus_gpa'))}, {_g(prm.get('shear_modulus_gpa'))} "
        f"({prov.get('moduli', '—')})"
    )


def run_row(name: str, store: Path = STORE) -> str:
    """One row of the run examples' table (the "not regenerated" row without a stored run)."""
    d = store / name
    if not (d / "04-laws" / "laws.json").is_file():
        return f"| {name} | {NOT_REGENERATED} |" + " — |" * 8
    laws = _json(d / "04-laws" / "laws.json")
    analyze = _json(d / "03-analyze" / "analyze.json")
    scan = _json(d / "02-scan" / "scan.json")
    summary = _json(d / "06-contact" / "summary.json")
    table = pd.read_csv(d / "03-analyze" / "friction.csv")
    first = table.sort_values("p_gpa").iloc[0]
    form = laws.get("energy_form", "internal")
    label = name if form == "internal" else f"{name} ({form} form)"
    w = (scan.get("adhesion") or {}).get("work_of_separation_j_per_m2")
    cells = (
        label,
        _wall(_json(d / "timings.json")),
        _stackings(first),
        _g(first.get("lowest_barrier_mev_per_a2")),
        _law(laws, "k_mpa_per_gpa", "tau0_mpa", "k_stderr_mpa_per_gpa", "tau0_stderr_mpa"),
        _law(laws, "mu_mpa_per_gpa", "sigma0_mpa", "mu_stderr_mpa_per_gpa", "sigma0_stderr_mpa"),
        _grid_part(laws, analyze),
        _g(w),
        _moduli(summary),
        _contact(summary),
    )
    return "| " + " | ".join(cells) + " |"


RUN_HEADER = (
    "| example | wall (scan) | stackings at P = 0 (meV/Å²) | barrier (meV/Å²) | "
    "τ = k·P + τ0 (MPa, ± fit s.e.) | σ = μ·P + σ0 (MPa, ± fit s.e.) | grid part (MPa, MPa/GPa); "
    "the grid's verdict (largest δτ/τ) | W (J/m²) | E*, G* (GPa) | "
    "Q_peak/πa² (MPa) [interval] at each p0 |\n|" + "---|" * 10
)


def runs_table(store: Path = STORE) -> str:
    return "\n".join([RUN_HEADER, *(run_row(n, store) for n in RUN_EXAMPLES)]) + "\n"


def worked_table(store: Path = STORE) -> str:
    """docs/your-own-interface.md: the worked example's quantities."""
    d = store / WORKED
    head = "| quantity | value |\n|---|---|\n"
    if not (d / "04-laws" / "laws.json").is_file():
        return head + f"| all | {NOT_REGENERATED} |\n"
    laws = _json(d / "04-laws" / "laws.json")
    analyze = _json(d / "03-analyze" / "analyze.json")
    scan = _json(d / "02-scan" / "scan.json")
    elastic = _json(d / "05-elastic" / "elastic.json")
    summary = _json(d / "06-contact" / "summary.json")
    table = pd.read_csv(d / "03-analyze" / "friction.csv").sort_values("p_gpa")
    first = table.iloc[0]
    iv = laws.get("intervals") or {}

    def interval(key: str) -> str:
        i = iv.get(key) or {}
        parts = i.get("components") or {}
        return (
            f"{_g(i.get('value'))} [{_g(i.get('low'))}, {_g(i.get('high'))}] (fit ± "
            f"{_g(parts.get('fit'), 2)}, grid ± {_g(parts.get('grid'), 2)})"
        )

    grid = analyze.get("grid") or {}
    tensor = elastic.get("tensor_gpa")
    c = (
        f"C11 = {_g(tensor[0][0])}, C12 = {_g(tensor[0][1])}, C44 = {_g(tensor[3][3])} GPa; "
        if tensor
        else ""
    )
    prm = summary.get("parameters") or {}
    rows = [
        ("named stackings at P = 0 (meV/Å² above the lowest)", _stackings(first)),
        (
            "lowest barrier, direction (auto)",
            f"{_g(first.get('lowest_barrier_mev_per_a2'))} meV/Å², "
            f"{_g(first.get('lowest_barrier_direction_deg'))}°",
        ),
        (
            "τ at P = " + ", ".join(_g(p) for p in table["p_gpa"]) + " GPa (± grid)",
            ", ".join(
                f"{_g(t)} ± {_g(abs(e), 2)}"
                for t, e in zip(table["tau_mpa"], table["tau_grid_error_mpa"], strict=True)
            )
            + " MPa",
        ),
        ("τ = k·P + τ0", _law(laws, "k_mpa_per_gpa", "tau0_mpa", "k_stderr_mpa_per_gpa", "tau0_stderr_mpa") + " MPa (± fit s.e.)"),
        ("τ0 interval", interval("tau0_mpa") + " MPa"),
        ("k interval", interval("k_mpa_per_gpa") + " MPa/GPa"),
        ("σ = μ·P + σ0", _law(laws, "mu_mpa_per_gpa", "sigma0_mpa", "mu_stderr_mpa_per_gpa", "sigma0_stderr_mpa") + " MPa"),
        ("σ0 interval", interval("sigma0_mpa") + " MPa"),
        ("the grid's verdict", _grid_part(laws, analyze) + f" (τ estimator: {(grid.get('source') or {}).get('tau_mpa', '—')})"),
        ("elastic stage, same EAM", f"{c}E* = {_g(prm.get('contact_modulus_gpa'))}, G* = {_g(prm.get('shear_modulus_gpa'))} GPa"),
        ("W (ideal work of separation)", f"{_g((scan.get('adhesion') or {}).get('work_of_separation_j_per_m2'))} J/m²"),
        ("Q_peak/πa² at p0 = " + ", ".join(_g(r["p0_gpa"]) for r in summary.get("results", [])) + " GPa [interval]", _contact(summary) + " MPa"),
        ("wall", _wall(_json(d / "timings.json"))),
    ]  # fmt: skip
    return head + "".join(f"| {q} | {v} |\n" for q, v in rows)


def _twist(deg: float) -> str:
    """The sheet's rotation modulo 60° (hexagonal lattices), in (−30°, 30°]."""
    r = (float(deg) + 30.0) % 60.0 - 30.0
    return f"{_g(r, 5)}°"


def approximants_table(store: Path = STORE) -> str:
    head = (
        "| interface, cell | atoms | rotation of the sheet (mod 60°) | strain on graphene (largest magnitude) | "
        "shift-lattice index, grid | corrugation (meV/Å²) | floor (meV/Å²) | resolved | "
        "τ = k·P + τ0 (MPa) | σ = μ·P + σ0 (MPa) | gates fired | collapse at 1.77 GPa (MPa) | "
        "÷ 26.7 | scan force calls, cell wall |\n|" + "---|" * 14 + "\n"
    )
    rows = []
    for key, label in STUDIES.items():
        d = store / key
        if not (d / "approximants.csv").is_file():
            rows.append(f"| {label} | {NOT_REGENERATED} |" + " — |" * 12)
            continue
        cells = pd.read_csv(d / "approximants.csv", keep_default_na=False)
        collapse = {c["label"]: c for c in _json(d / "experiment_collapse.json").get("cells", [])}
        for _, c in cells.iterrows():
            col = collapse.get(c["label"], {})
            stress = col.get("collapse_stress_mpa")
            ratio = (col.get("ratio_to_measured") or {}).get("graphene-passivated SiOx")
            corr, floor = float(c["barrier_mev_per_a2"]), float(c["floor_mev_per_a2"])
            resolved = str(c["resolved"]) == "True"
            lock = " (the lock)" if int(c["shift_lattice_index"]) == 1 else ""
            rows.append(
                "| "
                + " | ".join(
                    (
                        f"{label}, {c['label']}{lock}",
                        str(c["atoms"]),
                        _twist(c["twist_deg"]),
                        f"{_g(float(c['strain_percent_slab2']), 3)} %",
                        f"{c['shift_lattice_index']}, {str(c['grid']).replace('x', '×')}",
                        _g(corr, 3),
                        _g(floor, 2),
                        f"{_g(corr / floor, 2)}×" + ("" if resolved else ": **not resolved**"),
                        f"{_g(float(c['k_mpa_per_gpa']), 3)}·P + {_g(float(c['tau0_mpa']), 4)}",
                        f"{_g(float(c['mu_mpa_per_gpa']), 3)}·P + {_g(float(c['sigma0_mpa']), 4)}",
                        str(c["gates"]).replace(";", ", ") or "none",
                        f"**{_g(stress, 3)}**" if stress is not None else "— (not resolved)",
                        _g(ratio, 2),
                        f"{c['force_calls']}, {_g(float(c['wall_s']), 3)} s",
                    )
                )
                + " |"
            )
    return head + "\n".join(rows) + "\n"


def _lock(build: dict) -> str:
    match = (build.get("recipe") or {}).get("match") or {}
    strain = match.get("slab2_strain_percent")
    if not strain or not any(abs(float(x)) > 1e-9 for x in strain):
        return "none (unstrained)"
    return f"{match.get('n_atoms', '?')} atoms, slab 2 {max(strain, key=abs):+.3g} %"


def _ratios(row: dict) -> tuple[str, str]:
    ratio = row.get("ratio_to_measured") or {}
    return _g(ratio.get("graphene-passivated SiOx"), 2), _g(ratio.get("bare SiOx"), 2)


def experiment_table(store: Path = STORE) -> str:
    """examples/README.md: the experiment's interfaces, their collapse stress at 1.77 GPa."""
    head = (
        "| interface (example) | wall (scan) | lock | barrier at P = 0 (meV/Å²) | "
        "τ = k·P + τ0 (MPa) | σ = μ·P + σ0 (MPa) | grid part; the grid's verdict | W (J/m²) | "
        "collapse at 1.77 GPa (MPa) [interval] | ÷ 26.7 (passivated) | ÷ 145 (bare SiOx) |\n|"
        + "---|" * 11
        + "\n"
    )
    rows, comparison = [], None
    for name, label in PASSIVATED:
        d = store / name
        if not (d / "06-contact" / "summary.json").is_file():
            rows.append(f"| {label} | {NOT_REGENERATED} |" + " — |" * 9)
            continue
        laws = _json(d / "04-laws" / "laws.json")
        summary = _json(d / "06-contact" / "summary.json")
        comparison = comparison or summary.get("experiment_comparison")
        run = (summary.get("experiment_comparison") or {}).get("run") or {}
        first = pd.read_csv(d / "03-analyze" / "friction.csv").sort_values("p_gpa").iloc[0]
        p0 = (summary.get("experiment_comparison") or {}).get("p0_gpa")
        bounds = [
            r["collapse_stress_mpa"]
            for r in (summary.get("intervals") or {}).get("results", [])
            if r.get("p0_gpa") == p0
        ]
        interval = f" [{_g(bounds[0]['low'])}, {_g(bounds[0]['high'])}]" if bounds else ""
        form = laws.get("energy_form", "internal")
        w = (_json(d / "02-scan" / "scan.json").get("adhesion") or {}).get(
            "work_of_separation_j_per_m2"
        )
        cells = (
            f"{label}" + ("" if form == "internal" else f" ({form} form)"),
            _wall(_json(d / "timings.json")),
            _lock(_json(d / "01-build" / "build.json")),
            _g(first.get("lowest_barrier_mev_per_a2")),
            _law(laws, "k_mpa_per_gpa", "tau0_mpa", "k_stderr_mpa_per_gpa", "tau0_stderr_mpa"),
            _law(
                laws, "mu_mpa_per_gpa", "sigma0_mpa", "mu_stderr_mpa_per_gpa", "sigma0_stderr_mpa"
            ),
            _grid_part(laws, _json(d / "03-analyze" / "analyze.json")),
            _g(w),
            f"**{_g(run.get('collapse_stress_mpa'))}**{interval}",
            *_ratios(run),
        )
        rows.append("| " + " | ".join(cells) + " |")
    rows += [f"| {label} | {NOT_REGENERATED} |" + " — |" * 9 for label in PASSIVATED_OTHER]
    if comparison is None:
        rows.append(f"| quartz references, measured collapses | {NOT_REGENERATED} |" + " — |" * 9)
        return head + "\n".join(rows) + "\n"
    for ref in comparison.get("references", []):
        law = (
            f"{_g(ref.get('k_mpa_per_gpa'))}·P + {_g(ref.get('tau0_mpa'))}",
            f"{_g(ref.get('mu_mpa_per_gpa'))}·P + {_g(ref.get('sigma0_mpa'))}",
        )
        rows.append(
            f"| {ref.get('label')} | — | — | — | {law[0]} | {law[1]} | — | — | "
            f"**{_g(ref.get('collapse_stress_mpa'), 3)}** | " + " | ".join(_ratios(ref)) + " |"
        )
    for what, value in (comparison.get("measured_mpa") or {}).items():
        rows.append(f"| measured, {what} (paper, Fig. 6) |" + " |" * 7 + f" **~{_g(value)}** | | |")
    return head + "\n".join(rows) + "\n"


TABLES = {
    "experiment": experiment_table,
    "runs": runs_table,
    "worked": worked_table,
    "approximants": approximants_table,
}


def render(text: str, store: Path = STORE) -> str:
    """``text`` with every marked table rewritten from ``store``."""

    def table(m: re.Match) -> str:
        return m.group(1) + TABLES[m.group("name")](store) + m.group(4)

    return MARK.sub(table, text)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=Path, help="directory of finished run directories")
    ap.add_argument("--studies", type=Path, help="directory of finished approximant studies")
    args = ap.parse_args(argv)
    if args.runs:
        for name in (*RUN_EXAMPLES, *(n for n, _ in PASSIVATED), WORKED):
            if (args.runs / name / "04-laws" / "laws.json").is_file():
                print(f"stored {store_run(args.runs / name, name).relative_to(ROOT)}")
    if args.studies:
        for name in STUDIES:
            if (args.studies / name / "approximants.csv").is_file():
                print(f"stored {store_study(args.studies / name, name).relative_to(ROOT)}")
    for doc in DOCS:
        text = doc.read_text()
        new = render(text)
        if new != text:
            doc.write_text(new)
            print(f"rewrote {doc.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
