"""The paper's experiment for each approximant cell: the collapse stress of the cell's laws.

An approximant study (:mod:`flatcontact.studies.approximants`) gives each commensurate cell
its load laws τ = k·P + τ0, σ = μ·P + σ0. With ``contact.experiment.compare`` set
(``passivated-tip``: a diamond tip on few-layer graphene over SiOx, the paper's Fig. 6) each
resolved cell's laws go through the contact model at the experiment's conditions
(``contact.radius_um``, ``contact_modulus_gpa``, ``shear_modulus_gpa``,
``contact.experiment.p0_gpa``) exactly as a run's laws do in the contact stage
(:func:`flatcontact.stages.contact.experiment_comparison`, whose criterion this is: the
amplitude stress Q_max/(π a²) where the load-controlled d⟨Q⟩/d⟨u⟩ first falls to
``contact.collapse_fraction`` of its initial value), set against the measured collapses
(:data:`flatcontact.foundation.reference.PAPER_EXPERIMENT_COLLAPSE_MPA`).

A cell whose corrugation is not resolved above its noise floor has no laws (NaN): its row
has no collapse stress and says why; a cell whose laws the contact model refuses (e.g.
τ0 < 0, or a negative slope that makes τ or σ negative on the contact) says that instead.
The validity gates that fired on a cell are carried into its row: a number from a gated
landscape is reported, not trusted.
"""

from __future__ import annotations

import math

from flatcontact.config.run import RunConfig
from flatcontact.contact.parameters import ContactParameters
from flatcontact.contact.tip_comparison import LAW_KEYS, compare_collapse
from flatcontact.foundation.errors import InputError
from flatcontact.foundation.layout import EXPERIMENT_COLLAPSE_JSON  # noqa: F401 (the file these rows go to)
from flatcontact.foundation.reference import PAPER_EXPERIMENT_COLLAPSE_MPA, is_paper_material
from flatcontact.stages.build import structure_elements
from flatcontact.stages.contact import quartz_reference_laws


def check_experiment_moduli(cfg: RunConfig) -> None:
    """Refuse, before any cell runs, a study that compares with the experiment without E*, G*.

    The study runs build and scan only: without ``contact.experiment.compare`` it needs no
    contact moduli at all (no contact model runs). With it, each cell's laws go through the
    contact model with ``contact.contact_modulus_gpa`` and ``contact.shear_modulus_gpa``, so
    both must be given, unless the slabs are the paper's α-quartz (whose E*, G* the defaults
    are). ``elastic.enabled`` does not give them here: the study runs no elastic stage.

    Raises
    ------
    InputError
        One line naming the two fields and why they are needed.
    """
    c = cfg.contact
    if c.experiment.compare is None:
        return
    if {"contact_modulus_gpa", "shear_modulus_gpa"} <= c.model_fields_set:
        return
    elements = structure_elements(cfg.structure)
    if is_paper_material(cfg, elements):
        return
    what = f"structure.kind={cfg.structure.kind}"
    if elements is not None:
        what += f" ({'-'.join(sorted(elements))})"
    raise InputError(
        f"contact.contact_modulus_gpa/shear_modulus_gpa: contact.experiment.compare is set, so "
        f"the approximant study puts each cell's laws through the contact model, and {what} is "
        "not the paper's alpha-quartz whose E* and G* are the defaults; give both moduli (GPa) "
        "(the study runs no elastic stage: elastic.enabled does not give them) or unset "
        "contact.experiment.compare"
    )


