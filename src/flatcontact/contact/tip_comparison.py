"""A computed interface against the paper's oscillatory-shear experiment: collapse stresses.

The experiment (the paper's Fig. 6) drives a diamond tip (R = 5 µm) laterally under load
control at p0 = 1.77 GPa and reads where the lateral stiffness collapses, as a mean shear
stress (force amplitude over the Hertz area). The model side uses the same criterion as
:func:`flatcontact.contact.experiment.model_collapse_stress`: the amplitude stress
Q_max/(π a²) at which d⟨Q⟩/d⟨u⟩ first falls to ``fraction`` (0.2) of its initial value.

With adhesion the contact stage evaluates the model at the adhesive contact's peak pressure
p1 (:mod:`flatcontact.contact.adhesion_regime`: the Hertzian part over the adhesive radius,
what ``contact.nc`` stores at the given p0); ``contact_p0_gpa`` puts the run's row at that
same p1, so its collapse stress is the one read off the run's own stiffness curve; the
quartz references stay in the paper's adhesion-free contact at p0.

That stress depends on p0 and the load laws (k, τ0, μ, σ0) alone: the Hertz pressure
p(r) = p0 √(1 − r²/a²) and the full-stick traction q0/√(1 − r²/a²) are functions of r/a, so
E*, G* and R fix the scale of a and u but cancel out of Q/(π a²) and of k/k0.

:func:`compare_collapse` evaluates it for the run's laws and for reference law sets (the
quartz laws) at the experiment's p0, and sets each against the measured collapses.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from flatcontact.contact import mindlin
from flatcontact.contact.experiment import model_collapse_stress
from flatcontact.contact.parameters import ContactParameters
from flatcontact.foundation import units

#: The law coefficients a reference law set carries.
LAW_KEYS = ("k_mpa_per_gpa", "tau0_mpa", "mu_mpa_per_gpa", "sigma0_mpa")


def collapse_row(label: str, p0_gpa: float, params: ContactParameters, fraction: float) -> dict:
    """One model row: the laws, the collapse stress (amplitude, MPa) and the effective shear
    strength Q_peak/(π a²) (MPa) at the peak pressure ``p0_gpa`` the model is evaluated at
    (the adhesive contact's p1 where there is adhesion) with ``params``."""
    p0_pa = params.check_p0_gpa(p0_gpa, "contact.experiment.p0_gpa")[0] * units.GPA_TO_PA
    radius_m = float(mindlin.contact_radius(p0_pa, params))
    area = np.pi * radius_m**2
    peak = float(mindlin.peak_force(p0_pa, params).force_n)
    return {
        "label": label,
        **{key: float(getattr(params, key)) for key in LAW_KEYS},
        "collapse_stress_mpa": model_collapse_stress(p0_pa, params, fraction=fraction)
        / units.MPA_TO_PA,
        "effective_shear_strength_mpa": peak / area / units.MPA_TO_PA,
        "contact_radius_nm": radius_m / units.NM_TO_M,
    }


def compare_collapse(
    label: str,
    params: ContactParameters,
    p0_gpa: float,
    measured_mpa: Mapping[str, float],
    references: Mapping[str, Mapping[str, float]],
    *,
    fraction: float = 0.2,
    contact_p0_gpa: float | None = None,
) -> dict:
    """The run's collapse stress at ``p0_gpa`` next to the measured ones and reference laws.

    Parameters
    ----------
    label : the run's interface (its report title)
    params : the run's contact parameters (its laws, moduli, R)
    p0_gpa : the experiment's peak Hertz pressure (GPa)
    measured_mpa : measured collapse stresses (MPa, amplitude), by contact
    references : law sets (k, τ0, μ, σ0 in MPa/GPa and MPa) by label, evaluated with the
        run's R, E*, G* (which cancel out of the collapse stress)
    fraction : the collapse criterion, k < fraction·k0
    contact_p0_gpa : the peak pressure (GPa) the run's row is evaluated at for ``p0_gpa``:
        its adhesive contact's p1 (:func:`flatcontact.stages.contact_range.contact_p0_gpa`),
        as in its ``contact.nc``; None: ``p0_gpa`` (Hertz). The reference rows stay at the
        Hertz ``p0_gpa``: the quartz laws in the paper's adhesion-free model, where R, E*
        and G* cancel out, the same for every run (the run's adhesion is its interface's)

    Returns
    -------
    dict
        ``p0_gpa``, ``contact_p0_gpa`` (the p1 evaluated at), ``collapse_fraction``,
        ``stress_measure`` ("amplitude"), ``run`` (the
        row of :func:`collapse_row` with ``ratio_to_measured``: run/measured per contact),
        ``references`` (rows, same keys), ``measured_mpa``.
    """
    measured = {k: float(v) for k, v in measured_mpa.items()}
    p1_gpa = float(p0_gpa if contact_p0_gpa is None else contact_p0_gpa)

    def with_ratios(row: dict) -> dict:
        row["ratio_to_measured"] = {k: row["collapse_stress_mpa"] / v for k, v in measured.items()}
        return row

    return {
        "p0_gpa": float(p0_gpa),
        "contact_p0_gpa": p1_gpa,
        "collapse_fraction": float(fraction),
        "stress_measure": "amplitude",
        "criterion": f"amplitude stress Q_max/(pi a^2) where d<Q>/d<u> first falls to "
        f"{fraction:g} x its initial value (load control)",
        "measured_mpa": measured,
        "run": with_ratios(collapse_row(label, p1_gpa, params, fraction)),
        "references": [
            with_ratios(
                collapse_row(
                    name, p0_gpa, params.replace(**{k: laws[k] for k in LAW_KEYS}), fraction
                )
            )
            for name, laws in references.items()
        ],
    }
