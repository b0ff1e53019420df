"""``flatcontact scan``: the ISPES grid of an interface (resumable, parallel).

Thin: reads the run configuration (:func:`flatcontact.config.load_config`, the file
``flatcontact run`` reads; its ``potential``/``calculator`` and ``scan`` sections), lays the
flags over it, validates everything, runs :func:`flatcontact.ispes.scan.run_scan` and prints
a summary.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated, Any

import typer

from flatcontact.cli.app import app, check_out_dir, console, err_console, parse_floats
from flatcontact.errors import InputError

#: Config field (dotted path) -> the flag that sets it, to name the flag in errors.
_FLAG_OF = {
    "potential": "--potential",
    "potential.intra": "--potential",
    "calculator": "--calculator",
    "scan.grid": "--grid",
    "scan.thickness_angstrom": "--thickness",
    "scan.p_range_gpa": "--p-range-gpa",
    "scan.fmax_ev_per_angstrom": "--fmax-ev-per-angstrom",
    "scan.optimizer": "--optimizer",
    "scan.max_steps": "--max-steps",
    "scan.order": "--order",
    "scan.executor": "--executor",
    "scan.workers": "--workers",
    "scan.dask_address": "--dask-address",
}
_FLAGS_SOURCE = "command-line flags"
#: Where ``flatcontact build`` writes the interface by default (``--out build``).
DEFAULT_INTERFACE = "build/interface.extxyz"


def _floats(values: list[str] | None, flag: str) -> list[float] | None:
    """The numbers of a list flag, ``None`` when it is not given (empty items refused)."""
    return parse_floats(values, flag, "Å") if values else None


def _potential_section(potential: str) -> dict[str, Any]:
    """``--potential`` as a change of the config's ``potential`` section."""
    path = Path(potential).expanduser()
    if potential.endswith(".json"):
        if not path.is_file():
            raise InputError(f"--potential {potential}: no such potential spec file")
        try:
            data = json.loads(path.read_text())
        except ValueError:
            raise InputError(f"--potential {potential}: not valid JSON") from None
        if not isinstance(data, dict):
            raise InputError(f"--potential {potential}: expected a JSON object (a PotentialSpec)")
        return data
    return {"intra": potential}  # any spelling: PotentialSpec normalizes it


def _flag_error(exc: InputError) -> InputError:
    """A validation error of the flags, with the flag named instead of the config path."""
    text = str(exc).removeprefix(f"{_FLAGS_SOURCE}: ")
    where, sep, msg = text.partition(": ")
    field, sep2, rest = msg.partition(": ")  # a section validator naming its field first
    if sep2 and f"{where}.{field}" in _FLAG_OF:
        where, msg = f"{where}.{field}", rest
    for key in sorted(_FLAG_OF, key=len, reverse=True):
        if sep and where == key:
            return InputError(f"{_FLAG_OF[key]}: {msg}")
        if sep and where.startswith(key + "."):
            return InputError(f"{_FLAG_OF[key]} ({where}): {msg}")
    return InputError(f"{_FLAGS_SOURCE}: {text}")


def resolve_config(config: Path | None, preset: str | None, flags: dict[str, Any]):
    """The :class:`~flatcontact.config.RunConfig` of ``CONFIG`` (or the preset) with ``flags`` laid over.

    ``flags`` holds the non-``None`` flag values as a nested mapping of config sections
    (``{"scan": {"grid": [4, 4]}, "potential": {"intra": "vashishta"}}``). Errors in the file
    name the file and ``scan.<field>``; errors in a flag name the flag.
    """
    from flatcontact.config import build_config, load_config, merge_config

    cfg = load_config(config, preset)
    flags = {k: v for k, v in flags.items() if v != {}}
    if not flags:
        return cfg
    merged = merge_config(cfg.to_dict(), flags)
    try:
        return build_config(merged, source=_FLAGS_SOURCE)
    except InputError as exc:
        raise _flag_error(exc) from None


