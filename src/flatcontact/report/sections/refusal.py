"""The box at the top of a refused run's report: which stage refused, on which points, and
what to change.

A run that got past the scan and was stopped later (a validity gate before the contact stage,
:mod:`flatcontact.analysis.gates`; a fold or a load outside the data in the analysis; a law
the contact model cannot take) still writes its report: the sections of the stages that
finished, and this one above them. The refusal record (``refusal.json`` in the report's
folder, :func:`refusal_record`) holds the refused stage, its one-line message, each gate that
fired with its points (the loads, columns and numbers of its message) and the remedies
(:func:`remedies`): the gate's own and, where the refusal can be the grid's, the grid (a
negative slope: τ and σ_MSS per load carry the lateral grid's discretisation error; a fold: the
energy-derived load is a spline derivative between thickness nodes).
"""

from __future__ import annotations

import math

from flatcontact.report.html import Section, Table

#: A grid this much finer per lateral axis is the one the grid remedy names.
GRID_REFINEMENT = 1.5

#: The remedies of each gate besides its message's own, in the order to try them.
GATE_REMEDIES: dict[str, tuple[str, ...]] = {
    "in_slab_slip": (
        "hold the slabs' inner planes laterally: scan.relax_mode: normal",
        "hold more layers of each slab: structure.held_layers",
    ),
    "broken_symmetry": (
        "scan.relax_mode: normal (equivalent stackings then cannot relax into different states)",
        "a smaller scan.fmax_ev_per_angstrom (a relaxation branch that depends on the scan order)",
        "{grid}: on a coarse grid one point's relaxation error is a large part of the map",
    ),
    "load_fold": (
        "tighten scan.fmax_ev_per_angstrom (points that stopped short of their minimum: the "
        "fold is then the relaxation's)",
        "scan.relax_mode: normal if a plane slips (scan.json layer_slip)",
        "more thicknesses around the fold (scan.p_range_gpa.n, or scan.thickness_angstrom): the "
        "load -(1/A) dU/dz is a spline derivative between thickness nodes, and a fold between "
        "two close nodes can be the grid's",
        "loads below the fold: analysis.p_gpa, scan.p_range_gpa.hi_gpa",
    ),
    "negative_slope": (
        "{grid}: τ and σ_MSS at each load carry the lateral grid's discretisation error, which "
        "can exceed their change with the load and turn the slope's sign (a convergence study, "
        "flatcontact study convergence, shows which grid resolves them)",
        "check τ and σ_MSS per load in 03-analyze/friction.csv for a fold, slip or a change of "
        "minimum",
        "give the law: contact.k_mpa_per_gpa / contact.mu_mpa_per_gpa",
    ),
    "degenerate_minima": (
        "{grid}: minima within the degeneracy tolerance are separated better on a finer grid",
        "fewer or lower loads: analysis.p_gpa",
    ),
}
#: The remedies of a refusal in the analysis stage, by what its message says.
ANALYSIS_REMEDIES: dict[str, tuple[str, ...]] = {
    "fold": GATE_REMEDIES["load_fold"],
    "outside the data": (
        "thicknesses that reach the load: scan.p_range_gpa (hi_gpa, lo_gpa) or "
        "scan.thickness_angstrom",
        "loads inside the data: analysis.p_gpa",
    ),
}
#: Always offered: go on with the numbers, stated as untrusted in the report.
ACCEPT = (
    "to go on with these numbers anyway, list the gates in contact.accept_untrusted (the "
    "report then names the numbers not to be trusted)"
)


def finer_grid(grid: tuple[int, int] | list[int]) -> str:
    """``"a finer lateral grid, scan.grid: [9, 9] (now [6, 6])"``."""
    n_a, n_b = (int(v) for v in grid)
    fine = [math.ceil(GRID_REFINEMENT * n_a), math.ceil(GRID_REFINEMENT * n_b)]
    return f"a finer lateral grid, scan.grid: [{fine[0]}, {fine[1]}] (now [{n_a}, {n_b}])"


def _analysis_kind(message: str) -> str | None:
    text = message.lower()
    if "fold" in text or "not monotonic" in text:
        return "fold"
    if "outside the data" in text:
        return "outside the data"
    return None


