"""Teachers vs the bundled SNAP: α-quartz elasticity and the ISPES quantities (issue 12).

Needs torch (CPU) + chgnet + sevenn, e.g. in a separate venv (docs/teachers.md)::

    python -m benchmarks.convergence.teachers elastic [NAME ...]   # results/elastic_<name>.json
    python -m benchmarks.convergence.teachers ispes [NAME ...]     # results/ispes_compare_{internal,enthalpy}.{json,csv}

Elastic: :func:`flatcontact.training.ispes_check.quartz_elastic_vs_experiment` per model.
ISPES: :func:`flatcontact.training.ispes_check.compare_ispes` on the interface built by the
reference run of the convergence study (the paper preset's build, bundled SNAP), 4×4
lateral grid, 8 thicknesses spanning −0.3…5.5 GPa at the probe stacking, fmax
0.005 eV/Å, loads 0…3 GPa; each teacher inside each slab + the same calibrated LJ across.
The SNAP row is first (the reference of the table): d_<q> = model − SNAP. Both energy
forms are analysed from the same scans.
"""

from __future__ import annotations

import json
import os
import sys

from benchmarks.convergence.study import RESULTS, RUNS, config_for

MODELS = ["snap", "chgnet-r2scan", "sevennet-0", "sevennet-mf-0-r2scan", "sevennet-mf-0-pbe"]
ISPES_GRID = (4, 4)
ISPES_P_RANGE = (-0.3, 5.5, 8)
ISPES_LOADS = (0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0)


def bulk(name: str):
    from flatcontact.training.ispes_check import teacher_calculator
    from flatcontact.training.potentials import bulk_calculator

    return bulk_calculator("sio2-snap") if name == "snap" else teacher_calculator(name)


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


def ispes(names: list[str]) -> None:
    from flatcontact.potentials import PotentialSpec
    from flatcontact.structures.interface import read_interface
    from flatcontact.training.ispes_check import compare_ispes, teacher_spec

    interface = read_interface(RUNS / "ref" / "01-build" / "interface.extxyz")
    # the study's reference model (LJ cut at 10 Å, as the teachers' default_potential() LJ)
    snap = config_for("ref").potential
    lj = snap.lj.model_dump()
    models = {}
    for name in names:
        models[name] = (
            PotentialSpec.model_validate(snap.model_dump())
            if name == "snap"
            else teacher_spec(name, lj)
        )
    RESULTS.mkdir(parents=True, exist_ok=True)
    for form in ("internal", "enthalpy"):  # the second reuses the scans (resumable stores)
        per_model: dict = {}
        table = compare_ispes(
            models,
            interface,
            RUNS / "teachers",
            grid=ISPES_GRID,
            p_range_gpa=ISPES_P_RANGE,
            p_gpa=ISPES_LOADS,
            form=form,
            results=per_model,
        )
        table.to_csv(RESULTS / f"ispes_compare_{form}.csv", index=False)
        (RESULTS / f"ispes_compare_{form}.json").write_text(
            json.dumps(per_model, indent=1, default=float) + "\n"
        )
        print(form, table.to_string(), flush=True)


def main(argv: list[str]) -> None:
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    if not argv or argv[0] not in ("elastic", "ispes"):
        sys.exit("usage: python -m benchmarks.convergence.teachers elastic|ispes [NAME ...]")
    names = argv[1:] or MODELS
    unknown = sorted(set(names) - set(MODELS))
    if unknown:
        sys.exit(f"error: unknown model(s) {unknown}; expected some of {MODELS}")
    {"elastic": elastic, "ispes": ispes}[argv[0]](names)


if __name__ == "__main__":
    main(sys.argv[1:])
