"""How the cross-interface LJ cutoff moves the work of separation and the zero-load pressure.

One column (the probe stacking) of the reference interface scanned with the paper preset's
settings and LJ cutoffs of 10…30 Å: the work of separation W, the equilibrium thickness
and the extra adhesive pressure the tail adds at the reference equilibrium thickness
(from the probe column's p(z)). The tail is laterally almost
uniform, so it shifts the load: at nominal P the interface carries P − Δp_tail, and τ, σ
move by k·Δp_tail, μ·Δp_tail (enthalpy-form slopes). Cheap (one column per cutoff)::

    python -m benchmarks.convergence.lj_tail      # -> results/lj_tail.json
"""

from __future__ import annotations

import json

from benchmarks.convergence.study import HERE, RUNS

#: 30 Å overflows LAMMPS's per-atom neighbour list in this cell.
CUTOFFS_ANGSTROM = (10.0, 14.0, 18.0, 24.0)


def main() -> None:
    from flatcontact.config import build_config
    from flatcontact.ispes.grid import GridSpec
    from flatcontact.ispes.relax import RelaxSettings
    from flatcontact.ispes.scan import run_scan
    from flatcontact.potentials import InteractionModel
    from flatcontact.potentials.engines import calculator_factory
    from flatcontact.structures.interface_io import read_interface

    interface = read_interface(RUNS / "ref" / "01-build" / "interface.extxyz")
    base = build_config({}, "paper").potential.model_dump()
    rows = []
    for rc in CUTOFFS_ANGSTROM:
        spec = InteractionModel.model_validate(
            {**base, "lj": {**base["lj"], "cutoff_angstrom": rc}}
        )
        res = run_scan(
            interface,
            calculator_factory(spec),
            GridSpec(1, 1, p_range_gpa=(-0.3, 5.5, 20)),
            RUNS / "lj_tail" / f"probe_rc{rc:g}",
            RelaxSettings(0.005),
            executor_options={"kind": "serial"},
        )
        rows.append({"cutoff_angstrom": rc, **res.adhesion})
        print(rc, res.adhesion, flush=True)
    (HERE / "results" / "lj_tail.json").write_text(json.dumps({"rows": rows}, indent=1) + "\n")


if __name__ == "__main__":
    main()
