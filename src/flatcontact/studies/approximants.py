"""``flatcontact study approximants``: the ISPES study of each commensurate approximant cell.

The cells are :func:`flatcontact.structures.approximants.approximant_sequence` of the
configuration's ``structure:`` and ``approximants:`` sections (commensurate twists toward a
target angle or the (n, n+1) family; coincidence lattices of decreasing strain). Each cell is
an ordinary run directory ``DIR/runs/<label>`` (the structure override merged in) run by
:class:`flatcontact.pipeline.Pipeline` through build and scan, the cells side by side through
the scan's executor (``scan.executor``/``scan.workers``; each cell's scan serial), so a rerun
skips every finished stage.

The grid (docs/incommensurate.md, "The approximant study"): the ISPES of a coincidence cell
is periodic in the shift lattice Λ_1 + Λ_2 (:mod:`flatcontact.ispes.shift_lattice`), whose
cell is ``index`` times smaller than the supercell (N² for an N-cell twist). Each cell is
scanned by the ordinary scan stage (:mod:`flatcontact.stages.scan`), which picks the grid
(:func:`~flatcontact.ispes.shift_lattice.scan_grid`: the base grid ``scan.grid``, the
density per period of the untwisted contact, raised to the next integer coprime to the
index; :func:`plan` states it with the same function) and writes its ``ispes.nc``
re-indexed onto ONE period of the landscape; the study copies it to
``runs/<label>/shift-cell/ispes.nc``. The analysis and the laws (the stages' own functions)
and the validity gates (:func:`flatcontact.stages.gates.evaluate_gates`) run on that file
(``shift-cell/analyze``, ``shift-cell/laws``); the loads are the configuration's
(pressures are intensive: the same loads for every cell).

Per cell it returns the laws (τ0, k, σ0, μ of the analysis' energy form), the corrugation of
the constant-pressure ISPES at the lowest load (max − min, meV/Å²), the energy noise floors
(the round-off: the same structure at two shifts one shift-lattice vector apart,
:func:`~flatcontact.ispes.shift_lattice.translation_noise_ev_per_a2`; for a scan that
relaxes anything, also the relaxation's: the same structure relaxed three times from
perturbed starts with the scan's tolerance, :func:`~flatcontact.ispes.relax_noise.relaxation_noise`;
the floor is the larger, written into the cell's shift-cell ``ispes.nc`` before its analysis,
which takes it as the smallest degeneracy tolerance of its minima: :func:`write_energy_floor`)
and whether the
corrugation is resolved (≥ :data:`RESOLVED_FACTOR` × the floor; a cell whose ISPES has no
lateral range above that at any thickness is not analysed: its laws are NaN and its
"barrier" is that range, an upper bound), the gates that fired, the
scan's force calls and the wall time of the cell; the study fits the size scaling of τ0 and
the corrugation on the resolved cells (:mod:`flatcontact.studies.scaling`).

Symmetry: every cell is scanned as the scan stage scans any interface under
``scan.symmetry`` (``auto``: reduced unless ``full``): the scan's group is found modulo the
shift-lattice translations and lifted onto the grid
(:func:`~flatcontact.ispes.shift_symmetry.shift_space_group`, ``modulo_translations``;
0.2–0.3 s for the (1, 2) to (3, 4) cells, 0.7 s for (7, 8), where the old search of every
pair of the slabs' translations took 227 s for the (2, 3) cell), and the verified points are
checked against a tolerance relative to the cell's own energy range
(:func:`flatcontact.ispes.reduction.energy_tolerances`), so a relaxed cell whose landscape
breaks the group by a sizeable fraction of its corrugation is computed in full and the
broken-symmetry gate sees it (a relaxed study under ``auto`` no longer needs a special case).
The gates use the group modulo the translations, restated on the shift cell.
"""

from __future__ import annotations

import math
import shutil
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from flatcontact.config.run import RunConfig
from flatcontact.foundation.errors import InputError
from flatcontact.foundation.fileio import refuse_link
from flatcontact.foundation.layout import (
    FRICTION_CSV,
    FRICTION_NC,
    INTERFACE,
    ISPES_NC,
    LAWS_JSON,
    OTHER_FORM_JSON,
    SCAN_JSON,
)
from flatcontact.foundation.result_json import read_result_json
from flatcontact.ispes.executors import make_executor
from flatcontact.ispes.shift_lattice import scan_grid
from flatcontact.studies.runner import run_jobs
from flatcontact.studies.scaling import fit_scaling
from flatcontact.studies.study_dir import RUNS, folder_name, refuse_study_links
from flatcontact.studies.variants import variant_config

