"""Teachers vs the bundled SNAP: α-quartz elasticity and the ISPES quantities (issue 12).

Needs torch (CPU) + chgnet + sevenn, e.g. in a separate venv (docs/teachers.md)::

    python -m benchmarks.convergence.teachers elastic [NAME ...]   # results/elastic_<name>.json
    python -m benchmarks.convergence.teachers ispes [NAME ...]     # results/ispes_compare_{internal,enthalpy}.{json,csv}
    python -m benchmarks.convergence.teachers ispes snap sevennet-mf-0-r2scan --reuse chgnet-r2scan
    python -m benchmarks.convergence.teachers table                # the docs/teachers.md tables

Elastic: :func:`flatcontact.training.ispes_check.quartz_elastic_vs_experiment` per model.
ISPES: :func:`flatcontact.training.ispes_check.compare_ispes` on the interface built by the
reference run of the convergence study (the paper preset's build, bundled SNAP), 4×4
lateral grid, 8 thicknesses spanning −0.3…5.5 GPa at the probe stacking (the current scan
adds 2 tensile ones), fmax 0.005 eV/Å, loads 0…3 GPa; each teacher inside each slab + the
same calibrated LJ across. The SNAP row is first (the reference of the table): d_<q> =
model − SNAP. Both energy forms are analysed from the same scans. ``table`` needs no torch.
The model spread of the laws over every model written here enters the paper preset through
:mod:`benchmarks.convergence.uncertainty`.
"""

from __future__ import annotations

import json
import os
import sys

from benchmarks.convergence.study import RESULTS, RUNS, config_for

#: "snap" is the bundled ``sio2-snap`` (CHGNet r2SCAN labels, the paper preset's), "snap-mf0"
#: the bundled ``sio2-snap-mf0`` (SevenNet-MF-0 r2SCAN labels, refit to its teacher's Cij).
SURROGATES = {"snap": "sio2-snap", "snap-mf0": "sio2-snap-mf0"}
MODELS = [
    "snap",
    "snap-mf0",
    "chgnet-r2scan",
    "sevennet-0",
    "sevennet-mf-0-r2scan",
    "sevennet-mf-0-pbe",
]
ISPES_GRID = (4, 4)
ISPES_P_RANGE = (-0.3, 5.5, 8)
ISPES_LOADS = (0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0)
#: Resumable scan stores, one per model. "teachers-v2": the stores of the first comparison
#: (``RUNS/teachers``) carry the store fingerprint of before the potential-model refactor
#: and are refused by the current code; their results stay usable through ``--reuse``.
ISPES_RUNS = RUNS / "teachers-v2"


def bulk(name: str):
    from flatcontact.potentials.engines import bulk_calculator
    from flatcontact.training.ispes_check import teacher_calculator

    return bulk_calculator(SURROGATES[name]) if name in SURROGATES else teacher_calculator(name)


def elastic(names: list[str]) -> None:
    from flatcontact.training.ispes_check import quartz_elastic_vs_experiment

    RESULTS.mkdir(parents=True, exist_ok=True)
    for name in names:
        doc = quartz_elastic_vs_experiment(bulk(name), name)
        (RESULTS / f"elastic_{name}.json").write_text(json.dumps(doc, indent=1) + "\n")
        cij = ", ".join(f"{k} {v:.1f}" for k, v in doc["cij_gpa"].items())
        print(
            f"{name}: a {doc['lattice']['a_angstrom']:.4f} c {doc['lattice']['c_angstrom']:.4f}; {cij}; {doc['seconds']:.0f} s",
            flush=True,
        )


def ispes(names: list[str], reuse: list[str] = ()) -> None:
    """Scan ``names`` (resumable stores in :data:`ISPES_RUNS`) and write the comparison.

    ``reuse``: models whose per-model results are taken from the results JSON already
    written (``results/ispes_compare_<form>.json``) instead of being scanned, in the order
    of ``names``; e.g. CHGNet, whose store predates the current store fingerprint.
    """
    from flatcontact.potentials import InteractionModel
    from flatcontact.structures.interface_io import read_interface
    from flatcontact.training.ispes_check import compare_ispes, comparison_table, teacher_spec

    interface = read_interface(RUNS / "ref" / "01-build" / "interface.extxyz")
    # Layer ids only steer the rigid-layers relax mode; these scans relax fully (same atoms,
    # cell and tags as the stores of the first comparison).
    interface.arrays.pop("layer", None)
    # the study's reference model (LJ cut at 10 Å, as the teachers' default_potential() LJ)
    snap = config_for("ref").potential
    lj = snap.lj.model_dump()
    stored = {}
    for form in ("internal", "enthalpy"):
        path = RESULTS / f"ispes_compare_{form}.json"
        old = json.loads(path.read_text()) if path.exists() else {}
        missing = [name for name in reuse if name not in old]
        if missing:
            sys.exit(f"error: {path} has no results for {missing}; scan them instead")
        stored[form] = {name: old[name] for name in reuse}
    models = {}
    for name in names:
        if name in reuse:
            continue
        models[name] = (
            InteractionModel.model_validate(
                snap.model_dump() | {"intra": f"snap:{SURROGATES[name]}"}
            )
            if name in SURROGATES
            else teacher_spec(name, lj)
        )
    RESULTS.mkdir(parents=True, exist_ok=True)
    for form in ("internal", "enthalpy"):  # the second reuses the scans (resumable stores)
        scanned: dict = {}
        compare_ispes(
            models,
            interface,
            ISPES_RUNS,
            grid=ISPES_GRID,
            p_range_gpa=ISPES_P_RANGE,
            p_gpa=ISPES_LOADS,
            form=form,
            results=scanned,
        )
        per_model = {
            name: (stored[form][name] | {"reused": True}) if name in reuse else scanned[name]
            for name in names
        }
        table = comparison_table(per_model)
        table.to_csv(RESULTS / f"ispes_compare_{form}.csv", index=False)
        (RESULTS / f"ispes_compare_{form}.json").write_text(
            json.dumps(per_model, indent=1, default=float) + "\n"
        )
        print(form, table.to_string(), flush=True)


