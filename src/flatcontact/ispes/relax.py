"""One ISPES grid point: place slab 2, relax the free atoms, measure energy and load.

At a point (shift_a, shift_b, z) slab 2 of the reference interface is placed by
``place_slab2``; every atom except the held outer layers (``arrays["held"]``, by default
surfaces 1 and 4) is relaxed until the largest force on a free atom is below ``fmax``
(paper, "Interfacial sliding potential energy surface": "the atoms in the surfaces 1 and 4
are held fixed ... those on surface 2, 3 and the inner atomic layers are fully
relaxed").

Held layers
-----------
A held layer is a rigid body whose lateral shift and height are imposed (slab 1's at the
reference, slab 2's at (shift_a, shift_b, z)); an infinite periodic layer cannot rotate,
so the rigid body is fully fixed by these three translations and every one of its atoms
keeps its reference position relative to the layer. Held layers are always held whole
(``validate_interface`` refuses a partly held layer), so stackings related by a symmetry
of the two slabs stay equivalent to round-off.

Relaxation modes (:attr:`RelaxSettings.mode`)
---------------------------------------------
``full`` (default, the paper's)
    The free atoms relax in 3D.
``normal``
    The free atoms relax along z only; their lateral positions are those of the rigidly
    placed reference (the generalized-stacking-fault convention: Vitek, Phil. Mag. 18,
    773 (1968)).
``rigid-layers``
    Every layer keeps its reference shape and lateral position; each non-held layer
    (``arrays["layer"]``) is a rigid body that moves along z only, until the mean z-force
    per atom of every free layer, |Σ_layer F_z|/n_layer, is below ``fmax`` (interlayer
    spacings relax, nothing inside a layer does).
``rigid``
    Nothing relaxes: both slabs keep the reference geometry (every layer its shape and
    its spacing), slab 2 is translated rigidly to the grid point, and U and p are those
    of that configuration (the rigid-layer scans of interlayer-potential papers). The
    point is reported converged with zero optimiser steps; ``max_force_ev_per_a`` is the
    largest force on a non-held atom, for information.
The modes are nested minimisations: U_full ≤ U_normal ≤ U_rigid-layers ≤ U_rigid.
An interface whose atoms are all held (a bilayer of monolayers) has nothing to relax:
every mode gives the rigid scan.

Normal load
-----------
p = (1/A) Σ_{i ∈ slab 2} F_z,i, in GPa (``units.EV_PER_A3_TO_GPA``): the net z-force on
slab 2 as a rigid body, i.e. the force slab 1 exerts on slab 2 across the interface,
A = |a1 × a2|. Slab 2 lies above slab 1, so a compressed interface pushes slab 2 up:
p > 0 when the slabs are pressed together, p < 0 in adhesive tension.

At an exact force minimum of the free atoms this equals the z-reaction on slab 2's
fixed (surface-4) atoms per area, (1/A) Σ_{i ∈ slab 2, fixed} F_z,i, which is the
paper's definition and is also recorded (``reaction_stress_gpa``), and both equal
-(1/A) dU/dz (envelope theorem; the tests check it along a column). At a finite
tolerance they differ: the reaction absorbs the residual forces of all free atoms of
slab 2 (error up to N_free·fmax/A through the stiff intra-slab bonds), while the
rigid-body force is insensitive to them to first order because the intra-slab
energy is translation invariant, leaving only the soft cross-interface coupling. At
separation the reaction estimate keeps a spurious residual, the rigid-body one is
zero. Their difference is stored as a convergence diagnostic.
"""

from __future__ import annotations

import dataclasses
import threading
import time
from collections.abc import Callable
from typing import Any, Literal

import numpy as np
from ase import Atoms

