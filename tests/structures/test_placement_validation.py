"""``place_slab2`` checks its reference against the interface contract once per reference
content, not at every grid point: the placements after the first skip the validation, yet
every reference that breaks the contract is refused, with ``validate_interface``'s own line,
whatever was validated before, including a reference changed in place after it passed."""

import numpy as np
import pytest

from flatcontact.foundation.errors import InputError
from flatcontact.structures import placement
from flatcontact.structures.interface_contract import validate_interface
from flatcontact.structures.placement import place_slab2
from flatcontact.structures.toy import toy_interface


def _breaks(name: str):
    """A way of breaking the contract in place (each a check of ``validate_interface``)."""

    def surface_2_untagged(atoms):
        atoms.arrays["surface"][atoms.arrays["surface"] == 2] = 0

    def slab_1_above_slab_2(atoms):
        atoms.positions[atoms.arrays["slab"] == 1, 2] += 40.0

    def a_foreign_slab_id(atoms):
        atoms.arrays["slab"][0] = 3

    def partly_held_layer(atoms):
        atoms.arrays["layer"] = np.where(atoms.arrays["slab"] == 1, 1, 2)

    def not_periodic(atoms):
        atoms.pbc = (True, False, False)

    def held_not_boolean(atoms):
        atoms.arrays["held"] = np.full(len(atoms), 2)

    return locals()[name]


BREAKS = [
    "surface_2_untagged",
    "slab_1_above_slab_2",
    "a_foreign_slab_id",
    "partly_held_layer",
    "not_periodic",
    "held_not_boolean",
]


@pytest.fixture
def counted(monkeypatch):
    """The validations ``place_slab2`` runs, counted (the cache emptied first)."""
    calls = []

    def validate(atoms, source="interface"):
        calls.append(source)
        validate_interface(atoms, source)

    monkeypatch.setattr(placement, "validate_interface", validate)
    monkeypatch.setattr(placement, "_VALID_REFERENCE", [])
    return calls


def test_one_reference_is_validated_once_for_all_its_points(counted):
    ref = toy_interface(layers=3)
    z = 10.0
    placed = [place_slab2(ref, a / 4, b / 4, z) for a in range(4) for b in range(4)]
    assert counted == ["reference interface"]
    # the same atoms as with a validation at each point
    again = place_slab2(ref, 0.75, 0.75, z, validate_reference=False)
    assert np.array_equal(placed[-1].positions, again.positions)
    # an equal copy is the same reference; another thickness of the same contract is not
    place_slab2(ref.copy(), 0.5, 0.0, z)
    assert counted == ["reference interface"]
    other = ref.copy()
    other.positions[other.arrays["slab"] == 2, 2] += 0.5
    place_slab2(other, 0.5, 0.0, z)
    assert len(counted) == 2


@pytest.mark.parametrize("how", BREAKS)
def test_a_reference_that_breaks_the_contract_is_refused_every_time(how, counted):
    """Changed in place after it passed, copied, or placed again after a refusal: the line is
    ``validate_interface``'s, at every placement."""
    ref = toy_interface(layers=3)
    place_slab2(ref, 0.0, 0.0, 10.0)  # valid: kept
    _breaks(how)(ref)
    with pytest.raises(InputError) as expected:
        validate_interface(ref, "reference interface")
    for atoms in (ref, ref, ref.copy()):
        with pytest.raises(InputError) as refused:
            place_slab2(atoms, 0.25, 0.0, 10.0)
        assert str(refused.value) == str(expected.value)
    assert counted == ["reference interface"] * 4