#: Folder of a cell's run directory that holds the ISPES on one shift-lattice period.
SHIFT_CELL = "shift-cell"
#: A cell's corrugation is resolved when it is at least this multiple of the energy noise
#: floor (the larger of :func:`flatcontact.ispes.shift_lattice.translation_noise_ev_per_a2`
#: and, for a relaxed scan, :func:`flatcontact.ispes.relax_noise.relaxation_noise`); the
#: scaling is fitted on resolved cells only.
RESOLVED_FACTOR = 10.0


def planned_index(approximant) -> int:
    """The shift-lattice index the cell will have (before it is built): ``N²`` for a
    commensurate twist of N cells per layer (``N²/3`` when m − n is a multiple of 3: the
    built cell is 3 coincidence cells), Λ_1 + Λ_2 of the match matrices for a coincidence
    cell (:func:`flatcontact.ispes.shift_lattice.shift_lattice`). The run checks it on the
    built atoms (:func:`flatcontact.ispes.shift_lattice.shift_lattice_of`)."""
    from flatcontact.ispes.shift_lattice import shift_lattice

    override = approximant.structure_override
    if "twist" in override:
        m, n = override["twist"]
        cells = m * m + m * n + n * n
        return cells * cells // (3 if (m - n) % 3 == 0 else 1)
    match = override.get("match", {})
    if "slab1_supercell" in match:
        return shift_lattice(match["slab1_supercell"], match["slab2_supercell"]).index
    return 1


def plan(cfg: RunConfig) -> list[dict]:
    """The cells of the study: per approximant its record, the grid, the index and the
    validated configuration (every cell checked before any work; one-line InputError). The
    contact moduli are required only with ``contact.experiment.compare``
    (:func:`flatcontact.studies.approximant_collapse.check_experiment_moduli`)."""
    from flatcontact.structures.approximants import approximant_sequence
    from flatcontact.studies.approximant_collapse import check_experiment_moduli

    check_experiment_moduli(cfg)
    cells = approximant_sequence(cfg.section("structure"), cfg.approximants)
    n_z = (
        cfg.scan.p_range_gpa.n
        if cfg.scan.p_range_gpa is not None
        else len(cfg.scan.thickness_angstrom)
    )
    out = []
    for a in cells:
        index = planned_index(a)
        n_a, n_b = scan_grid(cfg.scan.grid, index)
        scan = {"grid": [n_a, n_b]}
        over = {"structure": a.structure_override, "scan": scan, "report": {"svg": False}}
        config = variant_config(cfg, over, f"approximants ({a.label})").to_dict()
        out.append(
            {
                "label": a.label,
                "kind": a.kind,
                "n_atoms": a.n_atoms,
                "twist_deg": a.twist_deg,
                "angle_error_deg": a.angle_error_deg,
                "strain_percent_slab1": _max_abs(a.strain_percent_slab1),
                "strain_percent_slab2": _max_abs(a.strain_percent_slab2),
                "shift_lattice_index": index,
                "grid": [n_a, n_b],
                # grid points as planned (the load bracket may add thicknesses); a rigid-layers
                # point costs one force call, a relaxed one ~10 (docs/incommensurate.md)
                "points_planned": n_a * n_b * n_z,
                "atom_points_planned": n_a * n_b * n_z * a.n_atoms,
                "structure_override": a.structure_override,
                "config": config,
            }
        )
    return out