from flatcontact.foundation.errors import InputError
from flatcontact.foundation.units import EV_PER_A3_TO_GPA
from flatcontact.ispes import precondition
from flatcontact.ispes.calculators import count_force_calls
from flatcontact.ispes.contract import cell_area
from flatcontact.ispes.geometry import (
    extrapolated_positions,
    fixed_mask,
    in_plane_vectors,
    place_slab2,
    warm_start_positions,
)
from flatcontact.ispes.lbfgs import ASE_ALPHA_EV_PER_A2, largest_atomic_norm, lbfgs_relax
from flatcontact.ispes.precondition import slips_inside_slab
from flatcontact.ispes.scan_context import ScanContext
from flatcontact.potentials.guarded import failing_at

Optimizer = Literal["LBFGS-scaled", "LBFGS", "FIRE", "FIRE2", "BFGS", "BFGSLineSearch", "lammps-cg"]
OPTIMIZERS: tuple[str, ...] = (
    "LBFGS-scaled",
    "LBFGS",
    "FIRE",
    "FIRE2",
    "BFGS",
    "BFGSLineSearch",
    "lammps-cg",
)
#: The built-in L-BFGS (:mod:`flatcontact.ispes.lbfgs`) under its two names: ``LBFGS`` takes
#: ASE's steps (H0 = I/70 eV/Å² at every step), ``LBFGS-scaled`` rescales H0 at every step
#: (Nocedal & Wright eq. 7.20; the scan's default: fewer force calls, measured in
#: ``docs/performance.md``, "Fewer force calls per point").
BUILT_IN_LBFGS: dict[str, bool] = {"LBFGS": False, "LBFGS-scaled": True}
RelaxMode = Literal["full", "normal", "rigid-layers", "rigid"]
RELAX_MODES: tuple[str, ...] = ("full", "normal", "rigid-layers", "rigid")

Index = tuple[int, int, int]


@dataclasses.dataclass(frozen=True)
class RelaxSettings:
    """How each point is relaxed.

    Attributes
    ----------
    fmax_ev_per_angstrom
        Convergence when max |F| over the free atoms < fmax (eV/Å).
    optimizer
        ``LBFGS-scaled`` (the default: the built-in L-BFGS with the textbook rescaled initial
        inverse Hessian, :mod:`flatcontact.ispes.lbfgs`, "Initial Hessian scaling"),
        ``LBFGS`` (the built-in with ASE's steps, iterates equal to ASE's ``LBFGS``),
        another ASE optimiser name, or ``lammps-cg``: LAMMPS's own ``minimize``
        (``min_style cg``, the same max-norm tolerance; LAMMPS models, modes ``full`` and
        ``normal`` only). On large cells of cheap potentials it takes fewer force calls
        than L-BFGS (measured in ``docs/performance.md``); its iterates are not ASE's.
    max_steps
        Optimiser step cap; a point that hits it is stored with ``converged=False``.
    mode
        ``full`` (free atoms relax in 3D), ``normal`` (along z only), ``rigid-layers``
        (each free layer a rigid body moving along z) or ``rigid`` (no relaxation); see the
        module docstring.
    precondition
        The built-in L-BFGS starts every point with the reference interface's inverse
        Hessian as H0, kept at every step (:mod:`flatcontact.ispes.precondition`: 2 force
        calls per relaxed coordinate, once per scan in its driver, in no point's calls),
        where it applies (:attr:`uses_reference_hessian`: ``LBFGS-scaled`` and ``LBFGS``,
        modes ``full`` and ``normal``, at most ``precondition.MAX_COORDINATES`` relaxed
        coordinates); elsewhere the optimizer's own H0. Default on. In mode ``full`` a point
        whose preconditioned relaxation slid a plane inside a slab is relaxed again with the
        optimizer's own H0 (:func:`_relax_built_in`; ``docs/performance.md``, "The reference
        interface's Hessian as H0").
    """

    fmax_ev_per_angstrom: float = 0.005
    optimizer: str = "LBFGS-scaled"
    max_steps: int = 2000
    mode: str = "full"
    precondition: bool = True

    def __post_init__(self) -> None:
        if not (np.isfinite(self.fmax_ev_per_angstrom) and self.fmax_ev_per_angstrom > 0):
            raise InputError(
                f"fmax_ev_per_angstrom: expected a positive force tolerance (eV/Å), got {self.fmax_ev_per_angstrom}"
            )
        if self.optimizer not in OPTIMIZERS:
            raise InputError(f"optimizer: '{self.optimizer}' is not one of {', '.join(OPTIMIZERS)}")
        if self.max_steps < 1:
            raise InputError(f"max_steps: expected at least 1 optimiser step, got {self.max_steps}")
        if self.mode not in RELAX_MODES:
            raise InputError(f"mode: '{self.mode}' is not one of {', '.join(RELAX_MODES)}")
        if self.optimizer == "lammps-cg" and self.mode == "rigid-layers":
            raise InputError(
                "optimizer: 'lammps-cg' relaxes atoms (modes full, normal), not rigid layers; "
                "use LBFGS-scaled (the default) with mode rigid-layers"
            )

    @property
    def uses_reference_hessian(self) -> bool:
        """Whether ``precondition`` applies to this optimizer and mode (the cell's size is
        checked per reference: :func:`reference_root`)."""
        return (
            self.precondition
            and self.optimizer in BUILT_IN_LBFGS
            and self.mode in ("full", "normal")
        )

    def as_dict(self) -> dict[str, Any]:
        """The settings for the store fingerprint; ``mode`` only when it is not the default
        ``full`` (a store written before the modes existed stays valid: same numbers). The
        force tolerance is stored under its key of the ``points.db`` contract,
        ``fmax_ev_per_a`` (docs/file-contracts.md), so existing stores resume."""
        out = {
            "fmax_ev_per_a" if k == "fmax_ev_per_angstrom" else k: v
            for k, v in dataclasses.asdict(self).items()
        }
        if self.mode == "full":
            del out["mode"]
        if self.uses_reference_hessian:  # with the slip guard (_relax_point): its iterates
            out["precondition"] = "reference-hessian, slip-guarded"
        else:  # the iterates do not depend on it: one store
            del out["precondition"]
        return out


