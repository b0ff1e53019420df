"""Active-learning probes: configurations the current SNAP visits where it matters.

A fitted SNAP is run through the same kinds of calculation that validation (and the
ISPES scan) will run: zero-stress and high-pressure relaxations of alpha-quartz,
ion relaxations under small strains, relaxation and 300 K MD of the dense (0001)
slab (1x1, and 2x2 for 1.5 ps), and 1 ps of 600 K MD of bulk quartz (2x2x2). Frames along those trajectories are labelled by the teacher and added
to the training set (``config_type = "active"``), so the next fit is corrected
exactly where the previous one wandered (e.g. towards a beta-quartz-like cell).
"""

from __future__ import annotations

import numpy as np
from ase import Atoms, units
from ase.filters import FrechetCellFilter
from ase.md.langevin import Langevin
from ase.md.velocitydistribution import MaxwellBoltzmannDistribution
from ase.neighborlist import neighbor_list
from ase.optimize import FIRE

#: Frames with two atoms closer than this (Å) are dropped (the potential blew up).
MIN_PROBE_DISTANCE_ANGSTROM = 1.1


def _bare(a: Atoms) -> Atoms:
    return Atoms(a.get_chemical_symbols(), positions=a.positions, cell=a.cell, pbc=True)


def _trajectory(
    atoms: Atoms, calc, steps: int, every: int, pressure_gpa=None, fmax=0.005
) -> list[Atoms]:
    a = atoms.copy()
    a.calc = calc
    obj = (
        a
        if pressure_gpa is None
        else FrechetCellFilter(a, scalar_pressure=pressure_gpa * units.GPa)
    )
    frames = []
    try:
        for k, _ in enumerate(FIRE(obj, logfile=None).irun(fmax=fmax, steps=steps)):
            if k % every == 0 and k > 0:
                frames.append(_bare(a))
    except Exception:  # a blown-up potential (LAMMPS lost atoms, NaN): keep what we have
        pass
    frames.append(_bare(a))
    return frames


def _md_until_blowup(
    atoms: Atoms, calc, temperature_k: float, steps: int, every: int, rng
) -> list[Atoms]:
    """Langevin MD snapshots every ``every`` steps, stopping when two atoms come closer
    than :data:`MIN_PROBE_DISTANCE_ANGSTROM` (the frames before a collapse are the
    informative ones)."""
    md = atoms.copy()
    md.calc = calc
    MaxwellBoltzmannDistribution(md, temperature_K=temperature_k, rng=rng)
    dyn = Langevin(
        md, 1.0 * units.fs, temperature_K=temperature_k, friction=0.02, fixcm=False, rng=rng
    )
    out = []
    try:
        for _ in range(steps // every):
            dyn.run(every)
            if neighbor_list("d", md, MIN_PROBE_DISTANCE_ANGSTROM).size:
                break
            out.append(_bare(md))
    except Exception:  # the potential blew up inside LAMMPS
        pass
    return out


def probe_frames(calc, seed: int, max_frames: int = 100) -> list[Atoms]:
    """Frames from SNAP-driven relaxations and MD (see the module docstring), deduplicated."""
    from flatcontact.training.recipe import alpha_quartz, dense_slabs, strain_cell
    from flatcontact.training.validate import dense_start_slab

    rng = np.random.default_rng(seed)
    frames: list[Atoms] = []
    q = alpha_quartz()
    frames += _trajectory(q, calc, steps=200, every=8, pressure_gpa=0.0)
    q0 = frames[-1]
    for p in (5.0, 10.0):
        frames += _trajectory(q0, calc, steps=150, every=15, pressure_gpa=p)
    for comp in range(6):
        e = np.zeros(6)
        e[comp] = rng.choice([-0.01, 0.01])
        frames += _trajectory(strain_cell(q0, e), calc, steps=100, every=50)[-1:]
    a_l, _, c_l, *_ = q0.cell.cellpar()
    if not (np.isfinite(a_l) and 3.5 < a_l < 6.5 and 3.5 < c_l < 7.5):
        a_l, c_l = 4.916, 5.405
    try:
        slab = dense_start_slab(a_l, c_l)
    except Exception:
        from flatcontact.training.lammps_bulk import vashishta_calculator

        slab = dense_slabs(vashishta_calculator(), max_distinct=1)[0]
    traj = _trajectory(slab, calc, steps=300, every=30, fmax=0.01)
    frames += traj
    md = traj[-1].copy()
    md.calc = calc
    MaxwellBoltzmannDistribution(md, temperature_K=300.0, rng=rng)
    dyn = Langevin(md, 1.0 * units.fs, temperature_K=300.0, friction=0.02, fixcm=False, rng=rng)
    try:
        for _ in range(5):
            dyn.run(60)
            frames.append(_bare(md))
    except Exception:
        pass
    frames += _md_until_blowup(traj[-1].repeat((2, 2, 1)), calc, 300.0, 1500, 100, rng)
    frames += _md_until_blowup(q0.repeat((2, 2, 2)), calc, 600.0, 1000, 100, rng)
    good = [
        f
        for f in frames
        if np.isfinite(f.positions).all()
        and neighbor_list("d", f, MIN_PROBE_DISTANCE_ANGSTROM).size == 0
    ]
    if len(good) > max_frames:
        idx = np.sort(rng.choice(len(good), max_frames, replace=False))
        good = [good[i] for i in idx]
    for f in good:
        f.info["config_type"] = "active"
    return good
