"""``flatcontact scan``: the ISPES grid of an interface (resumable, parallel).

Thin: reads the run configuration (:func:`flatcontact.config.load_config`, the file
``flatcontact run`` reads; its ``potential`` and ``scan`` sections), lays the flags over it
(one per ``scan`` setting, derived from the settings by :mod:`flatcontact.cli.options`), runs the scan stage (:func:`flatcontact.stages.scan.scan_stage`, the one
``flatcontact run`` runs: ``points.db``, ``ispes.nc``, ``scan.json`` and
``fig_scan_columns.png``, + ``.svg`` with ``report.svg``) with a progress bar and prints its
summary and warnings.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated, Any

import typer

from flatcontact.cli.app import (
    app,
    check_out_dir,
    console,
    say_interrupted,
)
from flatcontact.cli.options import flags_of, setting_options, settings_command
from flatcontact.foundation.errors import InputError
from flatcontact.foundation.layout import INTERFACE

#: The settings the command exposes, one flag each (:mod:`flatcontact.cli.options`); laid
#: over CONFIG (the flags not given keep its values).
PATHS = (
    "scan.relax_mode",
    "scan.grid",
    "scan.thickness_angstrom",
    "scan.p_range_gpa",
    "scan.workers",
    "scan.executor",
    "scan.dask_address",
    "scan.fmax_ev_per_angstrom",
    "scan.optimizer",
    "scan.precondition",
    "scan.max_steps",
    "scan.order",
)
OPTIONS = setting_options(PATHS)
#: Settings path -> the flag that sets it, to name the flag in errors.
FLAG_OF = {
    **flags_of(OPTIONS),
    "potential": "--potential",
    "potential.intra": "--potential",
    "potential.calculator": "--calculator",
    "potential.calculator.target": "--calculator",
    "potential.calculator.kwargs": "--calculator-kwarg",
}
#: Where ``flatcontact build`` writes the interface by default (``--out build``).
DEFAULT_INTERFACE = f"build/{INTERFACE}"


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
            raise InputError(
                f"--potential {potential}: expected a JSON object (a InteractionModel)"
            )
        return data
    return {"intra": potential}  # any spelling: InteractionModel normalizes it


def potential_flag(potential: str) -> dict[str, Any]:
    """``--potential`` as laid over the config's ``potential`` section: an intra-slab model in
    place of the configured model's (its coupling kept; an ASE calculator over the whole
    interface replaced whole, :func:`flatcontact.config.merge.kept_for_intra`), not a
    calculator; or a spec's model (a calculator in it kept)."""
    return {"calculator": None, **_potential_section(potential)}


def resolve_config(config: Path | None, preset: str | None, flags: dict[str, Any]):
    """The run configuration of ``CONFIG`` with the scan flags laid over (errors name the flag)."""
    from flatcontact.cli.settings import resolve_config as resolve

    return resolve(config, preset, flags, FLAG_OF)


def _given(flags: dict[str, Any], prefix: str = "") -> set[str]:
    """The settings paths (and their sections) that ``flags`` sets."""
    out = set()
    for key, value in flags.items():
        path = f"{prefix}{key}"
        out.add(path)
        if isinstance(value, dict):
            out |= _given(value, f"{path}.")
    return out


def check_settings(
    cfg, config: Path | None, flags: dict[str, Any], interface: Path | None = None
) -> None:
    """The pre-run checks of the scan's settings (:func:`~flatcontact.stages.preflight.check_scan_settings`),
    refused in the line ``flatcontact run CONFIG`` and ``config --check CONFIG`` give: it names
    CONFIG and the settings path, or the flag when a flag set that path. With ``interface``,
    the model on that interface instead (:func:`~flatcontact.stages.preflight.check_scan_interface`:
    one energy and forces), before the scan writes anything."""
    from flatcontact.cli.settings import config_source
    from flatcontact.stages._common import rename
    from flatcontact.stages.preflight import check_scan_interface, check_scan_settings

    source = config_source(config)
    try:
        if interface is None:
            check_scan_settings(cfg, source)
        else:
            check_scan_interface(cfg, interface, source)
    except InputError as exc:
        text = str(exc).removeprefix(f"{source}: ")
        path = text.partition(": ")[0]
        if path in _given(flags) and path in FLAG_OF:
            raise InputError(rename(text, {path: FLAG_OF[path]})) from None
        if text.startswith("potential '") and "potential" in flags:  # the flag's model refused
            flag = "--calculator" if flags["potential"].get("calculator") else "--potential"
            raise InputError(flag + text.removeprefix("potential")) from None
        raise


