"""The report's section next to the summary: this run beside the paper (its α-quartz), or the
results of another material on their own.

The paper's numbers come from :mod:`flatcontact.foundation.reference`; the set-up differences read the
run's interaction model (``cfg.potential``, a :class:`flatcontact.potentials.InteractionModel`).
"""

from __future__ import annotations

import json
from typing import Any

from flatcontact.config import BUNDLED_SNAP
from flatcontact.foundation.errors import InputError
from flatcontact.foundation.reference import (
    PAPER,
    PAPER_THRESHOLD_GPA,
    QUARTZ_HAMAKER_ZJ,
    QUARTZ_LATTICE_EXPERIMENT_ANGSTROM,
)
from flatcontact.potentials.files import BUNDLED_DIR
from flatcontact.potentials.lj import (
    ALPHA_QUARTZ_NUMBER_DENSITY_PER_NM3,
    pairwise_hamaker_constant_zj,
)
from flatcontact.report.format import LAW_COEFFICIENTS, fmt, pm
from flatcontact.report.html import Section, Table
from flatcontact.report.sections.analysis import stacking_rows
from flatcontact.report.sections.contact import slip_note

A_EXP = QUARTZ_LATTICE_EXPERIMENT_ANGSTROM["a"]


def compare_with_paper(laws: dict) -> list[tuple[str, str, str, str, str]]:
    """Rows (quantity, this run ± s.e., paper, difference, reading) for k, τ0, μ, σ0.

    The reading says whether the difference is within two standard errors of the fit
    and otherwise names the differences of set-up that can cause it.
    """
    rows = []
    for key, err_key, label in LAW_COEFFICIENTS:
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
        rows.append((label, pm(value, err), f"{ref:g}", rel, reading))
    return rows


def paper_section(cfg, laws: dict, scan: dict, contact: dict) -> Section:
    """This run next to the paper: the laws (``laws.json``), the work of separation
    (``scan.json``) and the effective shear strength with the run's and the paper's laws
    (``summary.json``), and why the numbers can differ (:func:`setup_differences`)."""
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
    for i, (r_run, r_pap) in enumerate(zip(res, ref, strict=True)):
        rows.append(
            (
                f"effective shear strength Q_peak/πa² at p0 = {r_run['p0_gpa']:g} GPa (MPa)",
                fmt(r_run["effective_shear_strength_mpa"]) + slip_note(contact, i),
                fmt(r_pap["effective_shear_strength_mpa"]),
                f"{r_run['effective_shear_strength_mpa'] - r_pap['effective_shear_strength_mpa']:+.3g}",
                "paper column: the same contact model with the paper's k, τ0, μ, σ0",
            )
        )
    return Section(
        "This run next to the paper",
        paragraphs=[
            f"Paper (Dong, Uluca, Cross, Sanvito): τ = k·P + τ0 with k = {PAPER['k_mpa_per_gpa']:g} "
            f"MPa/GPa, τ0 = {PAPER['tau0_mpa']:g} MPa; σ = μ·P + σ0 with μ = "
            f"{PAPER['mu_mpa_per_gpa']:g} MPa/GPa, σ0 = {PAPER['sigma0_mpa']:g} MPa (SNAP + "
            f"TS-vdW LJ, P < {PAPER_THRESHOLD_GPA:g} GPa).",
        ],
        notes=["Why the numbers can differ: " + " ".join(setup_differences(cfg))],
        tables=[Table(("quantity", "this run", "paper", "difference", "reading"), rows)],
    )


