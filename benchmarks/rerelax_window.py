"""Re-relax a stored scan's points around z*(P) at a tighter force tolerance and re-read τ(P).

The diagnosis of docs/convergence.md, "Slab layers at high load: the study's 9 → 12 step":
a scan point stops where the largest force on a free atom is below ``scan.fmax``, which leaves
an energy error ΔE ≈ ½ Fᵀ H⁻¹ F above the minimum (large along a slab's soft collective modes).
The internal form ẽ = U(z*)/A carries it at first order through z*(P) (ẽ = h − P·z*, h
stationary in z), the enthalpy form h only at second order. This script measures that error
instead of estimating it: for every column of the grid it re-relaxes the stored points at the
thickness nodes ``k + offset`` (k: the node below z*(P) of the stored data) from their stored
positions with the run's own model and the scan's own relaxation
(:func:`flatcontact.ispes.relax.relax_point`, L-BFGS, mode ``full``) at ``--fmax``, replaces
those energies and loads in a copy of the grid, and analyses both grids at P with the
pipeline's analysis (:func:`flatcontact.analysis.analyze.analyze_ispes`). Columns are taken in
a seeded random order, so ``--columns`` below the grid's count is a uniform sample (the
per-column errors are then reported, τ only for the full grid).

Run directories stay read-only: ``points.db`` (with its write-ahead log) is copied first.

    python -m benchmarks.rerelax_window RUN_DIR --p-gpa 3.0 --fmax 0.0005 \\
        --offsets=-2,-1,0,1,2,3 --out rerelax.jsonl

One JSON line per point (energies in eV, loads in GPa, CPU seconds), then a summary on stdout.
"""

from __future__ import annotations

import argparse
import json
import shutil
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
import xarray as xr

from flatcontact.analysis.analyze import analyze_ispes
from flatcontact.analysis.constant_pressure import constant_pressure
from flatcontact.analysis.options import AnalysisOptions
from flatcontact.config.load import load_config
from flatcontact.ispes.calculators import count_force_calls
from flatcontact.ispes.relax import PointTask, RelaxSettings, relax_point
from flatcontact.potentials.engines import calculator_factory
from flatcontact.structures.interface_io import read_interface


def stored_points(run: Path, workdir: Path) -> dict:
    """``{(i_a, i_b, i_z): row}`` of the run's ``02-scan/points.db``, read from a copy."""
    import ase.db

    for suffix in ("", "-wal"):
        src = run / "02-scan" / f"points.db{suffix}"
        if src.exists():
            shutil.copy(src, workdir / f"points.db{suffix}")
    db = ase.db.connect(str(workdir / "points.db"), type="db", use_lock_file=False)
    return {(r.i_a, r.i_b, r.i_z): r for r in db.select()}


