"""Work of separation W against slab thickness (6, 9, 12 layers) at LJ cutoffs 10 and 18 Å.

The 8×8 slab-thickness variants of ``study.py`` use the study's 10 Å cross-interface LJ
cutoff, which sees little of a slab beyond its first ~10 Å. The paper preset's 18 Å cutoff
reaches through a whole 6-layer slab (about 9 Å of atoms per slab), so a thicker slab adds
vdW partners and W may grow with thickness there. One column (the probe stacking) per
(layers, cutoff), each interface built by its own recipe with that potential, scanned with
the paper preset's settings (like ``lj_tail.py``)::

    python -m benchmarks.convergence.layers_w      # -> results/layers_w.json
"""

from __future__ import annotations

import json
import time

from benchmarks.convergence.study import HERE, RUNS, THICK_SLAB_P_RANGE

LAYERS = (6, 9, 12)
CUTOFFS_ANGSTROM = (10.0, 18.0)


def main() -> None:
    from flatcontact.config import build_config
    from flatcontact.ispes.grid import GridSpec
    from flatcontact.ispes.relax import RelaxSettings
    from flatcontact.ispes.scan import run_scan
    from flatcontact.potentials.engines import calculator_factory
    from flatcontact.structures.construct import build_interface

    rows = []
    for rc in CUTOFFS_ANGSTROM:
        for layers in LAYERS:
            cfg = build_config(
                {
                    "structure": {"layers": layers},
                    "potential": {"lj": {"cutoff_angstrom": rc}},
                },
                "paper",
                f"layers {layers}, LJ {rc:g} Å",
            )
            t0 = time.perf_counter()
            interface, report = build_interface(cfg.structure, potential=cfg.potential)
            p = THICK_SLAB_P_RANGE.get(layers, {"lo_gpa": -0.3, "hi_gpa": 5.5, "n": 20})
            res = run_scan(
                interface,
                calculator_factory(cfg.potential),
                GridSpec(1, 1, p_range_gpa=(p["lo_gpa"], p["hi_gpa"], p["n"])),
                RUNS / "layers_w" / f"L{layers}_rc{rc:g}",
                RelaxSettings(cfg.scan.fmax_ev_per_angstrom),
                executor_options={"kind": "serial"},
            )
            row = {
                "layers": layers,
                "cutoff_angstrom": rc,
                "n_atoms": len(interface),
                "reference_thickness_angstrom": report["thickness_angstrom"],
                **res.adhesion,
                "seconds": time.perf_counter() - t0,
            }
            rows.append(row)
            print(json.dumps(row), flush=True)
    (HERE / "results" / "layers_w.json").write_text(json.dumps({"rows": rows}, indent=1) + "\n")


if __name__ == "__main__":
    main()