@dataclasses.dataclass(frozen=True)
class PointTask:
    """A grid point to compute, with an optional warm start from a finished neighbour."""

    index: Index
    shift_a: float
    shift_b: float
    thickness: float
    #: relaxed positions (Å) of a finished neighbour, or None for a cold start
    start_positions: np.ndarray | None = None
    start_shift: tuple[float, float] | None = None
    start_thickness: float | None = None
    start_index: Index | None = None
    #: relaxed positions and thickness of the parent's parent when both lie in the same
    #: column (same shift) as this point: the start is then extrapolated linearly in z
    previous_positions: np.ndarray | None = None
    previous_thickness: float | None = None


@dataclasses.dataclass(frozen=True)
class PointResult:
    """The outcome of one relaxation (units in the names; energy in eV)."""

    index: Index
    shift_a: float
    shift_b: float
    thickness: float
    energy_ev: float
    normal_stress_gpa: float
    reaction_stress_gpa: float
    force_calls: int
    steps: int
    converged: bool
    max_force_ev_per_a: float
    seconds: float
    positions: np.ndarray
    start_index: Index | None
    #: force calls of the reference's Hessian (:func:`reference_root`) computed before this
    #: point by its process (0 in a scan: its driver computed it, :mod:`~flatcontact.ispes.shared_hessian`;
    #: else the process's first preconditioned point): not in ``force_calls``
    hessian_force_calls: int = 0


def normal_stress_gpa(atoms: Atoms, forces: np.ndarray) -> float:
    """Normal load p (GPa, > 0 pressed): net z-force on slab 2 per area.

    p = Σ_{i ∈ slab 2} F_z,i / |a1 × a2| with the unconstrained forces (eV/Å),
    converted with ``EV_PER_A3_TO_GPA``.
    """
    a1, a2 = in_plane_vectors(atoms)
    top = np.asarray(atoms.arrays["slab"]) == 2
    return float(forces[top, 2].sum() / cell_area(a1, a2) * EV_PER_A3_TO_GPA)