def own_results_section(
    cfg,
    material: str,
    model: str,
    laws: dict,
    scan: dict,
    contact: dict,
    table,
    family: str = "generic",
) -> Section:
    """The laws, W, stackings (named for ``family``,
    :mod:`flatcontact.report.stacking_names`) and contact results of a material other than
    the paper's: no comparison with the paper's α-quartz numbers, which are not about this
    material."""
    studied = _carries_study(laws)
    rows = [
        (label, pm(laws.get(key), laws.get(err_key)) + _law_interval(laws, key, studied))
        for key, err_key, label in LAW_COEFFICIENTS
    ]
    adhesion = scan.get("adhesion") or {}
    at = adhesion.get("work_of_separation_stacking")
    rows.append(
        (
            "work of separation W (J/m²)" + (f", at the {at}" if at else ""),
            fmt(adhesion.get("work_of_separation_j_per_m2")),
        )
    )
    intervals = (contact.get("intervals") or {}).get("results") or []
    for i, r in enumerate(contact["results"]):
        cell = fmt(r["effective_shear_strength_mpa"])
        if studied and i < len(intervals):
            q = intervals[i]["effective_shear_strength_mpa"]
            cell += f" [{q['low']:.4g}, {q['high']:.4g}]"
        cell += slip_note(contact, i)
        rows.append(
            (f"effective shear strength Q_peak/πa² at p0 = {r['p0_gpa']:g} GPa (MPa)", cell)
        )
    moduli = contact.get("provenance", {}).get("moduli", "config")
    params = contact.get("parameters", {})
    tables = [Table(("quantity", "this run"), rows)]
    stackings = stacking_rows(table, family)
    if stackings:
        tables.append(
            Table(
                ("P (GPa)", "named stackings (meV/Å² above the lowest)", "barrier (meV/Å²)"),
                stackings,
                "Stationary stackings of the landscape, lowest first, and the "
                "minimum-energy-path barrier",
            )
        )
    paragraphs = [
        f"Material: {material}; interaction model: {model}. Load laws τ = k·P + τ0 and "
        f"σ = μ·P + σ0 fitted on P ≤ {cfg.analysis.threshold_gpa:g} GPa."
    ]
    if studied:
        paragraphs.append(
            "± is the fit's standard error; [low, high] the interval with the measured "
            "convergence and model spread of the uncertainty block (section 4, "
            "laws.json intervals; Q_peak/πa² over the box of those intervals)."
        )
    return Section(
        f"Results for {material}",
        paragraphs=[
            *paragraphs,
            f"Contact moduli E* = {fmt(params.get('contact_modulus_gpa'))} GPa, G* = "
            f"{fmt(params.get('shear_modulus_gpa'))} GPa ({moduli}).",
        ],
        tables=tables,
    )


def _carries_study(laws: dict) -> bool:
    """Do ``laws.json``'s intervals carry a study's parts (a nonzero convergence or model
    spread beside the fit)? Then the fit's standard error alone understates them."""
    for iv in (laws.get("intervals") or {}).values():
        parts = iv.get("components") or {}
        if any(v for k, v in parts.items() if k != "fit"):
            return True
    return False


def _law_interval(laws: dict, key: str, studied: bool) -> str:
    """``"; [low, high]"``: the coefficient's interval of ``laws.json`` when it carries a
    study's parts (else nothing: the ± standard error is the whole interval)."""
    iv = (laws.get("intervals") or {}).get(key)
    if not studied or not iv or iv.get("low") is None:
        return ""
    return f"; [{iv['low']:.3g}, {iv['high']:.3g}]"


def _intra(cfg) -> str | None:
    """The intra-slab name (``vashishta``, ``snap:...``) of a LAMMPS model, else ``None``."""
    m = cfg.potential
    return m.intra if m.engine == "lammps" and isinstance(m.intra, str) else None


def _lj(cfg) -> Any:
    """The cross-interface LJ of the model, or ``None`` when it has none."""
    m = cfg.potential
    return m.lj if m.coupling == "lj" and m.engine != "ase-interface" else None


def setup_differences(cfg) -> list[str]:
    """Why this run's numbers can differ from the paper's: a list of concrete set-up differences."""
    out = []
    intra = _intra(cfg)
    if intra is None:
        out.append(
            f"The interaction model is the {cfg.potential.label}, not the paper's SNAP + TS-vdW LJ."
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
    lj = _lj(cfg)
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
