"""Earlier names of the interaction model (kept so existing imports keep working).

``PotentialSpec`` *is* :class:`flatcontact.potentials.model.InteractionModel`; the name
resolution (:func:`normalize_potential_name`, :func:`resolve_intra`) and the LJ settings
(:class:`LJSpec`) live in :mod:`flatcontact.potentials.model`.
"""

from flatcontact.potentials.files import BUNDLED_DIR, bundled_snap_names, snap_elements
from flatcontact.potentials.model import (
    CLASSICAL,
    POTENTIAL_FORMS,
    InteractionModel,
    LJSpec,
    ResolvedIntra,
    normalize_potential_name,
    resolve_intra,
)

#: The earlier name of :class:`InteractionModel`.
PotentialSpec = InteractionModel

__all__ = [
    "BUNDLED_DIR",
    "CLASSICAL",
    "POTENTIAL_FORMS",
    "LJSpec",
    "PotentialSpec",
    "ResolvedIntra",
    "bundled_snap_names",
    "normalize_potential_name",
    "resolve_intra",
    "snap_elements",
]
