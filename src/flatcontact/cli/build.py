"""``flatcontact build``: the relaxed, verified two-slab interface.

Thin: maps the flags to run settings (``structure``, ``potential``, ``report.svg``) and runs
the build stage (:func:`flatcontact.stages.build.build_stage`), the one ``flatcontact run``
runs, so it writes the same files under the same names as ``01-build/``:
``interface.extxyz``, ``build.json`` and ``fig1_interface.png`` (+ ``.svg``).
"""

from __future__ import annotations

from pathlib import Path

import typer

from flatcontact.cli.app import (
    app,
    bounded,
    check_out_dir,
    console,
    print_warning,
    setting_bounds,
)
from flatcontact.cli.options import flags_of, setting_options, settings_command
from flatcontact.foundation import limits
from flatcontact.foundation.errors import InputError
from flatcontact.foundation.layout import BUILD_JSON

#: The settings the command exposes, one flag each (:mod:`flatcontact.cli.options`): the
#: quartz recipe's (with ``--config``, the file's recipe's: a flag it has no setting for is
#: refused) and the cutoff of the model's Lennard-Jones coupling.
PATHS = (
    "structure.layers",
    "structure.source",
    "structure.gap_angstrom",
    "structure.fmax_ev_per_angstrom",
    "potential.lj.cutoff_angstrom",
)

#: The defaults of the quartz flags when no configuration is given (with ``--config`` a flag
#: left out keeps the file's value).
_QUARTZ_DEFAULTS = {
    "layers": 6,
    "source": "auto",
    "gap_angstrom": 3.0,
    "fmax_ev_per_angstrom": 0.01,
}
OPTIONS = setting_options(
    PATHS,
    {
        **{
            f"structure.{k}": f"{v} (α-quartz; with --config the file's)"
            for k, v in _QUARTZ_DEFAULTS.items()
        },
        "potential.lj.cutoff_angstrom": "the run's (10; with --config the file's)",
    },
)
#: Settings path -> the flag that sets it, to name the flag in errors.
FLAG_OF = {
    **flags_of(OPTIONS),
    "structure.file": "--structure",
    "potential.lj": "--lj-cutoff-angstrom",
    "potential": "--potential",
}


