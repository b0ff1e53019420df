"""``flatcontact validate-potential --ispes``: scan one interface with several models and
compare τ, σ_MSS, G_int and W per load (:func:`flatcontact.training.ispes_check.compare_ispes`).

A mode of ``validate-potential`` (its flags are that command's), not a command of its own.
"""

from __future__ import annotations

import json
from pathlib import Path

from rich.table import Table

from flatcontact.cli.app import (
    bounded,
    bounded_int,
    check_out_dir,
    console,
    parse_floats,
    print_progress,
    setting_bounds,
)
from flatcontact.foundation.errors import InputError, require


def _ispes_model(name: str, flag: str, lj: dict):
    """The interaction model of ``name`` for the ISPES comparison: an offline teacher
    (``chgnet`` = ``chgnet-r2scan``) or any intra-slab potential name, with the shared LJ."""
    from flatcontact.potentials.model import InteractionModel
    from flatcontact.potentials.teachers import get_teacher, is_teacher
    from flatcontact.training.ispes_check import teacher_spec

    name = name.strip()
    if is_teacher(name):
        name = get_teacher(name).name
        return name, teacher_spec(name, lj)
    try:
        return name, InteractionModel(intra=name, lj=lj)
    except InputError as exc:
        raise InputError(f"{flag} {name!r}: {exc}") from None


def ispes_check(
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
    from flatcontact.analysis.uncertainty import committee_spread
    from flatcontact.config import default_potential
    from flatcontact.config.analysis import AnalysisConfig
    from flatcontact.config.scan import PressureRange, ScanConfig
    from flatcontact.foundation import limits
    from flatcontact.potentials.coupling import LJSpec
    from flatcontact.training.ispes_check import compare_ispes

    require(reference is not None, "--ispes: give the reference model with --reference NAME")
    require(
        Path(reference).suffix not in (".extxyz", ".xyz"),
        f"--reference {reference!r}: with --ispes the reference is a model, not frames",
    )
    require(
        energy in ("internal", "enthalpy"),
        f"--energy-form: expected internal or enthalpy, got {energy!r}",
    )
    for axis in grid:
        bounded_int(axis, "--grid", 2, limits.bound("grid_axis"), "points along one axis")
    lo, hi, n = p_range_gpa
    bounded(lo, "--p-range-gpa", setting_bounds(PressureRange, "lo_gpa"))
    bounded(hi, "--p-range-gpa", setting_bounds(PressureRange, "hi_gpa"))
    bounded_int(n, "--p-range-gpa", 3, limits.bound("thicknesses"), "thicknesses N")
    require(lo < hi, f"--p-range-gpa: expected LO < HI, got {lo:g} {hi:g}")
    bounded(fmax, "--fmax-ev-per-angstrom", setting_bounds(ScanConfig, "fmax_ev_per_angstrom"))
    loads = (
        parse_floats(p_gpa, "--p-gpa", "GPa", setting_bounds(AnalysisConfig, "p_gpa"))
        if p_gpa
        else [0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0]
    )
    require(len(loads) >= 2, "--p-gpa: expected at least two loads")
    limits.check("loads", len(loads), "--p-gpa", "loads")
    lj = dict(default_potential()["lj"])
    if lj_cutoff_angstrom is not None:
        lj["cutoff_angstrom"] = bounded(
            lj_cutoff_angstrom, "--lj-cutoff-angstrom", setting_bounds(LJSpec, "cutoff_angstrom")
        )
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
        from flatcontact.structures.build import build_quartz_interface
        from flatcontact.structures.quartz_layers import MIN_LAYERS

        bounded_int(layers, "--layers", MIN_LAYERS, limits.bound("layers"), "layers per slab")
        print_progress(
            f"building the dense alpha-quartz (0001) interface with {potential} ({layers} layers)"
        )
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


def print_ispes_check(report: dict) -> None:
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
