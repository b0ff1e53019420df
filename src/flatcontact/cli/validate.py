"""``flatcontact validate-potential``: a potential against a reference model, held-out
frames and experiment (:func:`flatcontact.training.validate.validate_potential`); with
``--ispes`` the comparison of the quantities of interest on one interface
(:mod:`flatcontact.cli.ispes_check`)."""

from __future__ import annotations

import json
from pathlib import Path

import typer
from rich.table import Table

from flatcontact.cli.app import app, check_out_dir, console, print_progress
from flatcontact.cli.bulk_models import bulk_potential
from flatcontact.cli.ispes_check import ispes_check, print_ispes_check
from flatcontact.foundation.errors import InputError
from flatcontact.foundation.fileio import write_json_atomic
from flatcontact.foundation.reference import (
    QUARTZ_CIJ_EXPERIMENT_GPA,
    QUARTZ_DENSITY_EXPERIMENT_G_CM3,
    QUARTZ_LATTICE_EXPERIMENT_ANGSTROM,
)


@app.command("validate-potential")
def validate_potential_cmd(
    potential: str = typer.Argument(
        ...,
        help="vashishta | tersoff | \\[snap:]NAME (sio2-snap) | \\[snap:]path/X.snapcoeff | chgnet.",
    ),
    reference: str = typer.Option(
        None,
        "--reference",
        help="Reference model (an offline teacher: chgnet, sevennet-0, sevennet-mf-0-r2scan, "
        "sevennet-mf-0-pbe; or a LAMMPS model) or a labelled extxyz of held-out frames.",
    ),
    heldout: Path = typer.Option(
        None,
        "--heldout",
        help="Labelled extxyz of held-out frames (e.g. DIR/test.extxyz of train-snap).",
    ),
    json_out: bool = typer.Option(False, "--json", help="Print the report as JSON."),
    surface: bool = typer.Option(True, "--surface/--no-surface", help="Dense-surface checks."),
    out: Path = typer.Option(None, "--out", help="Also write the report to this JSON file."),
    ispes: bool = typer.Option(
        False,
        "--ispes",
        help="Instead: scan the same interface with --reference (first) and POTENTIAL and "
        "compare τ, σ_MSS, G_int and W per load (models: vashishta, tersoff, a SNAP, or an "
        "offline teacher chgnet-r2scan, sevennet-0, sevennet-mf-0-r2scan, sevennet-mf-0-pbe).",
    ),
    ispes_model: list[str] = typer.Option(
        None, "--ispes-model", help="With --ispes: a further model to compare (repeat)."
    ),
    interface: Path = typer.Option(
        None,
        "--interface",
        help="With --ispes: interface.extxyz to scan (default: the dense α-quartz (0001) "
        "interface built and relaxed with POTENTIAL, --layers per slab).",
    ),
    layers: int = typer.Option(
        6, "--layers", help="With --ispes: layers per slab of the built interface."
    ),
    grid: tuple[int, int] = typer.Option(
        (4, 4), "--grid", help="With --ispes: lateral grid NA NB."
    ),
    p_range_gpa: tuple[float, float, int] = typer.Option(
        (-0.3, 5.5, 8),
        "--p-range-gpa",
        help="With --ispes: thicknesses spanning loads LO HI (GPa) in N steps, per model.",
    ),
    p_gpa: list[str] = typer.Option(
        None, "--p-gpa", help="With --ispes: loads analysed (GPa); default 0,0.5,…,3."
    ),
    fmax: float = typer.Option(
        0.005, "--fmax-ev-per-angstrom", help="With --ispes: force tolerance per point (eV/Å)."
    ),
    energy: str = typer.Option(
        "internal",
        "--energy-form",
        help="With --ispes: energy form, internal (the paper's) or enthalpy.",
    ),
    lj_cutoff_angstrom: float = typer.Option(
        None,
        "--lj-cutoff-angstrom",
        help="With --ispes: cutoff of the cross-interface LJ shared by all models (default the "
        "run's default model's).",
    ),
    ispes_dir: Path = typer.Option(
        Path("flatcontact-ispes-check"),
        "--ispes-dir",
        help="With --ispes: folder of the resumable scans, one per model.",
    ),
) -> None:
    """Held-out RMSEs, alpha-quartz lattice, Cij, EOS, dense surface; vs reference and experiment.

    With ``--ispes``: the potential's error on the quantities of interest (τ, σ_MSS, G_int,
    W per load) against a reference model on the same interface
    (:func:`flatcontact.training.ispes_check.compare_ispes`).
    """
    if out is not None:
        if out.is_dir():
            raise InputError(f"--out {str(out)!r}: is a directory, expected a JSON file path")
        check_out_dir(out.parent)
    if ispes:
        report = ispes_check(
            potential,
            reference,
            ispes_model or [],
            interface=interface,
            layers=layers,
            grid=grid,
            p_range_gpa=p_range_gpa,
            p_gpa=p_gpa,
            fmax=fmax,
            energy=energy,
            lj_cutoff_angstrom=lj_cutoff_angstrom,
            ispes_dir=ispes_dir,
        )
        _emit(report, out, json_out, print_ispes_check)
        return
    _emit(_validate_bulk(potential, reference, heldout, surface), out, json_out, _print_validation)


