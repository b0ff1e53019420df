"""The ``elastic`` section: self-consistent contact moduli E*, G* from the interaction model."""

from __future__ import annotations

from pydantic import Field

from flatcontact.config.section import Section
from flatcontact.foundation.numbers import physical


class ElasticConfig(Section):
    """Self-consistent contact moduli E*, G* from the potential (stage ``elastic``, optional)."""

    strain: physical(1e-6, 0.05) = Field(
        0.005, description="finite strain of the central differences for C_ij"
    )
    enabled: bool = Field(
        False,
        description="compute E* and G* (paper's convention) of the slabs' bulk crystal (alpha-"
        "quartz, the fcc metal, the crystal file, the layered bulk of sheets) with the run's "
        "interaction model; otherwise contact.contact_modulus_gpa/shear_modulus_gpa (required "
        "for any material but alpha-quartz)",
    )
