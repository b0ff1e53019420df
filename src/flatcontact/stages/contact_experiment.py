"""The contact stage's comparison with the paper's experiment: flatcontact's own quartz laws
and the collapse stress of a run against the measured ones (``contact.experiment.compare``).
Moved out of :mod:`flatcontact.stages.contact`, which re-exports these names."""

from __future__ import annotations

from flatcontact.reference import PAPER, PAPER_EXPERIMENT_COLLAPSE_MPA, PAPER_LAW_KEYS

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
