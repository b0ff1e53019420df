"""The report's content: what each section says, tables it shows and figures it embeds.

:func:`build_sections` reads the stage folders of a run (their JSON files, ``friction.csv`` and
figures) and returns :class:`~flatcontact.report.html.Section` objects; the report stage
(:mod:`flatcontact.stages.report`) renders them. The paper's numbers come from
:mod:`flatcontact.reference`. This module is in the report stage's code digest only, so
editing its wording reruns the report and nothing else.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from flatcontact.config import BUNDLED_SNAP
from flatcontact.errors import InputError
from flatcontact.potentials.files import BUNDLED_DIR
from flatcontact.reference import (
    PAPER,
    PAPER_THRESHOLD_GPA,
    QUARTZ_HAMAKER_ZJ,
    QUARTZ_LATTICE_EXPERIMENT_ANGSTROM,
)
from flatcontact.stages import _calculator
from flatcontact.stages.contact import is_paper_material

A_EXP = QUARTZ_LATTICE_EXPERIMENT_ANGSTROM["a"]


def fmt(value: Any, digits: int = 4) -> str:
    """A number for a table cell (4 significant digits; 'n/a' for None and non-finite)."""
    if value is None or (isinstance(value, float) and not np.isfinite(value)):
        return "n/a"
    if isinstance(value, float):
        return f"{value:.{digits}g}"
    return str(value)


def _pm(value: float | None, err: float | None) -> str:
    if value is None:
        return "n/a"
    return f"{value:.3g} ± {err:.2g}" if err is not None else f"{value:.3g}"


def compare_with_paper(laws: dict) -> list[tuple[str, str, str, str, str]]:
    """Rows (quantity, this run ± s.e., paper, difference, reading) for k, τ0, μ, σ0.

    The reading says whether the difference is within two standard errors of the fit
    and otherwise names the differences of set-up that can cause it.
    """
    rows = []
    for key, err_key, label in (
        ("k_mpa_per_gpa", "k_stderr_mpa_per_gpa", "k (MPa/GPa)"),
        ("tau0_mpa", "tau0_stderr_mpa", "τ0 (MPa)"),
        ("mu_mpa_per_gpa", "mu_stderr_mpa_per_gpa", "μ (MPa/GPa)"),
        ("sigma0_mpa", "sigma0_stderr_mpa", "σ0 (MPa)"),
    ):
        value, err, ref = laws.get(key), laws.get(err_key), PAPER[key]
        if value is None:
            rows.append(
                (label, "n/a", f"{ref:g}", "n/a", "not fitted (too few loads below the threshold)")
            )
            continue
        diff = value - ref
        rel = f"{diff:+.3g} ({100 * diff / ref:+.0f} %)"
        if err is not None and abs(diff) <= 2 * err:
            reading = "consistent with the paper within 2 standard errors of the fit"
        else:
            reading = (
                "differs beyond 2 standard errors"
                if err is not None
                else "differs (no error estimate)"
            )
        rows.append((label, _pm(value, err), f"{ref:g}", rel, reading))
    return rows


def _interface(folder: Path):
    from ase.io import read

    return read(folder / "interface.extxyz")


def interface_material(folder: Path) -> str:
    """The material of the run's interface (``info['material']`` of ``interface.extxyz``;
    its formula when the file names none)."""
    atoms = _interface(folder)
    return str(atoms.info.get("material") or atoms.get_chemical_formula(mode="hill"))


def interface_elements(folder: Path) -> set[str]:
    """The elements of the run's interface."""
    return set(_interface(folder).get_chemical_symbols())


def monotonicity_paragraph(table) -> str:
    """Where τ(P) falls with load by more than its noise, and what limits τ on each side.

    A drop from P_i to P_i+1 counts when τ_i − τ_i+1 > √(ν_i² + ν_i+1²), ν the per-load force
    noise (``force_noise_mpa``; :func:`flatcontact.analysis.convergence.monotonic_violations`).
    For each drop the paragraph names the mechanism that sets τ at both loads (the barrier
    top of the path, a jump, or the path's end), the number of jumps and the start stacking,
    so a reader can tell a change of mechanism (the model's physics) from scatter.
    """
    from flatcontact.analysis.convergence import monotonic_violations

    if "tau_mpa" not in table or len(table) < 2:
        return ""
    noise = table["force_noise_mpa"] if "force_noise_mpa" in table else 0.0
    drops = monotonic_violations(table["p_gpa"], table["tau_mpa"], noise)
    if not drops:
        return "τ(P) does not fall with load anywhere by more than its force noise."
    by_p = {float(r.p_gpa): r for r in table.itertuples()}

    def side(p):
        r = by_p[p]
        start = getattr(r, "start_stacking", "")
        jumps = int(r.n_jumps) if np.isfinite(r.n_jumps) else 0
        return (
            f"{fmt(r.tau_mpa)} MPa at {p:g} GPa (limited by the {r.tau_limited_by}, {jumps} "
            f"jump{'s' if jumps != 1 else ''}{f', start {start}' if isinstance(start, str) and start else ''})"
        )

    parts = [f"from {side(d['from_p_gpa'])} to {side(d['to_p_gpa'])}" for d in drops]
    return (
        "τ(P) is not monotonic: it falls by more than its noise "
        + "; ".join(parts)
        + ". Where the limiting mechanism or the number of jumps changes between the two loads, "
        "the drop is the model's landscape changing shape with load (a different barrier or a "
        "jump along the path), not scatter; a drop with the same mechanism on both sides is "
        "tested by refining the lateral grid (docs/convergence.md)."
    )


