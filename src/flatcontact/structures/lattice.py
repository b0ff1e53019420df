"""The interaction model's own lattice of a slab material, against the structure file's.

A slab cut from a crystal at another lattice than its potential's equilibrium carries a
lateral stress: the Zhou EAM relaxes fcc Al to a = 4.0817 Å, and its (111) γ-surface scanned
at a CIF's 4.05 Å (0.8 % compressed) gives γ_isf = 39.9 instead of 50.2 mJ/m². The build
therefore relaxes each slab material with the run's model first and cuts the slabs at that
lattice (``structure.lattice: potential``, the default), or keeps the file's and states the
mismatch (``structure.lattice: file``), refusing one above :data:`MAX_FILE_MISMATCH_PERCENT`.

Conventions
-----------
* A **bulk crystal** is relaxed in cell and ions (BFGS on ASE's Fréchet cell filter, zero
  stress, :func:`relax_cell`); the slabs are cut from the file's atoms in the relaxed cell
  (fractional positions kept: the cut, terminations and layers are the file's; the
  interface relaxation that follows relaxes the ions).
* A **2D sheet** (monolayer) is relaxed in its in-plane cell only (strain components xx,
  yy, xy; the cell is made 3D-periodic with :data:`SHEET_VACUUM_ANGSTROM` of vacuum for the
  stress), the vector normal to the sheet kept.
* **Mismatch** of a lattice vector: ``100 (|a_file| / |a_potential| − 1)`` %, positive when
  the file's lattice is larger (the slab stretched). The in-plane strain of a slab is the
  principal strains of the map from the potential's in-plane cell to the one used
  (:func:`flatcontact.structures.match.strain_and_rotation`).
* **Lateral stress** at the file's lattice: the potential's stress of the bulk at the
  file's cell, ions relaxed, projected on the cut plane, ``(tr σ − n·σ·n) / 2`` (the mean
  normal stress along the plane), in GPa with ASE's sign (negative = compressed). For a
  sheet the in-plane stress of its cell, per interlayer distance (the sheet's share of a
  layered crystal).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from ase import Atoms
from ase.filters import FrechetCellFilter
from ase.optimize import BFGS

from flatcontact.foundation.errors import InputError
from flatcontact.foundation.units import EV_PER_A3_TO_GPA
from flatcontact.potentials.guarded import CalculatorFailure

#: Largest in-plane mismatch (%) between the file's lattice and the potential's that
#: ``structure.lattice: file`` accepts. At 2 % a crystal with biaxial modulus
#: C11 + C12 − 2 C13²/C33 of 100–200 GPa carries 2–4 GPa of lateral stress, as much as the
#: largest loads of a scan (0–3 GPa), and the γ-surface moves by tens of percent (Al, Zhou
#: EAM: 0.8 % moves γ_isf by 21 %). Below it the mismatch and its stress are reported.
MAX_FILE_MISMATCH_PERCENT = 2.0
#: Force (eV/Å) and steps of the lattice relaxation (the elastic stage's tolerance).
RELAX_FMAX_EV_PER_ANGSTROM = 1e-4
RELAX_STEPS = 1000
#: Vacuum (Å) above a monolayer while its in-plane cell is relaxed (3D-periodic stress).
SHEET_VACUUM_ANGSTROM = 40.0
#: Strain components relaxed for a sheet (ASE Voigt order xx, yy, zz, yz, xz, xy).
IN_PLANE_MASK = (1, 1, 0, 0, 0, 1)

LATTICE_SOURCES = ("potential", "file")


def relax_cell(atoms: Atoms, calc, fmax: float = 1e-4, steps: int = 1000, mask=None) -> Atoms:
    """Zero-stress cell and ions (BFGS on ASE's Fréchet cell filter); returns a relaxed copy.

    ``mask``: the Voigt strain components allowed to relax (ASE's ``FrechetCellFilter``
    mask; all six by default, :data:`IN_PLANE_MASK` for a sheet).
    """
    a = atoms.copy()
    a.calc = calc
    converged = BFGS(FrechetCellFilter(a, mask=mask), logfile=None).run(fmax=fmax, steps=steps)
    a.info["cell_relaxation_converged"] = bool(converged)
    return a


def _stress_at_fixed_cell(atoms: Atoms, calc, fmax: float = 1e-3, steps: int = 500) -> np.ndarray:
    """3×3 stress (eV/Å³, ASE sign) of ``atoms`` with its ions relaxed in its own cell."""
    a = atoms.copy()
    a.calc = calc
    if len(a) > 1:
        BFGS(a, logfile=None).run(fmax=fmax, steps=steps)
    return np.asarray(a.get_stress(voigt=False), float)


def plane_normal(cell: np.ndarray, miller) -> np.ndarray:
    """Unit normal (Cartesian) of the plane ``miller`` in the cell ``cell`` (rows)."""
    rec = np.linalg.inv(np.asarray(cell, float)).T  # rows b_i with a_i·b_j = δ_ij
    n = np.asarray(miller, float) @ rec
    return n / np.linalg.norm(n)


def lateral_stress_gpa(stress: np.ndarray, normal: np.ndarray) -> float:
    """Mean normal stress along the plane of ``normal``: ``(tr σ − n·σ·n)/2`` (stress units)."""
    s = np.asarray(stress, float)
    n = np.asarray(normal, float)
    return float((np.trace(s) - n @ s @ n) / 2.0)


@dataclass(frozen=True)
class LatticeFit:
    """The file's and the potential's lattice of one slab material (module docstring)."""

    material: str
    kind: str  #: "bulk" (cell and ions relaxed) or "sheet" (in-plane cell only)
    file_cell: np.ndarray  #: 3×3 rows, Å
    potential_cell: np.ndarray  #: 3×3 rows, Å
    converged: bool
    #: potential's stress at the file's lattice, along the cut plane (GPa, negative = compressed)
    lateral_stress_gpa: float
    extra: dict = field(default_factory=dict)

    @property
    def vectors(self) -> int:
        """The lattice vectors compared: 3 for a bulk, the 2 in-plane ones for a sheet."""
        return 3 if self.kind == "bulk" else 2

    def mismatch_percent(self) -> list[float]:
        """``100 (|a_file|/|a_potential| − 1)`` per compared lattice vector."""
        n = self.vectors
        f = np.linalg.norm(self.file_cell[:n], axis=1)
        p = np.linalg.norm(self.potential_cell[:n], axis=1)
        return [float(100.0 * (x / y - 1.0)) for x, y in zip(f, p, strict=True)]

    def scaled(self, atoms: Atoms) -> Atoms:
        """``atoms`` (the file's structure) in the potential's cell, fractional positions kept."""
        out = atoms.copy()
        cell = np.asarray(atoms.cell.array, float).copy()
        cell[: self.vectors] = self.potential_cell[: self.vectors]
        out.set_cell(cell, scale_atoms=True)
        return out

    def record(self) -> dict:
        """JSON-ready: both lattices, the mismatch per vector and the lateral stress."""
        n = self.vectors
        return {
            "material": self.material,
            "relaxed": "bulk cell and ions"
            if self.kind == "bulk"
            else "monolayer in-plane cell and ions",
            "file_lengths_angstrom": [float(v) for v in np.linalg.norm(self.file_cell[:n], axis=1)],
            "potential_lengths_angstrom": [
                float(v) for v in np.linalg.norm(self.potential_cell[:n], axis=1)
            ],
            "file_cell_angstrom": np.round(self.file_cell, 6).tolist(),
            "potential_cell_angstrom": np.round(self.potential_cell, 6).tolist(),
            "file_vs_potential_percent": [round(v, 4) for v in self.mismatch_percent()],
            "lateral_stress_gpa_at_file_lattice": (
                round(self.lateral_stress_gpa, 4) if np.isfinite(self.lateral_stress_gpa) else None
            ),
            "relaxation_converged": self.converged,
            **self.extra,
        }


def bulk_lattice(atoms: Atoms, calc, material: str, miller=None) -> LatticeFit:
    """The potential's zero-stress cell of a bulk crystal and its stress at the file's cell.

    ``miller`` (in ``atoms``' cell): the cut plane the lateral stress is projected on; ``None``
    gives the mean normal stress ``tr σ / 3`` (a cubic crystal scaled isotropically).
    """
    relaxed = relax_cell(atoms, calc, fmax=RELAX_FMAX_EV_PER_ANGSTROM, steps=RELAX_STEPS)
    stress = _stress_at_fixed_cell(atoms, calc)
    if miller is None:
        lateral = float(np.trace(stress) / 3.0)
    else:
        lateral = lateral_stress_gpa(stress, plane_normal(atoms.cell.array, miller))
    return LatticeFit(
        material,
        "bulk",
        np.asarray(atoms.cell.array, float).copy(),
        np.asarray(relaxed.cell.array, float).copy(),
        bool(relaxed.info.get("cell_relaxation_converged", True)),
        lateral * EV_PER_A3_TO_GPA,
    )


def sheet_lattice(sheet: Atoms, calc, material: str, interlayer_angstrom: float) -> LatticeFit:
    """The potential's in-plane cell of a monolayer and its in-plane stress at the file's cell.

    The sheet is made 3D-periodic with :data:`SHEET_VACUUM_ANGSTROM` of vacuum and only its
    in-plane strains relax (:data:`IN_PLANE_MASK`). The stress is rescaled from the cell's
    height to ``interlayer_angstrom`` (the sheet's share of a layered crystal).
    """
    boxed = sheet.copy()
    z = boxed.positions[:, 2]
    cell = np.asarray(boxed.cell.array, float).copy()
    height = float(np.ptp(z)) + SHEET_VACUUM_ANGSTROM
    cell[2] = (0.0, 0.0, height)
    boxed.set_cell(cell, scale_atoms=False)
    boxed.positions[:, 2] -= z.min() - SHEET_VACUUM_ANGSTROM / 2
    boxed.pbc = True
    relaxed = relax_cell(
        boxed, calc, fmax=RELAX_FMAX_EV_PER_ANGSTROM, steps=RELAX_STEPS, mask=IN_PLANE_MASK
    )
    stress = _stress_at_fixed_cell(boxed, calc)
    in_plane = float(stress[0, 0] + stress[1, 1]) / 2.0 * height / interlayer_angstrom
    pot = np.asarray(sheet.cell.array, float).copy()
    pot[:2] = relaxed.cell.array[:2]
    return LatticeFit(
        material,
        "sheet",
        np.asarray(sheet.cell.array, float).copy(),
        pot,
        bool(relaxed.info.get("cell_relaxation_converged", True)),
        in_plane * EV_PER_A3_TO_GPA,
    )


def in_plane_mismatch_percent(file_cell2: np.ndarray, potential_cell2: np.ndarray) -> list[float]:
    """Principal strains (%) of the map from the potential's in-plane cell (2×2 rows, the
    slab's standard frame) to the file's: the strain a slab at the file's lattice carries."""
    from flatcontact.structures.match import strain_and_rotation

    f = np.linalg.solve(np.asarray(potential_cell2, float), np.asarray(file_cell2, float)).T
    strains, _ = strain_and_rotation(f)
    return [round(100.0 * s, 4) for s in strains]


def check_file_lattice(records: dict[str, dict], field: str = "structure.lattice") -> None:
    """Refuse (one line naming ``field``) a slab whose in-plane mismatch between the file's
    lattice and the potential's exceeds :data:`MAX_FILE_MISMATCH_PERCENT`.

    ``records``: slab name → its lattice record with ``in_plane_mismatch_percent``.
    """
    for name, rec in records.items():
        worst = max((abs(v) for v in rec.get("in_plane_mismatch_percent", [])), default=0.0)
        if (
            worst > MAX_FILE_MISMATCH_PERCENT
            and rec.get("lateral_stress_gpa_at_file_lattice") is not None
        ):
            raise InputError(
                f"{field}=file: {name} ({rec.get('material', '?')}) is strained "
                f"{worst:.3g} % in-plane against the potential's own lattice (file "
                f"{_lengths(rec['file_lengths_angstrom'])} Å, potential "
                f"{_lengths(rec['potential_lengths_angstrom'])} Å; lateral stress "
                f"{rec['lateral_stress_gpa_at_file_lattice']:.3g} GPa), above "
                f"{MAX_FILE_MISMATCH_PERCENT:g} %; use {field}: potential (the default) or a "
                "structure file at the potential's lattice"
            )


def _lengths(values) -> str:
    return "/".join(f"{v:.4f}" for v in values)


class LatticeChoice:
    """The lattice of every slab material of one build (``structure.lattice``).

    ``calculator_for(atoms)`` gives the run's model as a single-crystal calculator
    (:func:`flatcontact.potentials.engines.bulk_calculator`); ``source`` is ``potential`` or
    ``file``. Each material is relaxed once (cached by ``key``, e.g. its file); the records
    of the slabs (:meth:`note`) go to ``build.json`` (:meth:`record`).
    """

    def __init__(self, calculator_for, source: str = "potential"):
        if source not in LATTICE_SOURCES:
            raise InputError(f"lattice={source!r}: expected one of {', '.join(LATTICE_SOURCES)}")
        self.calculator_for = calculator_for
        self.source = source
        self.slabs: dict[str, dict] = {}
        self._fits: dict = {}

    @property
    def use_potential(self) -> bool:
        return self.source == "potential"

    def bulk(self, key, atoms: Atoms, material: str, miller=None) -> LatticeFit:
        """:func:`bulk_lattice` of ``atoms`` with the run's model (once per ``key``)."""
        if key not in self._fits:
            self._fits[key] = self._fit(
                lambda: bulk_lattice(atoms, self.calculator_for(atoms), material, miller),
                atoms,
                material,
                "bulk",
            )
        return self._fits[key]

    def sheet(self, key, sheet: Atoms, material: str, interlayer_angstrom: float) -> LatticeFit:
        """:func:`sheet_lattice` of ``sheet`` with the run's model (once per ``key``)."""
        if key not in self._fits:
            self._fits[key] = self._fit(
                lambda: sheet_lattice(
                    sheet, self.calculator_for(sheet), material, interlayer_angstrom
                ),
                sheet,
                material,
                "sheet",
            )
        return self._fits[key]

    @staticmethod
    def _fit(compute, atoms: Atoms, material: str, kind: str) -> LatticeFit:
        """``compute()``, or, when the model's engine cannot compute the material alone (a
        LAMMPS hybrid whose sub-style has no atom of it, e.g. h-BN's ``coul/shield`` on a
        graphene sheet, or a user's ASE calculator that fails on it:
        :class:`~flatcontact.potentials.guarded.CalculatorFailure`), the file's lattice
        recorded as not computed. Any other one-line :class:`InputError` (an element the model
        lacks) propagates."""
        try:
            return compute()
        except CalculatorFailure as exc:
            failed: Exception = exc
        except InputError:
            raise
        except Exception as exc:  # the engine's own error, kept as the reason
            failed = exc
        reason = next((ln.strip() for ln in str(failed).splitlines() if ln.strip()), repr(failed))
        cell = np.asarray(atoms.cell.array, float).copy()
        return LatticeFit(material, kind, cell, cell, False, float("nan"), {"not_computed": reason})

    def note(self, slab: str, fit: LatticeFit, file_cell2, potential_cell2) -> dict:
        """Record slab ``slab``'s lattice: ``fit`` and the in-plane strain the file's puts on it."""
        rec = {
            **fit.record(),
            "used": self.source,
            "in_plane_file_angstrom": [float(v) for v in np.linalg.norm(file_cell2, axis=1)],
            "in_plane_potential_angstrom": [
                float(v) for v in np.linalg.norm(potential_cell2, axis=1)
            ],
            "in_plane_potential_cell_angstrom": np.round(potential_cell2, 6).tolist(),
            "in_plane_mismatch_percent": in_plane_mismatch_percent(file_cell2, potential_cell2),
        }
        self.slabs[slab] = rec
        return rec

    def warnings(self) -> list[str]:
        """One line per slab built at the potential's lattice far from the file's: the model
        may not describe this crystal (the slab is still built at the potential's)."""
        out = []
        for name, rec in self.slabs.items():
            if "not_computed" in rec:
                out.append(
                    f"{name} ({rec['material']}): the model cannot compute this material alone "
                    f"({rec['not_computed']}); its slabs are at the file's lattice, unchecked"
                )
                continue
            worst = max(abs(v) for v in rec["in_plane_mismatch_percent"])
            if self.use_potential and worst > MAX_FILE_MISMATCH_PERCENT:
                out.append(
                    f"{name} ({rec['material']}): the potential's lattice differs from the "
                    f"file's by {worst:.3g} % in-plane (file "
                    f"{_lengths(rec['file_lengths_angstrom'])} Å, potential "
                    f"{_lengths(rec['potential_lengths_angstrom'])} Å); the slabs are built at "
                    "the potential's: check that the model describes this crystal"
                )
        return out

    def check(self, field: str = "structure.lattice") -> None:
        """:func:`check_file_lattice` when the file's lattice is kept."""
        if not self.use_potential:
            check_file_lattice(self.slabs, field)

    def record(self) -> dict:
        """``build.json["lattice"]``: the choice, the threshold and each slab's lattices."""
        return {
            "source": self.source,
            "max_file_mismatch_percent": MAX_FILE_MISMATCH_PERCENT,
            "convention": "mismatch = 100 (|a_file|/|a_potential| - 1) per lattice vector; "
            "in-plane: principal strains of the potential's in-plane cell -> the file's; "
            "lateral stress: the potential's stress at the file's lattice along the cut plane, "
            "GPa, negative = compressed",
            "slabs": self.slabs,
            "warnings": self.warnings(),
        }
