"""ISPES scan throughput on the paper's interface: points per second, force calls per point.

System
------
The verified dense α-quartz (0001) interface of the paper: two 6-layer slabs, 1×1
primitive cell, 36 atoms, built with
``build_quartz_interface(InteractionModel(intra=...), layers=6, source="shipped")`` (the
shipped CHGNet-relaxed dense slab, relaxed again and verified with each potential).

Measured
--------
1. Per potential (bundled ``snap:sio2-snap``, quadratic SNAP 2J = 6, the real default;
   Vashishta 1990), on a 4×4×8 subset whose 8 thicknesses span -0.5..5 GPa at the probe
   stacking (``GridSpec(p_range_gpa=(-0.5, 5, 8))``, probed once, then given explicitly):
   ``order="cold"`` vs ``order="columns"`` (warm), 1 and 2 worker processes, each
   timed after a throwaway 2×2 scan has started the workers (start-up printed apart). Printed:
   points/s, median and total force calls, the warm/cold force-call ratio, the 2-worker
   speed-up, and the largest energy/load difference between cold and warm (order
   independence).
2. Seconds per force call on the 36-atom interface (one core): sio2-snap (2J = 6),
   Vashishta, and a TIMING-ONLY 2J = 8 stand-in: no trained 2J = 8 SiO₂ SNAP exists, so
   a quadratic Si/O SNAP with the bundled model's settings but twojmax 8 (1596
   coefficients per element, small seeded random values; the cost of a call does not
   depend on the values) is timed. Its energies mean nothing; it never relaxes anything.
3. ONE real 12×12×8 grid (the issue's target size) with sio2-snap, 2 workers, warm
   (``columns``), thicknesses from ``p_range_gpa=(-0.5, 5, 8)``: probe and grid timed
   separately (start-up of the workers included), all 1152 points computed.
4. A 2J = 8 estimate, labelled as such: the measured 2J = 6 wall time plus (total force
   calls) × (extra seconds per 2J = 8 call, one core), with no parallel credit for the
   extra cost (an upper estimate as long as 2 workers are not slower than 1). It assumes
   a 2J = 8 model needs as many force calls per point as the 2J = 6 one.

0. First, issue 14's scale figures (:mod:`benchmarks.scale_report`): the ratio against a
   native LAMMPS input script, force calls per point, per-call overhead, fixed costs, parallel
   efficiency (measured and modelled) and one point of 1,000-5,000-atom cells.

Run: ``python -m benchmarks scan`` (10 minutes or more on 2 shared cores).
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

import numpy as np

from flatcontact.training.snapfiles import n_bispectrum

os.environ.setdefault("OMP_NUM_THREADS", "1")

SUBSET_LATERAL = (4, 4)
TARGET_LATERAL = (12, 12)
P_RANGE_GPA = (-0.5, 5.0, 8)  # 8 thicknesses spanning adhesion .. 5 GPa
FMAX = 0.005
OPTIMIZER = "LBFGS"
WORKERS = (1, 2)
ORDERS = ("cold", "columns")
POTENTIALS = ("snap:sio2-snap", "vashishta")
SNAP_BUNDLED = "sio2-snap"


def n_snap_coefficients(twojmax: int, quadratic: bool) -> int:
    """Coefficients per element: constant + linear (+ upper triangle of the quadratic form)."""
    k = n_bispectrum(twojmax)
    return 1 + k + (k * (k + 1) // 2 if quadratic else 0)


def bundled_snap_files() -> tuple[Path, Path]:
    from flatcontact.potentials.files import BUNDLED_DIR

    coeff = BUNDLED_DIR / SNAP_BUNDLED / f"{SNAP_BUNDLED}.snapcoeff"
    return coeff, coeff.with_suffix(".snapparam")


def _param_value(lines: list[str], key: str) -> str:
    for line in lines:
        tokens = line.split()
        if tokens and tokens[0] == key:
            return tokens[1]
    raise KeyError(key)


def twoj8_standin(directory: Path, seed: int = 0) -> Path:
    """TIMING-ONLY Si/O SNAP: the bundled model's settings with twojmax 8, random coefficients.

    Checks first that the coefficient count rule reproduces the bundled 2J = 6 file.
    """
    coeff6, param6 = bundled_snap_files()
    param_lines = param6.read_text().splitlines()
    twoj6 = int(_param_value(param_lines, "twojmax"))
    quadratic = _param_value(param_lines, "quadraticflag") == "1"
    header = next(
        line.split()
        for line in coeff6.read_text().splitlines()
        if line.strip() and not line.startswith("#")
    )
    assert int(header[1]) == n_snap_coefficients(twoj6, quadratic), (
        "coefficient count rule disagrees with the bundled file"
    )
    ncoeff = n_snap_coefficients(8, quadratic)
    rng = np.random.default_rng(seed)
    lines = ["# TIMING-ONLY stand-in (random coefficients), not a potential", "", f"2 {ncoeff}"]
    for element in ("Si", "O"):
        lines.append(f"{element} 0.5 1.0")
        lines += [f"{v:.6e}" for v in 1e-6 * rng.standard_normal(ncoeff)]
    coeff = directory / "standin-2j8.snapcoeff"
    coeff.write_text("\n".join(lines) + "\n")
    params = [
        "twojmax 8" if line.split()[:1] == ["twojmax"] else line
        for line in param_lines
        if not line.startswith("#")
    ]
    coeff.with_suffix(".snapparam").write_text("\n".join(params) + "\n")
    return coeff


def seconds_per_call(spec, atoms, n: int = 40) -> float:
    """Wall seconds per energy+forces evaluation through the interface calculator (1 core)."""
    from flatcontact.potentials import make_calculator

    atoms = atoms.copy()
    atoms.calc = make_calculator(spec, atoms)
    atoms.get_forces()
    t0 = time.perf_counter()
    for k in range(n):
        atoms.positions[10, 2] += 1e-4 * (-1) ** k  # a free atom: forces a new evaluation
        atoms.get_forces()
    return (time.perf_counter() - t0) / n


def timed_scan(
    reference, factory, grid, out, order="columns", workers=1, max_new_points=None, warm_up=None
):
    """``run_scan`` with a ``processes`` executor of ``workers``: (result, wall s, start-up s).

    The wall time includes starting the worker processes unless ``warm_up`` (a scratch
    directory) is given: then a throwaway cold 2×2 scan at the first thickness first
    starts the workers and builds their calculators, and its wall time is added to the
    returned start-up seconds (None without ``warm_up``).
    """
    from flatcontact.ispes.executors import make_executor
    from flatcontact.ispes.grid import GridSpec
    from flatcontact.ispes.relax import RelaxSettings
    from flatcontact.ispes.scan import run_scan

    settings = RelaxSettings(FMAX, OPTIMIZER)
    t_start = time.perf_counter()
    executor = make_executor("processes", workers=workers)
    try:
        start_up = None
        if warm_up is not None:
            z = (grid.thickness_angstrom[0],)
            scratch = GridSpec(2, 2, thickness_angstrom=z)
            run_scan(
                reference, factory, scratch, warm_up, settings, order="cold", executor=executor
            )
            start_up = time.perf_counter() - t_start
        t0 = time.perf_counter()
        result = run_scan(
            reference,
            factory,
            grid,
            out,
            settings,
            order=order,
            executor=executor,
            max_new_points=max_new_points,
        )
        wall = time.perf_counter() - t0
    finally:
        executor.close()
    return result, wall, start_up


def calls_by_start(db_path: Path) -> dict[str, str]:
    """Median force calls per point grouped by how the point was started (from ``points.db``)."""
    import ase.db

    def index(text):
        return tuple(int(x) for x in text.split(",")) if text else None

    rows = {(r.i_a, r.i_b, r.i_z): r for r in ase.db.connect(str(db_path)).select()}
    groups: dict[str, list[int]] = {}
    for (ia, ib, _iz), row in rows.items():
        start = index(row.get("start", ""))
        if start is None:
            kind = "cold"
        elif start[:2] != (ia, ib):
            kind = "lateral"
        else:
            grand = index(rows[start].get("start", ""))
            kind = "z-extrapolated" if grand is not None and grand[:2] == (ia, ib) else "z"
        groups.setdefault(kind, []).append(row.force_calls)
    return {k: f"{np.median(v):.0f} (n={len(v)})" for k, v in sorted(groups.items())}


def build(intra: str):
    from flatcontact.potentials import InteractionModel
    from flatcontact.potentials.engines import calculator_factory
    from flatcontact.structures.build import build_quartz_interface

    spec = InteractionModel(intra=intra)
    t0 = time.perf_counter()
    reference, report = build_quartz_interface(spec, layers=6, source="shipped")
    dense = all(v["dense"] for v in report["interface_verification"].values())
    print(
        f"{intra}: dense interface {len(reference)} atoms, z = {report['thickness_angstrom']:.3f} Å, "
        f"both slabs dense: {dense}, built in {time.perf_counter() - t0:.1f} s",
        flush=True,
    )
    return spec, reference, calculator_factory(spec)


def probe(reference, factory, lateral, out):
    """Thicknesses (Å) for ``P_RANGE_GPA`` from the driver's probe column, and its wall time."""
    from flatcontact.ispes.grid import GridSpec

    result, wall, _ = timed_scan(
        reference, factory, GridSpec(*lateral, p_range_gpa=P_RANGE_GPA), out, max_new_points=0
    )
    return tuple(float(z) for z in result.dataset.thickness.values), result, wall


