"""Stage 5 (optional), elastic: E* and G* of bulk α-quartz with the run's potential.

File: ``elastic.json`` (:meth:`ElasticResult.to_json`: lattice, Cij, Hill moduli and the contact
moduli the contact stage takes, ``contact_modulus_gpa`` = E* and ``shear_modulus_gpa`` = G*
in the paper's convention, 4 × Johnson's G*_J).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from flatcontact.fileio import write_json_atomic
from flatcontact.stages import _calculator

ELASTIC_JSON = "elastic.json"


@dataclass(frozen=True)
class ElasticInputs:
    """The elastic stage reads no upstream stage."""


@dataclass
class ElasticResult:
    """:func:`flatcontact.elastic.quartz_contact_moduli`'s document."""

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


def run_elastic(
    settings, inputs: ElasticInputs, folder: Path | None, progress=None
) -> ElasticResult:
    """Cij of relaxed α-quartz by finite strains (``elastic.strain``) and its contact moduli,
    with the run's model as a single crystal (:meth:`InteractionModel.bulk_calculator`)."""
    from flatcontact.elastic import quartz_contact_moduli

    _calculator.check_elastic(settings)
    doc = quartz_contact_moduli(_calculator.model(settings), strain=settings.elastic.strain)
    result = ElasticResult(doc)
    if folder is not None:
        folder.mkdir(parents=True, exist_ok=True)
        result.files.append(write_json_atomic(folder / ELASTIC_JSON, result.to_json()))
    return result
