"""The 9-layer dense α-quartz (0001) interface of the ``layers9`` variant (slab-thickness step).

The bundled SNAP does not reach the dense reconstruction from a seeded cut, so the 9-layer
slab is made the way the shipped 6-layer one was: seeded dense faces relaxed with CHGNet
r2SCAN (:func:`flatcontact.structures.build.reconstruct_dense_slab`), then relaxed and
verified with the bundled SNAP, and the interface is built and relaxed with the SNAP +
calibrated LJ of the paper preset (:func:`flatcontact.structures.build.interface_from_slab`,
face layers of 2 O–Si–O units as in the 6-layer build) and verified again. Needs chgnet::

    python -m benchmarks.convergence.make_9l       # -> benchmarks/convergence/interface_9L.extxyz
"""

from __future__ import annotations

import json
import sys

from benchmarks.convergence.study import HERE, RESULTS

LAYERS = 9


def main() -> None:
    from flatcontact.config import build_config
    from flatcontact.potentials import make_calculator
    from flatcontact.structures.build import interface_from_slab, reconstruct_dense_slab
    from flatcontact.structures.dense import (
        DENSE_FACE_LAYERS,
        QUARTZ_ATOMS_PER_LAYER,
        relax,
        verify_dense_slab,
    )
    from flatcontact.structures.interface import write_interface
    from flatcontact.training.teachers import chgnet_r2scan

    spec = build_config({}, "paper").potential
    teacher = chgnet_r2scan()
    slab, record = reconstruct_dense_slab(
        LAYERS, lambda atoms: teacher, model_label="chgnet-r2scan", fmax_ev_per_angstrom=0.02
    )
    if slab is None:
        sys.exit(f"error: CHGNet did not reach a verified dense {LAYERS}-layer slab")
    slab = slab.copy()
    slab.calc = None
    outcome = relax(slab, make_calculator(spec, slab), fmax_ev_per_angstrom=0.01)
    verdict = verify_dense_slab(slab)
    if not verdict["dense"]:
        sys.exit(f"error: the SNAP does not keep the dense surface: {verdict['failures']}")
    face = DENSE_FACE_LAYERS * QUARTZ_ATOMS_PER_LAYER
    interface, report = interface_from_slab(
        slab, spec, face_atoms=face, source=f"dense {LAYERS}-layer slab (CHGNet seed, SNAP relaxed)"
    )
    checks = {w: verify_dense_slab(interface[interface.arrays["slab"] == w]) for w in (1, 2)}
    bad = {w: c["failures"] for w, c in checks.items() if not c["dense"]}
    if bad:
        sys.exit(f"error: the dense surface did not survive the interface relaxation: {bad}")
    write_interface(interface, HERE / "interface_9L.extxyz")
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / "interface_9L.json").write_text(
        json.dumps(
            {"seed_search": record, "slab_relaxation": outcome, "interface": report},
            indent=1,
            default=str,
        )
        + "\n"
    )
    print(
        f"wrote interface_9L.extxyz: {len(interface)} atoms, thickness {report['thickness_angstrom']:.3f} Å"
    )


if __name__ == "__main__":
    main()
