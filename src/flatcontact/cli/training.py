"""Commands ``train-snap``, ``validate-potential`` and ``elastic``."""

from __future__ import annotations

import json
import shlex
import sys
from pathlib import Path

import typer

from flatcontact.cli.app import app, check_out_dir, console, err_console


def _bulk_potential(potential: str, flag: str) -> str:
    """``potential`` in any spelling of :func:`~flatcontact.potentials.names.normalize_potential_name`
    as the name or ``.snapcoeff`` path that the bulk calculators take (offline teachers of
    :mod:`flatcontact.potentials.teachers` pass through).
    """
    from flatcontact.errors import InputError
    from flatcontact.potentials.names import normalize_potential_name, resolve_intra
    from flatcontact.potentials.teachers import is_teacher

    if is_teacher(potential):
        return potential.strip()
    try:
        resolved = resolve_intra(potential)
    except InputError as exc:
        from flatcontact.potentials.teachers import TEACHERS

        raise InputError(f"{flag}: {exc}; or an offline teacher ({', '.join(TEACHERS)})") from None
    if resolved.style in ("vashishta", "tersoff"):
        return resolved.style
    if resolved.style == "snap":
        name = Path(resolved.files[0]).stem
        bundled = normalize_potential_name(potential) == f"snap:{name}"
        return name if bundled else resolved.files[0]
    raise InputError(
        f"{flag} {potential!r}: expected a LAMMPS model (vashishta, tersoff, a SNAP) or an "
        "offline teacher (chgnet-r2scan, sevennet-0, sevennet-mf-0-r2scan, sevennet-mf-0-pbe)"
    )


def check_base_name(name: str, flag: str = "--name") -> str:
    """A base file name written inside ``--out``: no path components, no leading dot.

    Raises
    ------
    InputError
        One line naming ``flag`` and the value (``../../evil``, ``a/b``, ``.hidden``, empty).
    """
    import re

    from flatcontact.errors import InputError

    if not re.fullmatch(r"[A-Za-z0-9_][A-Za-z0-9_.+-]{0,99}", name or ""):
        raise InputError(
            f"{flag} {name!r}: expected a plain file name (letters, digits, _ . + -, no '/' "
            "or '..', at most 100 characters); the files are written inside --out"
        )
    return name


def _say(msg: str) -> None:
    err_console.print(msg, style="dim")


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
    from flatcontact.errors import InputError
    from flatcontact.potentials.teachers import get_teacher
    from flatcontact.training.train import train_snap

    check_base_name(name)
    if recipe is not None:
        get_teacher(label, "--label")
    if not (scale > 0 and scale <= 100):
        raise InputError(
            f"--scale {scale:g}: expected a size factor of the recipe's random groups in (0, 100]"
        )
    if not 0 <= active_rounds <= 50:
        raise InputError(f"--active-rounds {active_rounds}: expected an integer from 0 to 50")
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
        progress=_say,
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


