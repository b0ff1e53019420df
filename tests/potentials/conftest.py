import pytest

from flatcontact.structures.assemble import make_interface
from flatcontact.structures.interface_contract import thickness
from flatcontact.structures.placement import place_slab2
from flatcontact.structures.slab import quartz_0001_slab


@pytest.fixture(scope="session")
def close_interface():
    """A 4-layer quartz interface pressed so that slab 2 is within the intra cutoffs of slab 1."""
    ref = make_interface(quartz_0001_slab(layers=4, cut=2), gap_angstrom=3.0, face_atoms=3)
    atoms = place_slab2(ref, 0.21, 0.37, thickness(ref) - 0.8)
    # break symmetry so forces are generic
    rng = __import__("numpy").random.default_rng(7)
    atoms.positions += rng.normal(scale=0.05, size=atoms.positions.shape)
    return atoms
