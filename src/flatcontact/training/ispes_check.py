"""The potential's error on the quantities of interest: same interface, several models, one table.

Two measurements for any SiO₂ model that has an ASE calculator:

* :func:`quartz_elastic_vs_experiment`: zero-stress α-quartz lattice and relaxed-ion
  Cij (:func:`flatcontact.training.validate.quartz_lattice`,
  :func:`~flatcontact.training.validate.quartz_elastic`: central finite strains ±0.5 %,
  ions relaxed) against experiment (:mod:`flatcontact.foundation.reference`, |C14|);
* :func:`compare_ispes`: the ISPES of ONE interface (the same reference geometry and
  lateral cell) scanned with each model on the same lateral grid and load range, then
  analysed identically (constant-pressure ISPES, zero-perpendicular-force path, τ and
  σ_MSS as in the paper, :func:`flatcontact.analysis.analyze.analyze_ispes`). The
  result is one row per (model, load) with τ, σ_MSS, G_int, the work of separation W
  and their differences from the first model (the reference, e.g. the teacher).

A model is a :class:`~flatcontact.potentials.InteractionModel` (intra-slab model + the same
cross-interface LJ: this isolates the intra-slab potential, which is what a surrogate
replaces) or a scan factory: a callable ``factory(atoms)`` -> ASE calculator with a
``fingerprint`` (:func:`flatcontact.potentials.engines.calculator_factory`). Offline
teachers come from their one registry, :mod:`flatcontact.potentials.teachers` (CHGNet
r2SCAN, SevenNet-0, SevenNet-MF-0 with its r2SCAN and PBE heads; weights ship in the
wheels, nothing is downloaded); they need ``torch`` (CPU) plus ``chgnet``/``sevenn``.
"""

from __future__ import annotations

import io
import time
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from ase import Atoms

from flatcontact.foundation.errors import InputError, require
from flatcontact.foundation.reference import (
    QUARTZ_CIJ_EXPERIMENT_GPA,
    QUARTZ_LATTICE_EXPERIMENT_ANGSTROM,
)
from flatcontact.potentials.teachers import TEACHERS, get_teacher, teacher_calculator  # noqa: F401

#: Experimental α-quartz Cij (GPa) as compared here: :data:`flatcontact.foundation.reference.QUARTZ_CIJ_EXPERIMENT_GPA`
#: with |C14| (a model's C14 sign depends on its axes).
QUARTZ_CIJ_ABS_EXPERIMENT_GPA = {k: abs(v) for k, v in QUARTZ_CIJ_EXPERIMENT_GPA.items()}
#: Per-load quantities compared between models.
ISPES_QUANTITIES = ("tau_mpa", "sigma_mss_mpa", "shear_stiffness_gpa_per_nm")


def teacher_spec(name: str, lj: Mapping | None = None):
    """``InteractionModel`` with teacher ``name`` inside each slab and the given (default) LJ across."""
    from flatcontact.config import default_potential
    from flatcontact.potentials.model import InteractionModel

    teacher = get_teacher(name)
    lj = dict(lj if lj is not None else default_potential()["lj"])
    return InteractionModel(intra=f"ase:{teacher.factory}", lj=lj)


# --------------------------------------------------------------------------- elasticity


def quartz_elastic_vs_experiment(calc, label: str, strain: float = 0.005) -> dict:
    """Zero-stress α-quartz lattice and relaxed-ion Cij of ``calc`` against experiment.

    Parameters
    ----------
    calc
        An ASE calculator for bulk α-quartz (periodic in 3D).
    label
        Name of the model in the result.
    strain
        Finite strain of the central differences (Voigt, engineering shear).

    Returns
    -------
    dict
        ``label``, ``lattice`` (a, c in Å, density), ``cij_gpa`` (trigonal set, C14 as
        |C14|), ``rel_error`` (model/experiment - 1 per Cij and for a, c), ``moduli_gpa``
        (Hill K, G, E, ν, E*, G*), ``seconds``.
    """
    from flatcontact.training.validate import quartz_elastic, quartz_lattice

    t0 = time.perf_counter()
    relaxed, lattice = quartz_lattice(calc)
    elastic = quartz_elastic(relaxed, calc, strain=strain)
    cij = {k: float(v) for k, v in elastic["cij_gpa"].items()}
    cij["C14"] = abs(cij["C14"])
    rel = {k: cij[k] / v - 1 for k, v in QUARTZ_CIJ_ABS_EXPERIMENT_GPA.items()}
    rel["a"] = lattice["a_angstrom"] / QUARTZ_LATTICE_EXPERIMENT_ANGSTROM["a"] - 1
    rel["c"] = lattice["c_angstrom"] / QUARTZ_LATTICE_EXPERIMENT_ANGSTROM["c"] - 1
    return {
        "label": label,
        "lattice": lattice,
        "cij_gpa": cij,
        "rel_error": rel,
        "moduli_gpa": {k: float(v) for k, v in elastic["moduli_gpa"].items()},
        "tensor_gpa": elastic["tensor_gpa"],
        "strain": strain,
        "seconds": time.perf_counter() - t0,
    }