def cell_collapse(cell: dict, cfg: RunConfig) -> dict:
    """One cell's row: its size, strain and laws, and its collapse stress (MPa, amplitude) at
    ``contact.experiment.p0_gpa`` with the ratios to the measured collapses, or ``None`` and
    the ``reason`` when there is none.

    Parameters
    ----------
    cell : a row of ``study.json["cells"]`` (:func:`flatcontact.studies.approximants.run_approximants`)
    cfg : the study's configuration (its ``contact:`` section: R in µm, E* and G* in GPa)
    """
    gates = (cell.get("gates") or {}).get("fired") or []
    row = {
        "label": cell["label"],
        "n_atoms": cell.get("n_atoms"),
        "twist_deg": cell.get("twist_deg"),
        "strain_percent_slab1": cell.get("strain_percent_slab1"),
        "strain_percent_slab2": cell.get("strain_percent_slab2"),
        **{key: cell.get(key, math.nan) for key in LAW_KEYS},
        "barrier_mev_per_a2": cell.get("barrier_mev_per_a2", math.nan),
        "noise_mev_per_a2": cell.get("noise_mev_per_a2", math.nan),
        "floor_mev_per_a2": cell.get("floor_mev_per_a2", cell.get("noise_mev_per_a2", math.nan)),
        "resolved": bool(cell.get("resolved")),
        "gates_fired": list(gates),
        "collapse_stress_mpa": None,
        "ratio_to_measured": None,
        "reason": "",
    }
    if "error" in cell:
        row["reason"] = f"cell refused: {cell['error']}"
        return row
    if not row["resolved"]:
        row["reason"] = (
            f"not resolved: corrugation {row['barrier_mev_per_a2']:.3g} meV/A^2 is below "
            f"10x the noise floor {row['floor_mev_per_a2']:.3g}; no laws (an upper bound only)"
        )
        return row
    laws = {key: float(cell[key]) for key in LAW_KEYS}
    if not all(math.isfinite(v) for v in laws.values()):
        row["reason"] = "no laws (the analysis gave none)"
        return row
    c = cfg.contact
    try:
        params = ContactParameters(
            radius_um=c.radius_um,
            contact_modulus_gpa=c.contact_modulus_gpa,
            shear_modulus_gpa=c.shear_modulus_gpa,
            **laws,
        )
        doc = compare_collapse(
            cell["label"],
            params,
            c.experiment.p0_gpa,
            PAPER_EXPERIMENT_COLLAPSE_MPA,
            {},
            fraction=c.collapse_fraction,
        )
    except InputError as exc:  # laws the contact model refuses (τ0 < 0, τ < 0 on the contact)
        row["reason"] = f"the contact model refuses the laws: {exc}"
        return row
    row["collapse_stress_mpa"] = doc["run"]["collapse_stress_mpa"]
    row["ratio_to_measured"] = doc["run"]["ratio_to_measured"]
    row["contact_radius_nm"] = doc["run"]["contact_radius_nm"]
    if gates:
        row["reason"] = "gates fired: " + ", ".join(gates)
    return row


def approximant_collapse(doc: dict, cfg: RunConfig) -> dict:
    """The collapse stress of every cell of an approximant study (``doc``: ``study.json``)
    at the experiment's conditions, with the quartz laws and the measurements for scale.

    Returns
    -------
    dict
        ``p0_gpa``, ``collapse_fraction``, ``radius_um``, ``contact_modulus_gpa``,
        ``shear_modulus_gpa``, ``measured_mpa``, ``cells`` (rows of :func:`cell_collapse`,
        in the study's order) and ``references`` (the quartz law sets' rows of
        :func:`flatcontact.contact.tip_comparison.compare_collapse`).
    """
    c = cfg.contact
    if c.experiment.compare is None:
        raise InputError(
            "contact.experiment.compare: not set; the approximant collapse needs the "
            "experiment to compare with (passivated-tip)"
        )
    params = ContactParameters(
        radius_um=c.radius_um,
        contact_modulus_gpa=c.contact_modulus_gpa,
        shear_modulus_gpa=c.shear_modulus_gpa,
    )
    references = compare_collapse(
        "quartz",
        params,
        c.experiment.p0_gpa,
        PAPER_EXPERIMENT_COLLAPSE_MPA,
        quartz_reference_laws(),
        fraction=c.collapse_fraction,
    )["references"]
    return {
        "experiment": c.experiment.compare,
        "p0_gpa": float(c.experiment.p0_gpa),
        "collapse_fraction": float(c.collapse_fraction),
        "radius_um": float(c.radius_um),
        "contact_modulus_gpa": float(c.contact_modulus_gpa),
        "shear_modulus_gpa": float(c.shear_modulus_gpa),
        "measured_mpa": dict(PAPER_EXPERIMENT_COLLAPSE_MPA),
        "cells": [cell_collapse(cell, cfg) for cell in doc["cells"]],
        "references": references,
    }
