"""The Python door (flatcontact.notebook): a scan with the calculator in hand, checked against
the same energies computed directly with ASE, a resume that computes nothing, the contact on
the fitted laws, and the module's own examples run as doctests."""

from __future__ import annotations

import doctest

import numpy as np
import pytest
from ase.build import fcc111
from ase.calculators.emt import EMT

import flatcontact
from flatcontact import notebook
from flatcontact.foundation.errors import InputError
from flatcontact.structures.assemble import make_interface

Z = [10.3, 10.45, 10.6]


@pytest.fixture(scope="module")
def interface():
    slab = fcc111("Cu", size=(1, 1, 3), a=3.59, orthogonal=False, periodic=True)
    return make_interface(slab, gap_angstrom=2.1, face_atoms=1)


def emt_factory(atoms=None):
    """A module-level factory: picklable, so it scans on worker processes."""
    return EMT()


def _placed(interface, shift_frac, thickness):
    """Slab 2 shifted by ``shift_frac`` of the cell and placed at ``thickness`` (surface 1 to
    surface 4, the contract's z): the rigid configuration of one grid point, by hand."""
    atoms = interface.copy()
    slab2 = atoms.arrays["slab"] == 2
    z = atoms.positions[:, 2]
    now = z[atoms.arrays["surface"] == 4].mean() - z[atoms.arrays["surface"] == 1].mean()
    lateral = shift_frac[0] * atoms.cell[0] + shift_frac[1] * atoms.cell[1]
    atoms.positions[slab2] += lateral + np.array([0.0, 0.0, thickness - now])
    return atoms


def test_a_rigid_scan_is_the_calculators_own_energy_point_by_point(interface):
    ispes = notebook.scan_interface(
        interface, EMT(), grid=(2, 2), thickness_angstrom=Z, relax_mode="rigid"
    )
    assert ispes["energy"].dims == ("shift_a", "shift_b", "thickness")
    for i, j, k in [(0, 0, 0), (1, 0, 1), (1, 1, 2)]:
        atoms = _placed(interface, (i / 2, j / 2), Z[k])
        atoms.calc = EMT()
        direct = atoms.get_potential_energy()
        stored = float(ispes["energy"].isel(shift_a=i, shift_b=j, thickness=k))
        # energies are stored relative to a reference or absolute: compare differences
        ref = _placed(interface, (0, 0), Z[0])
        ref.calc = EMT()
        e00 = float(ispes["energy"].isel(shift_a=0, shift_b=0, thickness=0))
        assert stored - e00 == pytest.approx(direct - ref.get_potential_energy(), abs=1e-6)


def test_the_store_resumes_and_another_calculator_is_refused(interface, tmp_path):
    first = notebook.scan_interface(
        interface, EMT(), grid=(2, 2), thickness_angstrom=Z, out=tmp_path
    )
    again = notebook.scan_interface(
        interface, EMT(), grid=(2, 2), thickness_angstrom=Z, out=tmp_path
    )
    np.testing.assert_array_equal(first["energy"].values, again["energy"].values)
    with pytest.raises(InputError):
        notebook.scan_interface(
            interface, EMT(), grid=(2, 2), thickness_angstrom=Z, out=tmp_path, label="other"
        )


def test_a_factory_scans_on_two_workers_like_the_object_serially(interface):
    serial = notebook.scan_interface(interface, EMT(), grid=(2, 2), thickness_angstrom=Z)
    pooled = notebook.scan_interface(
        interface, emt_factory, grid=(2, 2), thickness_angstrom=Z, workers=2
    )
    np.testing.assert_allclose(pooled["energy"].values, serial["energy"].values, atol=1e-9)


@pytest.mark.parametrize(
    ("kwargs", "named"),
    [
        ({"workers": 2}, "workers: 2 with a calculator object"),
        ({"grid": (2,)}, "grid: expected two lateral counts"),
        ({"relax_mode": "sideways"}, "relax_mode: expected one of"),
        ({"calculator": 42}, "calculator: expected an ASE calculator"),
    ],
)
def test_bad_arguments_are_one_line_naming_them(interface, kwargs, named):
    args = {"calculator": EMT(), "grid": (2, 2), "thickness_angstrom": Z, **kwargs}
    with pytest.raises(InputError, match=named):
        notebook.scan_interface(interface, **args)


def test_contact_from_laws_takes_a_fit_or_laws_json_alike():
    from flatcontact.analysis.laws import fit_load_laws

    p = np.array([0.0, 1.0, 2.0, 3.0])
    laws = fit_load_laws(p, 4.52 * p + 26.7, 0.21 * p + 11.1)
    as_json = {"k_mpa_per_gpa": 4.52, "tau0_mpa": 26.7, "mu_mpa_per_gpa": 0.21, "sigma0_mpa": 11.1}
    moduli = {"radius_um": 5.0, "contact_modulus_gpa": 52.5, "shear_modulus_gpa": 29.0}
    a = notebook.contact_from_laws(laws, [1.0], **moduli).records()[0]
    b = notebook.contact_from_laws(as_json, [1.0], **moduli).records()[0]
    # the paper's contact at p0 = 1 GPa: a = 149.6 nm (Hertz, a = pi p0 R / (2 E*))
    assert a["contact_radius_nm"] == pytest.approx(np.pi * 1.0 * 5000.0 / (2 * 52.5), rel=1e-9)
    assert a["contact_radius_nm"] == pytest.approx(149.6, abs=0.05)
    assert a["peak_lateral_force_un"] == pytest.approx(b["peak_lateral_force_un"], rel=1e-9)
    with pytest.raises(InputError, match="laws: missing tau0_mpa"):
        notebook.contact_from_laws({"k_mpa_per_gpa": 1.0}, [1.0], **moduli)


