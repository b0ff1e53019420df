"""Stage asperity (optional, ``asperity.enabled``): the asperity in atoms against the model.

Files: ``asperity.nc`` (per load and step: Q, normal force, contact and stick half-widths,
binned pressure, shear and slip; :func:`flatcontact.asperity.records.dataset`),
``asperity.json`` (:meth:`AsperityResult.to_json`: sizes, atom count, memory, wall time,
finite-size ratios, per load the atoms and the two continuum predictions side by side with
their ratios, and one verdict sentence), the figures, and ``state/`` (the saved relaxed
states: rerunning the same settings into the same folder resumes).

E*: ``asperity.contact_modulus_gpa``, else the elastic stage's (``inputs``), else
``contact.contact_modulus_gpa``. Laws: ``inputs.laws`` (the run's laws stage), else
``asperity.laws_file``; without laws only the atoms are reported.
"""

from __future__ import annotations

import contextlib
import json
import math
from dataclasses import dataclass, field
from pathlib import Path

from flatcontact.foundation.errors import InputError
from flatcontact.foundation.fileio import write_json_atomic
from flatcontact.foundation.layout import (
    ASPERITY_JSON,
    ASPERITY_NC,
    ASPERITY_STATE,
    FIG_ASPERITY_FORCE,
    FIG_ASPERITY_RAMP,
    FIG_ASPERITY_SLIP,
    FIG_ASPERITY_STICK,
    FIG_ASPERITY_TRACTIONS,
)
from flatcontact.stages import _calculator
from flatcontact.stages._common import renamed_errors, save

#: Q_peak of the atoms within this fraction of the model's: "the contact stage's numbers hold".
AGREEMENT_FRACTION = 0.25

_NAMES = {
    "geometry": "asperity.geometry",
    "radius_angstrom": "asperity.radius_angstrom",
    "p0_gpa": "asperity.p0_gpa",
    "contact_modulus_gpa": "asperity.contact_modulus_gpa",
    "rigid_angstrom": "asperity.rigid_angstrom",
    "structure": "structure",
}


@dataclass(frozen=True)
class AsperityInputs:
    """The laws (laws.json's document) and E* (GPa) from upstream, when the run has them."""

    laws: dict | None = None
    contact_modulus_gpa: float | None = None


@dataclass
class AsperityResult:
    """asperity.json's document."""

    doc: dict
    files: list[Path] = field(default_factory=list)

    def to_json(self) -> dict:
        return self.doc


def _spec(settings, inputs: AsperityInputs):
    from flatcontact.asperity.experiment import ExperimentSpec

    a = settings.asperity
    e_star = a.contact_modulus_gpa or inputs.contact_modulus_gpa
    e_star = e_star or settings.contact.contact_modulus_gpa
    return ExperimentSpec(
        a.geometry,
        a.radius_angstrom,
        tuple(a.p0_gpa),
        float(e_star),
        a.step_angstrom,
        a.steps,
        a.fmax_ev_per_angstrom,
        a.max_iterations,
        a.depth_factor,
        a.lateral_factor,
        a.axis_repeats,
        a.rigid_angstrom,
        tuple(a.repeats) if a.repeats else None,
        a.layers,
        a.gap_angstrom,
        a.bin_width_angstrom,
        a.contact_force_ev_per_angstrom,
        a.slip_threshold_angstrom,
        tuple(a.ramp_amplitudes_angstrom or ()),
        a.tip,
    )


def _laws(settings, inputs: AsperityInputs):
    from flatcontact.asperity.compare import Laws

    doc = inputs.laws
    if doc is None and settings.asperity.laws_file:
        path = Path(settings.asperity.laws_file)
        if not path.is_file():
            raise InputError(f"asperity.laws_file: {path} is not a file")
        doc = json.loads(path.read_text())
    if doc is None:
        return None
    try:
        return Laws.from_json(doc)
    except (KeyError, TypeError, ValueError):
        raise InputError(
            "asperity.laws_file: expected laws.json with k_mpa_per_gpa, tau0_mpa, "
            "mu_mpa_per_gpa, sigma0_mpa"
        ) from None


def _compute_seconds(states) -> float | None:
    """The steps' wall time when computed; None when a state predates the record."""
    seconds = [s.seconds for recs in states for s in recs]
    return None if any(x != x for x in seconds) else float(sum(seconds))


