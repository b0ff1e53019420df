"""The comparison's continuum side against the contact stage's own model and closed forms."""

import numpy as np
import pytest

from flatcontact.asperity import compare
from flatcontact.contact import line_contact as lc
from flatcontact.contact import mindlin
from flatcontact.contact.parameters import ContactParameters

PARAMS = ContactParameters()  # the paper's laws
LAWS = compare.Laws(PARAMS.k_mpa_per_gpa, PARAMS.tau0_mpa, PARAMS.mu_mpa_per_gpa, PARAMS.sigma0_mpa)


@pytest.mark.parametrize("p0_gpa", [0.5, 1.77, 3.0])
def test_the_radial_pointwise_model_on_hertz_is_the_contact_stages_model(p0_gpa):
    p0 = p0_gpa * 1e9
    a = float(mindlin.contact_radius(p0, PARAMS))
    r = a * np.sin(np.linspace(0, np.pi / 2, 4001))
    p = p0 * np.sqrt(np.clip(1 - (r / a) ** 2, 0, None))
    q0 = np.linspace(0, 1.5 * float(LAWS.point_laws().tau_pa(p0)), 6001)
    load, _ = compare._sphere_pointwise(r, p, a, LAWS.point_laws(), q0)
    peak = mindlin.peak_force(p0, PARAMS)
    assert load.max() == pytest.approx(float(peak.force_n), rel=2e-3)
    # Q(u) at a few u: the model's q0 = G* u / (π a)
    u = np.array([0.2, 0.5, 1.0]) * float(peak.displacement_m)
    q0_u = PARAMS.shear_modulus_pa * u / (np.pi * a)
    mine, _ = compare._sphere_pointwise(r, p, a, LAWS.point_laws(), q0_u)
    theirs = mindlin.lateral_force(u, p0, PARAMS)
    assert mine == pytest.approx(theirs.lateral_force_n, rel=2e-3)
    stick = [compare._sphere_pointwise(r, p, a, LAWS.point_laws(), [q])[1][0] for q in q0_u]
    assert stick == pytest.approx(theirs.stick_radius_m, rel=5e-3, abs=2e-3 * a)


def test_the_line_curve_is_the_pointwise_line_model_times_the_axis():
    a, p0, axis = 2e-9, 1e9, 5e-10
    prof = lc.hertz_profile(a, p0)
    qfs, q, edge = compare._curve("cylinder", prof.x_m, prof.p_pa, a, LAWS.point_laws(), axis)
    direct = lc.pointwise_response(prof, LAWS.point_laws(), qfs / axis)
    assert q == pytest.approx(direct.lateral_n_per_m * axis)
    assert edge == pytest.approx(direct.stick_half_width_m)
