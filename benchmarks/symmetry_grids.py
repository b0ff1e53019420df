"""Saddles and per-load τ, σ_MSS at 6×6 and 12×12, with and without the shift-space symmetry.

``python -m benchmarks.symmetry_grids OUT_DIR [EXAMPLE]`` (default ``cu111-eam``) scans
``examples/EXAMPLE.yaml``'s interface at
6×6 and 12×12, reduced (irreducible registries, the group stored in ispes.nc, so the
analysis's interpolant is symmetrised) and full (every point relaxed, no group stored: the
plain interpolant), and analyses each grid at the example's loads. The reduced grids are
also analysed without symmetrising (``analyze_ispes(symmetrise=False)``) to separate the
scan's part from the interpolant's. Printed per grid: the named stationary points at P = 0
(meV/Å²), the lowest barrier (for Cu against the plain-LAMMPS γ_usf = 10.116 meV/Å² of
/work/shared/NOTES.md), the analysis's C3 deviation and kept operations at P = 0, and τ,
σ_MSS (MPa) per load. Scans stay in OUT_DIR (rerun: resumed from the stores).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

from benchmarks.bench_symmetry import EXAMPLES, scan_example

#: plain-LAMMPS γ_usf of the Mishin EAM, relaxation along z (matscipy agrees), meV/Å²
GAMMA_USF_MEV_PER_A2 = 10.116


def analyse(ds, symmetrise: bool, example: str = "cu111-eam"):
    from flatcontact.analysis.analyze import analyze_ispes
    from flatcontact.analysis.options import AnalysisOptions
    from flatcontact.config.load import load_config

    a = load_config(EXAMPLES / f"{example}.yaml").analysis
    return analyze_ispes(
        ds,
        a.p_gpa,
        AnalysisOptions(
            direction_deg=a.direction_deg,
            form=a.energy_form,
            load_source=a.load_source,
            energy_zero=a.energy_zero,
            threshold_gpa=None,
            symmetrise=symmetrise,
        ),
    )


def row(label: str, result, reference_mev_per_a2: float | None = None) -> str:
    pa0 = result.pressures[0]
    st = pa0.stackings
    names = ", ".join(
        f"{p.name} {1e3 * p.energy:.3f}"
        for p in sorted(st.points, key=lambda p: p.energy)
        if p.kind != "minimum" or p.energy > 1e-9
    )
    saddles = sorted({round(1e3 * p.energy, 3) for p in st.points if p.kind == "saddle"})
    c3 = [op for op in pa0.symmetry.operations if op.name == "C3"]
    c3_dev = f"{100 * c3[0].deviation:.2g} %" if c3 else "n/a"
    tau = ", ".join(f"{pa.friction.tau_mpa:.1f}" for pa in result.pressures)
    sig = ", ".join(f"{pa.friction.sigma_mss_mpa:.2f}" for pa in result.pressures)
    barrier = 1e3 * st.barrier
    versus = (
        f" ({100 * (barrier / reference_mev_per_a2 - 1):+.2f} % vs γ_usf)"
        if reference_mev_per_a2
        else ""
    )
    return (
        f"{label} | {names} | saddle classes {len(saddles)}: {saddles} | barrier {barrier:.3f}"
        f"{versus} | C3 {c3_dev}; kept "
        f"{', '.join(pa0.symmetry.kept)} | τ {tau} | σ {sig}"
    )


def main(argv: list[str]) -> None:
    out = Path(argv[0]) if argv else Path("symmetry-grids")
    example = argv[1] if len(argv) > 1 else "cu111-eam"
    ref = GAMMA_USF_MEV_PER_A2 if example == "cu111-eam" else None
    for n in (6, 12):
        for reduced in (True, False):
            name = f"{n}x{n}-{'reduced' if reduced else 'full'}"
            t0 = time.perf_counter()
            scan, _ = scan_example(example, out / name, reduced, grid=(n, n))
            t_scan = time.perf_counter() - t0
            ds = scan.dataset
            print(
                f"# {name}: scan {t_scan:.1f} s, computed {scan.points_stored} of "
                f"{scan.points_total}, symmetry order {int(ds.attrs['symmetry_order'])}",
                flush=True,
            )
            label = f"{name}, {'symmetrised' if reduced else 'plain'}"
            print(row(label, analyse(ds, True, example), ref), flush=True)
            if reduced:
                print(
                    row(f"{name}, plain interpolant", analyse(ds, False, example), ref), flush=True
                )
            e = ds["energy"].values
            print(f"#   grid energy range {np.nanmin(e):.6f}..{np.nanmax(e):.6f} eV", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