def subset(intra: str, tmp: Path) -> dict:
    from flatcontact.ispes.grid import GridSpec

    _, reference, factory = build(intra)
    z, _, t_probe = probe(reference, factory, SUBSET_LATERAL, tmp / f"{intra}-probe")
    print(
        f"  probe ({t_probe:.1f} s): thicknesses {np.round(z, 3).tolist()} Å for "
        f"{P_RANGE_GPA[0]}..{P_RANGE_GPA[1]} GPa",
        flush=True,
    )
    grid = GridSpec(*SUBSET_LATERAL, thickness_angstrom=z)
    n = SUBSET_LATERAL[0] * SUBSET_LATERAL[1] * len(z)
    runs: dict[tuple[str, int], dict] = {}
    for order in ORDERS:
        for workers in WORKERS:
            out = tmp / f"{intra}-{order}-{workers}"
            r, wall, start_up = timed_scan(
                reference, factory, grid, out, order, workers, warm_up=tmp / f"{out.name}-warm-up"
            )
            calls = np.asarray(r.force_calls_computed)
            runs[order, workers] = {
                "wall": wall,
                "median": float(np.median(calls)),
                "total": int(calls.sum()),
                "converged": int(r.dataset.converged.sum()),
                "dataset": r.dataset,
            }
            print(
                f"  {order:7s} {workers} worker(s): {n} points in {wall:6.1f} s = {n / wall:5.2f} points/s "
                f"(after {start_up:.1f} s start-up + warm-up scan); "
                f"force calls/point median {np.median(calls):.0f} (total {calls.sum()}); "
                f"converged {runs[order, workers]['converged']}/{n}; by start: "
                f"{calls_by_start(out / 'points.db')}",
                flush=True,
            )
    cold, warm = runs["cold", 1], runs["columns", 1]
    d_e = float(np.abs(cold["dataset"].energy - warm["dataset"].energy).max())
    d_p = float(np.abs(cold["dataset"].normal_stress - warm["dataset"].normal_stress).max())
    from flatcontact.foundation.units import EV_PER_A3_TO_GPA
    from flatcontact.ispes.contract import cell_area
    from flatcontact.structures.interface_contract import fixed_mask

    # scale of the load error a relaxation to fmax allows: free atoms of slab 2 x fmax / A
    free2 = int(np.sum(~fixed_mask(reference) & (reference.arrays["slab"] == 2)))
    area = cell_area(reference.cell[0, :2], reference.cell[1, :2])
    p_tol = free2 * FMAX / area * EV_PER_A3_TO_GPA
    summary = {
        "n": n,
        "runs": runs,
        "warm_over_cold_median": warm["median"] / cold["median"],
        "warm_over_cold_total": warm["total"] / cold["total"],
        "speedup": {o: runs[o, 1]["wall"] / runs[o, 2]["wall"] for o in ORDERS},
    }
    print(
        f"  warm/cold force calls: median {summary['warm_over_cold_median']:.2f}, "
        f"total {summary['warm_over_cold_total']:.2f}; 2-worker speed-up: "
        + ", ".join(f"{o} {s:.2f}x" for o, s in summary["speedup"].items())
        + f"; cold vs warm max |ΔU| {d_e:.1e} eV, max |Δp| {d_p:.2f} GPa "
        f"(N_free,slab2·fmax/A = {free2}·{FMAX}/A = {p_tol:.2f} GPa)",
        flush=True,
    )
    return summary