def model_caveats(cfg: RunConfig) -> list[str]:
    """What the interaction model itself puts under the corrugation of large cells.

    A Coulomb term across the interface cut off at a finite radius (``coul/shield 16.0 1`` of
    the h-BN ILP presets, any ``coul/*`` interlayer style but a long-range one): summed to
    infinity, its registry dependence between two neutral charge lattices falls as
    e^(−|G| d) with the common reciprocal vectors |G| ∝ √N; truncated, it keeps a part that
    falls as a power of |G| and moves with the cutoff. Measured on rigid twisted h-BN: from
    the second cell on it is the whole corrugation (docs/incommensurate.md, "a new user's
    run"). One line per such style, naming it, when both slabs of the interface (built
    unrelaxed, milliseconds) carry charges (graphene/h-BN: the neutral sheet sees no
    Coulomb term); none for other models.
    """
    from flatcontact.potentials.styles import style_cutoff_angstrom
    from flatcontact.structures.construct import build_interface

    data = cfg.to_dict()["potential"]
    charges = data.get("charges") or {}
    if data.get("coupling") != "interlayer" or not charges:
        return []
    atoms, _ = build_interface(cfg.structure)
    symbols = np.asarray(atoms.get_chemical_symbols())
    slab = np.asarray(atoms.arrays["slab"])
    for i in (1, 2):
        if not any(abs(float(charges.get(e, 0.0))) > 0 for e in set(symbols[slab == i])):
            return []
    styles = data.get("interlayer") or []
    styles = [styles] if isinstance(styles, dict) else styles
    out = []
    for style in styles:
        pair_style = str(style.get("pair_style", ""))
        name = pair_style.split()[0] if pair_style.split() else ""
        if "coul" not in name or "long" in name:
            continue
        cutoff = style_cutoff_angstrom(pair_style)
        at = f"{cutoff:g} A" if cutoff is not None else "its cutoff"
        out.append(
            f"potential.interlayer {pair_style!r}: a Coulomb term cut off at {at} across the "
            "interface; its registry dependence does not vanish with the cell size (the "
            "exact sum's does): on rigid twisted h-BN it is the whole corrugation from the "
            "second cell on (docs/incommensurate.md); compare with a longer cutoff before "
            "reading the larger cells"
        )
    return out


def _max_abs(values) -> float:
    return float(max((abs(v) for v in values), default=0.0))


def corrugation_mev_per_a2(friction_nc: Path) -> tuple[float, float]:
    """(lowest load GPa, max − min of its constant-pressure ISPES in meV/Å²) of ``friction.nc``."""
    import xarray as xr

    with xr.open_dataset(friction_nc, engine="h5netcdf") as ds:
        p = np.asarray(ds["p_gpa"].values, float)
        i = int(np.argmin(p))
        surface = np.asarray(ds["energy_map"].values[i], float)
    return float(p[i]), float(np.nanmax(surface) - np.nanmin(surface))


def lateral_range_mev_per_a2(shifted) -> float:
    """The largest lateral range (max − min over the shifts) of the energy per area at any
    thickness of a shift-cell ISPES (meV/Å²): an upper bound of its corrugation at constant
    load, compared with the noise floor before any analysis."""
    e = np.asarray(shifted["energy"].values, float) / float(shifted.attrs["area"])
    return 1e3 * float(np.nanmax(np.nanmax(e, axis=(0, 1)) - np.nanmin(e, axis=(0, 1))))


def tolerance_advice(barrier_mev_per_a2: float, noise_mev_per_a2: float, relaxed) -> str:
    """One line when a relaxed cell is unresolved because of its force tolerance, else "".

    ``relaxed`` is the cell's :class:`~flatcontact.ispes.relax_noise.RelaxationNoise` (None:
    nothing relaxes). The line is written when the corrugation (an upper bound when the cell
    was not analysed) is below :data:`RESOLVED_FACTOR` × the relaxation floor but not below
    that multiple of the rigid (round-off) floor: a tighter ``scan.fmax_ev_per_angstrom``
    could resolve it, a rerun at the same tolerance cannot. The tolerance it names is
    necessary, not sufficient: the floor brought to 1/:data:`RESOLVED_FACTOR` of the
    corrugation bound, with the floor taken ∝ fmax² (the scaling of the harmonic bound: near a
    minimum the energy left is ½ Fᵀ H⁻¹ F), an estimate only: on relaxed twisted graphene the
    measured floor fell more slowly from 0.01 to 5e-4 eV/Å and far faster below
    (docs/incommensurate.md); and the true relaxed corrugation may be smaller than the bound.
    """
    if relaxed is None:
        return ""
    relax_noise = 1e3 * relaxed.ev_per_a2
    bound = RESOLVED_FACTOR * relax_noise
    if not (
        barrier_mev_per_a2 < bound and barrier_mev_per_a2 >= RESOLVED_FACTOR * noise_mev_per_a2
    ):
        return ""
    fmax = relaxed.fmax_ev_per_angstrom
    needed = fmax * math.sqrt(barrier_mev_per_a2 / bound)
    # two significant figures, rounded down: never the tolerance the cell already ran at
    # (0.000486 at fmax 0.0005 printed as 0.0005 with one figure)
    scale = 10.0 ** (math.floor(math.log10(needed)) - 1)
    needed = math.floor(needed / scale) * scale
    return (
        f"corrugation <= {barrier_mev_per_a2:.2g} meV/A^2 is below {RESOLVED_FACTOR:g}x the "
        f"relaxation floor {relax_noise:.2g} at scan.fmax_ev_per_angstrom {fmax:g} "
        f"({relaxed.mode}); resolving it needs scan.fmax_ev_per_angstrom <= ~{needed:.2g} "
        "(floor ~ fmax^2) or a rigid-layers scan"
    )