def window_nodes(ds: xr.Dataset, p_gpa: float, offsets: list[int]) -> np.ndarray:
    """Thickness nodes ``k + offset`` per column, k the node below z*(P); shape (n_a, n_b, n_off)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cp = constant_pressure(ds, [p_gpa], form="internal")
    z = ds["thickness"].values
    k = np.searchsorted(z, cp.thickness_angstrom[0]) - 1
    nodes = k[..., None] + np.asarray(offsets)[None, None, :]
    return np.clip(nodes, 0, z.size - 1)


def tau(ds: xr.Dataset, p_gpa: float, form: str, direction_deg: float) -> tuple[float, float, int]:
    """(τ, σ_MSS, number of near-degenerate starts) at P with the pipeline's analysis (MPa)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        pa = analyze_ispes(
            ds, [p_gpa], AnalysisOptions(direction_deg=direction_deg, form=form, threshold_gpa=None)
        )
    fr = pa.pressures[0]
    return fr.friction.tau_mpa, fr.friction.sigma_mss_mpa, max(1, len(fr.starts))


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run", type=Path, help="a finished run directory (01-build, 02-scan)")
    ap.add_argument("--p-gpa", type=float, default=3.0)
    ap.add_argument("--fmax", type=float, default=0.0005, help="eV/Å")
    ap.add_argument("--offsets", default="-1,0,1,2", help="nodes k+offset around z*(P)")
    ap.add_argument("--columns", type=int, default=None, help="a random sample of columns")
    ap.add_argument("--out", type=Path, required=True, help="JSON lines, appended")
    args = ap.parse_args(argv)
    offsets = [int(v) for v in args.offsets.split(",")]
    settings = load_config(args.run / "config.yaml")
    reference = read_interface(args.run / "01-build" / "interface.extxyz")
    ds = xr.load_dataset(args.run / "02-scan" / "ispes.nc")
    nodes = window_nodes(ds, args.p_gpa, offsets)
    calc = count_force_calls(calculator_factory(settings.potential)(reference))
    relax = RelaxSettings(fmax_ev_per_angstrom=args.fmax, optimizer="LBFGS", max_steps=5000)
    n_a, n_b = nodes.shape[:2]
    order = np.random.default_rng(21).permutation(n_a * n_b)[: args.columns]
    tight = ds.copy(deep=True)
    energy, stress = tight["energy"].values, tight["normal_stress"].values
    done, cpu0 = [], time.process_time()
    with tempfile.TemporaryDirectory() as tmp, args.out.open("a") as fh:
        rows = stored_points(args.run, Path(tmp))
        for c in order:
            i, j = divmod(int(c), n_b)
            for iz in sorted(set(int(v) for v in nodes[i, j])):
                row = rows[(i, j, iz)]
                task = PointTask(
                    (i, j, iz),
                    row.shift_a,
                    row.shift_b,
                    row.thickness,
                    start_positions=row.positions.copy(),
                    start_shift=(row.shift_a, row.shift_b),
                    start_thickness=row.thickness,
                )
                t0 = time.process_time()
                res = relax_point(reference, calc, task, relax)
                energy[i, j, iz], stress[i, j, iz] = res.energy_ev, res.normal_stress_gpa
                rec = {
                    "i_a": i,
                    "i_b": j,
                    "i_z": iz,
                    "fmax_ev_per_angstrom": args.fmax,
                    "energy_stored_ev": row.energy,
                    "energy_ev": res.energy_ev,
                    "p_stored_gpa": row.normal_stress_gpa,
                    "p_gpa": res.normal_stress_gpa,
                    "force_calls_stored": row.force_calls,
                    "force_calls": res.force_calls,
                    "converged": res.converged,
                    "cpu_s": time.process_time() - t0,
                }
                fh.write(json.dumps(rec) + "\n")
                fh.flush()
                done.append(rec)
    cols = sorted({(r["i_a"], r["i_b"]) for r in done})
    area = float(ds.attrs["area"])
    de = 1e3 * np.array([r["energy_ev"] - r["energy_stored_ev"] for r in done])
    print(
        f"{args.run.name}: {len(cols)} columns, {len(done)} points at fmax {args.fmax:g} eV/Å "
        f"({time.process_time() - cpu0:.0f} s CPU); E_tight - E_stored: mean {de.mean():.3f} meV, "
        f"rms {np.sqrt(np.mean(de**2)):.3f} meV, largest {de.min():.3f} meV"
    )
    ia, ib = (np.array(v) for v in zip(*cols, strict=True))
    direction = settings.analysis.direction_deg
    for form in ("internal", "enthalpy"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            a = constant_pressure(ds, [args.p_gpa], form=form)
            b = constant_pressure(tight, [args.p_gpa], form=form)
        d = 1e3 * (a.energy_ev_per_a2[0] - b.energy_ev_per_a2[0])[ia, ib]
        line = (
            f"  {form}: stored - re-relaxed per column at {args.p_gpa:g} GPa: rms "
            f"{np.sqrt(np.mean((d - d.mean()) ** 2)):.4f} meV/Å² (largest {np.abs(d - d.mean()).max():.4f}; "
            f"the analysis's own estimate {a.noise.energy_noise_mev_per_a2[0]:.4f}; area {area:.4g} Å²)"
        )
        if len(cols) == n_a * n_b:
            t_a, s_a, n_a_starts = tau(ds, args.p_gpa, form, direction)
            t_b, s_b, n_b_starts = tau(tight, args.p_gpa, form, direction)
            line += (
                f"; τ {t_a:.1f} -> {t_b:.1f} MPa, σ_MSS {s_a:.2f} -> {s_b:.2f} MPa, "
                f"near-degenerate starts {n_a_starts} -> {n_b_starts}"
            )
        print(line)


if __name__ == "__main__":
    main()
