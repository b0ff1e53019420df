"""The contact stage's comparison with the paper's experiment: flatcontact's own quartz laws
and the collapse stress of a run against the measured ones (``contact.experiment.compare``),
and the measured curves of ``contact.fit`` with their start-of-run check.
Moved out of :mod:`flatcontact.stages.contact`, which re-exports these names."""

from __future__ import annotations

from pathlib import Path

from flatcontact.foundation.errors import InputError
from flatcontact.foundation.reference import PAPER, PAPER_EXPERIMENT_COLLAPSE_MPA, PAPER_LAW_KEYS
from flatcontact.stages._common import rename

#: flatcontact's own α-quartz laws, a data file with its provenance: ``flatcontact run`` on
#: the built-in default (quick preset, ``make run``), its ``04-laws/laws.json``. Its content is
#: part of the contact stage's fingerprint when the experiment comparison quotes it.
QUARTZ_QUICK_LAWS_FILE = (
    Path(__file__).resolve().parents[1] / "data" / "measured" / "quartz_quick_laws.json"
)


def quartz_quick_laws() -> dict:
    """The quick preset's quartz laws of :data:`QUARTZ_QUICK_LAWS_FILE` (``label``, the four
    numbers of :data:`~flatcontact.foundation.reference.PAPER_LAW_KEYS`, ``source``).

    Raises
    ------
    InputError
        The package's data file is not what it claims (a damaged install): names the file and
        the key.
    """
    import json

    from flatcontact.foundation.result_json import ContractError, check_keys

    doc = json.loads(QUARTZ_QUICK_LAWS_FILE.read_text(encoding="utf-8"))
    try:
        check_keys(doc, {key: "number" for key in PAPER_LAW_KEYS}, {"label": "text"})
    except ContractError as exc:
        raise InputError(f"{QUARTZ_QUICK_LAWS_FILE.name}: {exc}") from None
    return doc


def quartz_reference_laws() -> dict[str, dict[str, float]]:
    """The quartz law sets the experiment comparison sets a run against: the paper's
    (:data:`flatcontact.foundation.reference.PAPER`) and flatcontact's quick preset
    (:func:`quartz_quick_laws`)."""
    quick = quartz_quick_laws()
    return {
        "quartz, the paper's laws (SNAP + TS-vdW LJ)": {k: PAPER[k] for k in PAPER_LAW_KEYS},
        quick["label"]: {k: float(quick[k]) for k in PAPER_LAW_KEYS},
    }


def experiment_comparison(settings, params, contact_p0_gpa: float | None = None) -> dict:
    """``summary.json["experiment_comparison"]`` for ``contact.experiment.compare``: the run's
    collapse stress at ``contact.experiment.p0_gpa`` against the measured collapses
    (:data:`flatcontact.foundation.reference.PAPER_EXPERIMENT_COLLAPSE_MPA`) and the quartz laws'
    (:func:`flatcontact.contact.tip_comparison.compare_collapse`), the model evaluated at
    ``contact_p0_gpa`` (the adhesive contact's p1 of that p0, as ``contact.nc``; None: Hertz)."""
    from flatcontact.contact.tip_comparison import compare_collapse

    c = settings.contact
    doc = compare_collapse(
        settings.report.title or settings.structure.kind,
        params,
        c.experiment.p0_gpa,
        PAPER_EXPERIMENT_COLLAPSE_MPA,
        quartz_reference_laws(),
        fraction=c.collapse_fraction,
        contact_p0_gpa=contact_p0_gpa,
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
