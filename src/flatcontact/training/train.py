"""End-to-end SNAP training: dataset (recipe + teacher labels, or a file) -> fit -> files + report.

Output directory layout (``train_snap(..., out=DIR)``)::

    DIR/dataset.extxyz          labelled frames (recipe runs only)
    DIR/test.extxyz             the held-out test split (for validate-potential --heldout)
    DIR/<name>.snapcoeff        LAMMPS coefficients
    DIR/<name>.snapparam        LAMMPS descriptor parameters
    DIR/fit_report.json         hyper-parameters, RMSEs per split and group, search table
    DIR/parity.png              parity plots (energy, force, stress) on the test split
    DIR/provenance.json         teacher, recipe + seed, sizes, package versions, command
"""

from __future__ import annotations

import importlib.metadata as md
import platform
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from flatcontact.foundation.errors import InputError
from flatcontact.foundation.fileio import atomic_path, write_json_atomic
from flatcontact.foundation.units import EV_PER_A3_TO_GPA
from flatcontact.training.dataset import labels, read_dataset, write_dataset
from flatcontact.training.fit import FitResult, default_hypers, default_settings, fit_snap
from flatcontact.training.snapfiles import write_snap_files

ELEMENTS = ("Si", "O")
#: Active-learning frames whose teacher forces exceed this (eV/Å) are dropped: the
#: probe went somewhere unphysical and the frame would only cost fit capacity.
MAX_ACTIVE_FORCE = 20.0
#: Row weights per group: up for what the ISPES scan and the contact moduli rely on
#: (bulk alpha-quartz elasticity and EOS, the dense surface, configurations the SNAP
#: itself visits), down for the far-from-equilibrium groups that a linear SNAP cannot
#: fit as well (annealed cut slabs, 1500 K MD, defects).
DEFAULT_GROUP_WEIGHTS = {
    "quartz_relaxed_strain": 20.0,
    "quartz_pressure": 3.0,
    "quartz_strain": 1.0,
    "dense_slab": 2.0,
    "active": 1.0,
    "close_contact": 0.5,
    "polymorph": 0.5,
    "slab": 0.3,
    "md": 0.5,
    "defect": 0.3,
}


def package_versions() -> dict:
    """Versions of the packages that shape a training run."""
    out = {"python": platform.python_version()}
    for pkg in ("flatcontact", "numpy", "scipy", "ase", "lammps", "chgnet", "sevenn", "torch"):
        try:
            out[pkg] = md.version(pkg)
        except md.PackageNotFoundError:
            out[pkg] = None
    return out


def build_recipe_dataset(
    recipe: str, seed: int, label: str, scale: float, say: Callable[[str], None]
) -> tuple[list, dict, object]:
    """Generate and label the recipe's frames; return (frames, info with timings, teacher)."""
    from flatcontact.potentials.teachers import teacher_calculator, teacher_info
    from flatcontact.training.label import label_frames
    from flatcontact.training.recipe import RECIPES, sio2_recipe

    if recipe not in RECIPES:
        raise InputError(f"--recipe {recipe!r}: expected one of {list(RECIPES)}")
    calc = teacher_calculator(label, "--label")
    t0 = time.perf_counter()
    frames = sio2_recipe(seed, calc, scale=scale, progress=lambda g: say(f"recipe: {g}"))
    t1 = time.perf_counter()
    say(f"recipe: {len(frames)} frames, {sum(len(a) for a in frames)} atoms in {t1 - t0:.0f} s")
    last = [0.0]

    def prog(k, n):
        if time.perf_counter() - last[0] > 10 or k == n:
            last[0] = time.perf_counter()
            say(f"labelling {k}/{n}")

    labelled = label_frames(frames, calc, progress=prog)
    t2 = time.perf_counter()
    info_calc = calc
    info = {
        **teacher_info(label, "--label"),
        "recipe": recipe,
        "seed": seed,
        "scale": scale,
        "recipe_s": t1 - t0,
        "labelling_s": t2 - t1,
    }
    return labelled, info, info_calc