def elastic_table(reports: Sequence[Mapping]) -> pd.DataFrame:
    """One row per model (and one for experiment): a, c, the seven Cij, E*, and the
    largest relative error of C11, C33, C44 (a bundled potential's target is 15 %,
    ``flatcontact.training.validate.TARGETS['cij_rel']``)."""
    rows = [
        {
            "model": "experiment",
            "a_angstrom": QUARTZ_LATTICE_EXPERIMENT_ANGSTROM["a"],
            "c_angstrom": QUARTZ_LATTICE_EXPERIMENT_ANGSTROM["c"],
            **QUARTZ_CIJ_ABS_EXPERIMENT_GPA,
            "e_star_gpa": np.nan,
            "max_rel_error_c11_c33_c44": 0.0,
        }
    ]
    for r in reports:
        rows.append(
            {
                "model": r["label"],
                "a_angstrom": r["lattice"]["a_angstrom"],
                "c_angstrom": r["lattice"]["c_angstrom"],
                **r["cij_gpa"],
                "e_star_gpa": r["moduli_gpa"]["e_star"],
                "max_rel_error_c11_c33_c44": max(
                    abs(r["rel_error"][k]) for k in ("C11", "C33", "C44")
                ),
            }
        )
    return pd.DataFrame(rows)


# --------------------------------------------------------------------------- ISPES


def _factory_of(model: Any):
    """A scan factory (callable(atoms) -> calculator, with ``fingerprint``) for ``model``."""
    from flatcontact.potentials.engines import calculator_factory
    from flatcontact.potentials.model import InteractionModel

    if isinstance(model, InteractionModel):
        return calculator_factory(model)
    if callable(model) and hasattr(model, "fingerprint"):
        return model
    raise InputError(
        f"model {model!r}: expected an InteractionModel or a calculator factory with a "
        "'fingerprint'"
    )


def scan_and_analyze(
    model: Any,
    interface: Atoms,
    out_dir: str | Path,
    *,
    grid: tuple[int, int] = (4, 4),
    p_range_gpa: tuple[float, float, int] | None = (-0.3, 5.5, 8),
    thickness_angstrom: Sequence[float] | None = None,
    p_gpa: Sequence[float] = (0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0),
    fmax_ev_per_angstrom: float = 0.005,
    direction_deg: float = 90.0,
    form: str = "internal",
    load_source: str = "energy",
    workers: int = 1,
) -> dict:
    """Scan ``interface`` with ``model`` (resumable, into ``out_dir``) and analyse it.

    Returns
    -------
    dict
        ``rows`` (per load: ``p_gpa``, τ, σ_MSS, G_int, ``tau_limited_by``,
        ``force_noise_mpa``), ``laws`` (``laws.json`` form), ``work_of_separation_j_per_m2``,
        ``force_calls``, ``seconds``, ``label``.
    """
    from flatcontact.analysis.analyze import analyze_ispes
    from flatcontact.analysis.options import AnalysisOptions
    from flatcontact.analysis.outputs import friction_csv_text
    from flatcontact.ispes.grid import GridSpec
    from flatcontact.ispes.relax import RelaxSettings
    from flatcontact.ispes.scan import run_scan

    require(
        (p_range_gpa is None) != (thickness_angstrom is None),
        "give exactly one of p_range_gpa and thickness_angstrom",
    )
    # checked before the scan: a bad form or direction costs nothing
    options = AnalysisOptions(
        direction_deg=direction_deg, form=form, load_source=load_source, allow_missing=True
    )
    factory = _factory_of(model)
    spec = GridSpec(
        int(grid[0]),
        int(grid[1]),
        thickness_angstrom=None
        if thickness_angstrom is None
        else tuple(float(z) for z in thickness_angstrom),
        p_range_gpa=None if p_range_gpa is None else tuple(p_range_gpa),
    )
    t0 = time.perf_counter()
    result = run_scan(
        interface,
        factory,
        spec,
        out_dir,
        RelaxSettings(fmax_ev_per_angstrom),
        executor_options={"kind": "serial" if workers == 1 else "processes", "workers": workers},
    )
    seconds = time.perf_counter() - t0
    analysis = analyze_ispes(result.dataset, list(p_gpa), options)
    table = pd.read_csv(io.StringIO(friction_csv_text(analysis)))
    keep = [
        c for c in (*ISPES_QUANTITIES, "tau_limited_by", "n_jumps", "force_noise_mpa") if c in table
    ]
    table = table[["p_gpa", *keep]]
    adhesion = result.adhesion or {}
    return {
        "label": getattr(factory, "label", str(model)),
        "rows": table.to_dict(orient="records"),
        "laws": analysis.laws.to_json(),
        "work_of_separation_j_per_m2": adhesion.get("work_of_separation_j_per_m2", np.nan),
        "force_calls": int(np.nansum(result.dataset["force_calls"].values)),
        "seconds": seconds,
    }