def _check_numbers(gap_angstrom, fmax_ev_per_angstrom, lj_cutoff_angstrom):
    """Every number flag of ``build`` that was given within the bounds of the setting it sets
    (the recipe's gap and force tolerance, the LJ cutoff), before anything is read or built."""
    from flatcontact.potentials.coupling import LJSpec
    from flatcontact.structures.recipe import QuartzDenseRecipe

    if gap_angstrom is not None:
        bounded(gap_angstrom, "--gap-angstrom", setting_bounds(QuartzDenseRecipe, "gap_angstrom"))
    if fmax_ev_per_angstrom is not None:
        bounded(
            fmax_ev_per_angstrom,
            "--fmax-ev-per-angstrom",
            setting_bounds(QuartzDenseRecipe, "fmax_ev_per_angstrom"),
        )
    if lj_cutoff_angstrom is not None:
        bounded(
            lj_cutoff_angstrom, "--lj-cutoff-angstrom", setting_bounds(LJSpec, "cutoff_angstrom")
        )


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
@settings_command(OPTIONS)
def build(
    settings: dict,
    potential: str = typer.Option(
        None,
        "--potential",
        help="vashishta | tersoff | \\[snap:]NAME | \\[snap:]path/X.snapcoeff | ase:module:factory "
        "(default: the run's default, snap:sio2-snap; vashishta if that is not installed).",
    ),
    out: Path = typer.Option(
        Path("build"),
        "--out",
        help="Output directory (default ./build, where 'flatcontact scan' looks by default).",
    ),
    structure: Path | None = typer.Option(
        None,
        "--structure",
        help="A slab structure file (any crystal, surface normal along cell vector 3) instead "
        "of α-quartz.",
    ),
    config: Path | None = typer.Option(
        None,
        "--config",
        help="A run configuration (YAML): its structure recipe and potential, the same as "
        "'flatcontact run CONFIG' builds; every other flag given is laid over the file "
        "(a flag the file's recipe has no setting for is refused).",
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
    from flatcontact.cli.settings import FLAGS_SOURCE, config_source, flag_errors
    from flatcontact.config import build_config
    from flatcontact.stages.build import BuildInputs, build_stage
    from flatcontact.structures import build as builder

    given = {k: settings.get("structure", {}).get(k) for k in _QUARTZ_DEFAULTS}
    layers, source = given["layers"], given["source"]
    gap_angstrom, fmax_ev_per_angstrom = given["gap_angstrom"], given["fmax_ev_per_angstrom"]
    lj_cutoff_angstrom = settings.get("potential", {}).get("lj", {}).get("cutoff_angstrom")
    _check_numbers(gap_angstrom, fmax_ev_per_angstrom, lj_cutoff_angstrom)
    if structure is not None and not structure.is_file():
        raise InputError(f"--structure {structure}: file not found")
    if config is not None:
        if regenerate_dense:
            raise InputError(
                "--regenerate-dense: not with --config (it rebuilds the shipped quartz slab)"
            )
        cfg = _config_settings(config, structure, potential, lj_cutoff_angstrom, given, svg)
        _check_build_inputs(
            cfg, config_source(config), potential is not None, structure is not None
        )
        check_out_dir(out)
        given_paths = [f"structure.{k}" for k, v in given.items() if v is not None]
        given_paths += ["potential"] * (potential is not None)
        given_paths += ["structure.file"] * (structure is not None)
        given_paths += ["potential.lj"] * (lj_cutoff_angstrom is not None)
        # the flags given only: a setting of the file is named as the file names it
        with flag_errors({k: v for k, v in FLAG_OF.items() if k in given_paths}):
            result = build_stage(cfg, BuildInputs(), out)
        _print(result, out)
        return
    quartz = {k: _QUARTZ_DEFAULTS[k] if v is None else v for k, v in given.items()}
    layers, source = quartz["layers"], quartz["source"]
    gap_angstrom, fmax_ev_per_angstrom = quartz["gap_angstrom"], quartz["fmax_ev_per_angstrom"]
    if structure is None:
        builder.check_layers(layers, "--layers")
        limits.check("layers", layers, "--layers", "layers per slab")
        if source == "shipped":
            builder.check_shipped_layers(layers, "--layers")
    elif given["layers"] is not None or given["source"] is not None:
        flag = "--layers" if given["layers"] is not None else "--source"
        raise InputError(
            f"{flag}: an α-quartz setting; with --structure the layers come from the file"
        )
    if regenerate_dense:
        provenance = builder.regenerate_shipped_dense_slab(
            layers=layers, fmax_ev_per_angstrom=fmax_ev_per_angstrom
        )
        console.print(
            f"wrote {builder.SHIPPED_DENSE_SLAB} (CHGNet energy {provenance['energy_ev']:.4f} eV)"
        )
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
        # the slab recipe finds the layers from the structure (a monolayer works) and takes
        # the surface normal along cell vector 3
        section = {
            "kind": "slab",
            "file": str(structure),
            "gap_angstrom": gap_angstrom,
            "fmax_ev_per_angstrom": fmax_ev_per_angstrom,
        }
    data = {
        "structure": section,
        "potential": spec.model_dump(mode="json"),
        "report": {"svg": svg},
    }
    with flag_errors(FLAG_OF):
        cfg = build_config(data, source=FLAGS_SOURCE)
    _check_build_inputs(cfg, FLAGS_SOURCE, potential is not None, structure is not None)
    with flag_errors(FLAG_OF):
        result = build_stage(cfg, BuildInputs(), out)
    _print(result, out)


def _config_settings(
    config: Path,
    structure: Path | None,
    potential: str | None,
    lj_cutoff_angstrom: float | None,
    given: dict,
    svg: bool,
):
    """The run settings of ``--config`` with every flag that was given laid over: ``--structure``
    (a slab file: the ``slab`` recipe, layers found from the structure, so a 2D monolayer
    works), ``--potential`` (a preset name or an intra-slab model), ``--lj-cutoff-angstrom``
    (the model's LJ coupling) and the recipe flags ``given`` (``layers``, ``source``,
    ``gap_angstrom``, ``fmax_ev_per_angstrom``; None: not given). A flag the resulting recipe
    or model has no setting for is one line naming the flag, never ignored; ``--layers`` is
    judged by the file's recipe (quartz: O–Si–O layers >= 5; fcc(111): planes >= 1)."""
    from flatcontact.cli.settings import resolve_config
    from flatcontact.config import load_config

    flags: dict = {"report": {"svg": svg}}
    recipe = {k: v for k, v in given.items() if v is not None}
    kind = "slab" if structure is not None else load_config(config).structure.kind
    fields = _recipe_fields(kind)
    for key in recipe:
        if key not in fields:
            raise InputError(
                f"{FLAG_OF['structure.' + key]}: the structure recipe {kind!r} has no {key} "
                "setting (remove the flag or change the recipe)"
            )
    if kind == "quartz-dense" and "layers" in recipe:
        from flatcontact.structures import build as builder

        builder.check_layers(recipe["layers"], "--layers")
    if structure is not None:
        recipe = {**recipe, "kind": "slab", "file": str(structure)}
    if recipe:
        flags["structure"] = recipe
    if potential is not None:
        flags["potential"] = _potential_flag_section(potential)
    cfg = resolve_config(config, None, flags, FLAG_OF)
    if lj_cutoff_angstrom is not None:
        if cfg.potential.coupling != "lj":
            raise InputError(
                f"--lj-cutoff-angstrom: the configuration's coupling across the interface is "
                f"{cfg.potential.coupling!r}, not lj: there is no Lennard-Jones cutoff to set"
            )
        lj = {**flags.get("potential", {}), "lj": {"cutoff_angstrom": lj_cutoff_angstrom}}
        cfg = resolve_config(config, None, {**flags, "potential": lj}, FLAG_OF)
    return cfg


def _check_build_inputs(cfg, source: str, potential_given: bool, structure_given: bool):
    """The pre-run checks of the build (:func:`~flatcontact.stages.preflight.check_build_inputs`:
    the structure file, the model set up on the recipe's interface and one energy and forces
    of it), before anything is written, in the line ``config --check CONFIG`` gives:
    ``<source>: <settings path>: ...`` (``source`` the ``--config`` file, or the flags), or
    ``--potential: ...`` / ``--structure: ...`` when that flag set the part refused."""
    from flatcontact.stages.preflight import check_build_inputs

    try:
        check_build_inputs(cfg, source)
    except InputError as exc:
        text = str(exc).removeprefix(f"{source}: ")
        field, _, said = text.partition(": ")
        if field == "potential.coupling":  # --potential names an intra model, never the coupling
            raise
        for given, section, flag in (
            (potential_given, "potential", "--potential"),
            (structure_given, "structure", "--structure"),
        ):
            if not given or not text.startswith(section):
                continue
            if said and (field == section or field.startswith(section + ".")):
                raise InputError(f"{flag}: {said}") from None
            if text[len(section) : len(section) + 1] == " ":  # "potential 'x' has no ..."
                raise InputError(f"{flag}{text[len(section) :]}") from None
        raise


def _recipe_fields(kind: str) -> set[str]:
    """The settings of the structure recipe ``kind`` (:data:`flatcontact.structures.recipe.StructureRecipe`)."""
    import typing

    from flatcontact.structures.recipe import StructureRecipe

    for cls in typing.get_args(typing.get_args(StructureRecipe)[0]):
        if cls.model_fields["kind"].default == kind:
            return set(cls.model_fields)
    return set()


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
