"""Pre-run checks: everything a run would refuse that needs the run's files or the physics cores.

The settings (:mod:`flatcontact.config`) check values alone; :func:`check_inputs` then reads
what they name (the interface file, the measured CSVs, the calculator's module), builds the
recipe's interface as the build stage does but without its relaxation (milliseconds: the
relaxation is the build's only expensive part), sets the model up for it (for LAMMPS: the
``pair_style``/``pair_coeff`` commands, files read and element map checked), computes one
energy and forces of it (a calculator that raises, as ASE's EMT does for Si, or returns NaN
is refused here, not in the build's relaxation) and asks the stages' own checks (the
contact moduli's material, the elastic crystal), so ``flatcontact config --check`` and
:class:`flatcontact.pipeline.Pipeline` refuse a run before its first stage, with one line
naming the field and the file. ``flatcontact scan`` asks :func:`check_scan_interface` for
the interface it is given, ``flatcontact build --config`` :func:`check_build_inputs`.
"""

from __future__ import annotations

from pathlib import Path

from flatcontact.analysis.analyze import MIN_LATERAL_POINTS
from flatcontact.config import RunConfig
from flatcontact.contact.measured import load_stiffness_csv
from flatcontact.foundation import limits
from flatcontact.foundation.errors import InputError
from flatcontact.ispes.executors import check_scheduler_address
from flatcontact.potentials.engines import calculator_factory
from flatcontact.potentials.loader import load_callable
from flatcontact.report.sections.approximant_study import read_approximant_study
from flatcontact.stages import _calculator
from flatcontact.stages.build import structure_elements
from flatcontact.stages.contact import check_fit_settings, check_moduli_source
from flatcontact.stages.elastic import bulk_crystal
from flatcontact.stages.measured_on import check_measured_on
from flatcontact.structures.bulk import alpha_quartz
from flatcontact.structures.construct import build_interface
from flatcontact.structures.interface_io import read_interface
from flatcontact.structures.recipe import FileRecipe, QuartzDenseRecipe, ToyRecipe
from flatcontact.structures.structure_file import read_structure


def check_inputs(cfg: RunConfig, source: str = "config") -> None:
    """Every check of ``cfg`` that needs its files or imports, before any stage runs.

    ``flatcontact config --check`` and :class:`flatcontact.pipeline.Pipeline` both call it,
    so the check refuses what a run would refuse before its first stage: an interface file
    that does not follow the contract (or has more atoms than the ``atoms`` bound), a
    recipe the builder refuses, a model that cannot compute the built interface or whose
    LAMMPS setup fails on it, a measured stiffness CSV that does not parse, a calculator
    that does not import, a model that cannot compute the elastic stage's crystal, a lateral
    grid the analysis cannot interpolate (fewer than 3 points per axis: refused here, not
    after the scan).

    Raises
    ------
    InputError
        One line naming ``source``'s field and the file.
    """
    if min(cfg.scan.grid) < MIN_LATERAL_POINTS:
        n_a, n_b = cfg.scan.grid
        raise InputError(
            f"{source}: scan.grid: {n_a}×{n_b} lateral points; the analysis (periodic "
            f"interpolation, sliding path) needs at least {MIN_LATERAL_POINTS} per axis"
        )
    if cfg.structure.kind in ("file", "slab") and getattr(cfg.structure, "file", None) is not None:
        _check_structure_file(cfg, source)
    if cfg.contact.experiment.csv is not None:
        try:
            load_stiffness_csv(cfg.contact.experiment.csv)
        except InputError as exc:
            raise InputError(f"{source}: contact.experiment.csv: {exc}") from None
    if cfg.contact.fit.csv:
        check_fit_settings(cfg)
    if cfg.report.approximant_study is not None:
        read_approximant_study(cfg.report.approximant_study, f"{source}: report.approximant_study")
    check_scan_settings(cfg, source)
    _check_structure(cfg, source)
    check_measured_on(cfg, source)
    check_moduli_source(cfg, structure_elements(cfg.structure))
    if cfg.asperity.enabled:
        check_asperity(cfg, source)
    if cfg.elastic.enabled:
        bulk, _ = bulk_crystal(cfg.structure)
        if bulk is None:
            _calculator.check(cfg)
        else:
            _calculator.check_atoms(cfg, bulk)