def _direction_text(cfg, table) -> str:
    """The pulling direction as run: the given angle, or auto's lowest-barrier direction."""
    if cfg.analysis.direction_deg != "auto":
        return f"{cfg.analysis.direction_deg:g}° from x"
    if "direction_deg" in table:
        angles = ", ".join(f"{v:g}°" for v in sorted(set(np.round(table["direction_deg"], 3))))
        return f"auto: the lowest-barrier direction at the lowest load, {angles} from x"
    return "auto: the lowest-barrier direction at the lowest load"


def _stacking_rows(table) -> list[tuple[str, ...]]:
    """(P, name=energy ...) rows of the named stackings (friction.csv), meV/Å² above the lowest."""
    if "stacking_energies_mev_per_a2" not in table:
        return []
    rows = []
    for r in table.itertuples():
        text = str(r.stacking_energies_mev_per_a2)
        if text in ("", "nan"):
            continue
        pairs = [item.split("=") for item in text.split(";") if "=" in item]
        low = min(float(v) for _, v in pairs)
        named = ", ".join(f"{k} {float(v) - low:.4g}" for k, v in pairs)
        rows.append((f"{r.p_gpa:g}", named, fmt(getattr(r, "lowest_barrier_mev_per_a2", None))))
    return rows


def _own_results_section(
    cfg, material: str, model: str, laws: dict, scan: dict, contact: dict, table
):
    """The laws, W, stackings and contact results of a material other than the paper's: no
    comparison with the paper's α-quartz numbers, which are not about this material."""
    from flatcontact.report.html import Section, Table

    rows = [
        ("k (MPa/GPa)", _pm(laws.get("k_mpa_per_gpa"), laws.get("k_stderr_mpa_per_gpa"))),
        ("τ0 (MPa)", _pm(laws.get("tau0_mpa"), laws.get("tau0_stderr_mpa"))),
        ("μ (MPa/GPa)", _pm(laws.get("mu_mpa_per_gpa"), laws.get("mu_stderr_mpa_per_gpa"))),
        ("σ0 (MPa)", _pm(laws.get("sigma0_mpa"), laws.get("sigma0_stderr_mpa"))),
        (
            "work of separation W (J/m²)",
            fmt((scan.get("adhesion") or {}).get("work_of_separation_j_per_m2")),
        ),
    ]
    for r in contact["results"]:
        rows.append(
            (
                f"effective shear strength Q_peak/πa² at p0 = {r['p0_gpa']:g} GPa (MPa)",
                fmt(r["effective_shear_strength_mpa"]),
            )
        )
    moduli = contact.get("provenance", {}).get("moduli", "config")
    params = contact.get("parameters", {})
    tables = [Table(("quantity", "this run"), rows)]
    stackings = _stacking_rows(table)
    if stackings:
        tables.append(
            Table(
                ("P (GPa)", "named stackings (meV/Å² above the lowest)", "barrier (meV/Å²)"),
                stackings,
                "High-symmetry stackings of the lattice and the minimum-energy-path barrier",
            )
        )
    return Section(
        f"Results for {material}",
        paragraphs=[
            f"Material: {material}; interaction model: {model}. The paper's numbers are for "
            "α-quartz (0001) and are not compared here. Load laws τ = k·P + τ0 and "
            f"σ = μ·P + σ0 fitted on P ≤ {cfg.analysis.threshold_gpa:g} GPa.",
            f"Contact moduli E* = {fmt(params.get('contact_modulus_gpa'))} GPa, G* = "
            f"{fmt(params.get('shear_modulus_gpa'))} GPa ({moduli}).",
        ],
        tables=tables,
    )


