"""``flatcontact build``: the relaxed, verified two-slab interface.

Thin: maps the flags to run settings (``structure``, ``potential``, ``report.svg``) and runs
the build stage (:func:`flatcontact.stages.build.run_build`), the one ``flatcontact run``
runs, so it writes the same files under the same names as ``01-build/``:
``interface.extxyz``, ``build.json`` and ``fig1_interface.png`` (+ ``.svg``).
"""

from __future__ import annotations

from pathlib import Path

import typer

from flatcontact import limits
from flatcontact.cli.app import (
    app,
    bounded,
    bounded_int,
    check_out_dir,
    console,
    print_warning,
    setting_bounds,
)
from flatcontact.errors import InputError
from flatcontact.layout import BUILD_JSON

#: Settings path -> the flag that sets it, to name the flag in errors.
_FLAG_OF = {
    "structure.file": "--structure",
    "structure.layers": "--layers",
    "structure.source": "--source",
    "structure.gap_angstrom": "--gap-angstrom",
    "structure.fmax_ev_per_angstrom": "--fmax-ev-per-angstrom",
    "structure.normal_axis": "--normal-axis",
    "structure.face_depth_angstrom": "--face-depth-angstrom",
    "potential": "--potential",
}


def _check_numbers(gap_angstrom, fmax_ev_per_angstrom, lj_cutoff_angstrom, normal_axis, face_depth):
    """Every number flag of ``build`` within the bounds of the setting it sets (the recipe's
    gap and force tolerance, the LJ cutoff), before anything is read or built."""
    from flatcontact.numbers import Bounds
    from flatcontact.potentials.coupling import LJSpec
    from flatcontact.structures.recipe import QuartzDenseRecipe

    bounded(gap_angstrom, "--gap-angstrom", setting_bounds(QuartzDenseRecipe, "gap_angstrom"))
    bounded(
        fmax_ev_per_angstrom,
        "--fmax-ev-per-angstrom",
        setting_bounds(QuartzDenseRecipe, "fmax_ev_per_angstrom"),
    )
    if lj_cutoff_angstrom is not None:
        bounded(
            lj_cutoff_angstrom, "--lj-cutoff-angstrom", setting_bounds(LJSpec, "cutoff_angstrom")
        )
    bounded_int(normal_axis, "--normal-axis", 0, 2, "a cell axis")
    bounded(face_depth, "--face-depth-angstrom", Bounds(0.1, 20.0, "Å"))


def _potential_spec(potential: str | None, lj_cutoff_angstrom: float | None):
    """The :class:`~flatcontact.potentials.InteractionModel` of the flags; errors name the flag.

    The run's default model (:func:`flatcontact.config.default_potential`: the bundled SNAP and
    the Hamaker-calibrated TS-vdW LJ) with ``--potential`` replacing its intra-slab model and
    ``--lj-cutoff-angstrom`` its LJ cutoff, so ``flatcontact build`` relaxes the interface with
    the model that ``flatcontact run`` and ``flatcontact scan`` use.
    """
    from flatcontact.config import default_potential
    from flatcontact.potentials.model import InteractionModel

    section = default_potential()
    if potential is not None:
        flag = _potential_flag_section(potential)
        # a preset is a whole model, not the quartz LJ's intra-slab part
        section = flag if "preset" in flag else {**section, **flag}
    if lj_cutoff_angstrom is not None:
        section.setdefault("lj", {})["cutoff_angstrom"] = lj_cutoff_angstrom
    try:
        return InteractionModel(**section)
    except InputError as exc:
        text = str(exc)
        if text.startswith("potential lj.cutoff_angstrom"):
            raise InputError(f"--lj-cutoff-angstrom: {text.split(': ', 1)[-1]}") from None
        raise InputError(f"--potential: {text.removeprefix('potential intra: ')}") from None


