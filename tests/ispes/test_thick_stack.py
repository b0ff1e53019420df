"""A compliant stack is loaded past what a rigid placement of slab 2 allows (place_slab2's spread).

A uniform Lennard-Jones stack (toy model with the same ε inside and across the interface,
10 layers per slab) shares a compression among its 19 interlayer gaps, so reaching 6 GPa
needs about 1.8 Å of total compression. Placed rigidly, all of it would first land in the
one interfacial gap and the 1.0 Å overlap guard refuses the thickness; spread over the stack
(each free layer's height scaled about slab 1's held layer), the starting structure is a
homogeneously compressed stack and the relaxed point carries the load.
"""

import pytest

import flatcontact.structures.placement as placement_module
from flatcontact.foundation.errors import InputError
from flatcontact.ispes.grid import GridSpec
from flatcontact.ispes.relax import RelaxSettings
from flatcontact.ispes.scan import run_scan
from flatcontact.potentials.engines import calculator_factory
from flatcontact.potentials.model import InteractionModel
from flatcontact.structures.placement import place_slab2
from flatcontact.structures.toy import toy_interface

UNIFORM = {"eps_cross_ev": 0.1}  # = the toy's in-slab ε: one LJ crystal, cut in two
P_HI_GPA = 6.0


@pytest.fixture(scope="module")
def stack():
    return toy_interface(layers=10, **UNIFORM)


def _scan(stack, out):
    factory = calculator_factory(
        InteractionModel(
            calculator={"target": "flatcontact.ispes.toy:toy_calculator", "kwargs": UNIFORM}
        )
    )
    return run_scan(
        stack,
        factory,
        GridSpec(2, 2, p_range_gpa=(-0.1, P_HI_GPA, 4)),
        out,
        RelaxSettings(0.001),
        executor_options={"kind": "serial", "workers": 1},
    )


def test_a_compliant_stack_reaches_the_load_a_rigid_placement_cannot(stack, tmp_path):
    ds = _scan(stack, tmp_path / "spread").dataset
    assert bool(ds.converged.all())
    # the thinnest thickness carries the requested load at every stacking
    thinnest = ds.normal_stress.isel(thickness=0)
    assert float(thinnest.min()) >= P_HI_GPA * (1 - 0.02)
    # ... at a thickness where slab 2, placed rigidly, would overlap slab 1 at some stacking
    z_min = float(ds.thickness.min())
    refused = 0
    for a in ds.shift_a.values:
        for b in ds.shift_b.values:
            try:
                place_slab2(stack, float(a), float(b), z_min, spread_compression=False)
            except InputError:
                refused += 1
    assert refused >= 1


def test_without_the_spread_the_same_request_is_refused(stack, tmp_path, monkeypatch):
    monkeypatch.setattr(placement_module, "MAX_SPREAD_STRAIN", 0.0)
    with pytest.raises(InputError, match="overlap before the load reaches"):
        _scan(stack, tmp_path / "rigid")