def _first_scan(form: str) -> dict | None:
    path = RESULTS / f"ispes_snap_first_scan_{form}.json"
    return json.loads(path.read_text()) if path.exists() else None


def markdown_tables() -> str:
    """docs/teachers.md tables from ``results/ispes_compare_<form>.json``: per load τ and
    σ_MSS of every model with its difference from the SNAP (first model), the SNAP's
    rescan difference |Δ| (``results/ispes_snap_first_scan_<form>.json``: the same model and
    settings scanned with another warm-start history, the resolution noise), and per model
    the laws and W."""
    out = []
    for form in ("internal", "enthalpy"):
        per_model = json.loads((RESULTS / f"ispes_compare_{form}.json").read_text())
        labels = list(per_model)
        ref = labels[0]
        rows = {m: {round(r["p_gpa"], 6): r for r in per_model[m]["rows"]} for m in labels}
        first = _first_scan(form)
        noise = {round(r["p_gpa"], 6): r for r in first["rows"]} if first else {}
        out.append(f"**{form} form** (Δ = model − {ref}; noise = |{ref} − its first scan|)\n")
        head = ["P (GPa)"] + [f"τ {m}" for m in labels] + [f"σ {m}" for m in labels]
        head += [f"Δτ/τ, Δσ/σ {m}" for m in labels[1:]]
        if noise:
            head += ["noise τ, σ"]
        out.append("| " + " | ".join(head) + " |")
        out.append("|" + "---|" * len(head))

        def tau(r):
            if r is None or r.get("tau_mpa") is None:
                return "n/a"
            lim = {"barrier top": "barr", "jump": "jump"}.get(r.get("tau_limited_by"), "?")
            return f"{r['tau_mpa']:.1f} ({lim})"

        for p in sorted(rows[ref]):
            cells = [f"{p:g}"] + [tau(rows[m].get(p)) for m in labels]
            cells += [
                f"{rows[m][p]['sigma_mss_mpa']:.2f}" if p in rows[m] else "n/a" for m in labels
            ]
            base = rows[ref][p]
            for m in labels[1:]:
                r = rows[m].get(p)
                if r is None:
                    cells.append("n/a")
                    continue
                dt = (r["tau_mpa"] - base["tau_mpa"]) / abs(base["tau_mpa"])
                ds = (r["sigma_mss_mpa"] - base["sigma_mss_mpa"]) / abs(base["sigma_mss_mpa"])
                cells.append(f"{100 * dt:+.0f}%, {100 * ds:+.0f}%")
            if noise:
                n = noise.get(p)
                cells.append(
                    "n/a"
                    if n is None
                    else f"{100 * abs(base['tau_mpa'] - n['tau_mpa']) / abs(n['tau_mpa']):.0f}%, "
                    f"{100 * abs(base['sigma_mss_mpa'] - n['sigma_mss_mpa']) / abs(n['sigma_mss_mpa']):.0f}%"
                )
            out.append("| " + " | ".join(cells) + " |")
        out.append("")
        for m in labels:
            lw, res = per_model[m]["laws"], per_model[m]

            def c(key, err, digits, lw=lw):
                if lw.get(key) is None:
                    return "n/a"
                return f"{lw[key]:.{digits}f} ± {lw[err]:.{digits}f}"

            out.append(
                f"- {m}: k = {c('k_mpa_per_gpa', 'k_stderr_mpa_per_gpa', 1)} MPa/GPa, "
                f"τ0 = {c('tau0_mpa', 'tau0_stderr_mpa', 1)} MPa, "
                f"μ = {c('mu_mpa_per_gpa', 'mu_stderr_mpa_per_gpa', 2)} MPa/GPa, "
                f"σ0 = {c('sigma0_mpa', 'sigma0_stderr_mpa', 2)} MPa; "
                f"W = {res['work_of_separation_j_per_m2']:.4f} J/m²; {res['force_calls']} force calls"
            )
        out.append("")
    return "\n".join(out)


def main(argv: list[str]) -> None:
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    if argv[:1] == ["table"]:
        print(markdown_tables())
        return
    if not argv or argv[0] not in ("elastic", "ispes"):
        sys.exit(
            "usage: python -m benchmarks.convergence.teachers elastic|ispes [NAME ...] "
            "[--reuse NAME ...] | table"
        )
    args = argv[1:]
    reuse: list[str] = []
    if "--reuse" in args:
        k = args.index("--reuse")
        args, reuse = args[:k], args[k + 1 :]
    names = args + [name for name in reuse if name not in args] if args or reuse else MODELS
    unknown = sorted(set(names) - set(MODELS))
    if unknown:
        sys.exit(f"error: unknown model(s) {unknown}; expected some of {MODELS}")
    if argv[0] == "elastic":
        if reuse:
            sys.exit("error: --reuse applies to 'ispes' only")
        elastic(names)
    else:
        ispes(names, reuse)


if __name__ == "__main__":
    main(sys.argv[1:])