def _gates(cfg: RunConfig, root: Path) -> dict:
    """The validity gates of the ordinary run (:func:`flatcontact.stages.gates.evaluate_gates`)
    on the shift-cell analysis: the scan's (in-slab slip, load folds), the laws' (negative
    slope), the landscape's (degenerate minima) and the broken-symmetry gate on the
    interface's shift-space group restated on the shift cell."""
    from flatcontact.stages.gates import GateInputs, evaluate_gates, shift_group_operations

    cell = root / SHIFT_CELL
    inputs = GateInputs(
        interface=root / "01-build" / INTERFACE,
        scan_json=cell / SCAN_JSON,
        friction_nc=cell / "analyze" / FRICTION_NC,
        laws_json=cell / "laws" / LAWS_JSON,
        symmetry_tolerance_angstrom=cfg.scan.symmetry.tolerance_angstrom,
        spread_compression=cfg.scan.relax_mode != "rigid",
    )
    report = evaluate_gates(inputs)
    return {
        "fired": [f.gate for f in report.findings],
        "messages": [f"{f.gate}: {f.message}" for f in report.findings],
        "not_checked": list(report.not_checked),
        "shift_group_order_on_shift_cell": len(shift_group_operations(inputs)),
    }


def write_energy_floor(path: Path, floor_mev_per_a2: float) -> None:
    """Store a cell's measured noise floor (meV/Å²) in its shift-cell ``ispes.nc`` (the
    contract's ``energy_floor_mev_per_a2``): the analysis takes it as the smallest degeneracy
    tolerance of its minima (:func:`flatcontact.analysis.starts.degeneracy_tolerance_ev_per_a2`),
    so minima closer than the floor count as indistinguishable and the ``degenerate_minima``
    gate compares them as such."""
    from flatcontact.ispes.contract import ENERGY_FLOOR_ATTR, open_ispes, write_ispes

    ds = open_ispes(path)
    ds.attrs[ENERGY_FLOOR_ATTR] = float(floor_mev_per_a2)
    write_ispes(ds, path)


