"""ASE calculators of an :class:`~flatcontact.potentials.model.InteractionModel`.

- :class:`LammpsInterfaceCalculator`: the LAMMPS engine with the model's compiled setup
  (:mod:`flatcontact.potentials.lammps_setup`); also the bulk calculator (energy, forces,
  stress of a 3D-periodic crystal).
- :class:`AseInterfaceCalculator`: an ASE calculator per slab (each slab as its own Atoms,
  keeping the interface cell and pbc) + vectorised numpy LJ across (``coupling: lj``).
- a whole-interface ASE calculator is the user's calculator itself.

The first two are created once per worker and reused: a call on Atoms with the same species,
order, slab/layer labels, cell and pbc only updates positions; anything else rebuilds the
engine. ``calc.force_calls`` counts energy+force evaluations (cumulative). Which calculator a
model gets is decided in :mod:`flatcontact.potentials.engines`.
"""

from __future__ import annotations

import numpy as np
from ase import Atoms
from ase.calculators.calculator import Calculator, all_changes

from flatcontact.foundation.errors import InputError
from flatcontact.potentials.guarded import guard_calculator
from flatcontact.potentials.lammps_engine import LammpsEngine
from flatcontact.potentials.lammps_setup import compile_setup
from flatcontact.potentials.lj import lj_cross_energy_forces
from flatcontact.potentials.loader import call_factory
from flatcontact.potentials.model import InteractionModel, slab_ids


def calculator_name(spec: InteractionModel) -> str:
    """How a refusal names the model's calculator: ``calculator 'module:callable'`` for a
    user's ASE calculator, ``ASE calculator factory '...'`` for ``intra: ase:...``, else
    ``potential <label>``."""
    if spec.calculator is not None:
        return f"calculator '{spec.calculator.target}'"
    if spec.engine == "ase-slab":
        return f"ASE calculator factory '{spec.intra.removeprefix('ase:')}'"
    return f"potential {spec.label}"


def _signature(atoms: Atoms) -> tuple:
    """What, besides positions, the engine is built for: species, slab/layer labels, cell, pbc
    (as bytes: compared on every call, so it must be cheap for thousands of atoms).

    Without z periodicity only the in-plane cell vectors count (the box is shrink-wrapped
    along z, see :mod:`flatcontact.potentials.lammps_box`)."""
    layer = atoms.arrays.get("layer")
    return (
        np.asarray(atoms.numbers, dtype=np.int64).tobytes(),
        np.asarray(slab_ids(atoms), dtype=np.int64).tobytes(),
        np.asarray(layer, dtype=np.int64).tobytes() if layer is not None else None,
        # a slab's vertical cell vector is not part of its LAMMPS box (z shrink-wrapped): the
        # scan resizes it with the thickness, which must not rebuild the engine
        np.round(atoms.cell.array if atoms.pbc[2] else atoms.cell.array[:2], 10).tobytes(),
        np.asarray(atoms.pbc, dtype=bool).tobytes(),
    )