def _setup_differences(cfg) -> list[str]:
    """Why this run's numbers can differ from the paper's: a list of concrete set-up differences."""
    out = []
    intra = _calculator.intra(cfg)
    if intra is None:
        out.append(
            f"The interaction model is the {_calculator.label(cfg)}, not the "
            "paper's SNAP + TS-vdW LJ."
        )
    elif not intra.startswith("snap:"):
        out.append(
            f"The intra-slab model is '{cfg.potential.intra}', a classical potential, not the paper's "
            "SNAP trained on DFT (Erhard et al. 2022). Its lattice constant, surface relaxation and "
            "interfacial corrugation differ, and τ and σ are differences of the corrugation "
            f"energy, so they inherit these differences directly (Vashishta: a = 4.829 Å vs {A_EXP:g} "
            f"Å; the interface's lateral cell is the experimental {A_EXP:g} Å, so Vashishta slabs carry "
            "+1.8 % in-plane strain)."
        )
    elif cfg.potential.intra == f"snap:{BUNDLED_SNAP}":
        validation = json.loads((BUNDLED_DIR / BUNDLED_SNAP / "validation.json").read_text())
        e_star = validation["potential"]["elastic"]["moduli_gpa"]["e_star"]
        out.append(
            f"The intra-slab SNAP is flatcontact's bundled {BUNDLED_SNAP}, trained on CHGNet "
            "r2SCAN labels, not on the DFT data of Erhard et al. (2022) like the paper's; its "
            f"α-quartz follows CHGNet's, softer than experiment: E* = {e_star:.1f} GPa from its "
            f"elastic constants (validation.json) vs the paper's {PAPER['contact_modulus_gpa']:g} "
            f"GPa. The interface's lateral cell is the experimental a = {A_EXP:g} Å; the SNAP's "
            "own α-quartz has "
            f"a = {validation['potential']['lattice']['a_angstrom']:.3f} Å, so the slabs carry "
            f"{100 * (A_EXP / validation['potential']['lattice']['a_angstrom'] - 1):+.1f} % "
            "in-plane strain."
        )
    else:
        out.append(
            f"The intra-slab SNAP '{cfg.potential.intra}' is not the paper's (trained on the DFT "
            "data of Erhard et al. 2022)."
        )
    lj = _calculator.lj(cfg)
    if lj is not None:
        out.append(_lj_difference(lj))
    if cfg.structure.kind != "quartz-dense":
        out.append("The interface is not the paper's α-quartz (0001) dense interface.")
    elif cfg.structure.layers != 6:
        out.append(f"Each slab has {cfg.structure.layers} O–Si–O layers (the paper: 6).")
    na, nb = cfg.scan.grid
    if na * nb < 144:
        out.append(
            f"The lateral grid is {na}×{nb} per primitive cell; the barrier heights and the "
            "largest slope (τ) of a coarse grid rely on the periodic interpolant."
        )
    n_fit = len([p for p in cfg.analysis.p_gpa if p <= cfg.analysis.threshold_gpa])
    out.append(
        f"The laws are fitted on {n_fit} loads with P ≤ {cfg.analysis.threshold_gpa:g} GPa; "
        "the paper does not list its loads or standard errors."
    )
    return out


def _lj_difference(lj) -> str:
    """How the cross-interface LJ compares with the paper's in-solid vdW-DFT C6, in numbers."""
    from flatcontact.potentials.lj import (
        ALPHA_QUARTZ_NUMBER_DENSITY_PER_NM3,
        pairwise_hamaker_constant_zj,
    )

    try:
        table = lj.table(["O", "Si"], ["O", "Si"])
        a_zj = pairwise_hamaker_constant_zj(table, ALPHA_QUARTZ_NUMBER_DENSITY_PER_NM3)
    except InputError:
        return "The cross-interface LJ does not cover Si and O; the paper's C6 are for SiO₂."
    hamaker = (
        f"its C6 sum to a pairwise Hamaker constant of {a_zj:.0f} zJ for α-quartz, against "
        f"≈ {QUARTZ_HAMAKER_ZJ:.0f} zJ from Lifshitz theory (Bergström 1997)"
    )
    if lj.hamaker_zj is not None:
        return (
            "The paper took the LJ C6 from vdW-DFT of the solid (Hirshfeld-scaled TS), which we "
            "cannot run here; flatcontact scales the Tkatchenko–Scheffler C6 instead so that "
            f"their pairwise Hamaker constant for α-quartz is {a_zj:.0f} zJ "
            f"(potential.lj.hamaker_zj; Lifshitz theory: ≈ {QUARTZ_HAMAKER_ZJ:.0f} zJ, "
            "Bergström 1997). Free-atom C6 would give 411 zJ and about "
            "4–5× the adhesion and τ0: τ0 follows the LJ well depth almost linearly "
            "(measurements in docs/run.md)."
        )
    return (
        "The cross-interface LJ is not calibrated: "
        + hamaker
        + ". The paper took in-solid C6 from vdW-DFT, where cationic Si is far less polarisable "
        "than a free atom; adhesion and τ0 scale almost linearly with the C6 (docs/run.md). "
        "Set potential.lj.hamaker_zj to calibrate."
    )