def run_cell(config: dict, folder: str, planned: int) -> dict:
    """Run one approximant cell (``config``: a validated configuration's ``to_dict()``) in
    ``folder``: build and scan through the pipeline, then the ISPES on one shift-lattice
    period, its analysis, laws and gates (module docstring). Module-level with plain
    arguments so an executor can run cells side by side."""
    from flatcontact.ispes.relax_noise import relaxation_noise, relaxes_something
    from flatcontact.ispes.shift_lattice import shift_lattice_of, translation_noise_ev_per_a2
    from flatcontact.pipeline import Pipeline
    from flatcontact.potentials.engines import make_calculator
    from flatcontact.stages.analyze import AnalyzeInputs, analyze_stage
    from flatcontact.stages.laws import LawsInputs, laws_stage
    from flatcontact.stages.scan import relax_settings
    from flatcontact.structures.interface_io import read_interface

    cfg = RunConfig.model_validate(config)
    cfg = cfg.model_copy(
        update={"scan": cfg.scan.model_copy(update={"executor": "serial", "workers": 1})}
    )
    root = Path(folder)
    refuse_link(root, "a study's variant folder")  # planted after the study's own check
    t0 = time.perf_counter()
    with Pipeline(cfg, root) as pipe:
        pipe.build()
        ds = pipe.scan()
        scan = pipe.scan_summary()
        action = pipe.results["scan"].action
        scan_folder = pipe.folder("scan")
        build_folder = pipe.folder("build")
    reference = read_interface(build_folder / INTERFACE)
    lattice = shift_lattice_of(reference, cfg.scan.symmetry.tolerance_angstrom)
    if lattice.index != planned or scan["shift_lattice"]["index"] != planned:
        raise InputError(
            f"approximants: the built cell's shift lattice has index {lattice.index} (the scan "
            f"{scan['shift_lattice']['index']}), the plan {planned}; the grid {cfg.scan.grid} "
            "was chosen for the plan"
        )
    cell = root / SHIFT_CELL
    if cell.exists():
        shutil.rmtree(cell)  # derived from the scan: rebuilt every time (seconds)
    cell.mkdir(parents=True)
    shifted = ds  # the scan stage's ispes.nc: already on one shift-lattice period
    shutil.copy2(scan_folder / ISPES_NC, cell / ISPES_NC)
    shutil.copy2(scan_folder / SCAN_JSON, cell / SCAN_JSON)
    calculator = make_calculator(cfg.potential, reference)
    noise = 1e3 * translation_noise_ev_per_a2(reference, calculator, lattice)
    relax, relaxed = relax_settings(cfg.scan), None
    if relaxes_something(reference, relax):
        relaxed = relaxation_noise(
            reference, calculator, lattice, relax, np.asarray(shifted["thickness"].values)
        )
    relax_noise = math.nan if relaxed is None else 1e3 * relaxed.ev_per_a2
    floor = max(noise, 0.0 if relaxed is None else relax_noise)
    write_energy_floor(cell / ISPES_NC, floor)
    lateral = lateral_range_mev_per_a2(shifted)
    nan = math.nan
    form, law, p_low, barrier, gates = cfg.analysis.energy_form, {}, nan, lateral, None
    if lateral >= RESOLVED_FACTOR * floor:
        analyze_stage(cfg, AnalyzeInputs(cell / ISPES_NC), cell / "analyze")
        laws_stage(
            cfg,
            LawsInputs.read(cell / "analyze" / FRICTION_CSV, cell / "analyze" / OTHER_FORM_JSON),
            cell / "laws",
        )
        laws = read_result_json(cell / "laws" / LAWS_JSON, energy_form=cfg.analysis.energy_form)
        form = laws.get("energy_form") or cfg.analysis.energy_form
        law = laws.get(form) if isinstance(laws.get(form), dict) else laws
        p_low, barrier = corrugation_mev_per_a2(cell / "analyze" / FRICTION_NC)
        gates = _gates(cfg, root)
    else:  # noise only: the analysis of a noise landscape costs minutes and means nothing
        gates = {
            "fired": [],
            "messages": [],
            "not_checked": ["all: the landscape is not resolved above the noise floor"],
        }
    calls = int(scan.get("force_calls_total") or 0)
    return {
        "folder": str(root),
        "energy_form": form,
        "tau0_mpa": float(law.get("tau0_mpa", nan)),
        "k_mpa_per_gpa": float(law.get("k_mpa_per_gpa", nan)),
        "sigma0_mpa": float(law.get("sigma0_mpa", nan)),
        "mu_mpa_per_gpa": float(law.get("mu_mpa_per_gpa", nan)),
        "tau0_stderr_mpa": float(law.get("tau0_stderr_mpa", nan)),
        "barrier_mev_per_a2": barrier,
        "lateral_range_mev_per_a2": lateral,
        "analysed": bool(law),
        "barrier_at_p_gpa": p_low,
        "noise_mev_per_a2": noise,
        "relax_noise_mev_per_a2": relax_noise,
        "floor_mev_per_a2": floor,
        "relax_noise": None if relaxed is None else relaxed.to_json(),
        "resolved": bool(barrier >= RESOLVED_FACTOR * floor),
        "tolerance_advice": tolerance_advice(barrier, noise, relaxed),
        "shift_lattice_index": lattice.index,
        "shift_cell_a1_angstrom": np.asarray(shifted.attrs["a1"], float).tolist(),
        "shift_cell_a2_angstrom": np.asarray(shifted.attrs["a2"], float).tolist(),
        "gates": gates,
        "work_of_separation_j_per_m2": float(
            (scan.get("adhesion") or {}).get("work_of_separation_j_per_m2") or math.nan
        ),
        "force_calls": calls,
        "force_calls_spent": 0 if action == "skipped" else calls,
        "computed_points": scan.get("computed_points"),
        "scan_action": action,
        "wall_s": time.perf_counter() - t0,
    }