def test_contact_from_laws_takes_one_p0_and_refuses_a_law_that_is_no_number():
    as_json = {"k_mpa_per_gpa": 4.52, "tau0_mpa": 26.7, "mu_mpa_per_gpa": 0.21, "sigma0_mpa": 11.1}
    moduli = {"radius_um": 5.0, "contact_modulus_gpa": 52.5, "shear_modulus_gpa": 29.0}
    one = notebook.contact_from_laws(as_json, 1.0, **moduli).records()
    assert len(one) == 1
    assert one[0] == notebook.contact_from_laws(as_json, [1.0], **moduli).records()[0]
    assert one[0]["contact_radius_nm"] == pytest.approx(np.pi * 5000.0 / (2 * 52.5), rel=1e-9)
    for bad in ("fast", [1.0, 2.0]):
        with pytest.raises(InputError) as info:
            notebook.contact_from_laws({**as_json, "tau0_mpa": bad}, [1.0], **moduli)
        assert str(info.value) == f"laws: tau0_mpa: expected a number, got {bad!r}"


def test_the_public_names_and_the_module_examples():
    assert flatcontact.scan_interface is notebook.scan_interface
    assert flatcontact.contact_from_laws is notebook.contact_from_laws
    failed, attempted = doctest.testmod(notebook, optionflags=doctest.ELLIPSIS)
    assert attempted >= 5 and failed == 0


# ---- a calculator that cannot evaluate: one line, before any work or naming the point -----


@pytest.fixture(scope="module")
def quartz_interface():
    """Two 2-cell α-quartz (0001) slabs: Si and O, which ASE's EMT has no parameters for."""
    from ase.build import surface

    from flatcontact.structures.bulk import alpha_quartz

    slab = surface(alpha_quartz(), (0, 0, 1), 2, vacuum=None, periodic=True)
    return make_interface(slab, gap_angstrom=2.5, face_atoms=3)


def test_emt_on_quartz_is_one_line_naming_the_calculator_before_any_work(
    quartz_interface, tmp_path, monkeypatch
):
    from flatcontact.ispes import scan as scan_module
    from flatcontact.ispes.geometry import thickness
    from flatcontact.potentials.guarded import CalculatorFailure

    def must_not_run(*args, **kwargs):
        raise AssertionError("the scan started: the calculator was not evaluated first")

    monkeypatch.setattr(scan_module, "run_scan", must_not_run)
    out = tmp_path / "scan"
    z = [thickness(quartz_interface)]
    with pytest.raises(CalculatorFailure) as info:
        notebook.scan_interface(quartz_interface, EMT(), grid=(3, 3), thickness_angstrom=z, out=out)
    failure = info.value
    assert str(failure) == (
        "calculator 'EMT' failed on the elements Si, O (NotImplementedError: No EMT-potential "
        "for Si)"
    )
    assert failure.elements == ("Si", "O") and "emt.py" in failure.detail
    assert not out.exists()


@pytest.mark.parametrize(
    ("calculator", "said"),
    [
        ("vashishta", "calculator: potential 'vashishta' has no parameters for element(s) ['Cu']"),
        (
            "ase:ase.calculators.lj:LennardJones",
            None,  # evaluates: Lennard-Jones knows every element
        ),
    ],
)
def test_a_model_by_name_is_evaluated_first_too(interface, calculator, said):
    if said is None:
        ds = notebook.scan_interface(
            interface, calculator, grid=(2, 2), thickness_angstrom=Z, relax_mode="rigid"
        )
        assert np.isfinite(ds["energy"].values).all()
        return
    with pytest.raises(InputError) as info:
        notebook.scan_interface(interface, calculator, grid=(2, 2), thickness_angstrom=Z)
    assert str(info.value).startswith(said)


def _boom(atoms=None):
    raise ValueError("sigma must be positive\nsee the manual")


def _nothing(atoms=None):
    return None


@pytest.mark.parametrize(
    ("factory", "said"),
    [
        (_boom, "calculator: factory '_boom' failed: ValueError: sigma must be positive"),
        (_nothing, "calculator: factory '_nothing' returned NoneType, expected an ASE calculator"),
    ],
)
def test_a_factory_that_fails_is_one_line_naming_it(interface, factory, said):
    with pytest.raises(InputError) as info:
        notebook.scan_interface(interface, factory, grid=(2, 2), thickness_angstrom=Z)
    assert str(info.value).startswith(said) and "\n" not in str(info.value)


def test_a_failure_mid_scan_is_one_line_naming_the_point(tmp_path):
    """The toy model that raises once the slabs are pressed closer than 2.1 Å: its one
    evaluation of the reference passes, a compressed point fails."""
    from tests.hardening.failing_calculators import FailsWhenPressed

    from flatcontact.potentials.guarded import CalculatorFailure
    from flatcontact.structures.toy import toy_interface

    calc = FailsWhenPressed(fail_gap_angstrom=2.1)
    with pytest.raises(CalculatorFailure) as info:
        notebook.scan_interface(
            toy_interface(layers=3), calc, grid=(2, 2), p_range_gpa=(0, 1, 3), out=tmp_path
        )
    text = str(info.value)
    assert "point at shift (" in text and "thickness " in text
    assert ": calculator 'FailsWhenPressed' failed on the element Ar (RuntimeError: gap " in text
    assert text.endswith("outside the fitted range)") and "\n" not in text
    assert "see the model card" in info.value.detail
