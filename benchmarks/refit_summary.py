"""α-quartz lattice, Cij (relaxed- and clamped-ion) and held-out errors of SNAP training outputs.

Usage (no torch; LAMMPS only)::

    python -m benchmarks.refit_summary OUT.json DIR [DIR ...]

Each DIR holds one ``*.snapcoeff`` (with its ``.snapparam``), ``test.extxyz`` and
``provenance.json`` (``train-snap`` or ``benchmarks.refit_weights`` output). Writes, per DIR,
the lattice, the trigonal Cij (±0.5 %, relaxed-ion as ``flatcontact elastic`` and
clamped-ion), E*, their relative errors against :mod:`flatcontact.foundation.reference`, the held-out
RMSEs per group against the labels of ``test.extxyz``, and the group weights and descriptor.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from flatcontact.elastic import elastic_tensor, quartz_contact_moduli, trigonal_constants
from flatcontact.foundation.reference import (
    QUARTZ_CIJ_EXPERIMENT_GPA,
    QUARTZ_LATTICE_EXPERIMENT_ANGSTROM,
)
from flatcontact.potentials.engines import bulk_calculator
from flatcontact.training.dataset import read_dataset
from flatcontact.training.validate import dataset_errors, quartz_lattice


def summarise(folder: Path) -> dict:
    """One row of the summary for the SNAP in ``folder``."""
    (coeff,) = sorted(folder.glob("*.snapcoeff"))
    calc = bulk_calculator(str(coeff))
    m = quartz_contact_moduli(str(coeff))
    relaxed, _ = quartz_lattice(calc)
    clamped = trigonal_constants(elastic_tensor(relaxed, calc, strain=0.005, relax_ions=False))
    exp = {k: abs(v) for k, v in QUARTZ_CIJ_EXPERIMENT_GPA.items()}
    cij = {k: abs(v) if k == "C14" else v for k, v in m["cij_gpa"].items()}
    prov = json.loads((folder / "provenance.json").read_text())
    err = dataset_errors(read_dataset(folder / "test.extxyz", ["Si", "O"]), calc)
    return {
        "folder": folder.name,
        "teacher": prov.get("teacher"),
        "hyper": prov.get("hyper"),
        "group_weights": prov["settings"]["group_weights"],
        "refit": prov.get("refit"),
        "a_angstrom": m["a_angstrom"],
        "c_angstrom": m["c_angstrom"],
        "rel_a": m["a_angstrom"] / QUARTZ_LATTICE_EXPERIMENT_ANGSTROM["a"] - 1,
        "rel_c": m["c_angstrom"] / QUARTZ_LATTICE_EXPERIMENT_ANGSTROM["c"] - 1,
        "cij_gpa": cij,
        "cij_clamped_ion_gpa": {k: float(v) for k, v in clamped.items()},
        "rel_error_vs_experiment": {k: cij[k] / exp[k] - 1 for k in exp},
        "e_star_gpa": m["moduli_gpa"]["e_star"],
        "heldout": err,
    }


def main(argv: list[str] | None = None) -> None:
    argv = sys.argv[1:] if argv is None else argv
    out, folders = Path(argv[0]), [Path(a) for a in argv[1:]]
    rows = [summarise(f) for f in folders]
    out.write_text(json.dumps(rows, indent=1) + "\n")
    for r in rows:
        c, e = r["cij_gpa"], r["rel_error_vs_experiment"]
        print(
            f"{r['folder']:>16}: a {r['a_angstrom']:.3f} c {r['c_angstrom']:.3f}  "
            f"C11 {c['C11']:.1f} ({e['C11']:+.1%})  C33 {c['C33']:.1f} ({e['C33']:+.1%})  "
            f"C44 {c['C44']:.1f} ({e['C44']:+.1%})"
        )


if __name__ == "__main__":
    main()