def _elastic_tables(cfg, folder: Path | None) -> list:
    """The elastic stage's Cij and moduli (when it ran), for the contact section."""
    from flatcontact.report.html import Table

    if folder is None or not cfg.elastic.enabled or not (folder / "elastic.json").exists():
        return []
    doc = json.loads((folder / "elastic.json").read_text())
    cij = doc.get("cij_gpa", {})
    moduli = doc.get("moduli_gpa", {})
    return [
        Table(
            ("α-quartz with the potential", "value"),
            [
                ("a, c (Å)", f"{fmt(doc.get('a_angstrom'))}, {fmt(doc.get('c_angstrom'))}"),
                *((f"{k} (GPa)", fmt(v)) for k, v in cij.items()),
                *((f"{k} (GPa)" if k != "poisson_ratio" else k, fmt(v)) for k, v in moduli.items()),
            ],
        )
    ]


_LOAD_SOURCE_TEXT = {
    "energy": "−(1/A) dU/dz of each column's energy spline (analysis.load_source = energy)",
    "stress": "the stored normal stress (analysis.load_source = stress)",
}
_ENERGY_ZERO_TEXT = {
    "lowest-p": "the global minimum at the lowest load analysed",
    "each": "the global minimum at each load",
    "none": "none (energies as computed, per area)",
}


def _symmetry_table(symmetry: dict):
    """Table of analyze.json's ``symmetry`` (per P: tolerance, kept operations, deviations)."""
    from flatcontact.report.html import Table

    tolerance = next(iter(symmetry.values()), {}).get("tolerance_percent", float("nan"))
    rows = [
        (
            p,
            ", ".join(doc["kept"]) or "none",
            ", ".join(f"{name} {dev:.2g}%" for name, dev in doc["deviation_percent"].items()),
        )
        for p, doc in symmetry.items()
    ]
    return Table(
        (
            "P (GPa)",
            f"symmetry operations of the cell kept (rms change < {tolerance:g} %)",
            "rms change of every operation",
        ),
        rows,
    )


