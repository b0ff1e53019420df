"""Stage 3, analyze: constant-pressure ISPES, sliding path, τ, σ_MSS and G_int per load.

Files: ``friction.csv``, ``friction.nc`` (:mod:`flatcontact.analysis.outputs`),
``analyze.json`` (:meth:`AnalyzeResult.to_json`) and ``fig2_p<P>gpa.png`` (+ ``.svg``) per
load; ``other_form.json``: the per-load values and analysis warnings of the energy form
``analysis.energy_form`` does not name (:func:`flatcontact.analysis.energy_forms.form_loads`,
same settings), which the laws stage fits beside the reported form, so the ISPES is analysed
once per form per run. The load laws are not fitted here: they are the laws stage's
(:mod:`.laws`), so a change of ``analysis.threshold_gpa`` reruns only that stage and leaves
no stale warning of the old threshold in ``analyze.json``.
"""

from __future__ import annotations

import contextlib
import logging
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from flatcontact.foundation.errors import InputError
from flatcontact.foundation.fileio import (
    atomic_path,
    read_json_file,
    write_json_atomic,
    write_text_atomic,
)
from flatcontact.foundation.layout import (
    ANALYZE_JSON,
    FRICTION_CSV,
    FRICTION_NC,
    OTHER_FORM_JSON,
    SCAN_JSON,
    analyze_figure,
)
from flatcontact.stages._common import captured, renamed_errors, save

#: Parameters of :func:`flatcontact.analysis.analyze.analyze_ispes` -> the settings path.
SETTINGS_NAMES = {
    "p_gpa": "analysis.p_gpa",
    "direction_deg": "analysis.direction_deg",
    "form": "analysis.energy_form",
    "energy_zero": "analysis.energy_zero",
    "load_source": "analysis.load_source",
    "allow_missing": "analysis.allow_missing",
}

log = logging.getLogger("flatcontact.run")


@dataclass(frozen=True)
class AnalyzeInputs:
    """The ISPES grid to analyse (``ispes.nc``)."""

    ispes: Path


@dataclass
class AnalyzeResult:
    """The analysis (:class:`flatcontact.analysis.analyze.AnalysisResult`, ``laws`` None)
    and the analysis warnings raised while computing it (``"Category: message"``);
    ``other_form``: the other energy form's per-load table and warnings
    (:func:`flatcontact.analysis.energy_forms.form_loads`), None when not asked for."""

    analysis: Any
    warnings: list[str] = field(default_factory=list)
    files: list[Path] = field(default_factory=list)
    other_form: dict | None = None

    def to_json(self) -> dict:
        """``analyze.json``: warnings, timings, Fig. 2 names, symmetry, energy zero, load noise
        and the grid's estimate of its own error (``grid``, :mod:`flatcontact.analysis.grid_error`)."""
        result = self.analysis
        return {
            "warnings": list(self.warnings),
            "timings_s": result.timings_s,
            "fig2": [analyze_figure(pa.p_gpa) for pa in result.pressures],
            "symmetry": {
                f"{pa.p_gpa:g}": pa.symmetry.to_json()
                for pa in result.pressures
                if pa.symmetry is not None
            },
            "energy_reference_ev_per_a2": result.energy_reference_ev_per_a2,
            "load_source": result.load_source,
            "noise": result.noise.to_json(),
            "grid": result.grid.to_json() if result.grid is not None else None,
        }


def analyze_stage(
    settings, inputs: AnalyzeInputs, folder: Path | None, progress=None, other_form: bool = True
) -> AnalyzeResult:
    """Analyse ``inputs.ispes`` at ``settings.analysis.p_gpa`` (see the module docstring);
    with ``other_form`` also in the other energy form (``other_form.json``).

    Raises
    ------
    InputError
        One line; a bad value names its settings path (``analysis.energy_form``), which the
        CLI translates to its flag.
    """
    from flatcontact.analysis.analyze import analyze_ispes
    from flatcontact.analysis.diagnostics import AnalysisWarning
    from flatcontact.ispes.contract import open_ispes

    s = settings.analysis
    with renamed_errors(SETTINGS_NAMES), _folds_named(Path(inputs.ispes).parent / SCAN_JSON):
        options = analysis_options(s)
        ds = open_ispes(inputs.ispes)
        with captured(AnalysisWarning) as caught:
            analysis = analyze_ispes(ds, s.p_gpa, options, source=str(inputs.ispes))
        other = _other_form(ds, s.p_gpa, options) if other_form else None
    notes = [f"{w.category.__name__}: {w.message}" for w in caught]
    for note in notes:
        log.warning("analyze: %s", note)
    result = AnalyzeResult(analysis, notes, other_form=other)
    if folder is not None:
        _write(result, folder, settings.report.svg)
    return result


def grid_note(folder: Path) -> str:
    """One line for the console when the analysis's grid does not resolve τ (``analyze.json``
    ``grid``, :mod:`flatcontact.analysis.grid_error`); "" when it does or the file has none."""
    import json

    try:
        grid = json.loads((Path(folder) / ANALYZE_JSON).read_text()).get("grid") or {}
    except (OSError, ValueError, AttributeError):
        return ""
    if grid.get("resolved", True):
        return ""
    rel = [v for v in grid.get("relative_tau_error") or [] if v is not None]
    n_a, n_b = grid.get("grid") or ("?", "?")
    rec = grid.get("recommended_grid") or ("?", "?")
    return (
        f"the {n_a}×{n_b} grid does not resolve τ (estimated error up to "
        f"{100 * max(rel, default=float('nan')):.3g} % of τ); a grid of about {rec[0]}×{rec[1]} "
        f"would (scan.grid); the intervals carry it ({ANALYZE_JSON} grid)"
    )


