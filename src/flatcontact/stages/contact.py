"""Stage 6, contact: the modified Mindlin contact at every ``contact.p0_gpa``.

Files: ``contact.nc`` (Q(u) and stiffness curves, per-p0 scalars), ``summary.json``
(:meth:`ContactResult.to_json`: parameters and where each comes from, conventions, the
per-p0 results, the same with the paper's laws, and the measured-data comparison) and the
figures ``fig4_traction``, ``fig5_force_stiffness`` (amplitude), ``fig5_force_stiffness_rms``
and, with ``contact.experiment.csv``, ``fig6_experiment`` (PNG, + SVG with ``report.svg``).

With ``contact.cycle.enabled`` the steady load-controlled cycle of ``contact.cycle.model`` at the
force amplitudes ``contact.cycle.amplitude_fractions`` (or ``amplitudes_un``) of every p0:
``summary.json`` gains ``cycle`` (one row per p0 and amplitude: W per cycle, lock-in k′ =
Q_amp/u′₁, quadrature u″₁, ...), ``contact.nc`` the loops (``cycle_*`` variables), Fig. 5b and
the Fig. 6 overlay the lock-in curve next to the paper's d⟨Q⟩/d⟨u⟩, plus ``fig5c_cycle_loops``
and ``fig6_lockin`` (lock-in vs the paper's construction, loss tangent). With
``contact.fit.csv`` the multi-load least-squares fit of the measured curves (modified and
classical model on the same data, :func:`flatcontact.contact.fit.fit_and_compare`) goes to
``fit.json`` (also ``summary.json`` ``fit``) and ``fig6_fit``.

Fig. 4 is drawn at 60 % of the displacement at the peak force
(:data:`flatcontact.plots.contact.FIG4_FRACTION_OF_PEAK`) at p0 = 1 GPa (or the first p0),
so both the stick and the slip zone show whatever the laws.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

import numpy as np

from flatcontact.config.contact import ContactConfig
from flatcontact.contact.parameters import ContactParameters
from flatcontact.foundation.errors import InputError
from flatcontact.foundation.fileio import atomic_path, file_sha256, write_json_atomic
from flatcontact.foundation.layout import (
    CONTACT_NC,
    FIG4_TRACTION,
    FIG5_FORCE_STIFFNESS,
    FIG5_FORCE_STIFFNESS_RMS,
    FIG5C_CYCLE_LOOPS,
    FIG6_EXPERIMENT,
    FIG6_FIT,
    FIG6_LOCKIN,
    FIG_SLIP_SIZE,
    FIT_JSON,
    SUMMARY_JSON,
)
from flatcontact.foundation.reference import PAPER, PAPER_LAW_KEYS, is_paper_material
from flatcontact.stages._common import renamed_errors, save
from flatcontact.stages.contact_experiment import (  # noqa: F401  (re-exported)
    QUARTZ_QUICK_LAWS_FILE,
    check_fit_settings,
    experiment_comparison,
    fit_curves,
    quartz_quick_laws,
    quartz_reference_laws,
)

#: ContactParameters fields -> the settings path that sets them: the fields the ``contact``
#: section has under the same name (R, E*, G*, the four law coefficients, w).
SETTINGS_NAMES = {
    f.name: f"contact.{f.name}"
    for f in fields(ContactParameters)
    if f.name in ContactConfig.model_fields
}


#: Cycle library parameter names -> the settings path that sets them.
CYCLE_NAMES = {
    "lateral_force_amplitude_un": "contact.cycle.amplitudes_un",
    "amplitude_fraction": "contact.cycle.amplitude_fractions",
    "p0_gpa": "contact.p0_gpa",
    **{k: v for k, v in SETTINGS_NAMES.items() if k != "radius_um"},
}


@dataclass(frozen=True)
class ContactInputs:
    """What the contact model takes from upstream stages (all optional).

    ``laws``: ``laws.json`` of the laws stage (k, τ0, μ, σ0 where ``contact`` gives none);
    ``work_of_separation_j_per_m2``: the scan's (w where ``contact.work_of_adhesion_j_per_m2``
    is null; ``from_scan`` says a scan was read); ``moduli``: ``elastic.json`` of the elastic
    stage (E*, G* replacing ``contact.contact_modulus_gpa``/``shear_modulus_gpa``);
    ``gates``: the validity gates' report (:meth:`flatcontact.analysis.gates.GateReport.to_json`,
    :mod:`flatcontact.stages.gates`), recorded in ``summary.json["gates"]``; ``interface``:
    the run's facts for the contact's range (:func:`flatcontact.stages.contact_range.facts`).
    """

    laws: dict | None = None
    work_of_separation_j_per_m2: float | None = None
    from_scan: bool = False
    moduli: dict | None = None
    gates: dict | None = None
    interface: dict | None = None


def contact_parameters(settings, inputs: ContactInputs):
    """The :class:`~flatcontact.contact.parameters.ContactParameters` and their provenance.

    k, τ0, μ, σ0 come from ``contact`` where given, else from the fitted laws; w is
    ``contact.work_of_adhesion_j_per_m2`` or the scan's work of separation; E*, G* come from the
    elastic stage when it ran. Errors name the settings path (``contact.tau0_mpa``).
    """
    from flatcontact.contact.parameters import ContactParameters

    c = settings.contact
    laws = inputs.laws or {}
    provenance: dict[str, str] = {}
    values = {}
    for key in PAPER_LAW_KEYS:
        given = getattr(c, key)
        if given is not None:
            values[key], provenance[key] = given, "config"
            continue
        fitted = laws.get(key)
        if fitted is None:
            why = "; ".join(laws.get("warnings", [])) or "too few loads"
            if inputs.laws is None:
                why = "no fitted laws were given"
            raise InputError(
                f"contact.{key}: the load law could not be fitted ({why}); give contact.{key}"
            )
        # negative slopes pass through: the model takes k < 0, μ < 0 wherever τ > 0
        # and σ >= 0 on the contact, and refuses the p0 where they are not
        values[key], provenance[key] = fitted, "fitted laws"
    w = c.work_of_adhesion_j_per_m2
    provenance["work_of_adhesion_j_per_m2"] = "config"
    if w is None:
        w = inputs.work_of_separation_j_per_m2
        provenance["work_of_adhesion_j_per_m2"] = "scan work of separation"
        if w is None or not w > 0:
            why = "none (no probe column)" if inputs.from_scan else "none"
            w, provenance["work_of_adhesion_j_per_m2"] = 0.0, why
    e_star, g_star = c.contact_modulus_gpa, c.shear_modulus_gpa
    provenance["moduli"] = "config"
    if inputs.moduli is not None:
        e_star, g_star = inputs.moduli["contact_modulus_gpa"], inputs.moduli["shear_modulus_gpa"]
        provenance["moduli"] = "elastic stage"
    try:
        with renamed_errors(SETTINGS_NAMES):
            params = ContactParameters(
                radius_um=c.radius_um,
                contact_modulus_gpa=e_star,
                shear_modulus_gpa=g_star,
                work_of_adhesion_j_per_m2=float(w),
                **values,
            )
    except InputError as exc:  # e.g. a fitted τ0 < 0, or k < 0 with τ0 = 0
        sources = ", ".join(f"contact.{k} from {provenance[k]}" for k in values)
        raise InputError(f"{exc} ({sources})") from None
    return params, provenance


def moduli_given(settings) -> bool:
    """Whether the run sets E* and G* itself: the elastic stage, or both contact moduli given."""
    given = settings.contact.model_fields_set
    return settings.elastic.enabled or {"contact_modulus_gpa", "shear_modulus_gpa"} <= given


def check_moduli_source(settings, elements=None) -> None:
    """Refuse, before any work, a material other than α-quartz that would take the quartz E*, G*.

    The contact defaults (E* = 52.5 GPa, G* = 29 GPa) are the paper's α-quartz values; for
    another material the run needs ``elastic.enabled: true`` (the moduli of its bulk crystal
    with its own potential) or both ``contact.contact_modulus_gpa`` and
    ``contact.shear_modulus_gpa``.
    """
    if moduli_given(settings) or is_paper_material(settings, elements):
        return
    what = f"structure.kind={settings.structure.kind}"
    if elements is not None:
        what += f" ({'-'.join(sorted(elements))})"
    raise InputError(
        f"contact.contact_modulus_gpa/shear_modulus_gpa: {what} is not the paper's alpha-quartz, "
        "whose E* and G* are the defaults; give both moduli (GPa) or set elastic.enabled: true"
    )


def check_cycle(settings, params) -> None:
    """The cycle request of ``contact`` (model, amplitudes below gross sliding at every p0,
    σ <= τ on the contact): one line naming the setting, before any work."""
    from flatcontact.contact import cycle

    c = settings.contact
    with renamed_errors(CYCLE_NAMES):
        cycle.validate_cycle_request(
            c.p0_gpa,
            params,
            c.cycle.model,
            amplitudes_un=c.cycle.amplitudes_un,
            amplitude_fractions=None if c.cycle.amplitudes_un else c.cycle.amplitude_fractions,
        )


def law_half_widths_used(inputs: ContactInputs, provenance: dict) -> dict[str, float]:
    """Half-widths of the law coefficients the contact model takes from the fitted laws
    (``laws.json`` ``half_widths`` of its configured energy form); 0 for a coefficient set
    in ``contact`` (a given number has no fit, convergence or model error here)."""
    laws = inputs.laws or {}
    form = laws.get("energy_form")
    hw = (laws.get(form) or {}).get("half_widths", {}) if form else {}
    return {
        key: float(hw.get(key) or 0.0) if provenance.get(key) == "fitted laws" else 0.0
        for key in PAPER_LAW_KEYS
    }


#: The parts of a law coefficient's uncertainty (``laws.json`` ``intervals.<c>.components``).
COMPONENTS = ("fit", "convergence", "models", "grid")


def law_components_used(inputs: ContactInputs, provenance: dict) -> dict[str, dict[str, float]]:
    """Per part (fit, convergence, models, grid) the half-widths of the law coefficients the contact
    model takes from the fitted laws: coverage × the part (``laws.json`` ``intervals`` of the
    configured form, :func:`flatcontact.analysis.uncertainty.law_components`); 0 for a
    coefficient set in ``contact``. ``{}`` when laws.json carries no convergence, model or grid
    part (the fit alone: nothing to split)."""
    laws = inputs.laws or {}
    form = laws.get("energy_form")
    intervals = (laws.get(form) or {}).get("intervals", {}) if form else {}
    coverage = float((laws.get("uncertainty") or {}).get("coverage", 1.0))
    out = {part: dict.fromkeys(PAPER_LAW_KEYS, 0.0) for part in COMPONENTS}
    for key in PAPER_LAW_KEYS:
        parts = (intervals.get(key) or {}).get("components")
        if parts and provenance.get(key) == "fitted laws":
            for part in COMPONENTS:
                out[part][key] = coverage * float(parts.get(part) or 0.0)
    if not any(v for part in COMPONENTS[1:] for v in out[part].values()):
        return {}
    return out


def contact_intervals(
    settings, params, half_widths: dict[str, float], components: dict | None = None, p0c=None
) -> dict:
    """Intervals of the effective shear strength Q_peak/πa², the collapse stress (stiffness
    at ``contact.collapse_fraction``·k0) and the knee (``knee_fraction``·k0), amplitude stress,
    at every p0, over the box of the law coefficients ± ``half_widths``
    (:func:`flatcontact.analysis.uncertainty.propagate_box`; τ0 and σ0 clipped at 0).

    Returns ``{"half_widths", "method", "results": [{"p0_gpa", <quantity>: {"low", "value",
    "high"}}]}``, or with ``"unavailable"`` (the reason) when a corner of the box leaves the
    model's domain (e.g. τ(centre) <= 0 for k < 0). With ``components`` (part -> coefficient
    -> half-width, :func:`law_components_used`) each quantity also carries
    ``components: {part: [low, high]}``, the interval over the box of that part alone, and the
    document ``component_half_widths``. ``p0c``: the peak pressures the model is evaluated
    at (the adhesive contact, :func:`flatcontact.stages.contact_range.contact_p0_gpa`).
    """
    from flatcontact.analysis.uncertainty import propagate_box
    from flatcontact.contact import experiment, mindlin, oscillation
    from flatcontact.foundation import units

    c = settings.contact
    p0s = [float(p) for p in c.p0_gpa]
    names = ("effective_shear_strength_mpa", "collapse_stress_mpa", "knee_stress_amplitude_mpa")

    def outputs(x: dict[str, float]) -> dict[str, float]:
        prm = params.replace(**x)
        out = {}
        for i, p0 in enumerate(p0c or p0s):
            pa = p0 * units.GPA_TO_PA
            area = np.pi * float(mindlin.contact_radius(pa, prm)) ** 2
            peak = float(mindlin.peak_force(pa, prm).force_n)
            knee = oscillation.amplitude_at_stiffness_fraction(pa, prm, c.knee_fraction)
            collapse = experiment.model_collapse_stress(pa, prm, fraction=c.collapse_fraction)
            out[(i, names[0])] = peak / area / units.MPA_TO_PA
            out[(i, names[1])] = collapse / units.MPA_TO_PA
            out[(i, names[2])] = knee / area / units.MPA_TO_PA
        return out

    doc: dict = {
        "half_widths": dict(half_widths),
        "method": "box of the law coefficients +- half-width (laws.json), every corner "
        "evaluated; tau0, sigma0 clipped at 0; amplitude stresses",
    }
    central = {k: float(getattr(params, k)) for k in PAPER_LAW_KEYS}
    try:
        box = propagate_box(outputs, central, half_widths, nonnegative=("tau0_mpa", "sigma0_mpa"))
    except InputError as exc:
        doc["unavailable"] = str(exc)
        return doc
    doc["results"] = [
        {
            "p0_gpa": p0,
            **{n: dict(zip(("low", "value", "high"), box[(i, n)], strict=True)) for n in names},
        }
        for i, p0 in enumerate(p0s)
    ]
    if components:
        doc["component_half_widths"] = components
        for part, hw in components.items():
            # each part's box lies inside the full one (part <= the quadrature sum): in domain
            sub = propagate_box(outputs, central, hw, nonnegative=("tau0_mpa", "sigma0_mpa"))
            for i, row in enumerate(doc["results"]):
                for n in names:
                    row[n].setdefault("components", {})[part] = [sub[(i, n)][0], sub[(i, n)][2]]
    return doc


def check_contact(settings, params) -> None:
    """Everything the contact stage refuses, before any work (one line naming the setting)."""
    c = settings.contact
    if c.cycle.enabled:
        check_cycle(settings, params)
    if c.fit.csv:
        fit_curves(settings, params)
    # with k < 0 or μ < 0 the model is defined only where τ > 0 and σ >= 0 on the whole
    # contact (p0 < τ0/|k|, p0 <= σ0/|μ|)
    params.check_p0_gpa(c.p0_gpa, "contact.p0_gpa")
    if c.experiment.csv or c.experiment.compare:
        params.check_p0_gpa(c.experiment.p0_gpa, "contact.experiment.p0_gpa")
    if c.maugis_lambda is not None and not params.work_of_adhesion_j_per_m2 > 0:
        raise InputError(
            "contact.maugis_lambda: the Maugis–Dugdale radius needs a work of adhesion > 0 "
            "(contact.work_of_adhesion_j_per_m2, or the scan's work of separation)"
        )


@dataclass
class ContactResult:
    """The contact analysis, its parameters and provenance, and the paper-laws comparison."""

    analysis: Any  # flatcontact.contact.summary.ContactAnalysis
    params: Any
    provenance: dict
    knee_fraction: float
    paper: Any = None  # the same analysis with the paper's k, τ0, μ, σ0 (None: identical)
    experiment: dict | None = None
    cycles: tuple = ()  # flatcontact.contact.cycle.SteadyCycle per p0 (contact.cycle)
    fit: Any = None  # flatcontact.contact.fit.ModelComparison (contact.fit.csv)
    fit_files: list[dict] = field(default_factory=list)
    intervals: dict | None = None  # contact_intervals: the laws' uncertainty carried through
    bands: tuple | None = None  # analyses at the lower and upper corner of the law box
    gates: dict | None = None  # the validity gates that fired and which were overridden
    experiment_comparison: dict | None = None  # contact.experiment.compare
    adhesion: dict | None = None  # contact_range.adhesion_of(...).to_json()
    slip_size: dict | None = None  # contact_range.slip_of
    moduli_note: str | None = None  # contact_range.foreign_moduli_note
    files: list[Path] = field(default_factory=list)

    def cycle_rows(self) -> list[dict]:
        """One row per p0 and force amplitude (:func:`flatcontact.contact.cycle_output.cycle_records`)."""
        from flatcontact.contact.cycle_output import cycle_records

        pairs = zip(self.analysis.p0_gpa, self.cycles, strict=True) if self.cycles else ()
        # the cycle runs at the adhesive contact's peak pressure p1; rows keep the given p0
        return [
            {**row, "p0_gpa": p0, "contact_peak_pressure_gpa": row["p0_gpa"]}
            for p0, cyc in pairs
            for row in cycle_records([cyc])
        ]

    def fit_json(self) -> dict | None:
        """``fit.json``: both models' fitted parameters with standard errors and correlations,
        information criteria, and the fitted files with their sha256."""
        if self.fit is None:
            return None
        return {"files": self.fit_files, **self.fit.to_json()}

    def to_json(self) -> dict:
        """``summary.json``."""
        doc = {
            "parameters": self.params.as_dict(),
            "provenance": self.provenance,
            "conventions": {
                "shear_modulus": "paper: q0 = G* u/(pi a); Johnson's G*_J = G*/4",
                "effective_shear_strength_mpa": "amplitude Q_peak/(pi a^2)",
                "effective_shear_strength_rms_mpa": "Q_peak/(sqrt(2) pi a^2)",
                "knee": f"stress where d<Q>/d<u> = {self.knee_fraction:g} x initial stiffness",
            },
            "results": self.analysis.records(),
            "results_with_paper_laws": (self.paper or self.analysis).records(),
        }
        if self.experiment is not None:
            doc["experiment"] = self.experiment
        if self.experiment_comparison is not None:
            doc["experiment_comparison"] = self.experiment_comparison
        if self.intervals is not None:
            doc["intervals"] = self.intervals
        extra = {"adhesion_regime": self.adhesion, "slip_size": self.slip_size}
        doc.update({k: v for k, v in extra.items() if v is not None})
        if self.moduli_note:
            doc["moduli_note"] = self.moduli_note
        if self.gates is not None:
            doc["gates"] = self.gates
        if self.cycles:
            doc["conventions"]["cycle"] = (
                "Q(t) = Q_amp sin(theta); first harmonic u'_1 sin(theta) - u''_1 cos(theta); "
                "lockin_stiffness_n_per_m = Q_amp/u'_1 (what a lock-in amplifier reads); "
                "dissipated energy per cycle W = pi Q_amp u''_1; paper_stiffness_n_per_m = the "
                "paper's d<Q>/d<u>; "
                + (
                    "classical = Cattaneo-Mindlin with friction coefficient mu = k "
                    "(k_mpa_per_gpa x 1e-3), Johnson's G*_J = G*/4 (paper's G* = 4 G*_J)"
                    if self.cycles[0].model == "classical"
                    else "modified Mindlin, paper's G*: q0 = G* u/(pi a)"
                )
            )
            doc["cycle"] = self.cycle_rows()
        if self.fit is not None:
            doc["fit"] = self.fit_json()
        return doc


def contact_stage(
    settings, inputs: ContactInputs, folder: Path | None, progress=None
) -> ContactResult:
    """The modified Mindlin contact of ``settings.contact`` with the upstream ``inputs``."""
    from flatcontact.contact import experiment as exp
    from flatcontact.contact.measured import load_stiffness_csv
    from flatcontact.contact.summary import analyse
    from flatcontact.stages import contact_range as rng

    c = settings.contact
    params, provenance = contact_parameters(settings, inputs)
    check_contact(settings, params)
    regime = rng.adhesion_of(settings, inputs, params)  # refuses where no model applies
    p0c = rng.contact_p0_gpa(regime)
    measured = load_stiffness_csv(c.experiment.csv) if c.experiment.csv else None
    curves = fit_curves(settings, params) if c.fit.csv else None
    analysis = analyse(
        c.p0_gpa,
        params,
        maugis_lambda=c.maugis_lambda,
        knee_fraction=c.knee_fraction,
        p0_name="contact.p0_gpa",
        contact_p0_gpa=p0c,
    )
    paper_laws = {key: PAPER[key] for key in PAPER_LAW_KEYS}
    paper = None
    if any(getattr(params, k) != v for k, v in paper_laws.items()):
        paper = analyse(
            c.p0_gpa,
            params.replace(**paper_laws),
            maugis_lambda=c.maugis_lambda,
            knee_fraction=c.knee_fraction,
            contact_p0_gpa=p0c,
        )
    result = ContactResult(analysis, params, provenance, c.knee_fraction, paper)
    result.gates = inputs.gates
    result.adhesion = regime.to_json()
    result.slip_size = rng.slip_of(settings, rng.slip_interface(inputs), analysis)
    result.moduli_note = rng.foreign_moduli_note(settings, provenance, params)
    rng.log_lines(result.adhesion, result.slip_size, result.moduli_note)
    half_widths = law_half_widths_used(inputs, provenance)
    result.intervals = contact_intervals(
        settings, params, half_widths, law_components_used(inputs, provenance), p0c
    )
    if any(h > 0 for h in half_widths.values()) and "unavailable" not in result.intervals:
        result.bands = _band_analyses(settings, params, half_widths, p0c)
    comparison = None
    if measured is not None:
        comparison = exp.compare_with_measurement(
            measured,
            c.experiment.p0_gpa,
            params,
            fraction=c.collapse_fraction,
            measure=c.experiment.stress_measure,
        )
        result.experiment = comparison.to_json()
    if c.experiment.compare:
        at = rng.contact_p0_gpa(  # the adhesive contact of the experiment's p0, as contact.nc
            rng.adhesion_of(
                settings, inputs, params, [c.experiment.p0_gpa], "contact.experiment.p0_gpa"
            )
        )
        result.experiment_comparison = experiment_comparison(
            settings, params, None if at is None else at[0]
        )
    if c.cycle.enabled:
        from flatcontact.contact import cycle

        result.cycles = cycle.cycles(
            p0c or c.p0_gpa,
            params,
            c.cycle.model,
            amplitudes_un=c.cycle.amplitudes_un,
            amplitude_fractions=None if c.cycle.amplitudes_un else c.cycle.amplitude_fractions,
        )
    if curves is not None:
        from flatcontact.contact import fit

        result.fit = fit.fit_and_compare(
            curves,
            params,
            c.fit.free,
            c.fit.fixed,
            stiffness=c.fit.stiffness,
            measure=c.experiment.stress_measure,
        )
        result.fit_files = [{"name": Path(f).name, "sha256": file_sha256(f)} for f in c.fit.csv]
    if folder is not None:
        _write(result, settings, folder, measured, comparison)
    return result


def _band_analyses(settings, params, half_widths: dict[str, float], p0c=None) -> tuple | None:
    """The contact analysis at the lower and the upper corner of the law box (every
    coefficient − and + its half-width; τ0, σ0 clipped at 0): the edges of the Fig. 5 band.
    The Mindlin outputs grow with each of k, τ0, μ, σ0, so these corners bound them.
    None if a corner leaves the model's domain."""
    from flatcontact.contact.summary import analyse

    out = []
    for sign in (-1.0, 1.0):
        corner = {k: getattr(params, k) + sign * h for k, h in half_widths.items()}
        for k in ("tau0_mpa", "sigma0_mpa"):
            corner[k] = max(corner[k], 0.0)
        try:
            out.append(
                analyse(
                    settings.contact.p0_gpa,
                    params.replace(**corner),
                    knee_fraction=settings.contact.knee_fraction,
                    contact_p0_gpa=p0c,
                )
            )
        except InputError:
            return None
    return tuple(out)