def reaction_stress_gpa(atoms: Atoms, forces: np.ndarray, fixed: np.ndarray) -> float:
    """z-reaction on slab 2's fixed atoms per area (GPa, > 0 pressed), the paper's definition.

    Σ_{i ∈ slab 2 ∩ fixed} F_z,i / |a1 × a2|; equals :func:`normal_stress_gpa` at an
    exact force minimum of the free atoms.
    """
    a1, a2 = in_plane_vectors(atoms)
    top = fixed & (np.asarray(atoms.arrays["slab"]) == 2)
    return float(forces[top, 2].sum() / cell_area(a1, a2) * EV_PER_A3_TO_GPA)


def _optimizer_class(name: str):
    # ASE's optimisers (≈0.4 s of scipy imports) only for the other names: kept out of
    # the scan workers that run the built-in L-BFGS
    import ase.optimize

    return getattr(ase.optimize, name)


def relax_point(reference: Atoms, calc, task: PointTask, settings: RelaxSettings) -> PointResult:
    """Relax one grid point with ``calc`` (reused across calls) and measure it
    (:func:`_relax_point`). A user's calculator that fails there
    (:class:`~flatcontact.potentials.guarded.CalculatorFailure`) names the point: ``point at
    shift (0.5, 0), thickness 11.2 Å: calculator '...' failed on ...``."""
    where = (
        f"point at shift ({task.shift_a:.4g}, {task.shift_b:.4g}), thickness {task.thickness:.4g} Å"
    )
    with failing_at(where):
        return _relax_point(reference, calc, task, settings)


