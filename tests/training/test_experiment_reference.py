"""Experimental α-quartz constants have one home, flatcontact.foundation.reference, and are self-consistent."""

import ast
from pathlib import Path

import numpy as np
import pytest

import flatcontact
from flatcontact.foundation import reference

SRC = Path(flatcontact.__file__).parent
ONE_HOME = (
    "QUARTZ_CIJ_EXPERIMENT_GPA",
    "QUARTZ_LATTICE_EXPERIMENT_ANGSTROM",
    "QUARTZ_DENSITY_EXPERIMENT_G_CM3",
)


def _assigned_names(path: Path) -> set[str]:
    names = set()
    for node in ast.walk(ast.parse(path.read_text())):
        targets = []
        if isinstance(node, ast.Assign):
            targets = node.targets
        elif isinstance(node, ast.AnnAssign):
            targets = [node.target]
        names |= {t.id for t in targets if isinstance(t, ast.Name)}
    return names


def test_experimental_constants_are_assigned_only_in_reference_py():
    homes = {
        name: sorted(
            str(p.relative_to(SRC)) for p in SRC.rglob("*.py") if name in _assigned_names(p)
        )
        for name in ONE_HOME
    }
    assert homes == {name: ["foundation/reference.py"] for name in ONE_HOME}


def test_consumers_compare_with_the_same_object():
    from flatcontact.training import ispes_check, validate

    assert validate.QUARTZ_CIJ_EXPERIMENT_GPA is reference.QUARTZ_CIJ_EXPERIMENT_GPA
    assert ispes_check.QUARTZ_CIJ_EXPERIMENT_GPA is reference.QUARTZ_CIJ_EXPERIMENT_GPA
    assert ispes_check.QUARTZ_CIJ_ABS_EXPERIMENT_GPA == {
        k: abs(v) for k, v in reference.QUARTZ_CIJ_EXPERIMENT_GPA.items()
    }


def test_mcskimin_set_is_trigonal_and_mechanically_stable():
    """C66 = (C11 − C12)/2 (trigonal), the Born criteria of class 32, and its Voigt bulk modulus."""
    c = reference.QUARTZ_CIJ_EXPERIMENT_GPA
    assert c["C66"] == pytest.approx((c["C11"] - c["C12"]) / 2, abs=0.01)
    assert c["C11"] > abs(c["C12"]) and c["C44"] > 0
    assert c["C13"] ** 2 < 0.5 * c["C33"] * (c["C11"] + c["C12"])
    assert c["C14"] ** 2 < 0.5 * c["C44"] * (c["C11"] - c["C12"])
    k_voigt = (2 * c["C11"] + c["C33"] + 2 * (c["C12"] + 2 * c["C13"])) / 9
    from flatcontact.training.validate import experiment_moduli

    assert experiment_moduli()["bulk_voigt"] == pytest.approx(k_voigt, rel=1e-12)
    # the well-known adiabatic bulk modulus of α-quartz, ≈ 37–38 GPa
    assert 36.5 < experiment_moduli()["bulk_modulus"] < 38.5


def test_experimental_density_follows_from_the_lattice():
    """ρ = 3 SiO₂ per cell / (√3/2 a² c): the three lattice-side constants agree to 0.1 %."""
    from ase.data import atomic_masses, atomic_numbers
    from ase.units import _amu

    a = reference.QUARTZ_LATTICE_EXPERIMENT_ANGSTROM["a"]
    c = reference.QUARTZ_LATTICE_EXPERIMENT_ANGSTROM["c"]
    mass_g = 3 * (atomic_masses[atomic_numbers["Si"]] + 2 * atomic_masses[atomic_numbers["O"]])
    mass_g *= _amu * 1e3
    rho = mass_g / (np.sqrt(3) / 2 * a**2 * c * 1e-24)
    assert rho == pytest.approx(reference.QUARTZ_DENSITY_EXPERIMENT_G_CM3, rel=1e-3)


@pytest.mark.parametrize("name", ["sio2-snap", "sio2-snap-mf0"])
def test_bundled_reports_compare_with_the_one_experimental_set(name):
    """The stored vs_experiment blocks are what flatcontact.foundation.reference gives (|C14| compared)."""
    import json

    from flatcontact.potentials.files import BUNDLED_DIR
    from flatcontact.training.validate import experiment_moduli, vs_experiment

    report = json.loads((BUNDLED_DIR / name / "validation.json").read_text())
    stored, now = report["vs_experiment"], vs_experiment(report["potential"])
    for k, v in now["cij_rel"].items():
        assert stored["cij_rel"][k] == pytest.approx(v, abs=1e-12), k
    assert stored["a_rel"] == pytest.approx(now["a_rel"], abs=1e-12)
    assert report["experiment_moduli_gpa"]["e_star"] == pytest.approx(experiment_moduli()["e_star"])
    c11 = report["potential"]["elastic"]["cij_gpa"]["C11"]
    assert now["cij_rel"]["C11"] == pytest.approx(
        c11 / reference.QUARTZ_CIJ_EXPERIMENT_GPA["C11"] - 1
    )
