"""Force calls per point with the reference interface's Hessian as H0 (issue 33).

``python -m benchmarks precondition``: about 3-4 minutes on a quiet 2-core machine. On the
verified dense quartz interface (36 atoms, :func:`benchmarks.bench_scan.build`), the 6 × 6
grid at the thicknesses the probe chooses for -0.5 … 5 GPa (6 loads; 8 thicknesses), serial,
``fmax`` 0.005 eV/Å, warm-start tree ``columns`` (root at the largest z), for sio2-snap + LJ
and Vashishta + LJ:

- the built-in L-BFGS as ASE's (``LBFGS``: H0 = I/70), with γ-scaling (``LBFGS-scaled``, the
  scan's default: H0 = γ I, Nocedal & Wright eq. 7.20), each with and without the
  reference's Hessian (``RelaxSettings(precondition=True)``,
  :mod:`flatcontact.ispes.precondition`);
- force calls per point (the store's counts: exact, load-independent): mean, median, max,
  by tree-edge kind (root; lateral: the root plane; z-first: a column's first step off it,
  a rigid start; z-extrap: the rest, extrapolated in z), unconverged points; the Hessian's
  own calls (once per process, in no point's count) apart;
- the reference Hessian's eigenvalue floor (``precondition.FLOOR_FRACTION``, 0.01) at
  0.001 … 0.05 of the largest eigenvalue;
- the largest energy and load differences against the γ-scaled scan (two relaxations to the
  same tolerance);
- sio2-snap only: the preconditioned and the γ-scaled scans' wall and CPU times (Hessian
  included) against the hand-written native LAMMPS script (:mod:`benchmarks.native_lammps`) on the same grid, as
  part 2 of ``python -m benchmarks scanspeed``; the two scans are timed again right after
  the native script (the CPU ratio is the one a shared machine does not distort: the scan runs in this
  process, LAMMPS as a library, as the native script does). On a shared machine the walls are
  upper bounds (the load is printed).
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

import numpy as np

GRID = (6, 6)
P_RANGE_GPA = (-0.5, 5.0, 6)
FMAX = 0.005
POTENTIALS = ("snap:sio2-snap", "vashishta")
#: name: (RelaxSettings.optimizer, RelaxSettings.precondition)
VARIANTS = {
    "L-BFGS, H0 = I/70 (ASE: LBFGS)": ("LBFGS", False),
    "L-BFGS, H0 = γI (LBFGS-scaled)": ("LBFGS-scaled", False),
    "reference Hessian (LBFGS)": ("LBFGS", True),
    "reference Hessian and γ (LBFGS-scaled)": ("LBFGS-scaled", True),
}
BASELINE = "L-BFGS, H0 = γI (LBFGS-scaled)"
BEST = "reference Hessian (LBFGS)"
#: the eigenvalue floor of the reference Hessian (fraction of the largest), beside the default
FLOORS = (0.001, 0.005, 0.02, 0.05)


def _load() -> str:
    return f"load {os.getloadavg()[0]:.1f}"


#: :func:`benchmarks.scale_report.start_kind`'s names, as this table calls them
_EDGE_NAMES = {"cold": "root", "lateral": "lateral", "z": "z-first", "z-extrapolated": "z-extrap"}


def edge_kind(parent: dict, idx) -> str:
    """root, lateral (parent in the same plane), z-first (parent in the column, no
    grandparent there: a rigid start) or z-extrap (extrapolated in z)."""
    from benchmarks.scale_report import start_kind

    return _EDGE_NAMES[start_kind(parent, idx)]


def scan(reference, factory, grid, out: Path, optimizer: str, precondition: bool, floor=None):
    """(wall s, CPU s, dataset) of a serial scan in this process from scratch (the Hessian cache emptied first;
    ``floor``: another ``precondition.FLOOR_FRACTION`` for this scan)."""
    from flatcontact.ispes import precondition as pre
    from flatcontact.ispes.executors import SerialExecutor
    from flatcontact.ispes.relax import RelaxSettings
    from flatcontact.ispes.scan import run_scan

    pre._CACHE.clear()
    default = pre.FLOOR_FRACTION
    pre.FLOOR_FRACTION = default if floor is None else floor
    settings = RelaxSettings(FMAX, optimizer, precondition=precondition)
    try:
        t0, c0 = time.perf_counter(), time.process_time()
        r = run_scan(reference, factory, grid, out, settings, executor=SerialExecutor())
        return time.perf_counter() - t0, time.process_time() - c0, r.dataset
    finally:
        pre.FLOOR_FRACTION = default
        pre._CACHE.clear()


def summary(ds) -> dict:
    """Calls per point (mean, median, max), unconverged points, mean calls by edge kind."""
    from flatcontact.ispes.order import search_tree

    z = ds.thickness.values
    calls = ds.force_calls.values  # (a, b, z)
    parent = search_tree(calls.shape, (0, 0, int(np.argmax(z))), "columns")
    kinds: dict[str, list] = {}
    for idx in parent:
        kinds.setdefault(edge_kind(parent, idx), []).append(calls[idx])
    return {
        "mean": float(calls.mean()),
        "median": float(np.median(calls)),
        "max": int(calls.max()),
        "unconverged": int((~ds.converged.values.astype(bool)).sum()),
        "kinds": {k: (len(v), float(np.mean(v))) for k, v in sorted(kinds.items())},
    }


def potential(intra: str, tmp: Path) -> None:
    from benchmarks.bench_scan import build
    from flatcontact.ispes.geometry import fixed_mask
    from flatcontact.ispes.grid import GridSpec
    from flatcontact.ispes.scan import run_scan

    spec, reference, factory = build(intra)
    probe = run_scan(
        reference, factory, GridSpec(*GRID, p_range_gpa=P_RANGE_GPA), tmp / "probe",
        max_new_points=0,
    )  # fmt: skip
    zs = tuple(float(z) for z in probe.dataset.thickness.values)
    grid = GridSpec(*GRID, thickness_angstrom=zs)
    n_hessian = 2 * 3 * int((~fixed_mask(reference)).sum())
    print(
        f"{intra}: {GRID[0]}x{GRID[1]}x{len(zs)} points, thicknesses "
        f"{np.round(zs, 3).tolist()} Å; the reference Hessian costs {n_hessian} force calls "
        f"once per process (in no point's count)",
        flush=True,
    )
    print(
        "| variant | mean | median | max | unconverged | by kind (points: mean) | wall s | CPU s |"
    )
    data, walls, cpus = {}, {}, {}
    runs = {name: (opt, pre, None) for name, (opt, pre) in VARIANTS.items()}
    runs.update({f"{BEST}, floor {f:g}": ("LBFGS", True, f) for f in FLOORS})
    for name, (opt, pre, floor) in runs.items():
        walls[name], cpus[name], data[name] = scan(
            reference, factory, grid, tmp / name, opt, pre, floor
        )
        s = summary(data[name])
        kinds = ", ".join(f"{k} ({n}): {m:.2f}" for k, (n, m) in s["kinds"].items())
        print(
            f"| {name} | {s['mean']:.2f} | {s['median']:.0f} | {s['max']} | {s['unconverged']} "
            f"| {kinds} | {walls[name]:.1f} ({_load()}) | {cpus[name]:.1f} |",
            flush=True,
        )
    base = data[BASELINE]
    for name, ds in data.items():
        if name != BASELINE:
            de = float(np.abs(ds.energy.values - base.energy.values).max())
            dp = float(np.abs(ds.normal_stress.values - base.normal_stress.values).max())
            print(f"  {name} against {BASELINE}: max |dE| {de:.2e} eV, max |dp| {dp:.3f} GPa")
    if intra != POTENTIALS[0]:
        return
    from benchmarks.native_lammps import run_script, write_inputs

    sa, sb = grid.shifts()
    script = write_inputs(reference, spec, list(sa), list(sb), list(zs), FMAX, tmp / "native")
    native = run_script(script)
    n_points = GRID[0] * GRID[1] * len(zs)
    per_point = native["force_evaluations"] / n_points
    for name in (BEST, BASELINE):  # timed again right after the native script
        opt, pre, _ = runs[name]
        walls[name], cpus[name], _ = scan(reference, factory, grid, tmp / f"{name} again", opt, pre)
        calls = float(data[name].force_calls.values.mean())
        print(
            f"NATIVE LAMMPS script {native['wall']:.1f} s ({native['cpu']:.1f} CPU), "
            f"{per_point:.1f} force evaluations/point; {name}: {walls[name]:.1f} s serial "
            f"({cpus[name]:.1f} CPU), ratio {walls[name] / native['wall']:.2f} wall (target <= "
            f"0.3), {cpus[name] / native['cpu']:.2f} CPU, {calls / per_point:.2f} force calls "
            f"({(calls + n_hessian / n_points) / per_point:.2f} with the Hessian's), {_load()}",
            flush=True,
        )


def main() -> None:
    print(f"== reference-Hessian preconditioner (issue 33), {_load()} ==", flush=True)
    for intra in POTENTIALS:
        with tempfile.TemporaryDirectory() as tmp:
            potential(intra, Path(tmp))