class InterfaceCalculator(Calculator):
    """Base: counts force calls, rebuilds the engine when the structure (not positions) changes."""

    implemented_properties = ("energy", "free_energy", "forces")

    def __init__(
        self, spec: InteractionModel, atoms: Atoms | None = None, bulk: bool = False, **kwargs
    ):
        super().__init__(**kwargs)
        self.spec = spec
        self.bulk = bulk
        self.force_calls = 0
        self._signature = None
        if bulk:  # the stress of a 3D-periodic crystal
            self.implemented_properties = ("energy", "free_energy", "forces", "stress")
        if atoms is not None:  # otherwise built lazily on the first call
            self._check(atoms)
            self._build(atoms)

    def _check(self, atoms: Atoms) -> None:
        if self.bulk:
            known = self.spec.elements
            missing = sorted(set(atoms.get_chemical_symbols()) - known) if known is not None else []
            if missing:
                raise InputError(
                    f"potential '{self.spec.name}' has no parameters for element(s) {missing} "
                    f"of the structure (it knows {sorted(known)})"
                )
        else:
            self.spec.check_atoms(atoms)

    def _build(self, atoms: Atoms) -> None:
        raise NotImplementedError

    def _evaluate(self, atoms: Atoms, stress: bool):
        raise NotImplementedError

    def check_state(self, atoms, tol=1e-15):
        """ASE's change check, exact comparisons only (a scan calls it 3-4 times per step).

        ``Calculator.check_state`` compares every array with ``numpy.allclose`` at ``tol =
        1e-15``; exact equality (``numpy.array_equal``) costs a fraction of it and differs only
        for changes below 1e-15 (which then count as a change: a needless, exact recomputation).
        When species, cell, pbc or the set of arrays differ, ASE's own check decides.
        """
        old = self.atoms
        if (
            old is not None
            and len(old) == len(atoms)
            and np.array_equal(old.numbers, atoms.numbers)
            and np.array_equal(old.cell.array, atoms.cell.array)
            and np.array_equal(old.pbc, atoms.pbc)
            and old.arrays.keys() == atoms.arrays.keys()
            and all(
                np.array_equal(old.arrays[k], atoms.arrays[k])
                for k in ("initial_charges", "initial_magmoms")
                if k in atoms.arrays
            )
        ):
            return [] if np.array_equal(old.positions, atoms.positions) else ["positions"]
        return super().check_state(atoms, tol)

    def calculate(self, atoms=None, properties=("energy",), system_changes=all_changes):
        super().calculate(atoms, properties, system_changes)
        self._engine_for(self.atoms)
        want_stress = "stress" in properties
        out = self._evaluate(self.atoms, want_stress)
        self.force_calls += 1
        self.results = {"energy": out[0], "free_energy": out[0], "forces": out[1]}
        if want_stress or (self.bulk and len(out) > 2):
            self.results["stress"] = out[2]

    def _engine_for(self, atoms: Atoms) -> None:
        """(Re)build the engine when the species, labels, cell or pbc of ``atoms`` are not
        those it was built for (:func:`_signature`); positions never rebuild it."""
        signature = _signature(atoms)
        if signature != self._signature:
            self._check(atoms)
            self.close()
            self._build(atoms)
            self._signature = signature

    def position_evaluator(self, atoms: Atoms):
        """``evaluate(positions) -> (energy_ev, forces)`` for ``atoms`` at new positions.

        The engine is checked (and rebuilt if the species, labels, cell or pbc changed) once
        here; each call is then one evaluation with nothing else around it (no ASE results
        cache, no change check), counted in ``force_calls``. The positions must belong to
        ``atoms``'s structure (same atoms, cell, pbc). ASE's cached results are dropped, so
        a later ``get_forces`` recomputes. The forces returned may be the engine's own
        array (read-only): valid until the next call, copy what is kept. The engine starts
        afresh (:meth:`start_afresh`): the evaluations depend on their positions alone.
        """
        self._engine_for(atoms)
        self.reset()
        self.start_afresh()
        fast = self._positions_evaluator(atoms)

        def evaluate(positions: np.ndarray) -> tuple[float, np.ndarray]:
            out = fast(positions)
            self.force_calls += 1
            return out[0], out[1]

        return evaluate

    def start_afresh(self) -> None:
        """The next evaluation does not depend on the earlier ones (LAMMPS: a full setup,
        :meth:`~flatcontact.potentials.lammps_engine.LammpsEngine.restart`). The scan calls
        it at the start of every point, so a point's numbers are a function of the point."""
        self.reset()

    def _positions_evaluator(self, atoms: Atoms):
        """positions -> engine output, for the structure of ``atoms`` (default: a copy)."""
        work = atoms.copy()
        work.set_constraint()

        def fast(positions: np.ndarray):
            work.positions = positions
            return self._evaluate(work, False)

        return fast

    def close(self) -> None:
        """Release engine resources (LAMMPS instances)."""


