"""A column's compression run as segments (many workers) joins into the sequential chain.

The relaxation here is history-free (its result depends on z only), so every segment's cold
start gives the sequential chain's numbers and the join must equal :func:`compress_chain`
point for point; only the force calls differ (a cold start costs more here, as on quartz).
"""

import numpy as np
import pytest

from flatcontact.foundation.errors import InputError
from flatcontact.ispes.geometry import thickness
from flatcontact.ispes.probe import (
    CompressionSegments,
    compress_chain,
    compress_segment,
    next_segments,
)


def _relax(p_of, overlap_below=None):
    def relax(a, b, z, start, start_z):
        if overlap_below is not None and z < overlap_below:
            raise InputError(f"thickness {z:.3f}: the slabs overlap")
        calls = 30 if start is None else 10
        return -1.0 / (1.0 + z * z), float(p_of(z)), calls, np.array([z])

    return relax


def _run_all(relax, reference, shift, p_hi, n_steps, max_down_steps=80):
    """Every segment the schedule asks for, in index order, joined."""
    plan = CompressionSegments(p_hi, n_steps=n_steps, max_down_steps=max_down_steps)
    while plan.join() is None:
        j = plan.launch()
        plan.add(
            j,
            compress_segment(
                relax, reference, shift, p_hi, j * n_steps, n_steps, max_down_steps=max_down_steps
            ),
        )
    return plan


@pytest.mark.parametrize("n_steps", [1, 2, 3, 5, 100])
@pytest.mark.parametrize("p_hi", [-1.0, 0.35, 1.0, 2.95])
def test_segments_join_into_the_sequential_compression(toy_reference, n_steps, p_hi):
    z_ref = thickness(toy_reference)
    relax = _relax(lambda z: 10.0 * (z_ref - z) - 0.5)  # 1 GPa per 0.1 Å step
    sequential = compress_chain(relax, toy_reference, (0.5, 0.0), p_hi)
    joined = _run_all(relax, toy_reference, (0.5, 0.0), p_hi, n_steps).join()
    for field in ("thickness_angstrom", "energy_ev", "normal_stress_gpa"):
        assert getattr(joined, field) == getattr(sequential, field)
    # the steps: z_ref - k * 0.1 Å, up to the first load at or above HI
    k = np.arange(len(joined.thickness_angstrom))
    np.testing.assert_allclose(joined.thickness_angstrom, z_ref - 0.1 * k, rtol=0, atol=1e-12)
    assert joined.normal_stress_gpa[-1] >= p_hi
    assert all(p < p_hi for p in joined.normal_stress_gpa[:-1])
    # every segment starts cold: one cold start per segment of the joined chain
    cold = sum(1 for c in joined.force_calls if c == 30)
    assert cold == -(-len(k) // n_steps)


def test_an_overlap_beyond_the_load_is_not_an_error(toy_reference):
    z_ref = thickness(toy_reference)
    p_of = lambda z: 10.0 * (z_ref - z)  # noqa: E731
    # HI at step 4; the slabs overlap from step 7 on: segment 4 (steps 8, 9) is unused
    relax = _relax(p_of, overlap_below=z_ref - 0.65)
    plan = CompressionSegments(4.0 - 1e-9, n_steps=2)
    for j in range(5):
        plan.add(j, compress_segment(relax, toy_reference, (0.0, 0.0), 4.0 - 1e-9, 2 * j, 2))
    assert plan.segments[4].overlap is not None and plan.segments[4].thickness_angstrom == ()
    assert len(plan.segments[3].thickness_angstrom) == 1  # started past HI: stops at once
    assert len(plan.join().thickness_angstrom) == 5


def test_errors_are_the_sequential_chains(toy_reference):
    z_ref = thickness(toy_reference)
    p_of = lambda z: 10.0 * (z_ref - z)  # noqa: E731
    overlapping = _relax(p_of, overlap_below=z_ref - 0.35)
    with pytest.raises(InputError) as seq:
        compress_chain(overlapping, toy_reference, (0.0, 0.0), 6.0)
    with pytest.raises(InputError) as seg:
        _run_all(overlapping, toy_reference, (0.0, 0.0), 6.0, 3).join()
    assert str(seg.value) == str(seq.value)
    with pytest.raises(InputError) as seq:
        compress_chain(_relax(p_of), toy_reference, (0.0, 0.0), 6.0, max_down_steps=4)
    with pytest.raises(InputError) as seg:
        _run_all(_relax(p_of), toy_reference, (0.0, 0.0), 6.0, 3, max_down_steps=4).join()
    assert str(seg.value) == str(seq.value)


def test_segments_go_to_the_column_least_started(toy_reference):
    plans = [CompressionSegments(1.0, n_steps=2), CompressionSegments(1.0, n_steps=2)]
    assert next_segments(plans, 5) == [(0, 0), (1, 0), (0, 1), (1, 1), (0, 2)]
    # column 0's segment 1 reaches HI: no further segment for it; the slots go to column 1
    plans[0].add(
        1, compress_segment(lambda *a: (0.0, 2.0, 1, None), toy_reference, (0, 0), 1.0, 2, 2)
    )
    assert not plans[0].wants_more()
    assert next_segments(plans, 2) == [(1, 2), (1, 3)]
    # a column whose steps are exhausted asks for nothing more
    short = CompressionSegments(1.0, n_steps=2, max_down_steps=3)
    assert next_segments([short], 5) == [(0, 0), (0, 1)]