#: The gates that distrust the landscape itself (its corrugation); the others (a load fold, a
#: falling law, degenerate minima) distrust the laws read from it (τ0).
LANDSCAPE_GATES = frozenset({"in_slab_slip", "broken_symmetry"})


def _distrusted(row: dict, accepted: set, only: frozenset | None = None) -> list[str]:
    """The gates that fired on a cell and were not accepted (``contact.accept_untrusted``),
    restricted to ``only``: a cell they name leaves the scaling fit (never silently: the study's
    ``scaling.<quantity>.gated`` lists it with its gates)."""
    fired = [g for g in (row.get("gates") or {}).get("fired", []) if g not in accepted]
    return [g for g in fired if only is None or g in only]


def scaling_block(cells: list[dict], accepted: set) -> dict:
    """``study.json["scaling"]``: the size-scaling fits of τ0 and of the corrugation.

    A fit takes the cells that are resolved above the noise floor and on which no gate that
    distrusts that quantity fired (:func:`_distrusted`; gates in ``accepted``, the
    configuration's ``contact.accept_untrusted``, count as not fired). The cells left out
    for their gates are listed under ``gated`` with the gates, so the console line and the
    figure name them.
    """
    resolved = [r for r in cells if r["resolved"]]
    out: dict = {}
    for key, only in (("tau0_mpa", None), ("barrier_mev_per_a2", LANDSCAPE_GATES)):
        kept = [r for r in resolved if not _distrusted(r, accepted, only)]
        out[key] = {
            **fit_scaling([r["n_atoms"] for r in kept], [r[key] for r in kept]),
            "cells": [r["label"] for r in kept],
            "gated": {
                r["label"]: _distrusted(r, accepted, only) for r in resolved if r not in kept
            },
        }
    out["cells"] = [r["label"] for r in resolved]
    out["unresolved"] = [r["label"] for r in cells if not r["resolved"]]
    out["resolved_factor"] = RESOLVED_FACTOR
    return out


def run_approximants(
    cfg: RunConfig, out: str | Path, on_done: Callable[[str, dict], None] | None = None
) -> dict:
    """Run every cell of :func:`plan` into ``out``; returns the ``study.json`` document.

    ``on_done(label, result)`` is told when each cell finishes (the CLI prints a line). A
    cell the builder, the model or the analysis refuses is that cell's ``error`` (the others
    stand); the scaling is fitted on the cells that ran.
    """
    out = Path(out)
    cells = plan(cfg)
    refuse_study_links(out)
    executor = make_executor(
        cfg.scan.executor, cfg.scan.workers, cfg.scan.dask_address, cfg.scan.jobqueue
    )
    jobs = [
        (
            c["label"],
            c["config"],
            str(out / RUNS / folder_name(c["label"])),
            c["shift_lattice_index"],
        )
        for c in cells
    ]
    try:
        results = run_jobs(executor, run_cell, jobs, on_done)
    finally:
        executor.close()
    rows = []
    for c in cells:
        r = results[c["label"]]
        entry = {k: v for k, v in c.items() if k != "config"}
        rows.append({**entry, **r})
    ok = [r for r in rows if "error" not in r]
    advice = {r["label"]: r["tolerance_advice"] for r in ok if r.get("tolerance_advice")}
    return {
        "study": "approximants",
        "approximants": cfg.section("approximants"),
        "base_grid": list(cfg.scan.grid),
        "relax_mode": cfg.scan.relax_mode,
        "cells": rows,
        "failed": {r["label"]: r["error"] for r in rows if "error" in r},
        "caveats": model_caveats(cfg),
        "scaling": scaling_block(ok, set(cfg.contact.accept_untrusted)),
        "tolerance_advice": advice,
        "cost": {
            "force_calls_study": sum(r["force_calls_spent"] for r in ok),
            "force_calls_stored": sum(r["force_calls"] for r in ok),
            "force_calls_floor": sum((r["relax_noise"] or {}).get("force_calls", 0) for r in ok),
            "wall_s_cells": sum(r["wall_s"] for r in ok),
            "cells": len(rows),
            "executor": executor.name,
            "workers": executor.workers,
        },
    }
