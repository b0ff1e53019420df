"""Wall time per stage of the default run (``flatcontact run``, quick preset), force calls of the scan.

Runs the built-in default in a temporary directory twice: the first pass computes
every stage, the second must skip them all (the cost of a no-op rerun).
Set ``FLATCONTACT_BENCH_PRESET=paper`` for the paper preset (hours).
"""

from __future__ import annotations

import json
import os
import tempfile
import time
from pathlib import Path


def main() -> None:
    from flatcontact.config import load_config
    from flatcontact.pipeline import Pipeline

    preset = os.environ.get("FLATCONTACT_BENCH_PRESET", "quick")
    cfg = load_config(preset_name=preset)
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp) / "run"
        start = time.perf_counter()
        with Pipeline(cfg, root) as pipe:
            pipe.run()
            first = dict(pipe.results)
        total = time.perf_counter() - start
        scan = json.loads((root / "02-scan" / "scan.json").read_text())
        start = time.perf_counter()
        with Pipeline(cfg, root) as pipe:
            pipe.run()
            actions = {n: r.action for n, r in pipe.results.items()}
        rerun = time.perf_counter() - start
    print(
        f"preset {preset}: {cfg.potential.label}, grid {cfg.scan.grid}, "
        f"{len(scan['thickness_angstrom'])} thicknesses, workers {cfg.scan.workers or 'auto'}"
    )
    for name, res in first.items():
        print(f"  {name:8s} {res.seconds:8.2f} s  ({res.action})")
    print(f"  total    {total:8.2f} s")
    print(
        f"  scan: {scan['points_done']} points, {scan['force_calls_total']} force calls, "
        f"median {scan['median_force_calls_per_point']} per point"
    )
    print(f"  rerun with nothing changed: {rerun:.2f} s, actions {sorted(set(actions.values()))}")
