"""One asperity experiment: build, press and slide every load, measure, compare.

Plain inputs (the recipe, the model, an :class:`ExperimentSpec`, the laws, E*); the stage
(:mod:`flatcontact.stages.asperity`) maps the settings onto them and writes the files.

The saved states live in ``state_dir`` (``load_<i>/step_<k>.npz``) with ``spec.json``, the
spec they were computed with: a rerun with the same spec resumes, one with another spec is
refused (one line) rather than mixing states.
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from flatcontact.asperity import builder
from flatcontact.asperity.compare import Laws, compare_load
from flatcontact.asperity.driver import EV_PER_ANGSTROM_N, Protocol, run_load
from flatcontact.asperity.ranks import check_ranks, mpiexec
from flatcontact.asperity.records import Binning, StepRecord, measure_load
from flatcontact.foundation.errors import InputError

GPA_ANGSTROM2_TO_EV_PER_ANGSTROM = 1e-11 / EV_PER_ANGSTROM_N


@dataclass(frozen=True)
class ExperimentSpec:
    """What one experiment computes (lengths Å, pressures GPa, forces eV/Å)."""

    geometry: str
    radius_angstrom: float
    p0_gpa: tuple[float, ...]
    contact_modulus_gpa: float
    step_angstrom: float
    steps: int
    fmax_ev_per_angstrom: float
    max_iterations: int
    depth_factor: float
    lateral_factor: float
    axis_repeats: int
    rigid_angstrom: float
    repeats: tuple[int, int] | None
    layers: int | None
    gap_angstrom: float | None
    bin_width_angstrom: float
    contact_force_ev_per_angstrom: float
    slip_threshold_angstrom: float
    #: lock-in cycles after the slide (:mod:`.ramp`); their states live apart (``ramp/``), so
    #: adding or extending a ramp reuses a finished slide
    ramp_amplitudes_angstrom: tuple[float, ...] = ()
    #: the crystal cut to the cap (:func:`.builder.oriented`)
    tip: str = "slab2"


@dataclass
class Experiment:
    """The built atoms, their sizes, the per-load records and comparisons."""

    atoms: object
    sizes: builder.Sizes
    binning: Binning
    targets_ev_per_angstrom: list[float]
    records: list[list[StepRecord]]
    comparisons: list[dict]
    states: list[list]
    wall_seconds: float
    memory_bytes: int
    ramps: list[dict] = field(default_factory=list)


def target_force_ev_per_angstrom(spec: ExperimentSpec, p0_gpa: float, axis_angstrom: float):
    """The Hertz normal force (eV/Å) at peak pressure p0: cylinder P' L = π a p0 L / 2,
    sphere P = 2π a² p0 / 3 (a from R and E*)."""
    a = builder.hertz_half_width_angstrom(
        spec.geometry, spec.radius_angstrom, p0_gpa, spec.contact_modulus_gpa
    )
    if spec.geometry == "cylinder":
        f = math.pi * a * p0_gpa / 2.0 * axis_angstrom
    else:
        f = 2.0 * math.pi * a * a * p0_gpa / 3.0
    return f * GPA_ANGSTROM2_TO_EV_PER_ANGSTROM


def _sizes(spec: ExperimentSpec, recipe):
    """The planned sizes, with the user's overrides."""
    from flatcontact.structures.construct import build_interface

    small = builder.oriented(build_interface(builder.deep_recipe(recipe, 3))[0], spec.tip)
    spacing = builder.plane_spacing(small)
    sizes = builder.plan_sizes(
        spec.geometry,
        spec.radius_angstrom,
        max(spec.p0_gpa),
        spec.contact_modulus_gpa,
        small.cell.array[:2, :2],
        spacing,
        depth_factor=spec.depth_factor,
        lateral_factor=spec.lateral_factor,
        axis_repeats=spec.axis_repeats,
        rigid_angstrom=spec.rigid_angstrom,
        tip_plane_spacing_angstrom=builder.plane_spacing(small, 2),
    )
    if spec.repeats is not None or spec.layers is not None:
        rigid_planes = sizes.tip_layers - sizes.flat_layers
        layers = spec.layers or sizes.flat_layers
        sizes = builder.Sizes(
            sizes.geometry,
            sizes.radius_angstrom,
            sizes.hertz_half_width_angstrom,
            tuple(spec.repeats) if spec.repeats else sizes.repeats,
            layers,
            layers + rigid_planes,
            sizes.rigid_angstrom,
        )
    return sizes


