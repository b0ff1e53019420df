"""The contact stage's comparison with the paper's experiment: flatcontact's own quartz laws
and the collapse stress of a run against the measured ones (``contact.experiment.compare``),
and the measured curves of ``contact.fit`` with their start-of-run check.
Moved out of :mod:`flatcontact.stages.contact`, which re-exports these names."""

from __future__ import annotations

from flatcontact.errors import InputError
from flatcontact.reference import PAPER, PAPER_EXPERIMENT_COLLAPSE_MPA, PAPER_LAW_KEYS
from flatcontact.stages._common import rename

#: flatcontact's own α-quartz laws: ``flatcontact run`` on the built-in default (quick preset,
#: ``make run``; bundled sio2-snap + Hamaker LJ, (0001) dense interface), its
#: ``04-laws/laws.json`` (the same before and after issue 20, re-measured 2026-11-25; the check
#: every branch keeps). Code, not a data file, so a change reruns the contact stage.
QUARTZ_QUICK_LAWS = {
    "label": "quartz, flatcontact quick preset (make run)",
    "k_mpa_per_gpa": 14.370389,
    "tau0_mpa": 30.503874,
    "mu_mpa_per_gpa": 4.99966,
    "sigma0_mpa": 7.014888,
}


def quartz_reference_laws() -> dict[str, dict[str, float]]:
    """The quartz law sets the experiment comparison sets a run against: the paper's
    (:data:`flatcontact.reference.PAPER`) and flatcontact's quick preset
    (:data:`QUARTZ_QUICK_LAWS`)."""
    return {
        "quartz, the paper's laws (SNAP + TS-vdW LJ)": {k: PAPER[k] for k in PAPER_LAW_KEYS},
        QUARTZ_QUICK_LAWS["label"]: {k: float(QUARTZ_QUICK_LAWS[k]) for k in PAPER_LAW_KEYS},
    }


def experiment_comparison(settings, params) -> dict:
    """``summary.json["experiment_comparison"]`` for ``contact.experiment.compare``: the run's
    collapse stress at ``contact.experiment.p0_gpa`` against the measured collapses
    (:data:`flatcontact.reference.PAPER_EXPERIMENT_COLLAPSE_MPA`) and the quartz laws'
    (:func:`flatcontact.contact.tip_comparison.compare_collapse`)."""
    from flatcontact.contact.tip_comparison import compare_collapse

    c = settings.contact
    doc = compare_collapse(
        settings.report.title or settings.structure.kind,
        params,
        c.experiment.p0_gpa,
        PAPER_EXPERIMENT_COLLAPSE_MPA,
        quartz_reference_laws(),
        fraction=c.collapse_fraction,
    )
    doc["experiment"] = c.experiment.compare
    return doc


def check_fit_settings(settings) -> None:
    """``contact.fit`` checked at the start of a run, before the laws exist (names freed and
    fixed, files readable, load columns): the loads of a normal-load column are converted with
    the configured R and E* here; the stage converts them again with the run's moduli."""
    from flatcontact.contact.parameters import ContactParameters

    c = settings.contact
    if c.fit.csv:
        start = ContactParameters(
            radius_um=c.radius_um,
            contact_modulus_gpa=c.contact_modulus_gpa,
            shear_modulus_gpa=c.shear_modulus_gpa,
        )
        fit_curves(settings, start)


def fit_curves(settings, params) -> list:
    """The measured curves of ``contact.fit.csv`` (validated with the parameter names, before
    any work): :func:`flatcontact.contact.measured.load_fit_data`, ``check_free_fixed``."""
    from flatcontact.contact import fit, measured

    c = settings.contact
    try:
        fit.check_free_fixed(c.fit.free, c.fit.fixed, "modified")
    except InputError as exc:
        where = "contact.fit.fixed" if "fixed" in str(exc) else "contact.fit.free"
        raise InputError(f"{where}: {exc} (contact.fit.free = {list(c.fit.free)})") from None
    try:
        return measured.load_fit_data(c.fit.csv, params, c.fit.p0_gpa)
    except InputError as exc:
        text = rename(str(exc), {"fit_p0_gpa": "contact.fit.p0_gpa"})
        raise InputError(f"contact.fit.csv: {text}") from None
