"""Wall time per stage of the default run (``flatcontact run``, quick preset), its size, force calls.

Runs the built-in default in a temporary directory twice: the first pass computes
every stage, the second must skip them all (the cost of a no-op rerun). Prints the per-stage
table, the scan driver's phases (probe, ideal work of separation, symmetry, grid, writing:
:mod:`flatcontact.ispes.phases`), the run directory's size (its files' bytes, a file under
two names once, as ``du`` counts; the largest files), report.html's size,
the scan's force calls and, against the figures before issue 33
(``benchmarks/run_baseline.json``), the ratio of each. Stores them as the ``"run"`` block of
``benchmarks/run_record.json`` (:mod:`benchmarks.record`), from which
``python -m benchmarks.readme_block`` writes the README's figures.

Set ``FLATCONTACT_BENCH_PRESET=paper`` for the paper preset (hours; not stored).
"""

from __future__ import annotations

import json
import logging
import os
import tempfile
import time
from pathlib import Path

from benchmarks import record

#: The largest files listed.
LARGEST = 6


def sizes(root: Path) -> tuple[int, list[tuple[str, int]]]:
    """Bytes of the files under ``root``, a file under two names (a hard link: the run's
    ``report.html``) counted once, as ``du`` does; and the largest files (relative name,
    bytes), every name listed."""
    files, inodes = [], {}
    for p in root.rglob("*"):
        if p.is_file() and not p.is_symlink():
            st = p.stat()
            files.append((p.relative_to(root).as_posix(), st.st_size))
            inodes[(st.st_dev, st.st_ino)] = st.st_size
    files.sort(key=lambda x: -x[1])
    return sum(inodes.values()), files[:LARGEST]


class PhaseLog(logging.Handler):
    """The scan driver's phases (:mod:`flatcontact.ispes.phases`), from its DEBUG log."""

    def __init__(self) -> None:
        super().__init__(logging.DEBUG)
        self.seconds: dict[str, float] = {}

    def emit(self, record: logging.LogRecord) -> None:
        name, seconds = record.getMessage().rsplit(" ", 1)
        self.seconds[name] = self.seconds.get(name, 0.0) + float(seconds)

    def __enter__(self) -> PhaseLog:
        logger = logging.getLogger("flatcontact.ispes.phases")
        self._level = logger.level
        logger.setLevel(logging.DEBUG)
        logger.addHandler(self)
        return self

    def __exit__(self, *exc: object) -> None:
        logger = logging.getLogger("flatcontact.ispes.phases")
        logger.removeHandler(self)
        logger.setLevel(self._level)


class ScanClock:
    """The scan stage's phases from the outside (ispes/scan.py is not instrumented): its start
    and end (the pipeline's events) and the first and last ``progress(done, total)`` call;
    the first comes when the grid is dispatched, after the serial work in front of it."""

    def __init__(self) -> None:
        self.marks: dict[str, float] = {}

    def event(self, ev) -> None:
        if ev.name == "scan" and ev.kind in ("start", "end"):
            self.marks[ev.kind] = time.perf_counter()

    def progress(self, done: int, total: int) -> None:
        now = time.perf_counter()
        self.marks.setdefault("first_progress", now)
        self.marks["last_progress"] = now

    def phases(self) -> dict[str, float]:
        """Seconds before the grid (probe, ideal work of separation, symmetry detection,
        worker start-up), on the grid (points and the symmetry verification), after it
        (``ispes.nc``, ``scan.json``, the figure)."""
        m = self.marks
        if not {"start", "end", "first_progress", "last_progress"} <= set(m):
            return {}
        return {
            "before_grid_s": round(m["first_progress"] - m["start"], 2),
            "grid_s": round(m["last_progress"] - m["first_progress"], 2),
            "after_grid_s": round(m["end"] - m["last_progress"], 2),
        }


def measure(preset: str) -> dict:
    """Run the default twice in a temporary directory; the ``"run"`` block of the record."""
    from flatcontact.config import load_config
    from flatcontact.foundation.layout import REPORT_HTML, SCAN_JSON
    from flatcontact.pipeline import Pipeline

    cfg = load_config(preset_name=preset)
    block = {"preset": preset, **record.machine()}
    clock = ScanClock()
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp) / "run"
        start = time.perf_counter()
        with (
            PhaseLog() as phases,
            Pipeline(cfg, root, on_event=clock.event, scan_progress=clock.progress) as pipe,
        ):
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
        "scan_phases_s": clock.phases(),
        "scan_driver_phases_s": {k: round(v, 3) for k, v in phases.seconds.items()},
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
    if block.get("scan_driver_phases_s"):
        lines.insert(
            -1,
            "  scan driver phases (s; a/b is part of a): "
            + ", ".join(f"{k} {v:.2f}" for k, v in block["scan_driver_phases_s"].items()),
        )
    if block.get("scan_phases_s"):
        ph = block["scan_phases_s"]
        lines.insert(
            -1,
            f"  scan phases: {ph['before_grid_s']:.2f} s before the grid (probe, ideal work of "
            f"separation, symmetry, worker start-up), {ph['grid_s']:.2f} s on the grid, "
            f"{ph['after_grid_s']:.2f} s after it",
        )
    return lines


def main() -> None:
    preset = os.environ.get("FLATCONTACT_BENCH_PRESET", "quick")
    block = measure(preset)
    baseline = json.loads(record.BASELINE.read_text()) if preset == "quick" else {}
    print("\n".join(table(block, baseline)))
    if preset == "quick":
        print(f"  stored: {record.write_block('run', block)}")