class LammpsInterfaceCalculator(InterfaceCalculator):
    """The LAMMPS engine with the model's setup (see :mod:`flatcontact.potentials.lammps_setup`)."""

    def _build(self, atoms: Atoms) -> None:
        setup = compile_setup(self.spec, atoms, bulk=self.bulk)
        self.engine = LammpsEngine(setup, atoms.cell.array, atoms.pbc, label=self.spec.label)
        self._signature = _signature(atoms)

    def _evaluate(self, atoms: Atoms, stress: bool):
        return self.engine.compute(atoms.positions, stress=self.bulk and all(atoms.pbc))

    def start_afresh(self) -> None:
        super().start_afresh()
        engine = getattr(self, "engine", None)
        if engine is not None:
            engine.restart()

    def _positions_evaluator(self, atoms: Atoms):
        # forces not copied where LAMMPS's array is already in the caller's frame and order
        # (read-only, valid until the next call: position_evaluator's contract)
        stress = self.bulk and all(atoms.pbc)
        compute = self.engine.compute
        return lambda positions: compute(positions, stress=stress, copy=False)

    def minimize_positions(
        self, atoms: Atoms, held: np.ndarray, fmax: float, max_iterations: int
    ) -> tuple[np.ndarray, float, np.ndarray, int, int]:
        """Relax ``atoms`` (not modified) with LAMMPS's own minimiser
        (:meth:`~flatcontact.potentials.lammps_engine.LammpsEngine.minimize`); its evaluations
        are counted in ``force_calls``. Returns positions, energy, raw forces, iterations,
        evaluations."""
        self._engine_for(atoms)
        self.reset()
        out = self.engine.minimize(atoms.positions, held, fmax, max_iterations)
        self.force_calls += out[4]
        return out

    def close(self) -> None:
        engine = getattr(self, "engine", None)
        if engine is not None:
            engine.close()
            self.engine = None


class AseInterfaceCalculator(InterfaceCalculator):
    """An ASE calculator per slab (each slab as its own Atoms) + vectorised numpy LJ across.

    The factory is called once per slab (independent calculator instances); each slab's Atoms
    keeps the interface cell and pbc, so lateral periodic images are included.
    """

    def _factory(self):
        """``make()`` -> one slab's calculator, guarded
        (:func:`~flatcontact.potentials.guarded.guard_calculator`: the user's code)."""
        spec, name = self.spec, calculator_name(self.spec)
        if spec.calculator is not None:
            c = spec.calculator
            return lambda: guard_calculator(call_factory(c.target, None, c.kwargs), name)
        target = spec.intra.removeprefix("ase:")
        return lambda: guard_calculator(
            call_factory(target, None, {}, what="ASE calculator factory"), name
        )

    def _build(self, atoms: Atoms) -> None:
        make = self._factory()
        groups = slab_ids(atoms)
        self._members = [np.flatnonzero(groups == g) for g in sorted(set(groups.tolist()))]
        self._slabs = []
        for idx in self._members:
            part = Atoms(
                atoms.numbers[idx], positions=atoms.positions[idx], cell=atoms.cell, pbc=atoms.pbc
            )
            part.calc = make()
            self._slabs.append(part)
        sym = np.array(atoms.get_chemical_symbols())
        self._table = None
        if len(self._members) > 1 and self.spec.coupling == "lj":
            self._table = self.spec.lj.table(
                sorted(set(sym[groups == 1])), sorted(set(sym[groups != 1]))
            )
        self._signature = _signature(atoms)

    def _evaluate(self, atoms: Atoms, stress: bool):
        energy = 0.0
        forces = np.zeros((len(atoms), 3))
        for idx, part in zip(self._members, self._slabs, strict=True):
            part.positions = atoms.positions[idx]
            part.cell = atoms.cell  # the vertical vector may change (see _signature)
            energy += float(part.get_potential_energy())
            forces[idx] = part.get_forces()
        if self._table is not None:
            e_lj, f_lj = lj_cross_energy_forces(
                atoms, slab_ids(atoms), self._table, self.spec.lj.cutoff_angstrom
            )
            energy += e_lj
            forces += f_lj
        return energy, forces