def parity_plot(result: FitResult, path: Path, split: str = "test") -> Path:
    """Energy / force / stress parity plots of ``split`` (PNG, written atomically)."""
    from matplotlib.figure import Figure

    p = result.predictions.get(split) or result.predictions["validation"]
    fig = Figure(figsize=(12, 4))
    axes = fig.subplots(1, 3)
    pairs = [
        ("energy (eV/atom)", p["energy_ref"], p["energy_pred"]),
        ("force component (eV/Å)", p["force_ref"], p["force_pred"]),
        (
            "stress component (GPa)",
            p["stress_ref"] * EV_PER_A3_TO_GPA,
            p["stress_pred"] * EV_PER_A3_TO_GPA,
        ),
    ]
    for ax, (name, ref, pred) in zip(axes, pairs, strict=True):
        ax.plot(ref, pred, ".", ms=2, alpha=0.5)
        if len(ref):
            lo, hi = float(np.min([ref.min(), pred.min()])), float(np.max([ref.max(), pred.max()]))
            ax.plot([lo, hi], [lo, hi], "k-", lw=0.7)
        ax.set_xlabel(f"reference {name}")
        ax.set_ylabel(f"SNAP {name}")
    fig.suptitle(f"SNAP vs reference, {split} split")
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    return path


def _active_learning(frames, result, teacher, settings_grid, seed, n_rounds, out, say):
    """Rounds of probe -> label -> refit with the chosen descriptor hyper-parameters."""
    import tempfile

    from flatcontact.training.active import probe_frames
    from flatcontact.training.fit import split_indices
    from flatcontact.training.label import label_frames
    from flatcontact.training.lammps_bulk import snap_calculator

    frames = list(frames)
    split = {k: list(v) for k, v in result.split.items()}
    rounds = []
    for r in range(n_rounds):
        with tempfile.TemporaryDirectory(dir=out) as tmp:
            coeff, param = write_snap_files(Path(tmp) / "round", result.coefficients)
            t0 = time.perf_counter()
            new = probe_frames(snap_calculator(coeff, param), seed=seed + 17 * (r + 1))
        t1 = time.perf_counter()
        new = [
            a for a in label_frames(new, teacher) if np.abs(labels(a)[1]).max() <= MAX_ACTIVE_FORCE
        ]
        t2 = time.perf_counter()
        part = split_indices([a.info["config_type"] for a in new], seed + 31 * (r + 1))
        for k, idx in part.items():
            split[k] += [len(frames) + int(i) for i in idx]
        frames += new
        say(
            f"active round {r + 1}: +{len(new)} frames (probe {t1 - t0:.0f} s, label {t2 - t1:.0f} s)"
        )
        result = fit_snap(
            frames,
            ELEMENTS,
            [result.coefficients.hyper],
            settings_grid,
            split={k: np.array(sorted(v)) for k, v in split.items()},
            progress=say,
        )
        rounds.append(
            {
                "round": r + 1,
                "new_frames": len(new),
                "probe_s": t1 - t0,
                "label_s": t2 - t1,
                "test_errors": {
                    k: v for k, v in result.errors["test"].items() if k != "by_config_type"
                },
            }
        )
    return frames, result, rounds