def verdict(geometry: str, radius_angstrom: float, loads: list[dict]) -> str:
    """One sentence: whether the contact stage's Q_peak holds for this interface and size."""
    if not loads:
        return "no laws were given: the atoms are reported without a continuum comparison."
    ratios = [ld["ratios_atoms_over_model"]["peak_lateral_force_hertz"] for ld in loads]
    lo, hi = min(ratios), max(ratios)
    holds = all(abs(r - 1.0) <= AGREEMENT_FRACTION for r in ratios)
    size = f"a {geometry} of R = {radius_angstrom / 10:g} nm"
    span = f"{lo:.2f}" if math.isclose(lo, hi, rel_tol=1e-3) else f"{lo:.2f} to {hi:.2f}"
    if holds:
        return (
            f"For {size}, the contact stage's model (Hertz pressure, pointwise laws) holds: the "
            f"atoms' Q_peak is {span} times the model's (within {AGREEMENT_FRACTION:.0%})."
        )
    return (
        f"For {size}, the contact stage's model (Hertz pressure, pointwise laws) does not hold: "
        f"the atoms' Q_peak is {span} times the model's (more than {AGREEMENT_FRACTION:.0%} off)."
    )


@contextlib.contextmanager
def _executor(settings, cases: int):
    """The scan's executor (``scan.executor``, ``scan.workers``, ``scan.dask_address``,
    ``scan.jobqueue``) when there are several (radius, load) cases to run as jobs; else None
    (in-process, with per-step progress)."""
    if cases < 2:
        yield None
        return
    from flatcontact.ispes.executors import make_executor

    options = settings.scan.executor_options()
    if options["kind"] == "processes" and options["workers"] is None:
        options["workers"] = min(cases, _default_workers())
    with renamed_errors({"workers": "scan.workers", "dask-address": "scan.dask_address"}):
        executor = make_executor(**options)
    try:
        # inline (one worker): the in-process loop, with its per-step progress
        yield None if executor.inline else executor
    finally:
        executor.close()


def _default_workers() -> int:
    from flatcontact.ispes.executors import default_workers

    return default_workers()


def radius_settings(settings, radius_angstrom: float):
    """``settings`` with ``asperity.radius_angstrom`` replaced, within the field's bounds."""
    from pydantic import ValidationError

    from flatcontact.config.asperity import AsperityConfig

    try:
        section = AsperityConfig.model_validate(
            {**settings.asperity.model_dump(), "radius_angstrom": radius_angstrom}
        )
    except ValidationError:
        raise InputError(
            f"--radii: {radius_angstrom!r}: expected radii in Å, 5 <= R <= 100000"
        ) from None
    return settings.model_copy(update={"asperity": section})


def radius_folder(folder: Path, radius_angstrom: float) -> Path:
    """Where one radius of :func:`run_asperity_radii` writes: ``folder/R<radius in Å>``."""
    return folder / f"R{radius_angstrom:g}"


def run_asperity_radii(
    settings, inputs: AsperityInputs, folder: Path, radii, progress=None
) -> list[AsperityResult]:
    """One asperity per radius (``folder/R<r>``, each as :func:`asperity_stage` writes it),
    every (radius, load) case a job on the scan's executor, all in flight at once; each
    radius then reads its states and measures. Every radius's saved states are checked
    against its settings before any job starts."""
    from flatcontact.asperity.experiment import check_state, run_all_cases

    per = [radius_settings(settings, float(r)) for r in radii]
    with renamed_errors(_NAMES):
        specs = [_spec(s, inputs) for s in per]
        for spec in specs:
            check_state(radius_folder(folder, spec.radius_angstrom) / ASPERITY_STATE, spec)
        model = _calculator.model(settings)
        with _executor(settings, sum(len(sp.p0_gpa) for sp in specs)) as executor:
            if executor is not None:
                experiments = [
                    (sp, radius_folder(folder, sp.radius_angstrom) / ASPERITY_STATE) for sp in specs
                ]
                run_all_cases(experiments, settings.structure, model, executor, progress)
    return [
        asperity_stage(s, inputs, radius_folder(folder, sp.radius_angstrom), progress, jobs=False)
        for s, sp in zip(per, specs, strict=True)
    ]