def check_build_inputs(cfg: RunConfig, source: str = "config") -> None:
    """The checks of :func:`check_inputs` that concern the build stage alone: the structure
    file (readable, within the ``atoms`` bound, an interface for ``kind: file``) and the
    model on the recipe's interface, built unrelaxed (set up, one energy and forces), so
    ``flatcontact build --config CONFIG`` refuses them in the line ``flatcontact run CONFIG``
    and ``config --check CONFIG`` give, before the build writes anything.

    Raises
    ------
    InputError
        One line ``<source>: <settings path>: ...``; for a calculator that cannot evaluate
        the interface ``<source>: potential.calculator.target: <target> cannot evaluate the
        elements Si, O of this interface's alpha-quartz (<exception type>: <first line>)``;
        a per-slab model with nothing across the interface (:func:`check_coupling`).
    """
    check_coupling(cfg, source)
    if cfg.structure.kind in ("file", "slab") and getattr(cfg.structure, "file", None) is not None:
        _check_structure_file(cfg, source)
    _check_structure(cfg, source)


def check_scan_settings(cfg: RunConfig, source: str = "config") -> None:
    """The checks of :func:`check_inputs` that concern the scan alone (the optimiser against
    the model and the relaxation mode, the calculator's import, the Dask address), so
    ``flatcontact scan CONFIG`` refuses them in the same line as ``flatcontact run CONFIG``
    and ``flatcontact config --check CONFIG``. The analysis's minimum lateral grid is not
    one of them: a scan alone may be coarser.

    Raises
    ------
    InputError
        One line ``<source>: <settings path>: <what was expected>``; a per-slab model with
        nothing across the interface (:func:`check_coupling`).
    """
    check_coupling(cfg, source)
    calc = cfg.potential.calculator
    if calc is not None and cfg.scan.optimizer == "lammps-cg":
        raise InputError(
            f"{source}: scan.optimizer: 'lammps-cg' is LAMMPS's own minimiser and needs a "
            f"LAMMPS interaction model, not the ASE calculator {calc.target!r}; use LBFGS-scaled (the default)"
        )
    if cfg.scan.optimizer == "lammps-cg" and cfg.scan.relax_mode == "rigid-layers":
        raise InputError(
            f"{source}: scan.optimizer: 'lammps-cg' relaxes atoms (relax_mode full or normal), "
            "not rigid layers; use LBFGS-scaled (the default)"
        )
    if calc is not None:
        try:
            calculator_factory(cfg.potential)
            load_callable(calc.target)
        except InputError as exc:
            raise InputError(f"{source}: potential.calculator.target: {exc}") from None
    if cfg.scan.dask_address is not None:
        check_scheduler_address(cfg.scan.dask_address, field=f"{source}: scan.dask_address")


def check_coupling(cfg: RunConfig, source: str = "config") -> None:
    """Refuse a model under which the two slabs do not interact: a per-slab model (LAMMPS
    styles per slab or layer, an ASE calculator per slab) with ``coupling: none``. Every
    stacking would have the same energy and no load between the slabs, a flat ISPES with
    τ = 0 for no physical reason of the interface; an ASE calculator over the whole interface
    (``coupling: none`` there only says it sees both slabs) passes
    (:meth:`~flatcontact.potentials.model.InteractionModel.check_couples_slabs`).

    Raises
    ------
    InputError
        One line ``<source>: potential.coupling: 'none' with the per-slab model <name>: ...;
        expected lj, same or interlayer, or an ASE calculator over the whole interface``.
    """
    cfg.potential.check_couples_slabs(f"{source}: potential.coupling")


