"""How many O–Si–O layers a dense α-quartz (0001) slab may have: the layer-count rules of the
``quartz-dense`` recipe, as plain data and checks.

The settings validate ``structure.layers`` with these (no structure is built to do it), and
the builders (:mod:`.dense`, :mod:`.thicken`, :mod:`.build`) use the same numbers.
"""

from __future__ import annotations

from flatcontact.foundation.errors import require

#: Dense face layer = the two outermost O–Si–O units.
DENSE_FACE_LAYERS = 2
#: O–Si–O units per c-repeat of α-quartz along [0001].
UNITS_PER_REPEAT = 3
#: O–Si–O layers of the shipped slab; thicker slabs insert whole bulk c-repeats (6, 9, 12, ...).
SHIPPED_LAYERS = 6
#: Fewest O–Si–O layers per slab of the dense quartz interface. Each slab has two tagged face
#: layers of ``DENSE_FACE_LAYERS`` units each: the outer one (surface 1 or 4) is held fixed
#: during a scan, the inner one (surface 2 or 3) is the sliding surface; the paper fully relaxes
#: "surfaces 2, 3 and the inner atomic layers", so at least one bulk-like unit must lie between
#: the two face layers (with 4 units the fixed face would bond directly to the sliding face and
#: there would be no inner layer to relax). Used by ``flatcontact build`` and the run config.
MIN_LAYERS = 2 * DENSE_FACE_LAYERS + 1


def check_layers(layers: object, name: str = "layers") -> int:
    """``layers`` if it is an integer >= :data:`MIN_LAYERS`, else a one-line :class:`InputError`."""
    require(
        isinstance(layers, int) and not isinstance(layers, bool) and layers >= MIN_LAYERS,
        f"{name}={layers!r}: expected an integer >= {MIN_LAYERS} O-Si-O layers per slab "
        f"(a fixed outer and a sliding inner face layer of {DENSE_FACE_LAYERS} units each, "
        "and at least one inner layer between them)",
    )
    return layers  # type: ignore[return-value]


def shipped_reaches(layers: int) -> bool:
    """True if the shipped slab, thickened by whole bulk c-repeats, has ``layers`` layers."""
    return layers >= SHIPPED_LAYERS and (layers - SHIPPED_LAYERS) % UNITS_PER_REPEAT == 0


def check_shipped_layers(layers: int, name: str = "layers") -> int:
    """``layers`` if the shipped slab reaches it (6, 9, 12, ...), else a one-line :class:`InputError`."""
    require(
        shipped_reaches(layers),
        f"{name}={layers}: the shipped dense slab has {SHIPPED_LAYERS} O-Si-O layers and grows "
        f"by whole alpha-quartz c-repeats of {UNITS_PER_REPEAT} layers: expected "
        f"{SHIPPED_LAYERS}, {SHIPPED_LAYERS + UNITS_PER_REPEAT}, "
        f"{SHIPPED_LAYERS + 2 * UNITS_PER_REPEAT}, ... (or source: seed)",
    )
    return layers