@app.command("validate-potential")
def validate_potential_cmd(
    potential: str = typer.Argument(
        ...,
        help="vashishta | tersoff | [snap:]NAME (sio2-snap) | [snap:]path/X.snapcoeff | chgnet.",
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
        "--energy",
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
    from flatcontact.errors import InputError
    from flatcontact.fileio import write_json_atomic
    from flatcontact.potentials.engines import bulk_calculator
    from flatcontact.training.dataset import read_dataset
    from flatcontact.training.validate import validate_potential

    if out is not None:
        if out.is_dir():
            raise InputError(f"--out {str(out)!r}: is a directory, expected a JSON file path")
        check_out_dir(out.parent)
    if ispes:
        report = _ispes_check(
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
        if out is not None:
            write_json_atomic(out, report)
        if json_out:
            print(json.dumps(report, indent=2))
            return
        _print_ispes_check(report)
        return
    calc = bulk_calculator(_bulk_potential(potential, "POTENTIAL"))
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
            ref_calc = bulk_calculator(_bulk_potential(reference, "--reference"))
            ref_label = reference
    report = validate_potential(
        calc, potential, ref_calc, ref_label, frames=frames, surface=surface, progress=_say
    )
    if out is not None:
        write_json_atomic(out, report)
    if json_out:
        print(json.dumps(report, indent=2))
        return
    _print_validation(report)


def _ispes_model(name: str, flag: str, lj: dict):
    """The interaction model of ``name`` for the ISPES comparison: an offline teacher
    (``chgnet`` = ``chgnet-r2scan``) or any intra-slab potential name, with the shared LJ."""
    from flatcontact.errors import InputError
    from flatcontact.potentials import PotentialSpec
    from flatcontact.potentials.teachers import get_teacher, is_teacher
    from flatcontact.training.ispes_check import teacher_spec

    name = name.strip()
    if is_teacher(name):
        name = get_teacher(name).name
        return name, teacher_spec(name, lj)
    try:
        return name, PotentialSpec(intra=name, lj=lj)
    except InputError as exc:
        raise InputError(f"{flag} {name!r}: {exc}") from None


def _ispes_check(
    potential: str,
    reference: str | None,
    extra: list[str],
    *,
    interface,
    layers,
    grid,
    p_range_gpa,
    p_gpa,
    fmax,
    energy,
    lj_cutoff_angstrom,
    ispes_dir,
) -> dict:
    """``validate-potential --ispes``: checks every argument, then compare_ispes."""
    import numpy as np

    from flatcontact.analysis.uncertainty import committee_spread
    from flatcontact.cli.app import parse_floats
    from flatcontact.config import default_potential
    from flatcontact.errors import InputError, require
    from flatcontact.training.ispes_check import compare_ispes

    require(reference is not None, "--ispes: give the reference model with --reference NAME")
    require(
        Path(reference).suffix not in (".extxyz", ".xyz"),
        f"--reference {reference!r}: with --ispes the reference is a model, not frames",
    )
    require(
        energy in ("internal", "enthalpy"),
        f"--energy: expected internal or enthalpy, got {energy!r}",
    )
    require(
        grid[0] >= 2 and grid[1] >= 2, f"--grid: expected at least 2 x 2, got {grid[0]} {grid[1]}"
    )
    lo, hi, n = p_range_gpa
    require(
        np.isfinite(lo) and np.isfinite(hi) and lo < hi and n >= 3,
        f"--p-range-gpa: expected LO < HI and N >= 3, got {lo:g} {hi:g} {n}",
    )
    require(np.isfinite(fmax) and fmax > 0, f"--fmax-ev-per-angstrom: expected > 0, got {fmax:g}")
    loads = parse_floats(p_gpa, "--p-gpa", "GPa") if p_gpa else [0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0]
    require(len(loads) >= 2, "--p-gpa: expected at least two loads")
    lj = dict(default_potential()["lj"])
    if lj_cutoff_angstrom is not None:
        require(
            np.isfinite(lj_cutoff_angstrom) and lj_cutoff_angstrom > 0,
            f"--lj-cutoff-angstrom: expected > 0, got {lj_cutoff_angstrom:g}",
        )
        lj["cutoff_angstrom"] = float(lj_cutoff_angstrom)
    named = [(reference, "--reference"), (potential, "POTENTIAL")]
    named += [(m, "--ispes-model") for m in extra]
    pairs = [_ispes_model(name, flag, lj) for name, flag in named]
    labels = [label for label, _ in pairs]
    models = dict(pairs)
    require(len(models) == len(named), "--ispes: the models to compare must be distinct")
    if interface is not None:
        from flatcontact.structures.interface_io import read_interface

        require(interface.is_file(), f"--interface {str(interface)!r}: file not found")
        atoms = read_interface(interface)
        source = str(interface)
    else:
        from flatcontact.structures.build import MIN_LAYERS, build_quartz_interface

        if layers < MIN_LAYERS:
            raise InputError(f"--layers: expected >= {MIN_LAYERS}, got {layers}")
        _say(f"building the dense alpha-quartz (0001) interface with {potential} ({layers} layers)")
        atoms, _ = build_quartz_interface(models[labels[1]], layers)
        source = f"dense alpha-quartz (0001), {layers} layers per slab, relaxed with {potential}"
    check_out_dir(ispes_dir)
    per_model: dict = {}
    table = compare_ispes(
        models,
        atoms,
        ispes_dir,
        grid=(int(grid[0]), int(grid[1])),
        p_range_gpa=(float(lo), float(hi), int(n)),
        p_gpa=loads,
        fmax_ev_per_angstrom=fmax,
        form=energy,
        results=per_model,
    )
    return {
        "reference": labels[0],
        "interface": source,
        # the uncertainty.model_spread_<energy form> of a run: half the max − min range of
        # each law coefficient over all models compared
        "model_spread": committee_spread(per_model),
        "settings": {
            "grid": list(grid),
            "p_range_gpa": [lo, hi, n],
            "p_gpa": loads,
            "fmax_ev_per_angstrom": fmax,
            "energy_form": energy,
            "lj": lj,
        },
        "models": {
            label: {k: v for k, v in res.items() if k != "rows"} for label, res in per_model.items()
        },
        "table": json.loads(table.to_json(orient="records")),
    }


def _print_ispes_check(report: dict) -> None:
    from rich.table import Table

    ref = report["reference"]
    t = Table(title=f"ISPES per load vs {ref} ({report['settings']['energy_form']} form)")
    for col in ("model", "P (GPa)", "τ (MPa)", "Δτ/τ", "σ_MSS (MPa)", "Δσ/σ", "W (J/m²)"):
        t.add_column(col, justify="right")
    for r in report["table"]:

        def pct(v):
            return "–" if v is None else f"{100 * v:+.0f} %"

        t.add_row(
            r["model"],
            f"{r['p_gpa']:g}",
            f"{r['tau_mpa']:.3g}" if r["tau_mpa"] is not None else "n/a",
            pct(r.get("rel_tau_mpa")),
            f"{r['sigma_mss_mpa']:.3g}" if r["sigma_mss_mpa"] is not None else "n/a",
            pct(r.get("rel_sigma_mss_mpa")),
            f"{r['work_of_separation_j_per_m2']:.4g}",
        )
    console.print(t)
    for label, res in report["models"].items():
        laws = res["laws"]

        def num(key, laws=laws):
            v = laws.get(key)
            return "n/a" if v is None else f"{v:.3g}"

        console.print(
            f"{label}: k = {num('k_mpa_per_gpa')} MPa/GPa, τ0 = {num('tau0_mpa')} MPa, "
            f"μ = {num('mu_mpa_per_gpa')} MPa/GPa, σ0 = {num('sigma0_mpa')} MPa "
            f"({res['force_calls']} force calls, {res['seconds']:.0f} s)",
            highlight=False,
        )
    spread = report["model_spread"]
    form = report["settings"]["energy_form"]
    console.print(
        f"model spread (half the max - min range over all models; uncertainty.model_spread_{form}): "
        + ", ".join(f"{k} {v:.3g}" for k, v in spread.items()),
        highlight=False,
    )


def _print_validation(report: dict) -> None:
    from rich.table import Table

    from flatcontact.reference import (
        QUARTZ_CIJ_EXPERIMENT_GPA,
        QUARTZ_DENSITY_EXPERIMENT_G_CM3,
        QUARTZ_LATTICE_EXPERIMENT_ANGSTROM,
    )

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


@app.command("elastic")
def elastic_cmd(
    config: Path | None = typer.Argument(
        None,
        help="A run configuration: the elastic stage of that run (the bulk crystal of its "
        "structure with its potential), the same elastic.json as 'flatcontact run'.",
    ),
    potential: str = typer.Option(
        "sio2-snap",
        "--potential",
        help="Without CONFIG: alpha-quartz with vashishta | tersoff | [snap:]NAME | "
        "[snap:]path/X.snapcoeff | chgnet.",
    ),
    strain: float = typer.Option(0.005, "--strain", help="Finite strain amplitude (fraction)."),
    out: Path | None = typer.Option(
        None, "--out", help="With CONFIG: write elastic.json into this folder."
    ),
    json_out: bool = typer.Option(False, "--json", help="Print JSON."),
) -> None:
    """Cij (relaxed ions), Voigt-Reuss-Hill K, G, E, nu and the contact moduli E*, G*.

    With CONFIG this is the run's elastic stage (:func:`flatcontact.stages.elastic.run_elastic`)
    for any material; without it, alpha-quartz with ``--potential``.
    """
    from flatcontact.elastic import quartz_contact_moduli
    from flatcontact.errors import InputError

    if not 0 < strain < 0.05:  # the run's elastic.strain bounds
        raise InputError(
            f"--strain {strain:g}: expected a finite strain amplitude in (0, 0.05), e.g. 0.005"
        )
    if config is not None:
        res = _elastic_stage(config, strain, out)
    else:
        if out is not None:
            raise InputError(
                "--out: needs CONFIG (the run configuration whose elastic stage to run)"
            )
        res = quartz_contact_moduli(_bulk_potential(potential, "--potential"), strain=strain)
    if json_out:
        print(json.dumps(res, indent=2))
        return
    crystal = res.get("crystal", {}).get("crystal", "alpha-quartz")
    model = res.get("potential", potential)
    lattice = ", ".join(
        f"{k.removesuffix('_angstrom')} = {res[k]:.4f} Å"
        for k in ("a_angstrom", "c_angstrom")
        if isinstance(res.get(k), float)
    )
    console.print(f"{crystal} with {model}" + (f": {lattice}" if lattice else ""))
    cij = res.get("cij_gpa") or _cij_of_tensor(res["tensor_gpa"])
    console.print("  " + "  ".join(f"{k} {v:.1f}" for k, v in cij.items()) + "  (GPa)")
    m = res["moduli_gpa"]
    console.print(
        f"  Hill: K {m['bulk_modulus']:.1f}  G {m['shear_modulus']:.1f}  E {m['youngs_modulus']:.1f} GPa  "
        f"nu {m['poisson_ratio']:.3f}"
    )
    console.print(
        f"  two identical bodies: E* {m['e_star']:.1f} GPa; G* {m['g_star_johnson']:.1f} GPa (Johnson, "
        f"q0 = 4G*u/(pi a)) = {m['g_star_paper']:.1f} GPa (paper, q0 = G*u/(pi a))"
    )


def _elastic_stage(config: Path, strain: float, out: Path | None) -> dict:
    """The run's elastic stage for ``config`` (strain from ``--strain``), writing ``--out``."""
    from flatcontact.cli.settings import resolve_config
    from flatcontact.stages.elastic import ElasticInputs, run_elastic

    flags = {"elastic": {"enabled": True, "strain": strain}}
    settings = resolve_config(config, None, flags, {"elastic.strain": "--strain"})
    if out is not None:
        out = check_out_dir(out)
    return run_elastic(settings, ElasticInputs(), out).to_json()


def _cij_of_tensor(tensor) -> dict[str, float]:
    """C11, C12, C13, C33, C44, C66 (GPa) of a 6x6 Voigt stiffness (Voigt order xx,yy,zz,yz,xz,xy)."""
    pick = {
        "C11": (0, 0),
        "C12": (0, 1),
        "C13": (0, 2),
        "C33": (2, 2),
        "C44": (3, 3),
        "C66": (5, 5),
    }
    return {name: float(tensor[i][j]) for name, (i, j) in pick.items()}