def _relax_point(reference: Atoms, calc, task: PointTask, settings: RelaxSettings) -> PointResult:
    """Relax one grid point with ``calc`` (reused across calls) and measure it.

    The structure is ``place_slab2(reference, task.shift_a, task.shift_b,
    task.thickness)`` (compression spread over the stack where a rigid placement would
    overlap, except in ``rigid`` mode); with ``task.start_positions`` the free atoms start from the
    neighbour's relaxed structure translated to this point
    (:func:`~flatcontact.ispes.geometry.warm_start_positions`; in ``normal`` mode only
    their heights are taken from it). Held atoms never move. ``settings.mode`` selects
    full, normal-only or no relaxation (module docstring).
    """
    t0 = time.perf_counter()
    atoms = place_slab2(
        reference,
        task.shift_a,
        task.shift_b,
        task.thickness,
        spread_compression=settings.mode != "rigid",
    )
    fixed = fixed_mask(atoms)
    free = ~fixed
    relaxing = settings.mode != "rigid" and bool(free.any())
    if relaxing and task.start_positions is not None:
        placed = atoms.positions.copy()
        atoms.positions = warm_start_positions(
            atoms,
            task.start_positions,
            task.start_shift,
            (task.shift_a, task.shift_b),
            task.start_thickness,
            task.thickness,
            fixed,
        )
        if task.previous_positions is not None:
            atoms.positions = extrapolated_positions(
                atoms,
                (task.start_thickness, task.start_positions),
                (task.previous_thickness, task.previous_positions),
                task.thickness,
                fixed,
            )
        if settings.mode in ("normal", "rigid-layers"):
            pos = atoms.positions
            pos[:, :2] = placed[:, :2]
            if settings.mode == "rigid-layers":  # keep each layer's shape: its mean z shift only
                for group in free_layer_groups(atoms, free):
                    dz = float(np.mean(pos[group, 2] - placed[group, 2]))
                    pos[group, 2] = placed[group, 2] + dz
            atoms.positions = pos
    fixed_positions = atoms.positions[fixed].copy()
    lateral_positions = atoms.positions[:, :2].copy()
    calc = count_force_calls(calc)
    groups = free_layer_groups(atoms, free) if settings.mode == "rigid-layers" else []
    project = constraint_projector(fixed, settings.mode, groups)
    root, before_hessian = None, calc.force_calls
    if relaxing and settings.uses_reference_hessian:
        root = reference_root(reference, calc, fixed, settings.mode, project)
    calls0 = calc.force_calls
    steps = 0
    if relaxing and settings.optimizer in BUILT_IN_LBFGS:
        outcome = _relax_built_in(reference, calc, atoms, task, settings, project, root)
        atoms.positions = outcome.positions
        energy, forces, steps = outcome.energy_ev, outcome.forces, outcome.steps
    elif relaxing and settings.optimizer == "lammps-cg":
        minimize = getattr(calc, "minimize_positions", None)
        if minimize is None:
            raise InputError(
                "optimizer: 'lammps-cg' needs a LAMMPS interaction model (LAMMPS's own "
                f"minimiser), not {type(calc).__name__}"
            )
        held = project(np.ones_like(atoms.positions)) == 0.0  # the components P removes
        positions, energy, forces, steps, _ = minimize(
            atoms, held, settings.fmax_ev_per_angstrom, settings.max_steps
        )
        atoms.positions = positions
    elif relaxing:
        start_afresh(calc)
        steps = _relax_with_ase(atoms, calc, fixed, free, groups, settings)
        forces = atoms.get_forces(apply_constraint=False)
        energy = float(atoms.get_potential_energy())
        atoms.calc = None
        atoms.set_constraint()
    else:
        energy, forces = point_evaluator(calc, atoms)(atoms.positions)
    # the force the tolerance applies to, in every mode: the largest atomic norm of P(F)
    # (full: free atoms; normal: |F_z| of free atoms; rigid-layers: |mean F_z| per layer)
    max_force = largest_atomic_norm(project(forces))
    if not np.array_equal(atoms.positions[fixed], fixed_positions):  # pragma: no cover - a guard
        raise RuntimeError("held atoms moved during the relaxation")
    if settings.mode in ("normal", "rigid-layers") and not np.array_equal(
        atoms.positions[:, :2], lateral_positions
    ):  # pragma: no cover - a guard
        raise RuntimeError(f"atoms moved laterally in a {settings.mode} relaxation")
    result = PointResult(
        index=tuple(int(i) for i in task.index),
        shift_a=float(task.shift_a),
        shift_b=float(task.shift_b),
        thickness=float(task.thickness),
        energy_ev=energy,
        normal_stress_gpa=normal_stress_gpa(atoms, forces),
        reaction_stress_gpa=reaction_stress_gpa(atoms, forces, fixed),
        force_calls=int(calc.force_calls - calls0),
        hessian_force_calls=int(calls0 - before_hessian),
        steps=steps,
        converged=bool(not relaxing or max_force < settings.fmax_ev_per_angstrom),
        max_force_ev_per_a=max_force,
        seconds=time.perf_counter() - t0,
        positions=atoms.positions.copy(),
        start_index=task.start_index,
    )
    return result


def _relax_built_in(reference: Atoms, calc, atoms: Atoms, task: PointTask, settings, project, root):
    """The built-in L-BFGS from ``atoms.positions`` (:func:`lbfgs_relax`), with the reference's
    H0 where ``root`` is given. In mode ``full`` a preconditioned relaxation that slid a plane
    inside a slab (:func:`flatcontact.ispes.precondition.slips_inside_slab`) is done again
    from the same start with the optimizer's own H0, and that outcome is the point's (both
    relaxations' force calls count): on a soft in-slab mode the reference's curvature, raised
    to its eigenvalue floor, asks for long steps that can carry a plane over a barrier the
    plain iteration never approaches, and a column whose points switch between such
    branches is not a landscape (``docs/performance.md``, "The reference interface's
    Hessian as H0")."""
    outcome = lbfgs_relax(
        point_evaluator(calc, atoms),
        atoms.positions,
        project,
        settings.fmax_ev_per_angstrom,
        settings.max_steps,
        scaled=BUILT_IN_LBFGS[settings.optimizer] and root is None,
        preconditioner=root,
    )
    if root is None or settings.mode != "full":
        return outcome
    if not slips_inside_slab(reference, outcome.positions, (task.shift_a, task.shift_b)):
        return outcome
    return lbfgs_relax(
        point_evaluator(calc, atoms),
        atoms.positions,
        project,
        settings.fmax_ev_per_angstrom,
        settings.max_steps,
        scaled=BUILT_IN_LBFGS[settings.optimizer],
    )


