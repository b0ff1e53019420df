"""Stage 5 (optional), elastic: E* and G* of the slab material's bulk crystal with the run's model.

File: ``elastic.json`` (:meth:`ElasticResult.to_json`: lattice, Cij, Hill moduli and the contact
moduli the contact stage takes, ``contact_modulus_gpa`` = E* and ``shear_modulus_gpa`` = G*
in the paper's convention, 4 × Johnson's G*_J, plus ``crystal``: which bulk crystal was
computed and why it stands for the slabs).

The bulk crystal of each recipe (:func:`bulk_crystal`):

``quartz-dense``  α-quartz (:func:`flatcontact.elastic.quartz_contact_moduli`, the paper's);
``fcc111``        the fcc crystal of ``element`` (``a_angstrom`` or ASE's reference, relaxed);
``crystal``       the bulk file the slabs are cut from;
``sheets``        the bulk layered crystal: two sheets in the recipe's stacking (AB: Bernal
                  graphite; AA′: h-BN, 2H-MoS2) at the interlayer distance, periodic along z.
                  Convention (stated in ``elastic.json``): the Hill average of the relaxed-ion
                  Cij, i.e. the layered crystal as an isotropic polycrystal. A single-asperity
                  contact of a layered material is strongly anisotropic (C33, C44 << C11), so
                  this E*, G* is an order of magnitude, not a property of that contact.

A hetero-interface (``slab2``), ``file``, ``slab`` and ``toy-lj`` have no single bulk crystal:
the stage refuses them in one line naming ``elastic.enabled`` (give the contact moduli).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from flatcontact.foundation.errors import InputError
from flatcontact.foundation.fileio import write_json_atomic
from flatcontact.foundation.layout import ELASTIC_JSON
from flatcontact.stages import _calculator

#: The convention of the layered crystals' moduli (elastic.json ``crystal.convention``).
LAYERED_CONVENTION = (
    "Hill average of the relaxed-ion Cij of the bulk layered crystal (isotropic polycrystal); "
    "a contact of a layered material is strongly anisotropic, so E* and G* are an order of magnitude"
)


@dataclass(frozen=True)
class ElasticInputs:
    """The elastic stage reads no upstream stage."""


@dataclass
class ElasticResult:
    """:func:`flatcontact.elastic.crystal_contact_moduli`'s document (+ ``crystal``)."""

    doc: dict
    files: list[Path] = field(default_factory=list)

    @property
    def contact_modulus_gpa(self) -> float:
        return float(self.doc["moduli_gpa"]["e_star"])

    @property
    def shear_modulus_gpa(self) -> float:
        return float(self.doc["moduli_gpa"]["g_star_paper"])

    def to_json(self) -> dict:
        """``elastic.json``: the moduli document plus E*, G* under the contact model's names."""
        return {
            **self.doc,
            "contact_modulus_gpa": self.contact_modulus_gpa,
            "shear_modulus_gpa": self.shear_modulus_gpa,
        }


def bulk_crystal(recipe):
    """The bulk crystal standing for the slabs of ``recipe`` and a record of it.

    Returns ``(atoms, record)``; ``atoms`` is ``None`` for ``quartz-dense`` (α-quartz, the
    paper's path). Raises a one-line InputError naming ``elastic.enabled`` for recipes with
    no single bulk crystal.
    """
    kind = recipe.kind
    if getattr(recipe, "slab2", None) is not None:
        raise InputError(
            "elastic.enabled: structure.slab2 makes a hetero-interface of two materials; the "
            "elastic stage computes one crystal: give contact.contact_modulus_gpa and "
            "contact.shear_modulus_gpa instead"
        )
    if kind == "quartz-dense":
        return None, {"crystal": "alpha-quartz"}
    if kind == "fcc111":
        from ase.build import bulk

        atoms = bulk(recipe.element, "fcc", a=recipe.a_angstrom)
        return atoms, {"crystal": f"fcc {recipe.element}"}
    if kind == "crystal":
        from flatcontact.structures.crystal import read_bulk

        return read_bulk(recipe.bulk, "structure.bulk"), {
            "crystal": f"bulk file {Path(recipe.bulk).name}"
        }
    if kind == "sheets":
        return _layered_bulk(recipe)
    raise InputError(
        f"elastic.enabled: structure.kind={kind} names no bulk crystal; give "
        "contact.contact_modulus_gpa and contact.shear_modulus_gpa instead"
    )


def _layered_bulk(recipe):
    from flatcontact.structures.sheets import BUILTIN_SHEETS, builtin_sheet, stack_sheets
    from flatcontact.structures.structure_file import read_structure

    if recipe.sheet in BUILTIN_SHEETS:
        sheet = builtin_sheet(recipe.sheet)
        d = recipe.interlayer_angstrom or BUILTIN_SHEETS[recipe.sheet].interlayer_angstrom
    else:
        sheet = read_structure(recipe.sheet, "structure.sheet")
        d = recipe.interlayer_angstrom
    stacking = recipe.stacking if len(recipe.stacking.replace("'", "")) >= 2 else "AB"
    atoms = stack_sheets(sheet, 2, stacking, d, "structure.stacking")
    cell = atoms.cell.array.copy()
    cell[2] = [0.0, 0.0, 2 * d]
    atoms.set_cell(cell)
    atoms.positions[:, 2] -= atoms.positions[:, 2].min()
    atoms.pbc = True
    atoms.wrap()
    record = {
        "crystal": f"bulk {recipe.sheet}, two sheets stacked {stacking} at {d:g} Å",
        "convention": LAYERED_CONVENTION,
    }
    return atoms, record


def elastic_stage(
    settings, inputs: ElasticInputs, folder: Path | None, progress=None
) -> ElasticResult:
    """Cij of the relaxed bulk crystal of the slabs (:func:`bulk_crystal`) by finite strains
    (``elastic.strain``) and its contact moduli, with the run's model as a single crystal
    (:func:`flatcontact.potentials.engines.bulk_calculator`)."""
    from flatcontact.elastic import crystal_contact_moduli, quartz_contact_moduli

    atoms, record = bulk_crystal(settings.structure)
    model = _calculator.model(settings)
    if atoms is None:
        _calculator.check_elastic(settings)
        with _calculator.failing_at("elastic"):  # a user's calculator that fails: one line
            doc = quartz_contact_moduli(model, strain=settings.elastic.strain)
    else:
        _calculator.check_atoms(settings, atoms)
        with _calculator.failing_at("elastic"):
            doc = crystal_contact_moduli(atoms, model, strain=settings.elastic.strain)
        doc["potential"] = model.label
    result = ElasticResult({**doc, "crystal": record})
    if folder is not None:
        folder.mkdir(parents=True, exist_ok=True)
        result.files.append(write_json_atomic(folder / ELASTIC_JSON, result.to_json()))
    return result
