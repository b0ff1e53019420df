"""A scan's task context is pickled once and unpickled once per process
(:mod:`flatcontact.ispes.scan_context`), and stays exactly the context it was."""

import dataclasses
import pickle

import numpy as np

from flatcontact.ispes.relax import RelaxSettings, ScanContext
from flatcontact.ispes.scan_context import KEPT_CONTEXTS, context_from_bytes


def test_round_trip_is_the_same_context_and_one_object_per_process(toy_reference, toy_factory):
    ctx = ScanContext(toy_reference, toy_factory, RelaxSettings(0.005))
    first, second = pickle.dumps(ctx), pickle.dumps(ctx)
    assert first == second
    a, b = pickle.loads(first), pickle.loads(second)
    assert a is b  # unpickled once
    np.testing.assert_array_equal(a.reference.positions, toy_reference.positions)
    np.testing.assert_array_equal(a.reference.arrays["slab"], toy_reference.arrays["slab"])
    assert a.settings == ctx.settings and a.hessian is None
    assert a.factory.fingerprint == toy_factory.fingerprint
    assert pickle.dumps(a) == first  # a worker's context pickles to the same bytes


def test_a_changed_context_is_another_context(toy_reference, toy_factory):
    ctx = ScanContext(toy_reference, toy_factory, RelaxSettings(0.005))
    other = dataclasses.replace(ctx, settings=RelaxSettings(0.001))
    a, b = pickle.loads(pickle.dumps(ctx)), pickle.loads(pickle.dumps(other))
    assert a is not b
    assert a.settings.fmax_ev_per_angstrom == 0.005 and b.settings.fmax_ev_per_angstrom == 0.001


def test_the_process_keeps_only_a_few_contexts(toy_reference, toy_factory):
    from flatcontact.ispes import scan_context

    datas = [
        pickle.dumps(ScanContext(toy_reference, toy_factory, RelaxSettings(0.001 * (k + 1))))
        for k in range(KEPT_CONTEXTS + 3)
    ]
    for data in datas:
        pickle.loads(data)
    assert len(scan_context._unpickled) <= KEPT_CONTEXTS
    # an evicted context comes back equal, as a new object
    again = pickle.loads(datas[0])
    assert again.settings.fmax_ev_per_angstrom == 0.001
    assert context_from_bytes(pickle.loads(datas[0]).__reduce__()[1][0]) is again