def constraint_projector(fixed: np.ndarray, mode: str, groups: list[np.ndarray]):
    """The linear projector P of a relaxation mode, for forces and steps ((n, 3) arrays).

    ``full``: held atoms zero. ``normal``: held atoms zero and every x, y component zero.
    ``rigid-layers``: every component zero except z on the free layers, where each atom gets
    its layer's mean (the generalised force on the layer's height per atom). These are the
    forces ASE's ``FixAtoms``, ``FixCartesian`` and
    :class:`~flatcontact.ispes.rigid_layers.RigidLayersAlongZ` return, and the
    steps their ``adjust_positions`` allow. ``full`` and ``normal`` also take ``out=``: an
    array whose every component is written (it may be ``v`` itself: :func:`lbfgs_relax`
    projects into the memory's gradient row and the step in place).
    """
    held = np.asarray(fixed, dtype=bool)
    if mode == "rigid-layers":
        members = [np.asarray(g, dtype=int) for g in groups]

        def project(v: np.ndarray) -> np.ndarray:
            out = np.zeros_like(v)
            for g in members:
                out[g, 2] = np.mean(v[g, 2])
            return out

        return project
    # the components kept, as a mask broadcast over (n, 3), and as 1.0 / 0.0 factors
    keep = ~held[:, None]
    if mode == "normal":
        keep = keep & np.array([False, False, True])
    keep = np.broadcast_to(keep, (len(held), 3))
    factor = keep.astype(float)

    def project(v: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        if out is None:
            return np.where(keep, v, 0.0)
        # ``out`` (lbfgs_relax's gradient row, or v itself): v times the 0/1 factors, one vectorised pass (the
        # same numbers as the masked copy, the removed components ±0.0; np.copyto with a
        # broadcast ``where`` mask cost ≈ 50 instructions per component: 0.3 ms per call
        # at 4,704 atoms)
        return np.multiply(v, factor, out=out)

    return project


def reference_root(
    reference: Atoms, calc, fixed, mode: str, project, between_columns: Callable | None = None
) -> np.ndarray | None:
    """L = H0^{1/2} from the Hessian of ``reference`` over the coordinates ``project`` keeps
    (:mod:`flatcontact.ispes.precondition`), kept per calculator and key (reference, mode):
    computed at the first call unless a scan's driver handed its own (:func:`context_calculator`);
    None beyond ``precondition.MAX_COORDINATES`` relaxed coordinates. ``between_columns``:
    :func:`~flatcontact.ispes.precondition.finite_difference_hessian`'s."""
    coordinates = np.flatnonzero(project(np.ones((len(reference), 3))).ravel() != 0.0)
    if coordinates.size > precondition.MAX_COORDINATES:
        return None
    key = precondition.root_key(reference, fixed, mode)

    def compute() -> np.ndarray:
        evaluate = point_evaluator(calc, reference)
        hessian = precondition.finite_difference_hessian(
            evaluate, reference.positions, coordinates, between_columns=between_columns
        )
        return precondition.inverse_hessian_root(
            hessian, coordinates, 3 * len(reference), ASE_ALPHA_EV_PER_A2
        )

    return precondition.cached_root(calc, key, compute)


def start_afresh(calc) -> None:
    """Let ``calc`` forget what it computed before, so that its next evaluations depend on
    their positions alone (:meth:`flatcontact.potentials.calculator.InterfaceCalculator.start_afresh`:
    LAMMPS runs its full setup again). Every point and every single point of the scan starts
    so: a point's numbers do not depend on which worker computed it after which other point,
    and a resumed scan equals an uninterrupted one bit for bit. Any other ASE calculator is
    taken as it is (it keeps no state across structures, or none the scan can reset)."""
    afresh = getattr(calc, "start_afresh", None)
    if afresh is not None:
        afresh()


def point_evaluator(calc, atoms: Atoms):
    """``evaluate(positions) -> (energy_ev, forces)`` of ``atoms`` at new positions.

    Calculators of :mod:`flatcontact.potentials` give their engine directly
    (``calc.position_evaluator``: built once for this structure, started afresh
    (:func:`start_afresh`), one evaluation per call, counted in ``calc.force_calls``); any other ASE calculator is asked through a
    constraint-free copy of ``atoms`` (``calculate`` once per new structure). The forces
    returned are valid until the next call (they may be the engine's own array).
    """
    direct = getattr(calc, "position_evaluator", None)
    if direct is not None:
        return direct(atoms)
    work = atoms.copy()
    work.set_constraint()
    work.calc = calc

    def evaluate(positions: np.ndarray) -> tuple[float, np.ndarray]:
        work.positions = positions
        forces = work.get_forces()
        return float(work.get_potential_energy()), forces

    return evaluate


def _relax_with_ase(atoms, calc, fixed, free, groups, settings: RelaxSettings) -> int:
    """Relax ``atoms`` in place with an ASE optimiser and constraint objects; the steps."""
    # ase.constraints (≈0.4 s of scipy imports, also behind rigid_layers) only on this path
    from ase.constraints import FixAtoms, FixCartesian

    from flatcontact.ispes.rigid_layers import RigidLayersAlongZ

    constraints = [FixAtoms(mask=fixed)]
    if settings.mode == "normal" and free.any():
        constraints.append(FixCartesian(np.flatnonzero(free), mask=(True, True, False)))
    if groups:
        constraints.append(RigidLayersAlongZ(groups))
    atoms.set_constraint(constraints)
    atoms.calc = calc
    opt = _optimizer_class(settings.optimizer)(atoms, logfile=None)
    opt.run(fmax=settings.fmax_ev_per_angstrom, steps=settings.max_steps)
    return int(opt.nsteps)


def free_layer_groups(atoms: Atoms, free: np.ndarray) -> list[np.ndarray]:
    """Indices of the atoms of each non-held layer (``arrays["layer"]``; found from the
    structure if the interface has none)."""
    if "layer" in atoms.arrays:
        layer = np.asarray(atoms.arrays["layer"])
    else:
        # only for an interface without layer ids: keeps scipy.sparse and ase.neighborlist
        # (≈0.2 s of imports) out of the scan workers
        from flatcontact.structures.layers import interface_layers

        layer = interface_layers(atoms)
    return [np.flatnonzero(free & (layer == k)) for k in np.unique(layer[free])]


_local = threading.local()


def worker_calculator(factory, reference: Atoms) -> Any:
    """The calculator of this worker (thread) for ``factory``, built once and reused.

    ``reference`` is the interface the calculator is built for (species, order,
    slab membership); every grid point has the same atoms in the same order.
    """
    cache = _local.__dict__.setdefault("calculators", {})
    key = factory.fingerprint
    if key not in cache:
        cache[key] = count_force_calls(factory(reference))
    return cache[key]


def context_calculator(context: ScanContext) -> Any:
    """:func:`worker_calculator` for ``context``, holding the root of the reference's Hessian the
    scan's driver computed (``context.hessian``, :func:`flatcontact.ispes.precondition.shared_root`)
    for :func:`reference_root`: a scan's process never computes its own."""
    reference, shared = context.reference, context.hessian
    calc = worker_calculator(context.factory, reference)
    if shared is not None:
        key = precondition.root_key(reference, fixed_mask(reference), context.settings.mode)
        precondition.keep_root(calc, key, precondition.shared_root(shared))
    return calc


def run_task(context: ScanContext, task: PointTask) -> PointResult:
    """Worker entry point: relax ``task`` with this worker's cached calculator."""
    return relax_point(context.reference, context_calculator(context), task, context.settings)