def bin_edges(spec: ExperimentSpec, cell: np.ndarray, repeats) -> np.ndarray:
    """Bin edges (Å) commensurate with the lattice: the cylinder's bins are whole rows of the
    primitive cell across the axis (width an odd number of a2's y-period, nearest to
    ``bin_width_angstrom``), centred on the apex and covering the period, so every bin holds
    the same atoms per plane (no aliasing between atom rows and bins); the sphere's are
    annuli of ``bin_width_angstrom`` up to half the shorter period."""
    if spec.geometry == "cylinder":
        row = abs(cell[1, 1]) / repeats[1]
        # an odd number of rows per bin: the centre bin is symmetric about the apex and the
        # edges fall half a row from the apex's rows (fcc(111): the planes' rows lie at
        # thirds of a row, so no atom sits on an edge)
        per_bin = max(1, round(spec.bin_width_angstrom / row))
        per_bin += 1 - per_bin % 2
        nb = max(0, (repeats[1] // per_bin - 1) // 2)
        return (np.arange(-nb, nb + 2) - 0.5) * per_bin * row
    extent = min(abs(cell[0, 0]), abs(cell[1, 1])) / 2
    nb = max(1, math.floor(extent / spec.bin_width_angstrom))
    return np.linspace(0, nb, nb + 1) * spec.bin_width_angstrom


def check_state(state_dir: Path, spec: ExperimentSpec) -> None:
    """Refuse states of other settings; more (or fewer) ``steps`` extend (or reuse) them, as
    each step's state depends only on the steps before it."""
    state_dir.mkdir(parents=True, exist_ok=True)
    path = state_dir / "spec.json"
    doc = json.loads(json.dumps(asdict(spec)))
    if path.exists():
        old = {"tip": "slab2", **json.loads(path.read_text())}  # states from before `tip`
        free = {"steps": None, "ramp_amplitudes_angstrom": None}
        if {**old, **free} != {**doc, **free}:
            raise InputError(
                f"{state_dir}: holds the states of other asperity settings; give another --out "
                "or remove it"
            )
    path.write_text(json.dumps(doc, indent=1))


def plan(spec: ExperimentSpec, recipe, neighbours_per_atom: int, ranks: int = 1):
    """(atoms, sizes, memory bytes): built and checked against the machine (run over
    ``ranks`` MPI ranks) before any run."""
    sizes = _sizes(spec, recipe)
    atoms, sizes = builder.build_asperity(
        recipe,
        spec.geometry,
        spec.radius_angstrom,
        max(spec.p0_gpa),
        spec.contact_modulus_gpa,
        sizes=sizes,
        gap_angstrom=spec.gap_angstrom,
        neighbours_per_atom=neighbours_per_atom,
        ranks=ranks,
        tip=spec.tip,
    )
    need = builder.check_machine(len(atoms), neighbours_per_atom, ranks=ranks)
    return atoms, sizes, need


def run_experiment(
    spec: ExperimentSpec,
    recipe,
    model,
    laws: Laws | None,
    state_dir: Path,
    *,
    neighbours_per_atom: int = 100,
    progress: Callable[[str], None] | None = None,
    mpi_ranks: int = 1,
    executor=None,
) -> Experiment:
    """Build, run every load (resuming from ``state_dir``), measure and compare.

    ``mpi_ranks`` > 1 relaxes each step over that many MPI ranks
    (:mod:`flatcontact.asperity.ranks`); it is not part of the spec: a run may be resumed on
    another number of ranks (each saved step records its own).
    ``executor`` (:class:`flatcontact.ispes.executors.Executor`): the loads run as
    independent jobs on it first (:func:`run_cases`); the loop then reads their states.
    """
    t0 = time.perf_counter()
    if check_ranks(mpi_ranks) > 1:
        mpiexec()  # refused in one line before anything is built or written
    atoms, sizes, need = plan(spec, recipe, neighbours_per_atom, mpi_ranks)
    model.check_atoms(atoms)
    check_state(state_dir, spec)
    if executor is not None and len(spec.p0_gpa) > 1:
        parallel = min(executor.workers, len(spec.p0_gpa))
        builder.check_machine(len(atoms) * parallel, neighbours_per_atom)
        run_cases(spec, recipe, model, state_dir, executor, progress)
    cell = atoms.cell.array
    axis = float(np.linalg.norm(cell[0])) if spec.geometry == "cylinder" else 0.0
    edges = bin_edges(spec, cell, sizes.repeats)
    bins = Binning(
        edges,
        spec.contact_force_ev_per_angstrom,
        spec.slip_threshold_angstrom,
        spec.geometry,
        axis,
    )
    records, comparisons, targets, all_states, ramps = [], [], [], [], []
    for i, p0 in enumerate(spec.p0_gpa):
        protocol = case_protocol(spec, i, axis)
        targets.append(protocol.normal_force_ev_per_angstrom)

        def tell(done, total, seconds, i=i, p0=p0):
            if progress is not None:
                progress(
                    f"load {i + 1}/{len(spec.p0_gpa)} (p0 {p0:g} GPa): step {done}/{total} "
                    f"in {seconds:.1f} s"
                )

        states = run_load(
            model, atoms, protocol, state_dir / f"load_{i}", progress=tell, ranks=mpi_ranks
        )
        all_states.append(states)
        recs = measure_load(atoms, states, bins)
        records.append(recs)
        if laws is not None:
            comparisons.append(
                compare_load(recs, bins, laws, spec.radius_angstrom, spec.contact_modulus_gpa)
            )
        if spec.ramp_amplitudes_angstrom:
            ramps.append(
                _ramp(
                    spec,
                    model,
                    atoms,
                    protocol,
                    states[0],
                    state_dir / f"load_{i}",
                    recs,
                    bins,
                    laws,
                    comparisons[-1] if laws is not None else None,
                    progress,
                    i,
                )
            )
    return Experiment(
        atoms,
        sizes,
        bins,
        targets,
        records,
        comparisons,
        all_states,
        time.perf_counter() - t0,
        need,
        ramps,
    )


def case_protocol(spec: ExperimentSpec, i: int, axis_angstrom: float) -> Protocol:
    """The press-and-slide protocol of load ``i``."""
    target = target_force_ev_per_angstrom(spec, spec.p0_gpa[i], axis_angstrom)
    return Protocol(
        target, spec.step_angstrom, spec.steps, spec.fmax_ev_per_angstrom, spec.max_iterations
    )


def compute_case(spec: ExperimentSpec, recipe, model, i: int, state_dir: str) -> float:
    """One job: build the atoms (deterministic: the driver's build) and press, slide and
    ramp load ``i`` into ``state_dir/load_<i>`` (resuming its saved steps); the wall seconds.

    The job writes its own states, step by step, so it resumes per step wherever it ran;
    on Dask the workers must see ``state_dir`` (a shared filesystem).
    """
    t0 = time.perf_counter()
    atoms, _, _ = plan(spec, recipe, 100)
    cell = atoms.cell.array
    axis = float(np.linalg.norm(cell[0])) if spec.geometry == "cylinder" else 0.0
    protocol = case_protocol(spec, i, axis)
    folder = Path(state_dir) / f"load_{i}"
    states = run_load(model, atoms, protocol, folder)
    if spec.ramp_amplitudes_angstrom:
        from flatcontact.asperity import ramp

        ramp.run_ramp(
            model, atoms, states[0], protocol, spec.ramp_amplitudes_angstrom, folder / "ramp"
        )
    return time.perf_counter() - t0


def run_cases(spec, recipe, model, state_dir: Path, executor, progress=None) -> None:
    """Every load as a job on ``executor`` (the scan's: local processes or Dask); the
    results are the states they saved, identical to a sequential run's (each load depends
    only on the built atoms; tested)."""
    run_all_cases([(spec, state_dir)], recipe, model, executor, progress)


def run_all_cases(experiments, recipe, model, executor, progress=None) -> None:
    """Every (experiment, load) of ``experiments`` — (spec, state_dir) pairs, e.g. one per
    radius — as one job on ``executor``, all in flight at once (:func:`compute_case`)."""
    pending = {
        executor.submit(compute_case, spec, recipe, model, i, str(state_dir)): (spec, i)
        for spec, state_dir in experiments
        for i in range(len(spec.p0_gpa))
    }
    while pending:
        done, _ = executor.wait_first(list(pending))
        for handle in done:
            spec, i = pending.pop(handle)
            seconds = executor.result(handle)
            if progress is not None:
                progress(
                    f"R {spec.radius_angstrom:g} Å, load {i + 1}/{len(spec.p0_gpa)} "
                    f"(p0 {spec.p0_gpa[i]:g} GPa): done on {executor.name} in {seconds:.1f} s"
                )


def _ramp(spec, model, atoms, protocol, pressed, folder, recs, bins, laws, comparison, progress, i):
    """The lock-in ramp of one load (:mod:`.ramp`) and its comparison with the models."""
    from flatcontact.asperity import ramp
    from flatcontact.asperity.compare import profiles

    def tell(done, total, seconds):
        if progress is not None:
            progress(f"load {i + 1}: ramp step {done}/{total} in {seconds:.1f} s")

    path, q, loops, converged = ramp.run_ramp(
        model, atoms, pressed, protocol, spec.ramp_amplitudes_angstrom, folder / "ramp", tell
    )
    models, q_peak, k0 = {}, None, None
    if comparison is not None:
        q_peak = comparison["atoms"]["peak_lateral_force_n"]
        k0 = comparison["atoms"]["initial_stiffness_n_per_m"]
        axis_m = bins.axis_length_angstrom * 1e-10
        for name, (x, p, a) in profiles(
            recs, bins, spec.radius_angstrom, spec.contact_modulus_gpa
        ).items():
            models[name] = ramp.elements(bins.geometry, x, p, a, laws.point_laws(), axis_m)
    out = ramp.compare_ramp(path, q, loops, q_peak, k0, models)
    out["converged"] = bool(all(converged))
    return out
