"""Does the relaxed quartz ISPES have the interface's two-fold symmetry? (issue 22)

``python -m benchmarks.quartz_symmetry [PRESET] [N]`` (default ``quick`` 12): the preset's
interface, its shift-space group (order 2 for the shipped α-quartz (0001) slabs: a two-fold
axis in the interface plane that swaps the slabs), and the preset's full relaxation at three
thicknesses (the reference, 0.3 Å closer, 0.5 Å apart) on the preset's N × N lateral grid:

1. the full scan (every point relaxed, the preset's warm-start tree): for every grid point
   the difference of the relaxed energy (meV/Å²) and normal load (GPa) from its image under
   the two-fold operation, largest and median;
2. the reduced scan of the same grid (``scan.symmetry`` on, ``verify_points`` 6): what the
   scan's own verification reports, and whether it falls back to the full grid.

Against the scan's tolerances (:class:`flatcontact.ispes.reduction.SymmetrySettings`:
1e-2 meV/Å², 0.5 GPa) and the relaxation's own precision (fmax / area in GPa).
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import numpy as np


def main(argv: list[str] | None = None) -> None:
    from flatcontact.config import load_config
    from flatcontact.ispes.contract import cell_area
    from flatcontact.ispes.executors import make_executor
    from flatcontact.ispes.geometry import in_plane_vectors, thickness
    from flatcontact.ispes.grid import GridSpec
    from flatcontact.ispes.reduction import SymmetrySettings
    from flatcontact.ispes.scan import run_scan
    from flatcontact.ispes.shift_symmetry import shift_space_group
    from flatcontact.stages import _calculator
    from flatcontact.stages.build import BuildInputs, build_stage
    from flatcontact.stages.scan import relax_settings

    argv = list(argv or [])
    preset = argv[0] if argv else "quick"
    n = int(argv[1]) if len(argv) > 1 else 12
    settings = load_config(preset_name=preset)
    reference = build_stage(settings, BuildInputs(), None).atoms
    factory = _calculator.factory(settings)
    relax = relax_settings(settings.scan)
    z0 = thickness(reference)
    grid = GridSpec(n, n, thickness_angstrom=(z0 - 0.3, z0, z0 + 0.5))
    group = shift_space_group(reference, spread_compression=relax.mode != "rigid").for_grid(n, n)
    area = cell_area(*in_plane_vectors(reference))
    print(
        f"{preset}: {len(reference)} atoms, relax {relax.mode}, fmax {relax.fmax_ev_per_angstrom} eV/Å "
        f"({relax.fmax_ev_per_angstrom / area * 160.2176634:.3g} GPa over the cell), group order "
        f"{group.order} on {n}x{n}: {[op.as_dict() for op in group.operations]}",
        flush=True,
    )
    images = group.grid_images(n, n)
    with tempfile.TemporaryDirectory() as tmp:
        executor = make_executor("processes", workers=2)
        try:
            t0 = time.perf_counter()
            full = run_scan(reference, factory, grid, Path(tmp) / "full", relax, executor=executor)
            t_full = time.perf_counter() - t0
            e = full.dataset["energy"].transpose("shift_a", "shift_b", "thickness").values  # eV
            p = full.dataset["normal_stress"].transpose("shift_a", "shift_b", "thickness").values
            for k in range(1, group.order):
                ja, jb = images[k][..., 0], images[k][..., 1]
                de = np.abs(e - e[ja, jb, :]) / area * 1e3
                dp = np.abs(p - p[ja, jb, :])
                worst = np.unravel_index(np.argmax(de), de.shape)
                print(
                    f"full scan ({t_full:.0f} s): operation {k}: |E(s) - E(g.s)| max "
                    f"{de.max():.3g} meV/Å² at {tuple(int(v) for v in worst)}, median "
                    f"{np.median(de):.3g}; per thickness max "
                    f"{[float(f'{v:.3g}') for v in de.max(axis=(0, 1))]}; "
                    f"|p(s) - p(g.s)| max {dp.max():.3g} GPa, median {np.median(dp):.3g}; "
                    f"energy range {np.ptp(e) / area * 1e3:.3g} meV/Å²",
                    flush=True,
                )
            t0 = time.perf_counter()
            reduced = run_scan(
                reference,
                factory,
                grid,
                Path(tmp) / "reduced",
                relax,
                executor=executor,
                symmetry=SymmetrySettings(verify_points=6),
            )
            t_red = time.perf_counter() - t0
        finally:
            executor.close()
        sym = reduced.symmetry or {}
        check = sym.get("verification") or {}
        print(
            f"reduced scan ({t_red:.0f} s): {reduced.points_stored} points relaxed of "
            f"{reduced.points_total}; verification: {check.get('points')} points, max "
            f"{check.get('max_energy_difference_mev_per_a2', float('nan')):.3g} meV/Å², "
            f"{check.get('max_stress_difference_gpa', float('nan')):.3g} GPa; computed in full: "
            f"{sym.get('computed_in_full')}",
            flush=True,
        )
        if not sym.get("computed_in_full"):
            e_r = reduced.dataset["energy"].transpose("shift_a", "shift_b", "thickness").values
            p_r = (
                reduced.dataset["normal_stress"].transpose("shift_a", "shift_b", "thickness").values
            )
            print(
                f"reduced vs full: max |ΔE| {np.max(np.abs(e_r - e)) / area * 1e3:.3g} meV/Å², "
                f"max |Δp| {np.max(np.abs(p_r - p)):.3g} GPa",
                flush=True,
            )


if __name__ == "__main__":
    main(sys.argv[1:])