def full_grid(tmp: Path) -> dict:
    """The one real 12×12×8 sio2-snap grid, 2 workers, warm (columns)."""
    from flatcontact.ispes.grid import GridSpec

    _, reference, factory = build(f"snap:{SNAP_BUNDLED}")
    out = tmp / "full"
    grid = GridSpec(*TARGET_LATERAL, p_range_gpa=P_RANGE_GPA)
    _, _, t_probe = probe(reference, factory, TARGET_LATERAL, out)  # same store, probe only
    r, wall, _ = timed_scan(reference, factory, grid, out, order="columns", workers=2)
    calls = np.asarray(r.force_calls_computed)
    n = r.points_total
    print(
        f"REAL sio2-snap {TARGET_LATERAL[0]}x{TARGET_LATERAL[1]}x{P_RANGE_GPA[2]} grid, 2 workers, columns: "
        f"probe {t_probe:.1f} s + {r.points_computed} points in {wall:.1f} s "
        f"({r.points_computed / wall:.2f} points/s); total {(t_probe + wall) / 60:.2f} min; "
        f"force calls/point median {np.median(calls):.0f} (total {calls.sum()}); "
        f"converged {int(r.dataset.converged.sum())}/{n}; "
        f"thicknesses {np.round(r.dataset.thickness.values, 3).tolist()} Å",
        flush=True,
    )
    print(f"  by start: {calls_by_start(out / 'points.db')}", flush=True)
    return {"wall": wall, "probe": t_probe, "total_calls": int(calls.sum()), "n": n}


