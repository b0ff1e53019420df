"""Grid definition and the overlap check."""

import pytest

from flatcontact.foundation.errors import InputError
from flatcontact.ispes.geometry import thickness
from flatcontact.ispes.grid import GridSpec, check_thicknesses


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"n_a": 0, "n_b": 3, "thickness_angstrom": (10.0,)}, "n_a"),
        ({"n_a": 3, "n_b": 0, "thickness_angstrom": (10.0,)}, "n_b"),
        ({"n_a": 3, "n_b": 3, "thickness_angstrom": ()}, "thickness"),
        ({"n_a": 3, "n_b": 3, "thickness_angstrom": (10.0, 10.0)}, "repeat"),
        ({"n_a": 3, "n_b": 3, "thickness_angstrom": (-1.0,)}, "positive"),
        ({"n_a": 3, "n_b": 3}, "either"),
        ({"n_a": 3, "n_b": 3, "p_range_gpa": (2.0, 1.0, 4)}, "LO < HI"),
        ({"n_a": 3, "n_b": 3, "p_range_gpa": (-1.0, 3.0, 1)}, "N must"),
    ],
)
def test_bad_grids_are_one_line_errors(kwargs, match):
    with pytest.raises(InputError, match=match) as err:
        GridSpec(**kwargs)
    assert "\n" not in str(err.value)


def test_overlapping_thickness_is_refused(toy_reference):
    grid = GridSpec(2, 2, thickness_angstrom=(thickness(toy_reference) - 2.0,))
    with pytest.raises(InputError, match="overlap"):
        check_thicknesses(toy_reference, grid, grid.thickness_angstrom)