def train_snap(
    out: str | Path,
    data: str | Path | None = None,
    recipe: str | None = None,
    label: str = "chgnet",
    seed: int = 0,
    name: str = "snap",
    scale: float = 1.0,
    hypers=None,
    settings_grid=None,
    quadratic: bool | None = None,
    active_rounds: int = 4,
    command: str = "",
    progress: Callable[[str], None] | None = None,
) -> dict:
    """Train a SNAP from ``data`` (extxyz) or ``recipe`` labelled by ``label``; write ``out``.

    ``label`` names an offline teacher of :mod:`flatcontact.potentials.teachers`
    (``chgnet``/``chgnet-r2scan``, ``sevennet-0``, ``sevennet-mf-0-r2scan``,
    ``sevennet-mf-0-pbe``); it is checked before any work and recorded in
    ``provenance.json`` with its package versions.

    With a recipe (a teacher at hand), ``active_rounds`` rounds of active learning
    follow the first fit (:mod:`.active`): frames from the SNAP's own relaxations and
    MD are labelled and added, and the SNAP is refitted with the chosen descriptor.
    Returns the fit report (also written to ``out/fit_report.json``).
    """
    say = progress or (lambda msg: None)
    if (data is None) == (recipe is None):
        raise InputError("give exactly one of --data FILE.extxyz or --recipe NAME")
    if not name or Path(name).name != name or name in (".", "..") or name.startswith("."):
        raise InputError(f"name {name!r}: expected a plain file name written inside {out}")
    if not scale > 0:
        raise InputError(f"scale {scale!r}: expected a positive size factor")
    if active_rounds < 0:
        raise InputError(f"active_rounds {active_rounds!r}: expected >= 0")
    if recipe is not None:
        from flatcontact.potentials.teachers import get_teacher

        get_teacher(label, "--label")
    out = Path(out)
    t_start = time.perf_counter()
    teacher = None
    if data is not None:
        frames = read_dataset(data, ELEMENTS)
        info = {"dataset_file": str(data), "seed": seed}
        say(f"read {len(frames)} frames from {data}")
    else:
        frames, info, teacher = build_recipe_dataset(recipe, seed, label, scale, say)
        write_dataset(frames, out / "dataset.extxyz")
    hypers = hypers or default_hypers(ELEMENTS, quadratic=quadratic)
    settings_grid = settings_grid or default_settings(DEFAULT_GROUP_WEIGHTS)
    t0 = time.perf_counter()
    result = fit_snap(frames, ELEMENTS, hypers, settings_grid, seed=seed, progress=say)
    search = list(result.search)
    rounds = []
    if teacher is not None:
        frames, result, rounds = _active_learning(
            frames, result, teacher, settings_grid, seed, active_rounds, out, say
        )
        write_dataset(frames, out / "dataset.extxyz")
    fit_s = time.perf_counter() - t0
    header = f"flatcontact SNAP '{name}' for {' '.join(ELEMENTS)}; trained on {info.get('recipe') or info.get('dataset_file')}"
    coeff, param = write_snap_files(out / name, result.coefficients, header=header)
    write_dataset([frames[i] for i in result.split["test"]], out / "test.extxyz")
    parity_plot(result, out / "parity.png")
    report = fit_report(name, result, search, {"fit_total_s": fit_s}, active_learning=rounds)
    write_json_atomic(out / "fit_report.json", report)
    provenance = {
        **info,
        "n_frames": len(frames),
        "n_atoms": int(sum(len(a) for a in frames)),
        "frames_by_config_type": {
            ct: sum(1 for a in frames if a.info.get("config_type") == ct)
            for ct in sorted({a.info.get("config_type", "default") for a in frames})
        },
        "split_seed": seed,
        "split_sizes": report["split_sizes"],
        "hyper": report["hyper"],
        "settings": report["settings"],
        "package_versions": package_versions(),
        "command": command,
        "wall_time_s": time.perf_counter() - t_start,
        "files": [coeff.name, param.name],
    }
    write_json_atomic(out / "provenance.json", provenance)
    return report


def fit_report(name: str, result, search, extra_timings_s: dict, **extra) -> dict:
    """The content of ``fit_report.json``: hyper-parameters, settings, held-out errors, the
    split (sizes and frame indices), the hyper-parameter search, ``extra`` entries (e.g. the
    active-learning rounds) and the timings (s), the fit's own plus ``extra_timings_s``."""
    return {
        "name": name,
        "elements": list(ELEMENTS),
        "hyper": result.coefficients.hyper.as_dict(),
        "settings": result.settings.as_dict(),
        "errors": result.errors,
        "split_sizes": {k: len(v) for k, v in result.split.items()},
        "split_indices": {k: [int(i) for i in v] for k, v in result.split.items()},
        "search": list(search),
        **extra,
        "timings_s": {**result.timings, **extra_timings_s},
    }
