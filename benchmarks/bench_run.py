"""Wall time per stage of the default run (``flatcontact run``, quick preset), its size, force calls.

Runs the built-in default in a temporary directory twice: the first pass computes
every stage, the second must skip them all (the cost of a no-op rerun). Prints the per-stage
table, the run directory's size (every file's bytes; the largest files), report.html's size,
the scan's force calls and, against the figures before issue 33
(``benchmarks/run_baseline.json``), the ratio of each. Stores them as the ``"run"`` block of
``benchmarks/run_record.json`` (:mod:`benchmarks.record`), from which
``python -m benchmarks.readme_block`` writes the README's figures.

Set ``FLATCONTACT_BENCH_PRESET=paper`` for the paper preset (hours; not stored).
"""

from __future__ import annotations

import json
import os
import tempfile
import time
from pathlib import Path

from benchmarks import record

#: The largest files listed.
LARGEST = 6


def sizes(root: Path) -> tuple[int, list[tuple[str, int]]]:
    """Total bytes of the files under ``root`` and the largest files (relative name, bytes)."""
    files = [(p.relative_to(root).as_posix(), p.stat().st_size) for p in root.rglob("*")]
    files = [(name, n) for name, n in files if (root / name).is_file()]
    files.sort(key=lambda x: -x[1])
    return sum(n for _, n in files), files[:LARGEST]


def measure(preset: str) -> dict:
    """Run the default twice in a temporary directory; the ``"run"`` block of the record."""
    from flatcontact.config import load_config
    from flatcontact.layout import REPORT_HTML, SCAN_JSON
    from flatcontact.pipeline import Pipeline

    cfg = load_config(preset_name=preset)
    block = {"preset": preset, **record.machine()}
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp) / "run"
        start = time.perf_counter()
        with Pipeline(cfg, root) as pipe:
            pipe.run()
            first = dict(pipe.results)
        block["total_s"] = round(time.perf_counter() - start, 2)
        scan = json.loads((pipe.folder("scan") / SCAN_JSON).read_text())
        total, largest = sizes(root)
        report_bytes = (root / REPORT_HTML).stat().st_size
        start = time.perf_counter()
        with Pipeline(cfg, root) as pipe:
            pipe.run()
            actions = sorted({r.action for r in pipe.results.values()})
        rerun = time.perf_counter() - start
    block["load_average_end"] = round(os.getloadavg()[0], 2)
    block |= {
        "model": cfg.potential.label,
        "grid": list(cfg.scan.grid),
        "thicknesses": len(scan["thickness_angstrom"]),
        "stages_s": {n: round(r.seconds, 2) for n, r in first.items() if r.action == "ran"},
        "stage_actions": {n: r.action for n, r in first.items()},
        "rerun_s": round(rerun, 2),
        "rerun_actions": actions,
        "run_dir_bytes": total,
        "largest_files": [{"file": name, "bytes": n} for name, n in largest],
        "report_bytes": report_bytes,
        "scan": {
            "points_done": scan["points_done"],
            "points_computed": scan.get("points_computed"),
            "force_calls_total": scan["force_calls_total"],
            "median_force_calls_per_point": scan["median_force_calls_per_point"],
        },
    }
    return block


def _ratio(now: float | None, before: float | None) -> str:
    return f"{now / before:6.2f}x" if now and before else "      -"


def table(block: dict, baseline: dict) -> list[str]:
    """The printed lines: per stage, total, sizes, force calls; ratios against ``baseline``."""
    base = baseline.get("run", {})
    bstages = base.get("stages_s", {})
    lines = [
        f"preset {block['preset']}: {block['model']}, grid {block['grid']}, "
        f"{block['thicknesses']} thicknesses; {block['cpus']} cores, load average "
        f"{block['load_average']} -> {block['load_average_end']}"
        + (" (loaded: the times are upper bounds)" if record.loaded(block) else ""),
        f"  {'stage':10s} {'seconds':>9s} {'baseline':>9s} {'ratio':>8s}",
    ]
    for name, action in block["stage_actions"].items():
        s = block["stages_s"].get(name)
        shown = f"{s:9.2f}" if s is not None else f"{action:>9s}"
        b = bstages.get(name)
        lines.append(f"  {name:10s} {shown} {b if b else '':>9} {_ratio(s, b):>8s}")
    lines.append(
        f"  {'total':10s} {block['total_s']:9.2f} {base.get('total_s', ''):>9} "
        f"{_ratio(block['total_s'], base.get('total_s')):>8s}"
    )
    mb = 1e6
    lines += [
        f"  run directory {block['run_dir_bytes'] / mb:.2f} MB "
        f"({_ratio(block['run_dir_bytes'], base.get('run_dir_bytes')).strip()} the baseline's "
        f"{base.get('run_dir_bytes', 0) / mb:.0f} MB); largest: "
        + ", ".join(f"{f['file']} {f['bytes'] / mb:.2f} MB" for f in block["largest_files"]),
        f"  report.html {block['report_bytes'] / mb:.2f} MB "
        f"({_ratio(block['report_bytes'], base.get('report_bytes')).strip()})",
        f"  scan: {block['scan']['points_done']} points ({block['scan']['points_computed']} "
        f"computed), {block['scan']['force_calls_total']} force calls, median "
        f"{block['scan']['median_force_calls_per_point']} per point",
        f"  rerun with nothing changed: {block['rerun_s']:.2f} s, actions {block['rerun_actions']}",
    ]
    return lines


def main() -> None:
    preset = os.environ.get("FLATCONTACT_BENCH_PRESET", "quick")
    block = measure(preset)
    baseline = json.loads(record.BASELINE.read_text()) if preset == "quick" else {}
    print("\n".join(table(block, baseline)))
    if preset == "quick":
        print(f"  stored: {record.write_block('run', block)}")