def main() -> None:
    from benchmarks import scale_report

    scale_report.main()  # issue 14: native ratio, per-call overhead, fixed costs, parallel, large
    print(
        f"{os.cpu_count()} cores (shared), load average {os.getloadavg()[0]:.2f}; "
        f"relax {OPTIMIZER} fmax {FMAX} eV/Å",
        flush=True,
    )
    summaries = {}
    with tempfile.TemporaryDirectory() as tmp_name:
        tmp = Path(tmp_name)
        for intra in POTENTIALS:
            summaries[intra] = subset(intra, tmp)

        spec6, reference, _ = build(f"snap:{SNAP_BUNDLED}")
        from flatcontact.potentials import InteractionModel

        spec8 = InteractionModel(intra=f"snap:{twoj8_standin(tmp)}")
        t6 = seconds_per_call(spec6, reference)
        t8 = seconds_per_call(spec8, reference)
        tv = seconds_per_call(InteractionModel(intra="vashishta"), reference)
        print(
            f"seconds per force call, {len(reference)} atoms, 1 core: sio2-snap (2J=6, quadratic) "
            f"{t6 * 1e3:.2f} ms; TIMING-ONLY 2J=8 quadratic stand-in "
            f"({n_snap_coefficients(8, True)} coefficients/element) {t8 * 1e3:.2f} ms "
            f"(x{t8 / t6:.2f}); Vashishta {tv * 1e3:.2f} ms",
            flush=True,
        )
        snap = summaries[f"snap:{SNAP_BUNDLED}"]
        for order in ORDERS:
            for workers in WORKERS:
                run = snap["runs"][order, workers]
                est = run["wall"] + run["total"] * (t8 - t6)
                print(
                    f"ESTIMATE (2J=8 stand-in cost) subset, {order}, {workers} worker(s): "
                    f"{run['wall']:.1f} s + {run['total']} calls x {(t8 - t6) * 1e3:.2f} ms "
                    f"= {est:.1f} s ({snap['n'] / est:.2f} points/s)",
                    flush=True,
                )

        full = full_grid(tmp)
        est = full["probe"] + full["wall"] + full["total_calls"] * (t8 - t6)
        print(
            f"ESTIMATE (2J=8 stand-in cost) {TARGET_LATERAL[0]}x{TARGET_LATERAL[1]}x{P_RANGE_GPA[2]}, "
            f"2 workers: measured 2J=6 {(full['probe'] + full['wall']):.1f} s + {full['total_calls']} calls "
            f"x {(t8 - t6) * 1e3:.2f} ms = {est / 60:.1f} min (no parallel credit for the extra; "
            "assumes the 2J=6 force-call count; the probe's calls not included in the extra)",
            flush=True,
        )
    print(f"load average at the end {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