@app.command("scan")
def scan_command(
    config: Annotated[
        Path | None,
        typer.Argument(
            help="Run configuration (YAML), the same file 'flatcontact run' reads: its "
            "potential/calculator and scan sections are used, flags override them. "
            "Default: the built-in quick preset."
        ),
    ] = None,
    preset: Annotated[
        str | None,
        typer.Option("--preset", help="quick (default) or paper: the defaults under CONFIG."),
    ] = None,
    interface: Annotated[
        str | None,
        typer.Option(
            "--interface",
            help=f"interface.extxyz (default: {DEFAULT_INTERFACE}, what 'flatcontact build' writes).",
        ),
    ] = None,
    potential: Annotated[
        str | None,
        typer.Option(
            "--potential",
            help="potential.intra: vashishta | tersoff | [snap:]NAME | [snap:]path/X.snapcoeff | "
            "ase:module:factory; or a "
            "PotentialSpec .json whose fields replace the potential section's (default "
            "snap:sio2-snap, "
            "vashishta if that is not installed).",
        ),
    ] = None,
    calculator: Annotated[
        str | None,
        typer.Option(
            "--calculator",
            help="calculator.target: an ASE calculator 'module:callable' instead of --potential.",
        ),
    ] = None,
    grid: Annotated[
        tuple[int, int] | None,
        typer.Option("--grid", help="scan.grid: lateral points NA NB (default: the preset's)."),
    ] = None,
    thickness: Annotated[
        list[str] | None,
        typer.Option(
            "--thickness",
            help="scan.thickness_angstrom: thicknesses z in Å (surface 1 to 4); repeat or "
            "comma-separate. Replaces the pressure range.",
        ),
    ] = None,
    p_range_gpa: Annotated[
        tuple[float, float, int] | None,
        typer.Option(
            "--p-range-gpa",
            help="scan.p_range_gpa: choose N thicknesses spanning loads LO..HI GPa "
            "(default: the preset's).",
        ),
    ] = None,
    workers: Annotated[
        int | None,
        typer.Option("--workers", help="scan.workers: worker processes (default: one per core)."),
    ] = None,
    executor: Annotated[
        str | None,
        typer.Option("--executor", help="scan.executor: serial | processes (default) | dask."),
    ] = None,
    dask_address: Annotated[
        str | None,
        typer.Option("--dask-address", help="scan.dask_address: a running Dask scheduler."),
    ] = None,
    fmax_ev_per_angstrom: Annotated[
        float | None,
        typer.Option(
            "--fmax-ev-per-angstrom",
            help="scan.fmax_ev_per_angstrom: force tolerance on free atoms, eV/Å "
            "(default: the preset's).",
        ),
    ] = None,
    optimizer: Annotated[
        str | None,
        typer.Option(
            "--optimizer",
            help="scan.optimizer: LBFGS (default), BFGS, FIRE, FIRE2, BFGSLineSearch.",
        ),
    ] = None,
    max_steps: Annotated[
        int | None,
        typer.Option("--max-steps", help="scan.max_steps: optimiser step cap (default 2000)."),
    ] = None,
    order: Annotated[
        str | None,
        typer.Option(
            "--order", help="scan.order: warm-start tree columns (default), planes, cold."
        ),
    ] = None,
    out: Annotated[
        str | None, typer.Option("--out", help="Output directory (default ./ispes).")
    ] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print the summary as JSON.")] = False,
) -> None:
    """Relax every (shift_a, shift_b, z) point of the ISPES grid into OUT/points.db and OUT/ispes.nc.

    Settings come from CONFIG (a 'flatcontact run' configuration) or, without it, from the
    quick preset (see 'flatcontact config --show-default'); flags override them. Rerunning
    the same command continues an interrupted scan; a store made with other settings is
    refused.
    """
    from flatcontact.ispes.scan import ScanInterrupted, run_scan
    from flatcontact.structures.interface import read_interface

    if thickness and p_range_gpa is not None:
        raise InputError("give either --thickness or --p-range-gpa, not both")
    if potential is not None and calculator is not None:
        raise InputError("give either --potential or --calculator, not both")
    scan_flags = {
        "grid": list(grid) if grid is not None else None,
        "thickness_angstrom": _floats(thickness, "--thickness"),
        "p_range_gpa": dict(zip(("lo_gpa", "hi_gpa", "n"), p_range_gpa, strict=True))
        if p_range_gpa is not None
        else None,
        "fmax_ev_per_angstrom": fmax_ev_per_angstrom,
        "optimizer": optimizer,
        "max_steps": max_steps,
        "order": order,
        "executor": executor,
        "workers": workers,
        "dask_address": dask_address,
    }
    flags: dict[str, Any] = {"scan": {k: v for k, v in scan_flags.items() if v is not None}}
    if potential is not None:
        flags["potential"] = _potential_section(potential)
        flags["calculator"] = None
    if calculator is not None:
        flags["calculator"] = {"target": calculator, "kwargs": {}}
    cfg = resolve_config(config, preset, flags)
    out_dir = check_out_dir(out or "ispes")
    s = cfg.scan
    spec = s.grid_spec()
    relax = s.relax_settings()
    reference = read_interface(interface or DEFAULT_INTERFACE)
    _warn_other_potential(reference, cfg, interface or DEFAULT_INTERFACE)
    if cfg.calculator is not None:
        from flatcontact.ispes.calculators import CalculatorFactory

        factory = CalculatorFactory.from_target(cfg.calculator.target, **cfg.calculator.kwargs)
    else:
        from flatcontact.ispes.calculators import PotentialFactory
        from flatcontact.potentials import check_elements

        check_elements(cfg.potential, reference)
        factory = PotentialFactory.from_spec(cfg.potential)
    try:
        result = run_scan(
            reference,
            factory,
            spec,
            out_dir,
            relax,
            order=s.order,
            executor_options=s.executor_options(),
            progress=not as_json,
            console=console,
        )
    except ScanInterrupted as stop:
        r = stop.result
        err_console.print(
            f"interrupted: {r.points_done} of {r.points_total} points stored in {r.store_path}; "
            "rerun the same command to continue",
            highlight=False,
        )
        raise typer.Exit(130) from None
    _warn_no_repulsive_branch(result)
    _summary(result, as_json)