def remedies(record: dict, grid: tuple[int, int] | list[int]) -> list[str]:
    """The remedies of a refusal ``record`` (:func:`refusal_record`), the gates' in the order
    of their findings, each once; the grid of ``scan.grid`` named where it applies."""
    out: list[str] = []
    fine = finer_grid(grid)
    for finding in record.get("findings") or []:
        out += [r.format(grid=fine) for r in GATE_REMEDIES.get(finding["gate"], ())]
    kind = _analysis_kind(record.get("message", "")) if record.get("stage") == "analyze" else None
    survived = (record.get("fold_rerelaxation") or {}).get("surviving")
    if kind is not None:
        out += [r.format(grid=fine) for r in ANALYSIS_REMEDIES[kind]]
    folded = kind == "fold" or any(f["gate"] == "load_fold" for f in record.get("findings") or [])
    if survived and folded:  # the tighter fmax was tried: the fold is not the relaxation's
        out = [r for r in out if not r.startswith("tighten scan.fmax_ev_per_angstrom")]
    if record.get("findings"):
        out.append(ACCEPT)
    return list(dict.fromkeys(out))


def refusal_record(
    stage: str,
    message: str,
    findings: list[dict],
    finished: list[str],
    grid: tuple[int, int] | list[int],
    load_folds: list[dict] | None = None,
    fold_rerelaxation: dict | None = None,
) -> dict:
    """``refusal.json``: the refused ``stage``, its one-line ``message``, the gate
    ``findings`` (``{"gate", "message"}``: the message names the points and numbers), the
    ``load_folds`` the scan recorded (column, z, p, the loads refused), the scan's
    re-relaxation of folds (``scan.json`` ``fold_rerelaxation``,
    :mod:`flatcontact.ispes.rerelax`), the stages that ``finished`` and the :func:`remedies`
    (a fold that survived the tighter fmax is not told to tighten it)."""
    record = {
        "stage": stage,
        "message": message,
        "findings": [{"gate": f["gate"], "message": f["message"]} for f in findings],
        "load_folds": list(load_folds or []),
        "fold_rerelaxation": fold_rerelaxation,
        "finished": list(finished),
    }
    record["remedies"] = remedies(record, grid)
    return record


def refusal_section(record: dict) -> Section:
    """The section of a refused run (:func:`refusal_record`), above every other."""
    stage = record["stage"]
    finished = ", ".join(record.get("finished") or []) or "none"
    paragraphs = [
        f"The run stopped at the {stage} stage: the stages after it did not run, and no "
        "contact numbers exist. This report shows what was computed (finished stages: "
        f"{finished}); rerunning after a change redoes only the stages the change reaches."
    ]
    findings = record.get("findings") or []
    if findings:  # the refusal's message is made of them
        notes = [f"Gate {f['gate']} fired: {f['message']}" for f in findings]
    else:
        notes = [f"Refused ({stage}): {record['message']}"]
    tables = []
    folds = record.get("load_folds") or []
    if folds:
        rows = [
            (
                str(f.get("column", "?")),
                f"{float(f.get('z_angstrom', math.nan)):.4f}",
                f"{float(f.get('p_gpa', math.nan)):.4g}",
                ", ".join(f"{v:g}" for v in f.get("loads_refused_gpa", [])) or "—",
            )
            for f in folds
        ]
        tables.append(
            Table(
                ("column", "z (Å)", "p at the fold (GPa)", "loads refused (GPa)"),
                rows,
                "Folds the scan recorded (scan.json load_folds)",
            )
        )
    redone = record.get("fold_rerelaxation") or {}
    if redone.get("found"):
        fmax = redone.get("fmax_ev_per_angstrom")
        gone, kept = redone.get("remedied") or [], redone.get("surviving") or []
        notes.append(
            f"Before refusing, the scan re-relaxed the windows of {len(redone['found'])} folding "
            f"column(s) at fmax {fmax:g} eV/Å ({len(redone.get('points') or [])} points): "
            f"{len(gone)} fold(s) gone (the relaxation's), {len(kept)} survived"
            + (f" ({', '.join(w['column'] for w in kept[:4])})" if kept else "")
        )
    remedies_list = record.get("remedies") or []
    if remedies_list:
        notes.append(
            "What to change:\n" + "\n".join(f"{i}. {r}" for i, r in enumerate(remedies_list, 1))
        )
    return Section("Run refused", paragraphs, tables=tables, notes=notes)