def _write(result: ContactResult, settings, folder: Path, measured, comparison) -> None:
    from flatcontact.plots.contact import fig4_traction, fig5_force_and_stiffness, fig6_overlay

    c, analysis, params = settings.contact, result.analysis, result.params
    folder.mkdir(parents=True, exist_ok=True)
    p0_fig4 = 1.0 if 1.0 in analysis.p0_gpa else analysis.p0_gpa[0]
    p0_fig4 = analysis.contact_p0_pa[analysis.p0_gpa.index(p0_fig4)] / 1e9
    lockin = None
    if result.cycles:
        from flatcontact.contact.cycle import lockin_curve

        lockin = [lockin_curve(p, params, c.cycle.model) for p in analysis.contact_p0_pa]
    figs = {
        FIG4_TRACTION: fig4_traction(params, p0_fig4),
        FIG5_FORCE_STIFFNESS: fig5_force_and_stiffness(analysis, "amplitude", lockin, result.bands),
        FIG5_FORCE_STIFFNESS_RMS: fig5_force_and_stiffness(analysis, "rms", lockin, result.bands),
    }
    if comparison is not None:
        figs[FIG6_EXPERIMENT] = fig6_overlay(
            measured,
            c.experiment.p0_gpa,
            {
                f"τ0 = {params.tau0_mpa:.3g} MPa (run)": params,
                f"fitted τ0 = {comparison.fitted_tau0_mpa:.3g} MPa": comparison.fitted_params,
            },
            measure=c.experiment.stress_measure,
            measured_collapse_mpa=result.experiment["measured_collapse_stress_mpa"],
            lockin_model=c.cycle.model if result.cycles else None,
        )
    if result.cycles:
        from flatcontact.plots.cycle import fig_lockin_overlay, fig_loops

        p0c = [float(p) / 1e9 for p in analysis.contact_p0_pa]
        shown = sorted({p0_fig4, max(p0c)})
        figs[FIG5C_CYCLE_LOOPS] = fig_loops(
            params, shown, c.cycle.amplitude_fractions, model=c.cycle.model
        )
        figs[FIG6_LOCKIN] = fig_lockin_overlay(params, p0c, model=c.cycle.model)
    if result.slip_size is not None:
        from flatcontact.plots.slip_size import fig_slip_size

        figs[FIG_SLIP_SIZE] = fig_slip_size(result.slip_size)
    if result.fit is not None:
        from flatcontact.plots.cycle import fig_fit

        figs[FIG6_FIT] = fig_fit(result.fit)
        result.files.append(write_json_atomic(folder / FIT_JSON, result.fit_json()))
    for name, fig in figs.items():
        result.files += save(fig, folder, name, settings.report.svg)
    ds = analysis.to_dataset()
    if result.cycles:
        from flatcontact.contact.cycle_output import cycle_dataset

        cyc = cycle_dataset(result.cycles, params).assign_coords(p0=ds["p0"].values)
        ds = ds.merge(cyc)
        ds.attrs.update(cyc.attrs)
    with atomic_path(folder / CONTACT_NC) as tmp:
        ds.to_netcdf(tmp, engine="h5netcdf")
    result.files.append(folder / CONTACT_NC)
    result.files.append(write_json_atomic(folder / SUMMARY_JSON, result.to_json()))