@app.command("scan")
@settings_command(OPTIONS)
def scan_command(
    settings: dict,
    config: Annotated[
        Path | None,
        typer.Argument(
            help="Run configuration (YAML), the same file 'flatcontact run' reads: its "
            "potential and scan sections are used, flags override them. "
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
            help="potential.intra: vashishta | tersoff | \\[snap:]NAME | \\[snap:]path/X.snapcoeff | "
            "ase:module:factory; or a "
            "InteractionModel .json whose fields replace the potential section's (default "
            "snap:sio2-snap, "
            "vashishta if that is not installed).",
        ),
    ] = None,
    calculator: Annotated[
        str | None,
        typer.Option(
            "--calculator",
            help="potential.calculator.target: an ASE calculator 'module:callable' instead of --potential.",
        ),
    ] = None,
    calculator_kwarg: Annotated[
        list[str] | None,
        typer.Option(
            "--calculator-kwarg",
            help="potential.calculator.kwargs: key=value (value read as YAML), repeatable, e.g. "
            "--calculator-kwarg model=medium --calculator-kwarg device=cpu.",
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
    from flatcontact.cli.app import print_warning
    from flatcontact.cli.progress import ScanBar
    from flatcontact.foundation.rundir import RunLock
    from flatcontact.ispes.scan import ScanInterrupted
    from flatcontact.stages.scan import ScanInputs, scan_stage

    if {"thickness_angstrom", "p_range_gpa"} <= settings.get("scan", {}).keys():
        raise InputError("give either --thickness-angstrom or --p-range-gpa, not both")
    if potential is not None and calculator is not None:
        raise InputError("give either --potential or --calculator, not both")
    flags: dict[str, Any] = {"scan": {}, **settings}
    if potential is not None:
        flags["potential"] = potential_flag(potential)
    if calculator_kwarg and calculator is None:
        raise InputError("--calculator-kwarg: give --calculator module:callable with it")
    if calculator is not None:
        from flatcontact.potentials.loader import parse_kwargs

        flags["potential"] = {
            "calculator": {"target": calculator, "kwargs": parse_kwargs(calculator_kwarg)}
        }
    cfg = resolve_config(config, preset, flags)
    check_settings(cfg, config, flags)
    out_dir = check_out_dir(out or "ispes")
    where = Path(interface or DEFAULT_INTERFACE)
    if where.is_file():  # the model on the interface, before anything is written (a missing
        check_settings(cfg, config, flags, where)  # file is the scan stage's own refusal)
    created = not out_dir.exists()
    out_dir.mkdir(parents=True, exist_ok=True)
    lock = RunLock(out_dir).acquire()  # one writer per --out (a run or another scan)
    try:
        with ScanBar(console) as bar:
            result = scan_stage(cfg, ScanInputs(where), out_dir, progress=None if as_json else bar)
    except ScanInterrupted as stop:
        r = stop.result
        say_interrupted(
            f"{r.points_done} of {r.points_total} points done ({r.points_stored} relaxed) "
            f"and kept in {r.store_path}"
        )
        raise typer.Exit(130) from None
    finally:
        lock.release(tidy="created" if created else True)
    for line in result.warnings:
        print_warning(line)
    _summary(result, as_json)


def _summary(result, as_json: bool) -> None:
    """Print the stage's ``scan.json`` (plus the paths and wall time) as JSON or a table."""
    scan = result.scan
    summary = {
        "ispes": str(scan.ispes_path),
        "points_db": str(scan.store_path),
        "seconds": round(scan.seconds, 3),
        **result.to_json(),
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
        elif key not in ("adhesion", "warnings"):
            table.add_row(key, str(value))
    console.print(table)
