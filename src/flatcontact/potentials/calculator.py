"""ASE calculators for an interface: :func:`make_calculator` (LAMMPS or ASE-calculator engine).

Both give the energy (eV) and forces (eV/Å) of the whole interface: the intra-slab model
inside each slab (slab 1 and slab 2 never interact through it) and LJ only between atoms
of different slabs. They are created once per worker and reused: a call on Atoms with the
same species, order, slab labels, cell and pbc only updates positions; anything else
rebuilds the engine. ``calc.force_calls`` counts energy+force evaluations (cumulative).
"""

from __future__ import annotations

import importlib

import numpy as np
from ase import Atoms
from ase.calculators.calculator import Calculator, all_changes

from flatcontact.errors import InputError
from flatcontact.potentials.lammps_engine import LammpsEngine
from flatcontact.potentials.lj import lj_cross_energy_forces
from flatcontact.potentials.spec import PotentialSpec


def _groups(atoms: Atoms) -> np.ndarray:
    if "slab" in atoms.arrays:
        return np.asarray(atoms.arrays["slab"], dtype=int)
    return np.ones(len(atoms), dtype=int)


def check_elements(spec: PotentialSpec, atoms: Atoms) -> None:
    """Raise :class:`InputError` if the spec's intra model or LJ lacks an element of ``atoms``."""
    symbols = set(atoms.get_chemical_symbols())
    known = spec.resolved.elements
    if known is not None and not symbols <= set(known):
        raise InputError(
            f"potential '{spec.intra}' knows elements {list(known)}, but the structure has {sorted(symbols - set(known))}"
        )
    groups = _groups(atoms)
    if len(set(groups.tolist())) > 1:
        sym = np.array(atoms.get_chemical_symbols())
        spec.lj.table(sorted(set(sym[groups == 1])), sorted(set(sym[groups != 1])))


class _Signature:
    @staticmethod
    def of(atoms: Atoms) -> tuple:
        return (
            tuple(atoms.numbers.tolist()),
            tuple(_groups(atoms).tolist()),
            tuple(np.round(atoms.cell.array, 10).ravel().tolist()),
            tuple(bool(p) for p in atoms.pbc),
        )


class InterfaceCalculator(Calculator):
    """Base: counts force calls, rebuilds the engine when the structure (not positions) changes."""

    implemented_properties = ("energy", "free_energy", "forces")

    def __init__(self, spec: PotentialSpec, atoms: Atoms | None = None, **kwargs):
        super().__init__(**kwargs)
        self.spec = spec
        self.force_calls = 0
        self._signature = None
        if atoms is not None:  # otherwise built lazily on the first call
            check_elements(spec, atoms)
            self._build(atoms)

    def _build(self, atoms: Atoms) -> None:
        raise NotImplementedError

    def _evaluate(self, atoms: Atoms) -> tuple[float, np.ndarray]:
        raise NotImplementedError

    def calculate(self, atoms=None, properties=("energy",), system_changes=all_changes):
        super().calculate(atoms, properties, system_changes)
        signature = _Signature.of(self.atoms)
        if signature != self._signature:
            check_elements(self.spec, self.atoms)
            self.close()
            self._build(self.atoms)
        energy, forces = self._evaluate(self.atoms)
        self.force_calls += 1
        self.results = {"energy": energy, "free_energy": energy, "forces": forces}

    def close(self) -> None:
        """Release engine resources (LAMMPS instances)."""


class LammpsInterfaceCalculator(InterfaceCalculator):
    """LAMMPS engine: intra-slab style per slab (hybrid/overlay, NULL-mapped) + lj/cut across."""

    def _build(self, atoms: Atoms) -> None:
        groups = _groups(atoms)
        symbols = atoms.get_chemical_symbols()
        sym = np.array(symbols)
        table = None
        if len(set(groups.tolist())) > 1:
            table = self.spec.lj.table(sorted(set(sym[groups == 1])), sorted(set(sym[groups != 1])))
        self.engine = LammpsEngine(
            self.spec.resolved,
            symbols,
            groups,
            atoms.cell.array,
            atoms.pbc,
            lj_table=table,
            lj_cutoff_angstrom=self.spec.lj.cutoff_angstrom,
        )
        self._signature = _Signature.of(atoms)

    def _evaluate(self, atoms: Atoms) -> tuple[float, np.ndarray]:
        return self.engine.compute(atoms.positions)

    def close(self) -> None:
        engine = getattr(self, "engine", None)
        if engine is not None:
            engine.close()
            self.engine = None


def load_factory(path: str):
    """Import ``module:factory`` and return the callable (one-line InputError otherwise)."""
    module_name, _, attr = path.partition(":")
    try:
        module = importlib.import_module(module_name)
    except ImportError as exc:
        raise InputError(f"ASE calculator factory '{path}': cannot import module ({exc})") from None
    factory = getattr(module, attr, None)
    if not callable(factory):
        raise InputError(
            f"ASE calculator factory '{path}': '{attr}' is not a callable in {module_name}"
        )
    return factory


class AseInterfaceCalculator(InterfaceCalculator):
    """ASE engine: an ASE calculator per slab (each slab as its own Atoms) + vectorised numpy LJ across.

    The factory is called once per slab (two independent calculator instances); each slab's
    Atoms keeps the interface cell and pbc, so lateral periodic images are included.
    """

    def _build(self, atoms: Atoms) -> None:
        factory = load_factory(self.spec.resolved.factory)
        groups = _groups(atoms)
        self._group_ids = sorted(set(groups.tolist()))
        self._members = [np.flatnonzero(groups == g) for g in self._group_ids]
        self._slabs = []
        for idx in self._members:
            part = Atoms(
                atoms.numbers[idx], positions=atoms.positions[idx], cell=atoms.cell, pbc=atoms.pbc
            )
            part.calc = factory()
            self._slabs.append(part)
        sym = np.array(atoms.get_chemical_symbols())
        self._table = None
        if len(self._group_ids) > 1:
            self._table = self.spec.lj.table(
                sorted(set(sym[groups == 1])), sorted(set(sym[groups != 1]))
            )
        self._signature = _Signature.of(atoms)

    def _evaluate(self, atoms: Atoms) -> tuple[float, np.ndarray]:
        energy = 0.0
        forces = np.zeros((len(atoms), 3))
        for idx, part in zip(self._members, self._slabs, strict=True):
            part.positions = atoms.positions[idx]
            energy += float(part.get_potential_energy())
            forces[idx] = part.get_forces()
        if self._table is not None:
            e_lj, f_lj = lj_cross_energy_forces(
                atoms, _groups(atoms), self._table, self.spec.lj.cutoff_angstrom
            )
            energy += e_lj
            forces += f_lj
        return energy, forces


def make_calculator(spec: PotentialSpec, atoms: Atoms) -> InterfaceCalculator:
    """The calculator for ``spec`` on an interface (or, without a ``slab`` array, a single slab/bulk).

    Uses the ``slab`` array to give each slab its own atom types; raises :class:`InputError`
    on an element mismatch before any LAMMPS instance is created.
    """
    if spec.kind == "ase":
        return AseInterfaceCalculator(spec, atoms)
    return LammpsInterfaceCalculator(spec, atoms)