@app.command("build")
def build(
    layers: int = typer.Option(
        6,
        "--layers",
        help="O–Si–O layers per α-quartz (0001) slab, >= 5: a fixed outer and a sliding "
        "inner dense face layer of 2 units each and at least one inner layer between them "
        "(the scan relaxes 'surfaces 2, 3 and the inner atomic layers').",
    ),
    potential: str = typer.Option(
        None,
        "--potential",
        help="vashishta | tersoff | [snap:]NAME | [snap:]path/X.snapcoeff | ase:module:factory "
        "(default: the run's default, snap:sio2-snap; vashishta if that is not installed).",
    ),
    out: Path = typer.Option(
        Path("build"),
        "--out",
        help="Output directory (default ./build, where 'flatcontact scan' looks by default).",
    ),
    source: str = typer.Option(
        "auto",
        "--source",
        help="auto | shipped (CHGNet-relaxed 6-layer slab; 9, 12, ... layers: bulk "
        "alpha-quartz c-repeats inserted into its interior) | seed",
    ),
    gap_angstrom: float = typer.Option(
        3.0, "--gap-angstrom", help="Initial gap between the slabs (Å)."
    ),
    lj_cutoff_angstrom: float = typer.Option(
        None, "--lj-cutoff-angstrom", help="Cross-interface LJ cutoff (Å; default the run's, 10)."
    ),
    fmax_ev_per_angstrom: float = typer.Option(
        0.01, "--fmax-ev-per-angstrom", help="Relaxation tolerance on the max force."
    ),
    structure: Path | None = typer.Option(
        None, "--structure", help="A slab structure file (any crystal) instead of α-quartz."
    ),
    normal_axis: int = typer.Option(
        2, "--normal-axis", help="With --structure: cell axis (0, 1, 2) along the surface normal."
    ),
    face_depth_angstrom: float = typer.Option(
        2.0,
        "--face-depth-angstrom",
        help="Ignored (kept for old scripts): the layers are found from the structure.",
    ),
    config: Path | None = typer.Option(
        None,
        "--config",
        help="A run configuration (YAML): its structure recipe and potential, the same as "
        "'flatcontact run CONFIG' builds (--structure, --potential override them).",
    ),
    svg: bool = typer.Option(True, "--svg/--no-svg", help="Also write fig1_interface.svg."),
    regenerate_dense: bool = typer.Option(
        False,
        "--regenerate-dense",
        help="Regenerate the shipped dense slab with CHGNet r2SCAN and exit.",
    ),
) -> None:
    """Build the interface: writes interface.extxyz, build.json and fig1_interface.png to --out.

    The same files as the build stage of 'flatcontact run' (its 01-build/ folder).
    """
    from flatcontact.cli.settings import FLAGS_SOURCE, flag_errors
    from flatcontact.config import build_config
    from flatcontact.stages.build import BuildInputs, run_build
    from flatcontact.structures import build as builder

    _check_numbers(
        gap_angstrom, fmax_ev_per_angstrom, lj_cutoff_angstrom, normal_axis, face_depth_angstrom
    )
    if structure is None:
        builder.check_layers(layers, "--layers")
        limits.check("layers", layers, "--layers", "layers per slab")
        if source == "shipped":
            builder.check_shipped_layers(layers, "--layers")
    if regenerate_dense:
        provenance = builder.regenerate_shipped_dense_slab(
            layers=layers, fmax_ev_per_angstrom=fmax_ev_per_angstrom
        )
        console.print(
            f"wrote {builder.SHIPPED_DENSE_SLAB} (CHGNet energy {provenance['energy_ev']:.4f} eV)"
        )
        return
    if structure is not None and not structure.is_file():
        raise InputError(f"--structure {structure}: file not found")
    if config is not None:
        cfg = _config_settings(config, structure, potential, gap_angstrom, svg)
        check_out_dir(out)
        with flag_errors(_FLAG_OF):
            result = run_build(cfg, BuildInputs(), out)
        _print(result, out)
        return
    spec = _potential_spec(potential, lj_cutoff_angstrom)
    check_out_dir(out)
    section = {
        "kind": "quartz-dense",
        "layers": layers,
        "source": source,
        "gap_angstrom": gap_angstrom,
        "fmax_ev_per_angstrom": fmax_ev_per_angstrom,
    }
    if structure is not None:
        # the slab recipe finds the layers from the structure (a monolayer works); a normal
        # other than cell vector 3 is refused naming --normal-axis
        section = {
            "kind": "slab",
            "file": str(structure),
            "gap_angstrom": gap_angstrom,
            "fmax_ev_per_angstrom": fmax_ev_per_angstrom,
        }
        if normal_axis != 2:  # the default is the only axis taken (no deprecation warning)
            section["normal_axis"] = normal_axis
    data = {
        "structure": section,
        "potential": spec.model_dump(mode="json"),
        "report": {"svg": svg},
    }
    with flag_errors(_FLAG_OF):
        cfg = build_config(data, source=FLAGS_SOURCE)
        result = run_build(cfg, BuildInputs(), out)
    _print(result, out)


def _config_settings(config: Path, structure: Path | None, potential: str | None, gap, svg):
    """The run settings of ``--config`` with ``--structure`` (a slab file: the ``slab``
    recipe, layers found from the structure, so a 2D monolayer works) and ``--potential``
    (a preset name or an intra-slab model) laid over."""
    from flatcontact.cli.settings import resolve_config

    flags: dict = {"report": {"svg": svg}}
    if structure is not None:
        flags["structure"] = {"kind": "slab", "file": str(structure), "gap_angstrom": gap}
    if potential is not None:
        flags["potential"] = _potential_flag_section(potential)
    return resolve_config(config, None, flags, _FLAG_OF)


def _potential_flag_section(potential: str) -> dict:
    """``--potential`` as a ``potential:`` section: ``{preset: NAME}`` for an interaction
    preset (:data:`flatcontact.potentials.presets.PRESETS`), else ``{intra: NAME}``."""
    from flatcontact.potentials.presets import PRESETS

    name = potential.strip()
    return {"preset": name} if name in PRESETS else {"intra": name}


def _print(result, out: Path) -> None:
    for line in result.warnings:
        print_warning(line)
    figures = [f for f in result.files if f.name.startswith("fig1_")]
    console.print(
        f"wrote {out / 'interface.extxyz'} ({len(result.atoms)} atoms, thickness "
        f"{result.report['thickness_angstrom']:.3f} Å), {out / BUILD_JSON}, "
        + ", ".join(str(f) for f in figures),
        highlight=False,
        soft_wrap=True,
    )
