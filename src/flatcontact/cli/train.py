"""``flatcontact train-snap``: fit a SNAP to a labelled dataset or a generated recipe
(:func:`flatcontact.training.train.train_snap`)."""

from __future__ import annotations

import re
import shlex
import sys
from pathlib import Path

import typer

from flatcontact.cli.app import (
    app,
    bounded,
    bounded_int,
    check_out_dir,
    console,
    print_progress,
)
from flatcontact.foundation.errors import InputError


def check_base_name(name: str, flag: str = "--name") -> str:
    """A base file name written inside ``--out``: no path components, no leading dot.

    Raises
    ------
    InputError
        One line naming ``flag`` and the value (``../../evil``, ``a/b``, ``.hidden``, empty).
    """
    if not re.fullmatch(r"[A-Za-z0-9_][A-Za-z0-9_.+-]{0,99}", name or ""):
        raise InputError(
            f"{flag} {name!r}: expected a plain file name (letters, digits, _ . + -, no '/' "
            "or '..', at most 100 characters); the files are written inside --out"
        )
    return name


@app.command("train-snap")
def train_snap_cmd(
    data: Path = typer.Option(None, "--data", help="Labelled extxyz (energies, forces, stresses)."),
    recipe: str = typer.Option(None, "--recipe", help="Training-set recipe to generate (sio2)."),
    label: str = typer.Option(
        "chgnet",
        "--label",
        help="Offline teacher for --recipe labels: chgnet (= chgnet-r2scan), sevennet-0, "
        "sevennet-mf-0-r2scan, sevennet-mf-0-pbe.",
    ),
    out: Path = typer.Option(Path("snap-training"), "--out", help="Output directory."),
    name: str = typer.Option("snap", "--name", help="Base name of the .snapcoeff/.snapparam."),
    seed: int = typer.Option(0, "--seed", help="Seed of the recipe and the data split."),
    scale: float = typer.Option(1.0, "--scale", help="Size factor of the recipe's random groups."),
    quadratic: bool = typer.Option(
        None,
        "--quadratic/--linear",
        help="Only quadratic / only linear SNAPs (default: search both).",
    ),
    active_rounds: int = typer.Option(
        4, "--active-rounds", help="Active-learning rounds after the first fit (recipe runs only)."
    ),
) -> None:
    """Fit a SNAP (LAMMPS .snapcoeff/.snapparam) to a dataset or a generated recipe."""
    from flatcontact.foundation.numbers import Bounds
    from flatcontact.potentials.teachers import get_teacher
    from flatcontact.training.train import train_snap

    check_base_name(name)
    # a size factor of the recipe's random groups: 1e-3 leaves one frame per group, 100
    # is ~10⁵ labelled frames (days of teacher time)
    bounded(scale, "--scale", Bounds(1e-3, 100.0))
    bounded_int(seed, "--seed", 0, 2**32 - 1, "a numpy seed")
    bounded_int(active_rounds, "--active-rounds", 0, 50, "active-learning rounds")
    if recipe is not None:
        get_teacher(label, "--label")
    check_out_dir(out)
    command = "flatcontact " + " ".join(shlex.quote(a) for a in sys.argv[1:])
    report = train_snap(
        out,
        data=data,
        recipe=recipe,
        label=label,
        seed=seed,
        name=name,
        scale=scale,
        quadratic=quadratic,
        active_rounds=active_rounds,
        command=command,
        progress=print_progress,
    )
    h = report["hyper"]
    console.print(
        f"SNAP 2J={h['twojmax']} rcutfac={h['rcutfac']} quadratic={h['quadratic']} -> {out}/{name}.snapcoeff"
    )
    for split in ("train", "validation", "test"):
        e = report["errors"].get(split)
        if e:
            console.print(
                f"{split:>10}: {e['n_frames']:4d} frames  E {e['energy_rmse_mev_per_atom']:.1f} meV/atom  "
                f"F {e['force_rmse_mev_per_angstrom']:.0f} meV/Å  S {e['stress_rmse_gpa']:.2f} GPa"
            )
