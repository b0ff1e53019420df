"""Press and slide the asperity quasi-statically inside LAMMPS, one saved state per step.

Protocol (per target normal load, independent of the other loads)
------------------------------------------------------------------
1. **press**: the flat's rigid block is fixed (``fix setforce 0 0 0``); the tip's rigid block
   is held laterally (``fix setforce 0 0 NULL``) and pushed down with the target normal force
   shared equally by its atoms (``fix aveforce NULL NULL f``: every atom of the block gets the
   block's mean force plus f, so the block moves as one along z); everything relaxes with
   LAMMPS's ``minimize`` (``min_style fire``, ``min_modify norm max``: every force component
   below ``fmax``); the tip block finds its height under the load.
2. **slide**: the tip block is displaced by ``step`` along y (across the cylinder's axis) and
   everything relaxes again under the same normal force; repeated ``steps`` times.

The force loop is LAMMPS's own (its minimiser, neighbour lists and fixes); Python only
writes the positions in and reads them out between relaxations.

Resumable: each relaxation starts a fresh LAMMPS instance from the positions saved after the
previous one (``state/load_<i>/step_<k>.npz``, written atomically), so a run killed anywhere
and rerun reads the last saved step and continues with exactly the floating-point state an
uninterrupted run has (atom order fixed, ``atom_modify sort 0 0.0``).

Per step (:mod:`.binning`): the lateral force Q and normal force on the tip block (LAMMPS's
``fix setforce`` vector: the block's total force before the fix zeroes it), the per-atom
force the tip exerts on the flat (the force on each free flat atom with the tip removed, with
the sign reversed: at equilibrium the full force on a free atom is zero), and the positions
(for the slip field). Forces eV/Å, lengths Å.
"""

from __future__ import annotations

import ctypes
import dataclasses
import os
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from ase import Atoms

from flatcontact.foundation.errors import InputError
from flatcontact.potentials.lammps_box import create_box
from flatcontact.potentials.lammps_runtime import new_lammps
from flatcontact.potentials.lammps_setup import compile_setup

#: eV/Å -> N
EV_PER_ANGSTROM_N = 1.602176634e-9


@dataclass(frozen=True)
class Protocol:
    """How one load is pressed and slid (forces eV/Å, lengths Å).

    Attributes
    ----------
    normal_force_ev_per_angstrom : the target normal force on the tip block (> 0 pushes down)
    step_angstrom, steps : the lateral displacement per step and the number of steps
    fmax_ev_per_angstrom : relaxation tolerance (max force component)
    max_iterations : FIRE iterations per relaxation (a relaxation that reaches it is recorded
        as not converged)
    normal_tolerance : largest relative error of the normal force. LAMMPS's tolerance is per
        atom, and the tip block's atoms share its residual (``aveforce``: each carries 1/N of
        it), so the minimiser's tolerance is min(fmax, normal_tolerance · F / N_block)
    """

    normal_force_ev_per_angstrom: float
    step_angstrom: float
    steps: int
    fmax_ev_per_angstrom: float = 1e-3
    max_iterations: int = 20000
    normal_tolerance: float = 0.01


@dataclass(frozen=True)
class StepState:
    """One relaxed state: positions (Å, unwrapped), tip block force (eV/Å, 3), the force the
    tip exerts on each atom (eV/Å, n×3; zero on tip atoms), the tip's lateral displacement
    (Å), FIRE iterations, whether it converged (largest force component on a free atom, the
    residual, <= fmax), that residual, the wall seconds the step took when computed and the
    MPI ranks it was relaxed on."""

    positions: np.ndarray
    tip_force: np.ndarray
    cross_force: np.ndarray
    displacement_angstrom: float
    iterations: int
    converged: bool
    residual_ev_per_angstrom: float = float("nan")
    seconds: float = float("nan")
    ranks: int = 1


