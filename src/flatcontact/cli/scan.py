"""``flatcontact scan``: the ISPES grid of an interface (resumable, parallel).

Thin: builds a :class:`~flatcontact.ispes.config.ScanConfig` from a YAML file and flags,
validates everything, runs :func:`flatcontact.ispes.scan.run_scan` and prints a summary.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

import typer

from flatcontact.cli.app import app, console, err_console
from flatcontact.errors import InputError


def _floats(values: list[str] | None, flag: str) -> tuple[float, ...] | None:
    if not values:
        return None
    out = []
    for v in values:
        for item in v.replace(",", " ").split():
            try:
                out.append(float(item))
            except ValueError:
                raise InputError(f"{flag}: {item!r} is not a number") from None
    return tuple(out)


def potential_factory(potential: str, calculator: str | None):
    """The calculator factory for ``--potential`` (NAME, .snapcoeff path, spec .json) or ``--calculator``."""
    from flatcontact.ispes.calculators import CalculatorFactory, PotentialFactory

    if calculator:
        return CalculatorFactory.from_target(calculator)
    from flatcontact.potentials import PotentialSpec

    path = Path(potential).expanduser()
    if potential.endswith(".json"):
        if not path.is_file():
            raise InputError(f"--potential {potential}: no such potential spec file")
        spec = PotentialSpec.model_validate_json(path.read_text())
    elif potential.endswith(".snapcoeff"):
        spec = PotentialSpec(intra=f"snap:{path}")
    else:
        spec = PotentialSpec(intra=potential)
    return PotentialFactory.from_spec(spec)


@app.command("scan")
def scan_command(
    config: Annotated[
        Path | None,
        typer.Argument(help="YAML file with the same settings (top level or under 'scan:')."),
    ] = None,
    interface: Annotated[
        str | None,
        typer.Option("--interface", help="interface.extxyz (default: ./interface.extxyz)."),
    ] = None,
    potential: Annotated[
        str | None,
        typer.Option(
            "--potential",
            help="vashishta | tersoff | snap:NAME | path/X.snapcoeff | spec.json (default vashishta).",
        ),
    ] = None,
    calculator: Annotated[
        str | None,
        typer.Option(
            "--calculator", help="Instead of --potential: an ASE calculator 'module:callable'."
        ),
    ] = None,
    grid: Annotated[
        tuple[int, int] | None, typer.Option("--grid", help="Lateral points NA NB (default 12 12).")
    ] = None,
    thickness: Annotated[
        list[str] | None,
        typer.Option(
            "--thickness", help="Thicknesses z in Å (surface 1 to 4); repeat or comma-separate."
        ),
    ] = None,
    p_range_gpa: Annotated[
        tuple[float, float, int] | None,
        typer.Option(
            "--p-range-gpa", help="Choose N thicknesses spanning loads LO..HI GPa (probe column)."
        ),
    ] = None,
    workers: Annotated[
        int | None, typer.Option("--workers", help="Worker processes (default: one per core).")
    ] = None,
    executor: Annotated[
        str | None, typer.Option("--executor", help="serial | processes (default) | dask.")
    ] = None,
    dask_address: Annotated[
        str | None, typer.Option("--dask-address", help="Address of a running Dask scheduler.")
    ] = None,
    fmax_ev_per_a: Annotated[
        float | None,
        typer.Option(
            "--fmax-ev-per-a", help="Force tolerance on free atoms, eV/Å (default 0.005)."
        ),
    ] = None,
    optimizer: Annotated[
        str | None,
        typer.Option("--optimizer", help="LBFGS (default), BFGS, FIRE, FIRE2, BFGSLineSearch."),
    ] = None,
    max_steps: Annotated[
        int | None, typer.Option("--max-steps", help="Optimiser step cap (default 2000).")
    ] = None,
    order: Annotated[
        str | None,
        typer.Option("--order", help="Warm-start tree: columns (default), planes, cold."),
    ] = None,
    out: Annotated[
        str | None, typer.Option("--out", help="Output directory (default ./ispes).")
    ] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print the summary as JSON.")] = False,
) -> None:
    """Relax every (shift_a, shift_b, z) point of the ISPES grid into OUT/points.db and OUT/ispes.nc.

    Rerunning the same command continues an interrupted scan; a store made with other
    settings is refused.
    """
    from flatcontact.ispes.config import load_config
    from flatcontact.ispes.grid import GridSpec
    from flatcontact.ispes.relax import RelaxSettings
    from flatcontact.ispes.scan import ScanInterrupted, run_scan
    from flatcontact.structures.interface import read_interface

    cfg = load_config(
        config,
        {
            "interface": interface,
            "potential": potential,
            "calculator": calculator,
            "grid": grid,
            "thickness": _floats(thickness, "--thickness"),
            "p_range_gpa": p_range_gpa,
            "workers": workers,
            "executor": executor,
            "dask_address": dask_address,
            "fmax_ev_per_a": fmax_ev_per_a,
            "optimizer": optimizer,
            "max_steps": max_steps,
            "order": order,
            "out": out,
        },
    )
    if cfg.workers is not None and cfg.workers < 1:
        raise InputError(f"--workers: expected at least 1, got {cfg.workers}")
    if cfg.thickness is None and cfg.p_range_gpa is None:
        raise InputError("give --thickness Z [Z ...] or --p-range-gpa LO HI N")
    if cfg.thickness is not None and cfg.p_range_gpa is not None:
        raise InputError("give either --thickness or --p-range-gpa, not both")
    spec = GridSpec(
        cfg.grid[0], cfg.grid[1], thickness_angstrom=cfg.thickness, p_range_gpa=cfg.p_range_gpa
    )
    relax = RelaxSettings(cfg.fmax_ev_per_a, cfg.optimizer, cfg.max_steps)
    reference = read_interface(cfg.interface)
    factory = potential_factory(cfg.potential, cfg.calculator)
    if hasattr(factory, "spec"):
        from flatcontact.potentials import check_elements

        check_elements(factory.spec(), reference)
    try:
        result = run_scan(
            reference,
            factory,
            spec,
            cfg.out,
            relax,
            order=cfg.order,
            executor_options={
                "kind": cfg.executor,
                "workers": cfg.workers,
                "dask_address": cfg.dask_address,
                "jobqueue": cfg.jobqueue,
            },
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
    _summary(result, as_json)


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