def analysis_options(s):
    """The :class:`flatcontact.analysis.options.AnalysisOptions` of the ``analysis:`` settings
    section ``s``: no fit (the laws stage's), the MEP when asked for."""
    from flatcontact.analysis.options import AnalysisOptions

    return AnalysisOptions(
        direction_deg=s.direction_deg,
        form=s.energy_form,
        energy_zero=s.energy_zero,
        load_source=s.load_source,
        allow_missing=s.allow_missing,
        threshold_gpa=None,
        with_mep=s.with_mep,
    )


def _other_form(ds, p_gpa, options) -> dict:
    """The energy form ``options.form`` does not name, with the same options (no symmetry
    report, no MEP: the laws stage uses its per-load τ and σ_MSS)."""
    from flatcontact.analysis.energy_forms import FORMS, form_loads

    return form_loads(ds, p_gpa, FORMS[1 - FORMS.index(options.form)], options)


@contextlib.contextmanager
def _folds_named(scan_json: Path):
    """A load that is not monotonic where the scan recorded folds (``scan.json``
    ``load_folds``, :mod:`flatcontact.ispes.grid_bracket`) is named as that fold, with its two
    causes and their remedies (:data:`flatcontact.ispes.thicknesses.FOLD_REMEDY`: a plane that
    slips, or a relaxation stopped short of its minimum) besides the loads below it. A fold
    whose window the scan re-relaxed at a tighter fmax and which survived
    (``fold_rerelaxation``, :mod:`flatcontact.stages.fold_remedy`) is named as such."""
    try:
        yield
    except InputError as exc:
        text = str(exc)
        folds, survived, fmax = [], [], None
        if "not monotonic" in text or "fold" in text:
            try:  # only its folds, for the message: the FIFO-safe reader, leniently
                doc = read_json_file(scan_json, SCAN_JSON, 64_000_000)
            except InputError:  # no scan.json beside this ISPES, or not one: no fold named
                doc = None
            doc = doc if isinstance(doc, dict) else {}
            found = doc.get("load_folds")
            folds = [f for f in found if isinstance(f, dict)] if isinstance(found, list) else []
            redone = doc.get("fold_rerelaxation")
            redone = redone if isinstance(redone, dict) else {}
            surviving = redone.get("surviving")
            survived = [
                str(w["column"])
                for w in (surviving if isinstance(surviving, list) else [])
                if isinstance(w, dict) and "column" in w
            ]
            fmax = redone.get("fmax_ev_per_angstrom")
        if not folds and not survived:
            raise
        # imported here: the CLI imports this module before numpy and ASE may load
        from flatcontact.ispes.thicknesses import FOLD_REMEDY

        said = text
        if folds and "not monotonic" in text:
            first = folds[0]
            said += (
                f"; the scan recorded {len(folds)} folding column(s) ({SCAN_JSON} load_folds; "
                f"first: {first.get('column')}, p = {first.get('p_gpa', float('nan')):.3g} GPa "
                f"at z = {first.get('z_angstrom', float('nan')):.4g} Å): {FOLD_REMEDY}; or use "
                "loads below the fold (analysis.p_gpa, scan.p_range_gpa.hi_gpa)"
            )
        named = _shift_in(text)
        if named is not None:  # the column the analysis names, when it says which
            survived = [c for c in survived if _shift_in(c) == named]
        if survived:
            from flatcontact.ispes.rerelax import SURVIVING_FOLD_REMEDY

            said += (
                f"; the scan re-relaxed the fold's window of the {survived[0]} at fmax "
                f"{fmax:g} eV/Å and the fold survived: it is not the relaxation's; "
                f"{SURVIVING_FOLD_REMEDY}"
            )
        if said == text:
            raise
        raise InputError(said) from None


def _shift_in(text: str) -> tuple[str, str] | None:
    """The lateral shift a message names, ``(shift_a=a, shift_b=b)`` as the analysis labels
    a column or ``shift (a, b)`` as the scan does, as two strings (``%.4g``), or None."""
    import re

    found = re.search(r"shift_a=([-\d.e+]+), shift_b=([-\d.e+]+)", text) or re.search(
        r"shift \(([-\d.e+]+), ([-\d.e+]+)\)", text
    )
    return (found.group(1), found.group(2)) if found else None


def _write(result: AnalyzeResult, folder: Path, svg: bool) -> None:
    from flatcontact.analysis.outputs import friction_csv_text, friction_dataset
    from flatcontact.plots.analysis import figure_pressure

    folder.mkdir(parents=True, exist_ok=True)
    analysis = result.analysis
    result.files.append(write_text_atomic(folder / FRICTION_CSV, friction_csv_text(analysis)))
    with atomic_path(folder / FRICTION_NC) as tmp:
        friction_dataset(analysis).to_netcdf(tmp, engine="h5netcdf")
    result.files.append(folder / FRICTION_NC)
    if result.other_form is not None:
        result.files.append(write_json_atomic(folder / OTHER_FORM_JSON, result.other_form))
    for pa in analysis.pressures:
        result.files += save(figure_pressure(pa, analysis), folder, analyze_figure(pa.p_gpa), svg)
    result.files.append(write_json_atomic(folder / ANALYZE_JSON, result.to_json()))