def _lammps_for(model, atoms: Atoms, positions: np.ndarray):
    """A fresh LAMMPS instance with ``atoms`` at ``positions`` (the model's pair commands)."""
    setup = compile_setup(model, atoms)
    lmp = new_lammps()
    box = create_box(
        lmp,
        atoms.cell.array,
        atoms.pbc,
        setup.types,
        setup.type_elements,
        atom_style=setup.atom_style,
        molecules=setup.molecules,
        charges=setup.charges,
    )
    # created at the origin (inside the shrink-wrapped z range), then placed: the next run's
    # setup wraps x, y and shrink-wraps z around them (as the engine does)
    x = box.to_lammps(positions)
    n = len(atoms)
    lmp.scatter_atoms("x", 1, 3, (ctypes.c_double * (3 * n))(*x.ravel().tolist()))
    if lmp.extract_setting("world_size") > 1:
        # over MPI ranks (flatcontact.asperity.ranks) the rank owning the origin holds every
        # atom: hand each to the rank of its position (LAMMPS's irregular migration; a run's
        # setup only passes atoms to adjacent ranks, which loses them beyond two per axis)
        lmp.command("displace_atoms all move 0 0 0 units box")
    lmp.commands_list(list(setup.commands))
    lmp.commands_list(
        [
            "atom_modify sort 0 0.0",
            "neighbor 1.0 bin",
            "neigh_modify every 1 delay 0 check yes",
            "thermo_style custom step pe fnorm",
        ]
    )
    return lmp


def group_commands(block: np.ndarray) -> list[str]:
    """``group flatblock`` / ``group tipblock`` by atom id (1-based), runs of consecutive ids
    as LAMMPS ranges ``a:b`` (LAMMPS tests every atom against every argument, so a list of
    single ids costs n_block · n)."""
    out = []
    for name, value in (("flatblock", 1), ("tipblock", 2)):
        ids = np.flatnonzero(np.asarray(block) == value) + 1
        breaks = np.flatnonzero(np.diff(ids) != 1)
        starts = np.concatenate([ids[:1], ids[breaks + 1]])
        stops = np.concatenate([ids[breaks], ids[-1:]])
        runs = [f"{a}:{b}" if b > a else f"{a}" for a, b in zip(starts, stops, strict=True)]
        out.append(f"group {name} id " + " ".join(runs))
    return out


def _unwrapped(lmp, n: int, cell: np.ndarray) -> np.ndarray:
    """Positions ordered by atom id, unwrapped by the image flags (slab cell: a1 along x)."""
    x = np.ctypeslib.as_array(lmp.gather_atoms("x", 1, 3)).reshape(n, 3).copy()
    img = np.ctypeslib.as_array(lmp.gather_atoms("image", 0, 1)).astype(np.int64)
    # LAMMPS packs image flags as 10 bits per axis (IMGBITS), offset IMGMAX = 512
    ix = (img & 1023) - 512
    iy = ((img >> 10) & 1023) - 512
    return x + ix[:, None] * cell[0] + iy[:, None] * cell[1]


def _forces(lmp, n: int) -> np.ndarray:
    return np.ctypeslib.as_array(lmp.gather_atoms("f", 1, 3)).reshape(n, 3).copy()


def relax(model, atoms: Atoms, positions: np.ndarray, protocol: Protocol) -> StepState:
    """Relax ``atoms`` at ``positions`` under the protocol's normal force (module docstring)."""
    block = np.asarray(atoms.arrays["block"])
    slab = np.asarray(atoms.arrays["slab"])
    n = len(atoms)
    n_tip = int(np.sum(block == 2))
    lmp = _lammps_for(model, atoms, positions)
    try:
        lmp.commands_list(group_commands(block))
        per_atom = -protocol.normal_force_ev_per_angstrom / n_tip
        ftol = min(
            protocol.fmax_ev_per_angstrom,
            protocol.normal_tolerance * abs(protocol.normal_force_ev_per_angstrom) / n_tip,
        )
        lmp.commands_list(
            [
                "fix hold flatblock setforce 0.0 0.0 0.0",
                "fix tiplat tipblock setforce 0.0 0.0 NULL",
                f"fix press tipblock aveforce NULL NULL {per_atom:.17g}",
                "min_style fire",
                "min_modify norm max",
                f"minimize 0.0 {ftol:.17g} "
                f"{protocol.max_iterations} {10 * protocol.max_iterations}",
            ]
        )
        iterations = int(lmp.extract_global("ntimestep"))
        tip_force = np.array([lmp.extract_fix("tiplat", 0, 1, i) for i in range(3)])
        new = _unwrapped(lmp, n, atoms.cell.array)
        # the largest force component on a free atom after the minimiser (the fixes have
        # zeroed the held ones and equalised the tip block's)
        forces = _forces(lmp, n)
    finally:
        lmp.close()
    # LAMMPS's copy starts wrapped into the box: bring each atom back to the image nearest
    # to where it started, so states are continuous with the built atoms (a relaxation moves
    # atoms by far less than half a period)
    cell2 = atoms.cell.array[:2, :2]
    shift = np.linalg.solve(cell2.T, (new - positions)[:, :2].T).T
    new[:, :2] -= np.round(shift) @ cell2
    free = block == 0
    residual = float(np.max(np.abs(forces[free]))) if np.any(free) else 0.0
    converged = residual <= protocol.fmax_ev_per_angstrom * (1 + 1e-9)
    cross = np.zeros((n, 3))
    flat = slab == 1
    alone = atoms[flat]
    lmp = _lammps_for(model, alone, new[flat])
    try:
        lmp.command("run 0")
        cross[flat] = -_forces(lmp, int(flat.sum()))
    finally:
        lmp.close()
    cross[block == 1] = 0.0  # held atoms: their full force is not zero
    return StepState(new, tip_force, cross, 0.0, iterations, converged, residual)


