"""Irreducible registries: points computed and wall time of the reduced scan against the full one.

``python -m benchmarks symmetry`` (every example but the quartz one, the slow one) or
``python -m benchmarks.bench_symmetry EXAMPLE ...`` (e.g. ``quartz-paper``). For each example: the
interface as the build stage makes it, then the scan of its grid twice into temporary
folders, reduced (``scan.symmetry.enabled``, the default) and full, on the same executor;
printed: the group order, grid points, computed points, the verification, both wall times,
the ratios, and the largest difference between the two ``ispes.nc`` (energy per area,
normal load), which is the relaxation tolerance's, not the symmetry's, and the force calls
per computed point of each (the warm starts of the reduced tree against the full one's).

The first scan in a process pays one-time costs (imports of the netCDF writer and of the
workers' modules: about 5 s, measured on Cu(111), whichever scan comes first); they made the
reduced Cu scan look 1.32× slower than the full one. So one untimed warm-up scan of the first
example's reduced grid runs before the table.
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import numpy as np

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
CHEAP = (
    "cu111-eam",
    "graphene-bilayer-kc",
    "graphene-bilayer-ilp",
    "hbn-bilayer-ilp",
    "mos2-bilayer-ilp",
    "graphene-hbn-ilp",
    "au111-cif-eam",
)


def scan_example(name: str, out: Path, enabled: bool, grid: tuple[int, int] | None = None):
    """Build ``examples/<name>.yaml``'s interface and scan it; returns (ScanResult, seconds)."""
    from flatcontact.config.load import load_config
    from flatcontact.ispes.scan import run_scan
    from flatcontact.stages import _calculator
    from flatcontact.stages.build import BuildInputs, build_stage
    from flatcontact.stages.scan import grid_spec, relax_settings, symmetry_settings

    settings = load_config(EXAMPLES / f"{name}.yaml")
    if grid is not None:
        settings = settings.model_copy(
            update={"scan": settings.scan.model_copy(update={"grid": grid})}
        )
    reference = _build(settings, build_stage, BuildInputs)
    s = settings.scan
    sym = symmetry_settings(s)
    sym = type(sym)(**{**sym.as_dict(), "enabled": enabled})
    t0 = time.perf_counter()
    result = run_scan(
        reference,
        _calculator.factory(settings),
        grid_spec(s),
        out,
        relax_settings(s),
        order=s.order,
        executor_options=s.executor_options(),
        symmetry=sym,
    )
    return result, time.perf_counter() - t0


_BUILT: dict = {}


def _build(settings, build_stage, inputs_type):
    key = settings.model_dump_json()
    if key not in _BUILT:
        _BUILT[key] = build_stage(settings, inputs_type(), None).atoms
    return _BUILT[key]


def compare(a, b) -> tuple[float, float]:
    """Largest |ΔE|/A (meV/Å²) and |Δp| (GPa) between two assembled grids."""
    area = float(a.attrs["area"])
    de = np.nanmax(np.abs(a["energy"].values - b["energy"].values)) / area * 1e3
    dp = np.nanmax(np.abs(a["normal_stress"].values - b["normal_stress"].values))
    return float(de), float(dp)


def _per_point(result) -> float:
    calls = result.force_calls_computed
    return float(np.mean(calls)) if calls else float("nan")


def main(argv: list[str] | None = None) -> None:
    names = list(argv or ()) or list(CHEAP)
    with tempfile.TemporaryDirectory() as tmp:  # one-time costs out of the table
        scan_example(names[0], Path(tmp) / "warm-up", True)
    print(
        "example | order | grid points | computed | verified max dE (meV/Å²), dp (GPa) | "
        "wall reduced / full (s) | points ratio | wall ratio | force calls per computed point "
        "reduced / full | reduced vs full max dE, dp"
    )
    for name in names:
        with tempfile.TemporaryDirectory() as tmp:
            red, t_red = scan_example(name, Path(tmp) / "reduced", True)
            full, t_full = scan_example(name, Path(tmp) / "full", False)
        sym = red.symmetry or {"order": 1, "verification": {}}
        v = sym.get("verification") or {}
        de, dp = compare(red.dataset, full.dataset)
        print(
            f"{name} | {sym['order']} | {red.points_total} | {red.points_stored} | "
            f"{v.get('max_energy_difference_mev_per_a2', float('nan')):.2g}, "
            f"{v.get('max_stress_difference_gpa', float('nan')):.2g}"
            f"{' (computed in full)' if sym.get('computed_in_full') else ''} | "
            f"{t_red:.1f} / {t_full:.1f} | {red.points_stored / red.points_total:.3f} | "
            f"{t_red / t_full:.3f} | {_per_point(red):.2f} / {_per_point(full):.2f} | "
            f"{de:.2g}, {dp:.2g}",
            flush=True,
        )


if __name__ == "__main__":
    main(sys.argv[1:])