def asperity_stage(
    settings, inputs: AsperityInputs, folder: Path | None, progress=None, jobs: bool = True
) -> AsperityResult:
    """Build, press, slide, measure and compare (:mod:`flatcontact.asperity.experiment`).

    ``folder`` None computes into a temporary state folder (nothing kept). ``jobs``: several
    loads run as jobs on the scan's executor (:func:`_executor`); False runs them in process
    (:func:`run_asperity_radii` has run them already and only reads the states).
    """
    import tempfile

    from flatcontact.asperity.experiment import run_experiment
    from flatcontact.asperity.records import dataset

    with renamed_errors(_NAMES):
        spec = _spec(settings, inputs)
        laws = _laws(settings, inputs)
        model = _calculator.model(settings)
        cases = len(spec.p0_gpa) if jobs else 1
        with tempfile.TemporaryDirectory() as tmp, _executor(settings, cases) as executor:
            state = (folder or Path(tmp)) / ASPERITY_STATE
            exp = run_experiment(
                spec,
                settings.structure,
                model,
                laws,
                state,
                progress=progress,
                mpi_ranks=settings.asperity.mpi_ranks,
                executor=executor,
            )
    spec_sizes = exp.sizes
    depth = (spec_sizes.flat_layers - 1) * float(exp.atoms.info["plane_spacing_angstrom"])
    cell = exp.atoms.cell.array
    period = (
        abs(cell[1, 1]) if spec.geometry == "cylinder" else min(abs(cell[0, 0]), abs(cell[1, 1]))
    )
    loads = []
    for i, comp in enumerate(exp.comparisons):
        loads.append({"target_p0_gpa": spec.p0_gpa[i], **comp})
    unconverged = [
        f"load {i}, step {k}: the relaxation stopped at max_iterations"
        for i, recs in enumerate(exp.records)
        for k, r in enumerate(recs)
        if not r.converged
    ]
    unconverged += [
        f"load {i}: Q still rises at the last step; Q_peak is a lower bound (more steps)"
        for i, comp in enumerate(exp.comparisons)
        if not comp["atoms"]["peak_reached"]
    ]
    unconverged += [
        f"load {i}: a ramp relaxation stopped at max_iterations"
        for i, rp in enumerate(exp.ramps)
        if not rp["converged"]
    ]
    doc = {
        "geometry": spec.geometry,
        "radius_angstrom": spec.radius_angstrom,
        "target_p0_gpa": list(spec.p0_gpa),
        "contact_modulus_gpa": spec.contact_modulus_gpa,
        "potential": _calculator.label(settings),
        "sizes": spec_sizes.to_json(),
        "n_atoms": len(exp.atoms),
        "memory_estimate_bytes": exp.memory_bytes,
        "wall_seconds": exp.wall_seconds,
        "mpi_ranks": settings.asperity.mpi_ranks,
        # the steps' own wall time when they were computed (a resumed run reads them)
        "compute_seconds": _compute_seconds(exp.states),
        "finite_size": {
            "a_over_depth": spec_sizes.hertz_half_width_angstrom / depth,
            "contact_width_over_period": 2 * spec_sizes.hertz_half_width_angstrom / period,
            "note": "Hertz holds for both -> 0; at 0.25 expect errors of a few per cent in a",
        },
        "laws": None if laws is None else laws.__dict__,
        "peak_shear_stress_mpa": [
            {
                "target_p0_gpa": ld["target_p0_gpa"],
                "atoms": ld["atoms"]["peak_shear_stress_mpa"],
                "model_hertz": ld["model_hertz"]["peak_shear_stress_mpa"],
                "model_measured_pressure": ld["model_measured_pressure"]["peak_shear_stress_mpa"],
            }
            for ld in loads
        ],
        "loads": loads,
        "verdict": verdict(spec.geometry, spec.radius_angstrom, loads),
        # per load, the lock-in cycles of asperity.ramp_amplitudes_angstrom (:mod:`..ramp`)
        "ramp": exp.ramps or None,
        "warnings": unconverged,
    }
    result = AsperityResult(doc)
    if folder is not None:
        ds = dataset(
            spec.p0_gpa,
            exp.records,
            exp.binning,
            {"geometry": spec.geometry, "radius_angstrom": spec.radius_angstrom},
        )
        if exp.ramps:
            from flatcontact.asperity.records import ramp_dataset

            ds = ds.merge(ramp_dataset(exp.ramps))
        from flatcontact.foundation.fileio import atomic_path

        with atomic_path(folder / ASPERITY_NC) as tmp_nc:
            ds.to_netcdf(tmp_nc, engine="h5netcdf")
        result.files.append(folder / ASPERITY_NC)
        result.files.append(write_json_atomic(folder / ASPERITY_JSON, doc))
        result.files += _figures(doc, ds, folder, settings.report.svg)
    return result


def _figures(doc: dict, ds, folder: Path, svg: bool) -> list[Path]:
    from flatcontact.plots import asperity as plots

    files = save(plots.fig_slip_map(ds), folder, FIG_ASPERITY_SLIP, svg)
    if doc["loads"]:
        files += save(plots.fig_force_displacement(doc["loads"]), folder, FIG_ASPERITY_FORCE, svg)
        files += save(plots.fig_stick_ratio(doc["loads"]), folder, FIG_ASPERITY_STICK, svg)
        files += save(plots.fig_tractions(doc["loads"][-1]), folder, FIG_ASPERITY_TRACTIONS, svg)
    if doc["ramp"]:
        fig = plots.fig_lockin_ramp(doc["ramp"], doc["target_p0_gpa"])
        files += save(fig, folder, FIG_ASPERITY_RAMP, svg)
    return files