def save_state(path: Path, state: StepState) -> None:
    """Write a step atomically (a temporary file renamed over ``path``)."""
    tmp = path.with_suffix(".tmp.npz")
    np.savez(
        tmp,
        positions=state.positions,
        tip_force=state.tip_force,
        cross_force=state.cross_force,
        displacement_angstrom=state.displacement_angstrom,
        iterations=state.iterations,
        converged=state.converged,
        residual_ev_per_angstrom=state.residual_ev_per_angstrom,
        seconds=state.seconds,
        ranks=state.ranks,
    )
    os.replace(tmp, path)


def load_state(path: Path) -> StepState:
    """A saved step (``step_<k>.npz``)."""
    with np.load(path) as f:
        return StepState(
            f["positions"],
            f["tip_force"],
            f["cross_force"],
            float(f["displacement_angstrom"]),
            int(f["iterations"]),
            bool(f["converged"]),
            float(f["residual_ev_per_angstrom"]),
            float(f["seconds"]) if "seconds" in f else float("nan"),
            int(f["ranks"]) if "ranks" in f else 1,
        )


def step_path(folder: Path, k: int) -> Path:
    """Where step k's state is saved (0 = pressed)."""
    return folder / f"step_{k:04d}.npz"


def compute_step(
    model, atoms: Atoms, positions: np.ndarray, protocol: Protocol, k: int, ranks: int = 1
) -> StepState:
    """Step k from the previous step's ``positions``: the tip block moved by ``step_angstrom``
    along y (k > 0), relaxed; its wall seconds and the MPI ranks it ran on recorded."""
    t0 = time.perf_counter()
    start = positions.copy()
    if k:
        start[np.asarray(atoms.arrays["block"]) == 2, 1] += protocol.step_angstrom
    state = relax(model, atoms, start, protocol)
    return dataclasses.replace(
        state,
        displacement_angstrom=k * protocol.step_angstrom,
        seconds=time.perf_counter() - t0,
        ranks=ranks,
    )


def run_load(
    model,
    atoms: Atoms,
    protocol: Protocol,
    folder: Path,
    progress: Callable[[int, int, float], None] | None = None,
    ranks: int = 1,
) -> list[StepState]:
    """Press and slide one load; step k's state in ``folder/step_<k>.npz`` (0 = pressed).

    Steps already saved are read, not recomputed (resume). ``progress(done, total, seconds)``
    after each step. ``ranks`` > 1 relaxes the missing steps over that many MPI ranks
    (:mod:`flatcontact.asperity.ranks`: the same relaxations, one ``mpiexec`` per call).
    """
    if protocol.steps < 1 or not protocol.step_angstrom > 0:
        raise InputError("asperity: give steps >= 1 and step_angstrom > 0")
    folder.mkdir(parents=True, exist_ok=True)
    total = protocol.steps + 1
    if ranks > 1:
        first = next((k for k in range(total) if not step_path(folder, k).exists()), total)
        if first < total:
            from flatcontact.asperity.ranks import run_steps

            start = load_state(step_path(folder, first - 1)).positions if first else None
            run_steps(model, atoms, protocol, folder, first, start, ranks, progress)
    states: list[StepState] = []
    positions = atoms.positions.copy()
    for k in range(total):
        path = step_path(folder, k)
        if path.exists():
            state = load_state(path)
        else:
            state = compute_step(model, atoms, positions, protocol, k)
            save_state(path, state)
            if progress is not None:
                progress(k + 1, total, state.seconds)
        states.append(state)
        positions = state.positions
    return states
