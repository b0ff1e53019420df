"""The ``sio2`` training-set recipe: diverse silica configurations, deterministic in a seed.

Groups (``info["config_type"]``):

``quartz_strain``
    alpha-quartz cells (1x1x1, 2x1x1, 1x1x2) with every strain component drawn
    uniformly in ±4 % and atoms rattled (Gaussian, 0.01-0.05 Å per component).
``quartz_relaxed_strain``
    alpha-quartz under single Voigt strains ±0.5 ... ±4 % (unrelaxed and with ions
    relaxed by the teacher) and under 20 random mixed strains within ±1 % (relaxed):
    these carry the relaxed-ion elastic response.
``quartz_pressure``
    teacher relaxation (cell + ions) of alpha-quartz under hydrostatic
    pressure 0-10 GPa: trajectory frames and the end points.
``polymorph``
    cristobalite, coesite and stishovite (:mod:`.polymorphs`) strained (±3 %),
    rattled, and compressed.
``md``
    snapshots of NVT MD with the Vashishta (1990) potential at 300-1500 K
    (bulk quartz 2x2x2 and stishovite), LAMMPS, 1 fs steps.
``slab``
    (0001) quartz slabs cut at each of the three distinct cleavage planes
    (:mod:`flatcontact.structures.slab`, 6 layers 1x1 and 4 layers 2x1, 10 Å
    vacuum): Vashishta-annealed snapshots (600, 1200 K) and frames of the teacher's
    relaxations (bond-broken, under-coordinated surfaces).
``dense_slab``
    the dense reconstructed (0001) surface (:mod:`flatcontact.structures.dense`
    seeds, Vashishta pre-relaxed and verified): teacher relaxation frames,
    Vashishta MD snapshots at 300/600/900 K (1x1 and 2x2) with teacher relaxations
    of them, and ±2 % in-plane strained slabs.
``close_contact``
    alpha-quartz (2x1x1) and the dense slab with one O-O (1.1-2.2 Å), Si-O (1.2-1.5 Å)
    or Si-Si (1.8-2.7 Å) pair pushed together: the short-range repulsion.
``defect``
    vacancies (non-stoichiometric, they also separate the Si and O reference
    energies), stretched/broken Si-O bonds (pairs pulled 0.2-1.0 Å apart; no
    two atoms closer than 1.35 Å) and 6 % compressed, rattled cells.

Frames that need relaxation use the teacher calculator passed in, so the
recipe is deterministic for a given seed and teacher.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from ase import Atoms
from ase.filters import FrechetCellFilter
from ase.neighborlist import neighbor_list
from ase.optimize import FIRE
from ase.units import GPa

from flatcontact.potentials.lammps_runtime import new_lammps
from flatcontact.training.lammps_bulk import setup_box, vashishta_pair_commands
from flatcontact.training.polymorphs import build_polymorph

RECIPES = ("sio2",)
#: Bond-breaking frames with two atoms closer than this (Å) are redrawn.
MIN_CONTACT_ANGSTROM = 1.35


def alpha_quartz() -> Atoms:
    """alpha-quartz unit cell (9 atoms, :func:`flatcontact.structures.bulk.alpha_quartz`)."""
    from flatcontact.structures.bulk import alpha_quartz as _alpha_quartz

    return _alpha_quartz()


def strain_cell(atoms: Atoms, voigt_strain: np.ndarray) -> Atoms:
    """Copy of ``atoms`` homogeneously deformed by the (engineering) Voigt strain."""
    e = np.asarray(voigt_strain, dtype=float)
    eps = np.array(
        [[e[0], e[5] / 2, e[4] / 2], [e[5] / 2, e[1], e[3] / 2], [e[4] / 2, e[3] / 2, e[2]]]
    )
    out = atoms.copy()
    out.set_cell(np.asarray(atoms.cell) @ (np.eye(3) + eps), scale_atoms=True)
    return out


def quartz_slab(cut: int, layers: int = 6, repeats: tuple[int, int] = (1, 1)) -> Atoms:
    """(0001) alpha-quartz slab (:func:`flatcontact.structures.slab.quartz_0001_slab`), periodic in z."""
    from flatcontact.structures.slab import quartz_0001_slab

    slab = quartz_0001_slab(layers=layers, cut=cut).repeat((*repeats, 1))
    slab.pbc = True
    return slab


def dense_slabs(calc_pre, max_distinct: int = 3, layers: int = 6) -> list[Atoms]:
    """Seeded dense (0001) slabs that ``calc_pre`` relaxes to a verified dense surface.

    Seeds: :func:`flatcontact.structures.dense.dense_candidates`; energies equal within
    0.1 meV are symmetry duplicates and kept once.
    """
    from flatcontact.structures.build import SYMMETRIC_CUT
    from flatcontact.structures.dense import dense_candidates, relax, verify_dense_slab
    from flatcontact.structures.slab import quartz_0001_slab

    out, energies = [], []
    for _, seeded in dense_candidates(quartz_0001_slab(layers=layers, cut=SYMMETRIC_CUT)):
        seeded.pbc = True
        res = relax(seeded, calc_pre, fmax_ev_per_angstrom=0.02, steps=2000)
        if not verify_dense_slab(seeded)["dense"]:
            continue
        if any(abs(res["energy_ev"] - e) < 1e-4 for e in energies):
            continue
        energies.append(res["energy_ev"])
        seeded.calc = None
        out.append(seeded)
        if len(out) == max_distinct:
            break
    return out


def vashishta_md(
    atoms: Atoms, temperature_k: float, n_frames: int, stride: int, seed: int, equil: int = 2000
) -> list[Atoms]:
    """NVT (Nosé-Hoover, 0.1 ps) MD with Vashishta (1990) in LAMMPS; ``n_frames`` snapshots."""
    lmp = new_lammps()
    prism = setup_box(lmp, atoms, ["Si", "O"])
    lmp.commands_string("\n".join(vashishta_pair_commands()))
    lmp.commands_string(
        f"timestep 0.001\nvelocity all create {temperature_k!r} {seed} mom yes rot no dist gaussian\n"
        f"fix nvt all nvt temp {temperature_k!r} {temperature_k!r} 0.1\nrun {equil}"
    )
    frames = []
    for _ in range(n_frames):
        lmp.command(f"run {stride}")
        x = np.array(lmp.numpy.extract_atom("x")[: len(atoms)], dtype=float)
        snap = atoms.copy()
        snap.positions = prism.vector_to_ase(x)
        snap.wrap()
        frames.append(snap)
    lmp.close()
    return frames


def close_contact(atoms: Atoms, pair: tuple[str, str], distance: float, rng) -> Atoms | None:
    """Copy of ``atoms`` with one random ``pair`` of nearby atoms moved to ``distance`` (Å).

    Both atoms move symmetrically along their separation; small rattle. Teaches the
    short-range repulsion a SNAP does not have by construction. None if another pair
    ends up closer than 0.9 Å.
    """
    a = atoms.copy()
    sym = np.array(a.get_chemical_symbols())
    i = int(rng.choice(np.flatnonzero(sym == pair[0])))
    js = np.flatnonzero(sym == pair[1])
    js = js[js != i]
    d = a.get_distances(i, js, mic=True)
    j = int(js[np.argsort(d)[rng.integers(0, min(3, len(js)))]])
    vec = a.get_distance(i, j, mic=True, vector=True)
    r = np.linalg.norm(vec)
    shift = 0.5 * (r - distance) * vec / r
    a.positions[i] += shift
    a.positions[j] -= shift
    a.positions += rng.normal(0.0, 0.02, a.positions.shape)
    close = neighbor_list("ij", a, 0.9)[0]
    return None if close.size else a


def _relax_frames(
    atoms: Atoms, calc, fmax: float, steps: int, every: int, pressure_gpa=None
) -> list[Atoms]:
    """Frames along a teacher relaxation (every ``every`` steps, plus the end point)."""
    a = atoms.copy()
    a.calc = calc
    obj = a if pressure_gpa is None else FrechetCellFilter(a, scalar_pressure=pressure_gpa * GPa)
    opt = FIRE(obj, logfile=None)
    frames = []
    for k, _ in enumerate(opt.irun(fmax=fmax, steps=steps)):
        if k % every == 0:
            frames.append(_bare(a))
    frames.append(_bare(a))
    return frames


def _bare(atoms: Atoms) -> Atoms:
    out = Atoms(atoms.get_chemical_symbols(), positions=atoms.positions, cell=atoms.cell, pbc=True)
    return out


def sio2_recipe(
    seed: int,
    calc,
    scale: float = 1.0,
    progress: Callable[[str], None] | None = None,
) -> list[Atoms]:
    """Unlabelled configurations of the ``sio2`` recipe (see the module docstring).

    Parameters
    ----------
    seed
        Seed of every random choice (strains, rattles, MD velocities, defects).
    calc
        Teacher calculator used for the relaxation-derived groups.
    scale
        Multiplies the number of frames of the random groups (1.0 = default size).
    """
    rng = np.random.default_rng(seed)
    say = progress or (lambda msg: None)
    out: list[Atoms] = []

    def add(frames, group):
        for f in frames:
            f = _bare(f)
            f.info["config_type"] = group
            out.append(f)

    def n(k):
        return max(1, round(k * scale))

    q = alpha_quartz()
    say("quartz_strain")
    frames = []
    for rep in [(1, 1, 1)] * n(40) + [(2, 1, 1)] * n(20) + [(1, 1, 2)] * n(20):
        a = strain_cell(q.repeat(rep), rng.uniform(-0.04, 0.04, 6))
        a.positions += rng.normal(0.0, rng.uniform(0.01, 0.05), a.positions.shape)
        frames.append(a)
    add(frames, "quartz_strain")

    say("quartz_relaxed_strain")
    q0 = _relax_frames(q, calc, fmax=0.01, steps=300, every=10**6, pressure_gpa=0.0)[-1]
    frames = [q0]
    for comp in range(6):
        for mag in (-0.04, -0.02, -0.01, -0.005, 0.005, 0.01, 0.02, 0.04):
            e = np.zeros(6)
            e[comp] = mag
            traj = _relax_frames(strain_cell(q0, e), calc, fmax=0.01, steps=200, every=15)
            frames += [traj[0], traj[-1]]
    for _ in range(n(20)):  # mixed small strains, ions relaxed
        traj = _relax_frames(
            strain_cell(q0, rng.uniform(-0.01, 0.01, 6)), calc, fmax=0.01, steps=200, every=10**6
        )
        frames.append(traj[-1])
    add(frames, "quartz_relaxed_strain")

    say("quartz_pressure")
    frames = []
    for p in (-1.0, 1.0, 2.0, 4.0, 6.0, 8.0, 10.0, 12.0):
        frames += _relax_frames(q0, calc, fmax=0.01, steps=300, every=20, pressure_gpa=p)
    for a in list(frames[-8:]):
        b = a.copy()
        b.positions += rng.normal(0.0, 0.03, b.positions.shape)
        frames.append(b)
    add(frames, "quartz_pressure")

    say("polymorph")
    frames = _polymorph_frames(calc, rng, n)
    add(frames, "polymorph")

    say("md")
    frames = []
    bulk = q0.repeat((2, 2, 2))
    for k, t in enumerate((300.0, 600.0, 900.0, 1200.0, 1500.0)):
        frames += vashishta_md(bulk, t, n_frames=n(8), stride=250, seed=seed + 11 * k + 1)
    st = build_polymorph("stishovite").repeat((2, 2, 3))
    for k, t in enumerate((300.0, 900.0)):
        frames += vashishta_md(st, t, n_frames=n(4), stride=250, seed=seed + 7 * k + 3)
    add(frames, "md")

    say("slab")
    frames = []
    for cut in (0, 1, 2):
        slab = quartz_slab(cut)
        md = vashishta_md(slab, 1200.0, n_frames=2, stride=2000, seed=seed + 101 + cut, equil=1000)
        frames += md
        frames += _relax_frames(slab, calc, fmax=0.03, steps=250, every=25)
        frames += _relax_frames(md[-1], calc, fmax=0.03, steps=250, every=25)
        frames += vashishta_md(
            quartz_slab(cut, layers=4, repeats=(2, 1)),
            600.0,
            n_frames=2,
            stride=1000,
            seed=seed + 201 + cut,
            equil=500,
        )
    add(frames, "slab")

    say("dense_slab")
    frames, relaxed = _dense_slab_frames(calc, seed, n)
    add(frames, "dense_slab")

    say("defect")
    frames = _defect_frames(q0, rng, n)
    add(frames, "defect")

    say("close_contact")
    frames = _close_contact_frames(q0, relaxed, rng, n)
    add(frames, "close_contact")
    return out


def _dense_slab_frames(calc, seed: int, n: Callable[[int], int]) -> tuple[list[Atoms], list[Atoms]]:
    """The dense (0001) slabs relaxed with the teacher, their MD and strained relaxations;
    and the relaxed slabs (hosts of the close contacts)."""
    from flatcontact.training.lammps_bulk import vashishta_calculator

    frames = []
    starts = dense_slabs(vashishta_calculator())
    relaxed = []
    for start in starts:
        traj = _relax_frames(start, calc, fmax=0.02, steps=300, every=20)
        frames += traj
        relaxed.append(traj[-1])
    if relaxed:
        d0 = relaxed[0]
        for k, t in enumerate((300.0, 600.0, 900.0)):
            md = vashishta_md(d0, t, n_frames=n(3), stride=500, seed=seed + 301 + k, equil=500)
            frames += md
            frames += _relax_frames(md[-1], calc, fmax=0.03, steps=200, every=25)
        for e in (-0.02, 0.02):
            frames += _relax_frames(
                strain_cell(d0, np.array([e, e, 0, 0, 0, 0])), calc, fmax=0.02, steps=200, every=50
            )
        frames += vashishta_md(
            d0.repeat((2, 2, 1)), 300.0, n_frames=n(3), stride=500, seed=seed + 401
        )
    return frames, relaxed


def _defect_frames(q0: Atoms, rng, n: Callable[[int], int]) -> list[Atoms]:
    """Vacancies, stretched or broken Si-O bonds and compressed cells of a 2x2x1 quartz."""
    frames = []
    big = q0.repeat((2, 2, 1))
    symbols = np.array(big.get_chemical_symbols())
    for _ in range(n(8)):
        for el in ("O", "Si"):
            a = big.copy()
            del a[int(rng.choice(np.flatnonzero(symbols == el)))]
            a.positions += rng.normal(0.0, 0.03, a.positions.shape)
            frames.append(a)
    si, o = np.flatnonzero(symbols == "Si"), np.flatnonzero(symbols == "O")
    n_bonds = 0
    while n_bonds < n(16):
        # pull one Si-O pair apart symmetrically: a stretched or broken bond
        a = big.copy()
        i = int(rng.choice(si))
        j = int(o[np.argmin(a.get_distances(i, o, mic=True))])
        vec = a.get_distance(i, j, mic=True, vector=True)
        stretch = rng.uniform(0.2, 1.0)
        a.positions[j] += 0.5 * stretch * vec / np.linalg.norm(vec)
        a.positions[i] -= 0.5 * stretch * vec / np.linalg.norm(vec)
        a.positions += rng.normal(0.0, 0.02, a.positions.shape)
        if neighbor_list("d", a, MIN_CONTACT_ANGSTROM).size == 0:
            frames.append(a)
            n_bonds += 1
    for _ in range(n(6)):
        a = strain_cell(big, np.array([-0.06, -0.06, -0.06, 0, 0, 0]))
        a.positions += rng.normal(0.0, 0.04, a.positions.shape)
        frames.append(a)
    return frames


def _close_contact_frames(
    q0: Atoms, relaxed: list[Atoms], rng, n: Callable[[int], int]
) -> list[Atoms]:
    """Pairs of atoms pushed closer than in any crystal, in quartz and a relaxed dense slab."""
    frames = []
    targets = {("O", "O"): (1.1, 2.2), ("Si", "O"): (1.2, 1.5), ("Si", "Si"): (1.8, 2.7)}
    hosts = [q0.repeat((2, 1, 1))] + [d.copy() for d in relaxed[:1]]
    n_made = 0
    while n_made < n(36):
        host = hosts[n_made % len(hosts)]
        pair = list(targets)[n_made % len(targets)]
        a = close_contact(host, pair, rng.uniform(*targets[pair]), rng)
        if a is not None:
            frames.append(a)
            n_made += 1
    return frames


def _polymorph_frames(calc, rng, n: Callable[[int], int]) -> list[Atoms]:
    """Cristobalite, coesite and stishovite relaxed with the teacher, strained and compressed."""
    frames = []
    for name, rep in (
        ("cristobalite", (1, 1, 1)),
        ("coesite", (1, 1, 1)),
        ("stishovite", (2, 2, 2)),
    ):
        p0 = build_polymorph(name).repeat(rep)
        frames += _relax_frames(p0, calc, fmax=0.02, steps=200, every=25, pressure_gpa=0.0)
        for _ in range(n(10)):
            a = strain_cell(p0, rng.uniform(-0.03, 0.03, 6))
            a.positions += rng.normal(0.0, 0.03, a.positions.shape)
            frames.append(a)
        for s in (0.97, 0.94):
            frames.append(strain_cell(p0, np.array([s - 1, s - 1, s - 1, 0, 0, 0])))
    return frames