def _emit(report: dict, out: Path | None, json_out: bool, show) -> None:
    """Write ``report`` to ``--out`` (atomically), then print it as JSON or through ``show``."""
    if out is not None:
        write_json_atomic(out, report)
    if json_out:
        print(json.dumps(report, indent=2))
        return
    show(report)


def _validate_bulk(potential: str, reference: str | None, heldout, surface) -> dict:
    """The bulk checks of POTENTIAL (:func:`flatcontact.training.validate.validate_potential`)
    against a reference model or held-out frames (``--reference`` FILE.extxyz or ``--heldout``)."""
    from flatcontact.potentials.engines import bulk_calculator
    from flatcontact.training.dataset import read_dataset
    from flatcontact.training.validate import validate_potential

    calc = bulk_calculator(bulk_potential(potential, "POTENTIAL"))
    ref_calc, frames, ref_label = None, None, None
    if heldout is not None:
        frames = read_dataset(heldout, ["Si", "O"])
    if reference is not None:
        if Path(reference).suffix in (".extxyz", ".xyz"):
            if heldout is not None:
                raise InputError(
                    "give held-out frames either as --reference FILE or as --heldout FILE"
                )
            frames = read_dataset(reference, ["Si", "O"])
            ref_label = reference
        else:
            ref_calc = bulk_calculator(bulk_potential(reference, "--reference"))
            ref_label = reference
    return validate_potential(
        calc,
        potential,
        ref_calc,
        ref_label,
        frames=frames,
        surface=surface,
        progress=print_progress,
    )


def _print_validation(report: dict) -> None:
    cols = [c for c in ("potential", "reference") if isinstance(report.get(c), dict)]
    t = Table(title=f"alpha-quartz: {report['potential_label']}")
    t.add_column("quantity")
    for c in cols:
        t.add_column(c)
    t.add_column("experiment")
    for key, unit in (("a_angstrom", "Å"), ("c_angstrom", "Å"), ("density_g_cm3", "g/cm³")):
        exp = (
            QUARTZ_LATTICE_EXPERIMENT_ANGSTROM.get(key[0])
            if key != "density_g_cm3"
            else QUARTZ_DENSITY_EXPERIMENT_G_CM3
        )
        t.add_row(
            f"{key.split('_')[0]} ({unit})",
            *[f"{report[c]['lattice'][key]:.4f}" for c in cols],
            f"{exp}",
        )
    for k, v in QUARTZ_CIJ_EXPERIMENT_GPA.items():
        t.add_row(
            f"{k} (GPa)", *[f"{report[c]['elastic']['cij_gpa'][k]:.1f}" for c in cols], f"{v}"
        )
    for k in ("bulk_modulus", "shear_modulus", "e_star", "g_star_johnson", "g_star_paper"):
        t.add_row(f"{k} (GPa)", *[f"{report[c]['elastic']['moduli_gpa'][k]:.1f}" for c in cols], "")
    for c in cols:
        ds = report[c].get("dense_surface")
        if ds and "error" not in ds:
            t.add_row(
                f"dense surface ({c})",
                *[""] * (cols.index(c)),
                f"relax {ds['dense_after_relaxation']}, MD {ds['dense_after_md_300k']}, "
                f"γ {ds['surface_energy_j_per_m2']:.2f} J/m²",
                *[""] * (len(cols) - cols.index(c)),
            )
    console.print(t)
    he = report.get("heldout_errors")
    if he:
        console.print(
            f"held-out: E {he['energy_rmse_mev_per_atom']:.1f} meV/atom, "
            f"F {he['force_rmse_mev_per_angstrom']:.0f} meV/Å"
        )
    if "targets_met" in report:
        console.print(f"targets met: {report['targets_met']}")