def _warn_no_repulsive_branch(result) -> None:
    """One warning line when no scanned thickness is under compression (p > 0 nowhere).

    Such a grid holds only the separated (tensile) branch; the constant-pressure analysis at
    P >= 0 needs thicknesses where the slabs push back (p = normal_stress > 0, compressive).
    """
    import numpy as np

    from flatcontact.cli.app import print_warning

    p = np.asarray(result.dataset.normal_stress.values, dtype=float)
    if p.size and not np.any(p[np.isfinite(p)] > 0):
        z = [float(v) for v in result.dataset.thickness.values]
        print_warning(
            f"no scanned thickness reached p > 0 (max {np.nanmax(p):.3g} GPa at z = "
            f"{min(z):g}..{max(z):g} Å): the interface is separated everywhere and "
            "'flatcontact analyze' has no repulsive branch; scan smaller thicknesses"
        )


def built_with_other_model(reference, cfg) -> str | None:
    """The model an interface's recipe names when it is not the one of ``cfg``, else ``None``.

    The recipe (``info["recipe"]``, written by :mod:`flatcontact.structures.build`) holds the
    whole ``PotentialSpec`` (``potential_spec``; older files only its label ``potential``, of
    which the intra-slab part is compared). A recipe naming no potential gives ``None``.
    """
    from flatcontact.potentials.spec import PotentialSpec, normalize_potential_name

    try:
        recipe = json.loads(reference.info.get("recipe", "{}") or "{}")
    except (TypeError, ValueError):
        return None
    if not isinstance(recipe, dict):
        return None
    if isinstance(recipe.get("potential_spec"), dict):
        try:
            built = PotentialSpec(**recipe["potential_spec"])
        except (InputError, TypeError):
            return str(recipe["potential_spec"].get("intra", "an unknown model"))
        same = cfg.calculator is None and built == cfg.potential
        return None if same else built.label
    label = recipe.get("potential")
    if not isinstance(label, str) or not label:
        return None
    intra = label.split("+LJ(")[0]
    try:
        intra = normalize_potential_name(intra)
    except InputError:
        pass
    same = cfg.calculator is None and intra == cfg.potential.intra
    return None if same else label


def _warn_other_potential(reference, cfg, where: str) -> None:
    """One warning line when the interface was relaxed with another model than the scan's."""
    from flatcontact.cli.app import print_warning

    built_with = built_with_other_model(reference, cfg)
    if built_with is not None:
        model = cfg.calculator.target if cfg.calculator is not None else cfg.potential.label
        print_warning(
            f"{where} was built with {built_with}, this scan uses {model}: its reference "
            "stacking and thickness are not the relaxed ones of the scan's model"
        )


def _summary(result, as_json: bool) -> None:
    import numpy as np

    calls = result.force_calls_computed
    summary = {
        "ispes": str(result.ispes_path),
        "points_db": str(result.store_path),
        "points_total": result.points_total,
        "points_done": result.points_done,
        "points_computed": result.points_computed,
        "converged": int(result.dataset.converged.sum()),
        "median_force_calls": float(np.median(calls)) if calls else None,
        "seconds": round(result.seconds, 3),
        "thickness_angstrom": [float(z) for z in result.dataset.thickness.values],
        "adhesion": result.adhesion,
        "notes": result.notes,
    }
    if as_json:
        print(json.dumps(summary, indent=2))
        return
    from rich.table import Table

    table = Table(title="ISPES scan", show_header=False)
    for key, value in summary.items():
        if key == "adhesion" and value:
            for k, v in value.items():
                table.add_row(k, f"{v:.6g}" if isinstance(v, float) else str(v))
        elif key == "thickness_angstrom":
            table.add_row(key, ", ".join(f"{z:.4f}" for z in value))
        elif key != "adhesion":
            table.add_row(key, str(value))
    console.print(table)