def check_asperity(cfg: RunConfig, source: str = "config") -> None:
    """The asperity stage drives LAMMPS itself and makes the recipe deeper: it needs a LAMMPS
    interaction model, a recipe with ``layers`` and, over MPI ranks, an ``mpiexec`` (one line
    naming the field)."""
    if cfg.potential.calculator is not None:
        raise InputError(
            f"{source}: asperity.enabled: the asperity relaxes inside LAMMPS and needs a LAMMPS "
            f"interaction model, not the ASE calculator {cfg.potential.calculator.target!r}"
        )
    if not hasattr(cfg.structure, "layers"):
        raise InputError(
            f"{source}: asperity.enabled: structure.kind={cfg.structure.kind} has no layers; the "
            "asperity makes the recipe deeper (fcc111, crystal, slab, sheets, ...)"
        )
    if cfg.asperity.mpi_ranks > 1:
        from flatcontact.asperity.ranks import mpiexec

        try:
            mpiexec()
        except InputError as exc:
            raise InputError(f"{source}: {exc}") from None


def _check_structure_file(cfg: RunConfig, source: str) -> None:
    """structure.file: readable, within the ``atoms`` bound, and (kind file) an interface."""
    file = Path(cfg.structure.file)
    field = f"{source}: structure.file"
    try:
        with file.open("rb") as handle:
            handle.read(1)
    except OSError as exc:
        raise InputError(f"{field}: {file}: cannot read ({exc.strerror})") from None
    if cfg.structure.kind == "file":
        try:
            atoms = read_interface(file)
        except InputError as exc:
            raise InputError(f"{field}: {exc}") from None
        except Exception as exc:  # ASE readers raise anything on garbage
            raise InputError(
                f"{field}: {file}: not a readable interface.extxyz ({type(exc).__name__})"
            ) from None
        n = len(atoms)
    else:
        n = len(read_structure(file, field))
    if n > limits.bound("atoms"):
        raise InputError(f"{field}: {limits.message('atoms', n, f'atoms in {file.name}')}")


def check_scan_interface(cfg: RunConfig, interface: str | Path, source: str = "config"):
    """The interface ``flatcontact scan`` would scan: read (the interface contract), the
    model's elements, and one energy and forces with the model's calculator, before the
    scan writes anything. Returns the interface.

    Raises
    ------
    InputError
        The interface file's refusal, or one line
        ``<source>: potential.calculator.target: <target> cannot evaluate the elements Si, O
        of <interface> (<exception type>: <first line>)``; a per-slab model with nothing
        across the interface (:func:`check_coupling`).
    """
    check_coupling(cfg, source)
    atoms = read_interface(interface)
    try:
        _calculator.check_evaluation(cfg, atoms)
    except InputError as exc:
        raise _calculator.evaluation_refusal(cfg, exc, source, str(interface)) from None
    return atoms


def _check_structure(cfg: RunConfig, source: str) -> None:
    """The recipe's interface, built unrelaxed, the model set up for it and one energy and
    forces computed on it (one line)."""
    recipe = cfg.structure
    what = "this interface"
    if isinstance(recipe, QuartzDenseRecipe):  # its builder relaxes; the material is fixed
        atoms = alpha_quartz()
        what = "this interface's alpha-quartz"
    elif isinstance(recipe, FileRecipe):
        atoms = read_interface(recipe.file)
    else:
        if isinstance(recipe, ToyRecipe) and not recipe.params:  # as the build stage does
            recipe = recipe.model_copy(update={"params": _calculator.toy_kwargs(cfg)})
        try:
            atoms, _ = build_interface(recipe)
        except InputError as exc:
            raise InputError(f"{source}: {exc}") from None
    try:
        _calculator.check_evaluation(cfg, atoms)
    except InputError as exc:
        raise _calculator.evaluation_refusal(cfg, exc, source, what) from None
