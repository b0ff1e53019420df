"""A probed column as two chains run at once equals the column relaxed in sequence.

The relaxation here remembers its warm start: the returned "positions" are the chain of
thicknesses it started from, and the energy depends on that history, so a point started
from anything but the sequential column's previous point gives a different number.
"""

import numpy as np
import pytest

from flatcontact.ispes.geometry import thickness
from flatcontact.ispes.probe import (
    compress_chain,
    join_column,
    probe_column,
    stretch_chain,
)


def _history_relax(p_of, calls_of=lambda z: 7):
    def relax(a, b, z, start, start_z):
        history = np.array([z]) if start is None else np.append(start, z)
        if start is not None:
            assert start_z == pytest.approx(history[-2], abs=0.0)
        e = -1.0 / (1.0 + (z - 3.0) ** 2) + 1e-6 * history.size + 1e-7 * float(np.sum(history))
        return e, float(p_of(z)), int(calls_of(z)) + history.size, history

    return relax


def _loads(z_ref):
    """p(z) in GPa of four columns: a Morse-like load with a tensile maximum, one already
    past its maximum at the reference (rising on stretching: the sequential rule stops at
    once, a chain without the reference load does not), a plateau at the separation
    threshold, and a column in compression throughout the stretch's first steps."""
    d = 1.5

    def morse(z):
        x = np.exp(-d * (z - z_ref - 0.3))
        return 30.0 * (x * x - x)

    def pressed_below(f):  # compression reaches the test's 1.5 GPa within a few steps
        return lambda z: f(z) + (10.0 * (z_ref - z) if z < z_ref else 0.0)

    return {
        "morse": morse,
        "past maximum": pressed_below(lambda z: -np.exp(-(z - z_ref))),
        "separated": pressed_below(
            lambda z: -1e-5 * np.exp(-(z - z_ref)) - (1.0 if z <= z_ref else 0.0)
        ),
        "pressed": lambda z: 2.0 - 0.5 * (z - z_ref),
    }


@pytest.mark.parametrize("column", ["morse", "past maximum", "separated", "pressed"])
@pytest.mark.parametrize("stop_at", [None, 0.0, -0.5, -2.0])
def test_chains_run_at_once_equal_the_sequential_column(toy_reference, column, stop_at):
    z_ref = thickness(toy_reference)
    p_of = _loads(z_ref)[column]
    relax = _history_relax(p_of)
    shift = (0.25, 0.5)
    sequential = probe_column(relax, toy_reference, shift, 1.5, stop_at_gpa=stop_at)
    down = compress_chain(relax, toy_reference, shift, 1.5)
    up = stretch_chain(relax, toy_reference, shift, None, stop_at_gpa=stop_at)  # no p_ref
    joined = join_column(toy_reference, shift, down, up, stop_at_gpa=stop_at)
    assert len(up.thickness_angstrom) >= len(sequential.thickness_angstrom) - len(
        down.thickness_angstrom
    )
    for field in ("thickness_angstrom", "energy_ev", "normal_stress_gpa"):
        np.testing.assert_array_equal(getattr(joined, field), getattr(sequential, field))
    assert joined.force_calls == sequential.force_calls
    assert joined.shift == sequential.shift
    # the chains are what they say: the compression starts cold at the reference thickness
    # and walks down; the stretching starts cold above it and walks up
    assert down.thickness_angstrom[0] == z_ref
    assert np.all(np.diff(down.thickness_angstrom) < 0)
    assert up.thickness_angstrom[0] > z_ref and np.all(np.diff(up.thickness_angstrom) > 0)


def test_a_column_past_its_maximum_stops_at_the_first_stretched_point(toy_reference):
    """The sequential rule: the first stretched load above the reference one is past the
    tensile maximum; a column with a stop load below every load ends there, and the joined chains too."""
    z_ref = thickness(toy_reference)
    relax = _history_relax(_loads(z_ref)["past maximum"])
    column = probe_column(relax, toy_reference, (0.0, 0.0), 0.5, stop_at_gpa=-2.0)
    above = column.thickness_angstrom[column.thickness_angstrom > z_ref]
    assert above.size == 1 and above[0] == pytest.approx(z_ref + 0.1)
    up = stretch_chain(relax, toy_reference, (0.0, 0.0), None, stop_at_gpa=-2.0)
    assert len(up.thickness_angstrom) == 2  # ran one point further, cut by the join