def compare_ispes(
    models: Mapping[str, Any],
    interface: Atoms,
    out_dir: str | Path,
    *,
    grid: tuple[int, int] = (4, 4),
    p_range_gpa: tuple[float, float, int] | None = (-0.3, 5.5, 8),
    thickness_angstrom: Sequence[float] | None = None,
    p_gpa: Sequence[float] = (0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0),
    fmax_ev_per_angstrom: float = 0.005,
    direction_deg: float = 90.0,
    form: str = "internal",
    load_source: str = "energy",
    workers: int = 1,
    results: dict | None = None,
) -> pd.DataFrame:
    """τ, σ_MSS, G_int and W per load of the same interface with several models, side by side.

    Parameters
    ----------
    models
        Label -> model (an ``InteractionModel`` or a scan factory). The FIRST is the
        reference (e.g. the teacher); every other row carries its difference from it.
    interface
        The relaxed reference interface (:mod:`flatcontact.structures.interface_contract`):
        every model scans the same atoms, lateral cell and held layers.
    out_dir
        One resumable scan folder per model, ``out_dir/<label>``.
    grid, p_range_gpa, thickness_angstrom, fmax_ev_per_angstrom
        The scan (lateral grid; loads at the probe stacking that set each model's
        thicknesses, or explicit thicknesses shared by all models; per-point tolerance).
        With ``p_range_gpa`` every model gets thicknesses spanning the same loads on its
        own p(z), so the constant-pressure analysis compares equal loads.
    p_gpa, direction_deg, form, load_source
        The analysis (loads; pulling direction, 90 = y as in the paper; energy form).
    results
        If a dict, filled with the full per-model result of :func:`scan_and_analyze`
        (laws, timings, force calls).

    Returns
    -------
    pandas.DataFrame
        One row per (model, load): ``model, p_gpa, tau_mpa, sigma_mss_mpa,
        shear_stiffness_gpa_per_nm, work_of_separation_j_per_m2, tau_limited_by`` and, for
        every quantity q, ``d_<q>`` (model − reference) and ``rel_<q>`` (d/|reference|).
    """
    require(len(models) >= 1, "models: expected at least one model")
    for label in models:
        require(
            isinstance(label, str) and label and "/" not in label,
            f"models: label {label!r}: expected a non-empty name without '/'",
        )
    factories = {label: _factory_of(m) for label, m in models.items()}  # fail before any scan
    out_dir = Path(out_dir)
    per_model = {}
    for label, factory in factories.items():
        per_model[label] = scan_and_analyze(
            factory,
            interface,
            out_dir / label,
            grid=grid,
            p_range_gpa=p_range_gpa,
            thickness_angstrom=thickness_angstrom,
            p_gpa=p_gpa,
            fmax_ev_per_angstrom=fmax_ev_per_angstrom,
            direction_deg=direction_deg,
            form=form,
            load_source=load_source,
            workers=workers,
        )
    if results is not None:
        results.update(per_model)
    return comparison_table(per_model)


def comparison_table(per_model: Mapping[str, Mapping]) -> pd.DataFrame:
    """The side-by-side table of :func:`compare_ispes` from per-model results.

    ``per_model``: label -> ``{"rows": [per-load dicts], "work_of_separation_j_per_m2": W}``
    (the first label is the reference).
    """
    labels = list(per_model)
    require(labels, "per_model: expected at least one model")
    frames = []
    for label in labels:
        t = pd.DataFrame(per_model[label]["rows"])
        t.insert(0, "model", label)
        t["work_of_separation_j_per_m2"] = float(per_model[label]["work_of_separation_j_per_m2"])
        frames.append(t)
    table = pd.concat(frames, ignore_index=True)
    ref = frames[0].set_index(np.round(frames[0]["p_gpa"].to_numpy(float), 6))
    quantities = [*ISPES_QUANTITIES, "work_of_separation_j_per_m2"]
    for q in quantities:
        base = np.array(
            [
                ref[q].get(round(float(p), 6), np.nan) if q in ref else np.nan
                for p in table["p_gpa"]
            ],
            float,
        )
        d = table[q].to_numpy(float) - base
        table[f"d_{q}"] = d
        with np.errstate(divide="ignore", invalid="ignore"):
            table[f"rel_{q}"] = d / np.abs(base)
    return table