def build_sections(
    cfg, folders: dict[str, Path], stage_rows: list[tuple[str, str, str, str]]
) -> list:
    """The report's sections from the stage folders (``folders[name]``; figures embedded).

    ``stage_rows``: (stage, state, seconds, finished) of the summary table.
    """
    import pandas as pd

    from flatcontact.report.html import Figure, Section, Table

    f_build, f_scan = folders["build"], folders["scan"]
    f_an, f_laws, f_ct = folders["analyze"], folders["laws"], folders["contact"]
    build = json.loads((f_build / "build.json").read_text())
    scan = json.loads((f_scan / "scan.json").read_text())
    analyze = json.loads((f_an / "analyze.json").read_text())
    laws = json.loads((f_laws / "laws.json").read_text())
    contact = json.loads((f_ct / "summary.json").read_text())
    table = pd.read_csv(f_an / "friction.csv")
    model = _calculator.label(cfg)
    material = interface_material(f_build)
    paper_system = is_paper_material(cfg, interface_elements(f_build))
    sections = []

    # ---- summary
    sections.append(
        Section(
            "Summary",
            paragraphs=[
                f"Material: {material}. Interaction model: {model}. Structure: "
                f"{cfg.structure.kind}"
                + (
                    f", {cfg.structure.layers} layers per slab"
                    if getattr(cfg.structure, "layers", None) is not None
                    else ""
                )
                + f". Preset: {cfg.preset}. ISPES grid {cfg.scan.grid[0]}×{cfg.scan.grid[1]} lateral × "
                f"{len(scan['thickness_angstrom'])} thicknesses. Loads analysed: "
                + ", ".join(f"{p:g}" for p in cfg.analysis.p_gpa)
                + " GPa.",
                "Conventions: P > 0 is compression; z is the distance between surfaces 1 and 4; energies per "
                "area in meV/Å²; stresses in MPa; the contact model uses the paper's q0 = G*·u/(πa) "
                "(G* = 4 × Johnson's G*_J).",
            ],
            tables=[
                Table(
                    ("stage", "state", "seconds (last run)", "finished (UTC)"),
                    stage_rows,
                    "Stages of this run directory",
                )
            ],
        )
    )

    # ---- comparison with the paper (its SiO2 numbers only for its system)
    if not paper_system:
        sections.append(_own_results_section(cfg, material, model, laws, scan, contact, table))
    if paper_system:
        rows = compare_with_paper(laws)
        w = (scan.get("adhesion") or {}).get("work_of_separation_j_per_m2")
        rows.append(
            (
                "work of separation W (J/m²)",
                fmt(w),
                "not reported",
                "",
                "from the probe column: [U(separated) − U(z_eq)]/A",
            )
        )
        res = contact["results"]
        ref = contact["results_with_paper_laws"]
        for r_run, r_pap in zip(res, ref, strict=True):
            rows.append(
                (
                    f"effective shear strength Q_peak/πa² at p0 = {r_run['p0_gpa']:g} GPa (MPa)",
                    fmt(r_run["effective_shear_strength_mpa"]),
                    fmt(r_pap["effective_shear_strength_mpa"]),
                    f"{r_run['effective_shear_strength_mpa'] - r_pap['effective_shear_strength_mpa']:+.3g}",
                    "paper column: the same contact model with the paper's k, τ0, μ, σ0",
                )
            )
        sections.append(
            Section(
                "This run next to the paper",
                paragraphs=[
                    f"Paper (Dong, Uluca, Cross, Sanvito): τ = k·P + τ0 with k = {PAPER['k_mpa_per_gpa']:g} "
                    f"MPa/GPa, τ0 = {PAPER['tau0_mpa']:g} MPa; σ = μ·P + σ0 with μ = "
                    f"{PAPER['mu_mpa_per_gpa']:g} MPa/GPa, σ0 = {PAPER['sigma0_mpa']:g} MPa (SNAP + "
                    f"TS-vdW LJ, P < {PAPER_THRESHOLD_GPA:g} GPa).",
                ],
                notes=["Why the numbers can differ: " + " ".join(_setup_differences(cfg))],
                tables=[Table(("quantity", "this run", "paper", "difference", "reading"), rows)],
            )
        )

    # ---- interface
    rel = build.get("interface_relaxation", {})
    checks = build.get("interface_verification") or {}
    verified = bool(checks) and all(v.get("dense") for v in checks.values())
    sections.append(
        Section(
            "1. Interface",
            paragraphs=[
                f"{build.get('n_atoms', '?')} atoms; reference thickness z = {fmt(build.get('thickness_angstrom'))} Å"
                + (
                    f"; interface relaxation {'converged' if rel.get('converged') else 'NOT converged'}"
                    f" in {rel.get('steps', '?')} steps to "
                    f"{getattr(cfg.structure, 'fmax_ev_per_angstrom', float('nan')):g} eV/Å"
                    if rel
                    else ""
                )
                + (
                    "; the dense surface verified on both slabs after the interface relaxation"
                    if verified
                    else ""
                )
                + ". Surfaces 1 and 4 (outer faces) are held fixed during the scan; surfaces 2, 3 and the "
                "inner atoms relax at every grid point.",
            ],
            figures=[
                Figure(
                    f_build / "fig1_interface.png",
                    "Fig. 1 style: side view and the top view of the inner face.",
                )
            ],
        )
    )

    # ---- scan
    adh = scan.get("adhesion") or {}
    scan_rows = [
        ("grid points", f"{scan['points_done']} of {scan['points_total']}"),
        ("converged", str(scan["converged"])),
        ("force calls (total)", str(scan["force_calls_total"])),
        ("thicknesses z (Å)", ", ".join(f"{z:.4f}" for z in scan["thickness_angstrom"])),
    ]
    for key, label in (
        ("equilibrium_thickness_angstrom", "z at p = 0 (Å)"),
        ("max_tension_gpa", "maximum tension (GPa)"),
        ("work_of_separation_j_per_m2", "work of separation, energy (J/m²)"),
        ("work_of_separation_integral_j_per_m2", "work of separation, −∫p dz (J/m²)"),
    ):
        if key in adh:
            scan_rows.append((label, fmt(adh[key])))
    sections.append(
        Section(
            "2. ISPES scan",
            tables=[Table(("quantity", "value"), scan_rows)],
            notes=[*scan.get("notes", []), *scan.get("warnings", [])],
            figures=[
                Figure(
                    f_scan / "fig_scan_columns.png",
                    "p(z) and U(z) at every lateral shift: the load rises as the slabs are pressed together.",
                )
            ],
        )
    )

    # ---- constant-pressure ISPES
    ps = cfg.report.fig2_p_gpa
    if ps is None:
        allp = cfg.analysis.p_gpa
        ps = sorted({allp[0], allp[len(allp) // 2], allp[-1]})
    figs = [
        Figure(
            f_an / f"fig2_p{p:g}gpa.png",
            f"Fig. 2 at P = {p:g} GPa: (a) constant-pressure ISPES with the sliding path (white) and "
            "the 1×2 rectangular cell (red dotted); (b) energy along the path, barriers ΔU_i "
            "(arrows); (c) force per area with the shear stiffness (dashed) and τ (circle).",
        )
        for p in ps
        if (f_an / f"fig2_p{p:g}gpa.png").exists()
    ]
    rows = [
        (
            fmt(r.p_gpa),
            fmt(r.tau_mpa),
            fmt(r.tau_period_mpa),
            fmt(r.sigma_mss_mpa),
            fmt(r.shear_stiffness_gpa_per_nm),
            str(r.tau_limited_by),
            str(r.n_jumps),
        )
        for r in table.itertuples()
    ]
    sections.append(
        Section(
            "3. Constant-pressure ISPES, sliding path, τ and σ",
            paragraphs=[
                f"Pulling direction {_direction_text(cfg, table)}; energy form "
                f"'{cfg.analysis.energy_form}' (the paper's is 'internal'). τ is the paper's "
                "shear strength (largest force before leaving the initial minimum); τ_period is "
                "the largest force over a whole period, the pull needed for sustained sliding "
                "(always ≥ σ_MSS). The load laws use τ.",
                f"Load at each z from {_LOAD_SOURCE_TEXT[analyze.get('load_source', 'stress')]}. "
                f"Energy zero of the maps and profiles: {_ENERGY_ZERO_TEXT[cfg.analysis.energy_zero]}.",
                monotonicity_paragraph(table),
            ],
            notes=analyze.get("warnings", []),
            tables=[
                Table(
                    (
                        "P (GPa)",
                        "τ (MPa)",
                        "τ_period (MPa)",
                        "σ_MSS (MPa)",
                        "G_int (GPa/nm)",
                        "τ limited by",
                        "jumps",
                    ),
                    rows,
                ),
                _symmetry_table(analyze.get("symmetry", {})),
            ],
            figures=figs,
        )
    )

    # ---- laws
    sections.append(
        Section(
            "4. Load laws",
            paragraphs=[
                f"τ = ({_pm(laws.get('k_mpa_per_gpa'), laws.get('k_stderr_mpa_per_gpa'))}) MPa/GPa · P + "
                f"({_pm(laws.get('tau0_mpa'), laws.get('tau0_stderr_mpa'))}) MPa; "
                f"σ = ({_pm(laws.get('mu_mpa_per_gpa'), laws.get('mu_stderr_mpa_per_gpa'))}) MPa/GPa · P + "
                f"({_pm(laws.get('sigma0_mpa'), laws.get('sigma0_stderr_mpa'))}) MPa, fitted on P ≤ "
                f"{fmt(laws.get('p_max_gpa'))} GPa (± one standard error). τ linear up to "
                f"{fmt(laws.get('tau_linear_until_gpa'))} GPa, σ up to {fmt(laws.get('sigma_linear_until_gpa'))} GPa.",
            ],
            notes=laws.get("warnings", []),
            tables=_laws_tables(laws),
            figures=[
                Figure(
                    f_laws / "fig3_laws.png",
                    "Fig. 3: τ and σ against P with the linear fits"
                    + (
                        " and their bands over the coefficient intervals of the table "
                        "(every corner of the box of slope and intercept)."
                        if any(
                            (laws.get(laws.get("energy_form", ""), {}) or {})
                            .get("half_widths", {})
                            .values()
                        )
                        else "."
                    ),
                )
            ],
        )
    )
    if laws.get("internal") and laws.get("enthalpy"):
        sections[-1].paragraphs.append(ENERGY_FORMS_PARAGRAPH)

    # ---- contact
    params = contact["parameters"]
    prov = contact["provenance"]
    keys = [
        ("contact_radius_nm", "Hertz contact radius a (nm)"),
        ("normal_load_un", "normal load P (µN)"),
        ("contact_radius_change_dmt_percent", "DMT radius change vs Hertz (%)"),
        ("peak_lateral_force_un", "peak lateral force Q_peak (µN)"),
        ("saturated_lateral_force_un", "gross-sliding force Q_sat (µN)"),
        ("effective_shear_strength_mpa", "effective shear strength Q_peak/πa² (MPa)"),
        ("gross_sliding_stress_mpa", "gross sliding Q_sat/πa² (MPa)"),
        ("uniform_shear_strength_mpa", "τ at the mean pressure 2p0/3 (MPa)"),
        ("overshoot", "overshoot (Q_peak > Q_sat)"),
        ("knee_stress_amplitude_mpa", "stiffness knee, amplitude stress (MPa)"),
    ]
    res = contact["results"]
    keys = [k for k in keys if k[0] in res[0]]
    ct_rows = [(label, *(fmt(r[k]) for r in res)) for k, label in keys]
    contact_figs = [
        Figure(
            f_ct / "fig4_traction.png",
            "Fig. 4: τ(r), σ(r) and the full-stick q(r) at 60 % of the displacement at the peak "
            "force (p0 = 1 GPa, or the first p0); stick and slip zones.",
        ),
        Figure(
            f_ct / "fig5_force_stiffness.png",
            "Fig. 5: (a) Q(u) per p0 (dots: peak); (b) oscillatory stiffness vs mean shear stress (amplitude)"
            + (
                ": the paper's d⟨Q⟩/d⟨u⟩ (solid) and the lock-in stiffness Q_amp/u′₁ of the steady "
                "cycle (dash-dot), which is what a lock-in measurement corresponds to."
                if "cycle" in contact
                else "."
            ),
        ),
    ]
    notes = [
        "Where the parameters come from: "
        + "; ".join(f"{k}: {v}" for k, v in prov.items() if k != "moduli")
        + "."
    ]
    if "experiment" in contact:
        e = contact["experiment"]
        contact_figs.append(
            Figure(
                f_ct / "fig6_experiment.png",
                f"Fig. 6: measured stiffness ({e['source']}) at p0 = {e['p0_gpa']:g} GPa with the model.",
            )
        )
        notes.append(
            f"Measured collapse {e['measured_collapse_stress_mpa']:.3g} MPa, model "
            f"{e['model_collapse_stress_mpa']:.3g} MPa ({e['stress_measure']} stress); τ0 that "
            f"matches the data: {e['fitted_tau0_mpa']:.3g} MPa."
        )
    cyc_tables, cyc_figs, cyc_notes = _cycle_and_fit(contact, f_ct)
    cyc_tables = _interval_tables(contact) + cyc_tables
    notes += cyc_notes
    contact_figs += cyc_figs
    sections.append(
        Section(
            "5. Modified Mindlin contact",
            paragraphs=[
                f"R = {params['radius_um']:g} µm, E* = {params['contact_modulus_gpa']:g} GPa, G* = "
                f"{params['shear_modulus_gpa']:g} GPa ({prov.get('moduli')}); k = {params['k_mpa_per_gpa']:.3g} "
                f"MPa/GPa, τ0 = {params['tau0_mpa']:.3g} MPa, μ = {params['mu_mpa_per_gpa']:.3g} MPa/GPa, "
                f"σ0 = {params['sigma0_mpa']:.3g} MPa ; "
                f"w = {params['work_of_adhesion_j_m2']:.3g} J/m² ({prov.get('work_of_adhesion_j_m2')}).",
            ],
            notes=notes,
            tables=[
                Table(("quantity", *(f"p0 = {r['p0_gpa']:g} GPa" for r in res)), ct_rows),
                *_elastic_tables(cfg, folders.get("elastic")),
                *cyc_tables,
            ],
            figures=contact_figs,
        )
    )
    return sections


def _cycle_and_fit(contact: dict, folder: Path) -> tuple[list, list, list[str]]:
    """Tables, figures and notes of the oscillation cycle (``contact.cycle.enabled``) and of the
    multi-load fit (``contact.fit.csv``), from the contact stage's ``summary.json``."""
    from flatcontact.report.html import Figure, Table

    tables, figs, notes = [], [], []
    rows = contact.get("cycle")
    if rows:
        model = rows[0]["model"]
        tables.append(
            Table(
                (
                    "p0 (GPa)",
                    "Q_amp (µN)",
                    "Q_amp/Q_gross",
                    "W per cycle (fJ)",
                    "lock-in Q_amp/u′₁ (N/m)",
                    "u″₁ (nm)",
                    "loss tangent",
                    "paper d⟨Q⟩/d⟨u⟩ (N/m)",
                ),
                [
                    (
                        fmt(r["p0_gpa"]),
                        fmt(r["lateral_force_amplitude_un"]),
                        fmt(r["amplitude_fraction_of_gross_sliding"], 3),
                        fmt(r["dissipated_energy_per_cycle_fj"]),
                        fmt(r["lockin_stiffness_n_per_m"]),
                        fmt(r["lockin_quadrature_nm"]),
                        fmt(r["loss_tangent"], 3),
                        fmt(r["paper_stiffness_n_per_m"]),
                    )
                    for r in rows
                ],
                f"Steady load-controlled cycle, {model} model (W = π·Q_amp·u″₁)",
            )
        )
        notes.append(
            "A lock-in amplifier referenced to the drive Q_amp·sin(2πνt) reads the first harmonic "
            "of u: the measured stiffness is Q_amp/u′₁ (in phase) with the loss u″₁ (quadrature), "
            "not the paper's d⟨Q⟩/d⟨u⟩, which is built from the loading quarter cycle alone. "
            + contact["conventions"].get("cycle", "")
        )
        figs.append(
            Figure(
                folder / "fig5c_cycle_loops.png",
                f"Steady hysteresis loops u(Q) at several amplitudes ({model} model; dashed: "
                "loading from rest); the area of each loop is the energy dissipated per cycle.",
            )
        )
        figs.append(
            Figure(
                folder / "fig6_lockin.png",
                "Lock-in stiffness Q_amp/u′₁ (solid; what a lock-in measures) next to the "
                "paper's d⟨Q⟩/d⟨u⟩ (dashed) against the stress amplitude, and the loss tangent.",
            )
        )
    fit = contact.get("fit")
    if fit:
        fit_rows = []
        for name in ("modified", "classical"):
            res = fit[name]
            for key in res["free"]:
                fit_rows.append(
                    (
                        name,
                        key,
                        _pm(res["fitted"][key], res["standard_errors"][key]),
                        fmt(res["aicc"]),
                        fmt(res["rms_residual_n_per_m"]),
                    )
                )
        tables.append(
            Table(
                ("model", "parameter", "fitted ± standard error", "AICc", "rms residual (N/m)"),
                fit_rows,
                f"Multi-load fit of {', '.join(f['name'] for f in fit['files'])} "
                f"({fit['modified']['stiffness']} stiffness, loads "
                f"{', '.join(f'{p:g}' for p in fit['modified']['loads_gpa'])} GPa); preferred: "
                f"{fit['preferred_model']} (ΔAICc classical − modified = "
                f"{fit['delta_aicc_classical_minus_modified']:.3g})",
            )
        )
        figs.append(
            Figure(
                folder / "fig6_fit.png",
                "Measured stiffness curves with the fitted modified (solid) and classical (dotted) "
                "models, and the residuals.",
            )
        )
    return tables, figs, notes


#: Which energy form is the lateral force at constant load, and why the paper's differs.
ENERGY_FORMS_PARAGRAPH = (
    "Which form is the lateral force at constant load: the enthalpy form. At a fixed normal "
    "load P the slabs sit at the gap z*(x, y; P) that makes h = U/A + P·z stationary in z, so by "
    "the envelope theorem the lateral gradient of h at constant P equals the lateral force "
    "∇U at fixed z — the force an atomistic simulation or an instrument at constant load "
    "measures. The paper's internal form Ũ(x, y)|_P = U(x, y, z*) leaves out the work P·A·Δz* "
    "done against the load when the gap rises and falls along the path: ∇Ũ|_P = ∇U|_z − "
    "P·∇z*. Both agree at P = 0 and differ by the load times the gap corrugation, which grows "
    "with P; that is why the paper's slopes k and μ are small and the enthalpy form's are "
    "larger, by up to an order of magnitude. The contact model uses the configured form "
    "(analysis.energy_form)."
)


def _laws_tables(laws: dict) -> list:
    """The laws of both energy forms side by side, each coefficient with its standard error
    and its interval (fit, convergence and model spread), and what the interval is made of."""
    from flatcontact.report.html import Table

    forms = [f for f in ("internal", "enthalpy") if isinstance(laws.get(f), dict)]
    if not forms:
        return []
    configured = laws.get("energy_form")
    rows = []
    for key, err, label in (
        ("k_mpa_per_gpa", "k_stderr_mpa_per_gpa", "k (MPa/GPa)"),
        ("tau0_mpa", "tau0_stderr_mpa", "τ0 (MPa)"),
        ("mu_mpa_per_gpa", "mu_stderr_mpa_per_gpa", "μ (MPa/GPa)"),
        ("sigma0_mpa", "sigma0_stderr_mpa", "σ0 (MPa)"),
    ):
        row = [label]
        for form in forms:
            d = laws[form]
            iv = d.get("intervals", {}).get(key)
            row.append(_pm(d.get(key), d.get(err)))
            row.append(f"[{iv['low']:.3g}, {iv['high']:.3g}]" if iv else "n/a")
        row.append(f"{PAPER[key]:g}")
        rows.append(tuple(row))
    header = ["coefficient"]
    for form in forms:
        tag = f"{form}{' (used)' if form == configured else ''}"
        header += [f"{tag} ± s.e.", f"{form} interval"]
    header.append("paper (internal)")
    u = laws.get("uncertainty", {})
    parts = "fit standard error"
    if any(u.get(f"convergence_{f}") for f in forms):
        parts += ", convergence"
    if any(u.get(f"model_spread_{f}") for f in forms):
        parts += ", model spread"
    caption = (
        f"Load laws in both energy forms; intervals: coefficient ± {u.get('coverage', 1):g} × "
        f"the combined standard error ({parts}, in quadrature)"
        + (f"; {u['source']}" if u.get("source") else "")
    )
    return [Table(tuple(header), rows, caption)]


def _interval_tables(contact: dict) -> list:
    """The contact outputs with the laws' uncertainty carried through (``summary.json``
    ``intervals``), when any law coefficient has a nonzero half-width."""
    from flatcontact.report.html import Table

    iv = contact.get("intervals") or {}
    if not iv.get("results") or not any(iv.get("half_widths", {}).values()):
        return []
    labels = {
        "effective_shear_strength_mpa": "effective shear strength Q_peak/πa² (MPa)",
        "collapse_stress_mpa": "collapse stress, amplitude (MPa)",
        "knee_stress_amplitude_mpa": "stiffness knee, amplitude (MPa)",
    }
    rows = [
        (
            label,
            *(
                f"{r[key]['value']:.3g} [{r[key]['low']:.3g}, {r[key]['high']:.3g}]"
                for r in iv["results"]
            ),
        )
        for key, label in labels.items()
    ]
    hw = ", ".join(f"{k} ± {v:.2g}" for k, v in iv["half_widths"].items() if v)
    return [
        Table(
            ("quantity", *(f"p0 = {r['p0_gpa']:g} GPa" for r in iv["results"])),
            rows,
            f"Contact outputs over the laws' intervals ({hw}; every corner of the box)",
        )
    ]
