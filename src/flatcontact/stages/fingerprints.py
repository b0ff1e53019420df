"""What each stage's fingerprint takes from the settings (:class:`flatcontact.config.RunConfig`).

:class:`flatcontact.pipeline.Pipeline` fingerprints a stage by these inputs, the fingerprints
of the stages it reads and the digest of its code (:func:`stage_code_digest`).
The rule: **everything a stage reads from the settings is here**, or in an upstream stage's
fingerprint, so changing a setting reruns exactly the stages that read it
(``tests/pipeline/test_stage_reads.py`` runs every stage with settings that record what is
read and checks it against what these functions read). Two stated exceptions:

- :data:`EXECUTION_ONLY`: the scan's settings that change how, not what, is computed;
- :data:`FIGURE_SETTINGS` in the expensive stages of
  :data:`FIGURES_LEFT_OUT` (build, scan, asperity): the figure format
  follows with their next real rerun, as a restyled figure does (their code digests leave the
  figure modules out too); the cheap stages redraw their figures when it changes.

The code part is here too: :func:`stage_code`, the stage module's import closure, and
:func:`stage_code_digest` (``code_sha256``), re-exported by :mod:`flatcontact.pipeline`.

A file a setting names enters by its name and content (``*_sha256``), never by its path
(:func:`flatcontact.foundation.rundir.portable`), so moving a configuration folder reruns nothing.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from flatcontact.config import RunConfig, recipe_files
from flatcontact.foundation.codegraph import SOURCE_ROOT, closure_digest, import_closure
from flatcontact.foundation.fileio import file_sha256
from flatcontact.foundation.layout import STAGES
from flatcontact.foundation.rundir import portable
from flatcontact.stages import _calculator

#: The module of each stage; the flatcontact code a stage runs is that module's import
#: closure (:func:`flatcontact.foundation.codegraph.import_closure`): every flatcontact module it imports,
#: directly or not, at module or function level, with their parent packages' ``__init__``.
#: Editing any of them reruns the stage and, through the fingerprints, every stage that reads
#: it. ``pipeline.py`` itself is in no closure (it orders the stages, it computes nothing).
STAGE_MODULES: dict[str, str] = {name: f"flatcontact.stages.{name}" for name in STAGES}
#: The figure modules, left out of the code digest of the expensive stages
#: (:data:`FIGURES_LEFT_OUT`), so restyling a figure never reruns a build, a scan or an asperity (the
#: figure follows with the next real rerun). The cheap stages (analyze, laws, contact, report)
#: keep their figures in their digest: editing a figure reruns them and redraws it. The
#: modules the figures import stay in the closure.
FIGURE_MODULES = "flatcontact.plots"
FIGURES_LEFT_OUT = ("build", "scan", "asperity")
#: The top-level ``flatcontact/__init__.py`` is in no digest: it computes nothing (the version,
#: recorded in ``versions.json``, and the lazy map of public names), so growing the public API
#: never reruns a scan. The sub-packages' ``__init__`` files stay in.
PUBLIC_API_MODULE = "flatcontact"


def stage_code(name: str, root: Path = SOURCE_ROOT) -> frozenset[str]:
    """The flatcontact modules whose source enters stage ``name``'s code digest.

    Parameters
    ----------
    name
        A stage of :data:`STAGES`.
    root
        The source folder holding the ``flatcontact`` package (default: the installed one).
    """
    exclude = (FIGURE_MODULES,) if name in FIGURES_LEFT_OUT else ()
    return import_closure(STAGE_MODULES[name], root, exclude) - {PUBLIC_API_MODULE}


def stage_code_digest(name: str, root: Path = SOURCE_ROOT) -> str:
    """SHA-256 of the source of :func:`stage_code` (``code_sha256`` of the stage's inputs)."""
    return closure_digest(stage_code(name, root), root)


#: Scan settings that change how, not what, is computed (kept out of the fingerprint).
EXECUTION_ONLY = ("executor", "workers", "dask_address", "jobqueue")
#: Settings that change only the figures' file formats (dotted paths).
FIGURE_SETTINGS = ("report.svg",)


def _figures(cfg: RunConfig) -> dict:
    """The figure format of a cheap stage's figures: ``{"svg": False}`` when SVGs are not asked
    for, nothing with the default (SVGs too), so the default's fingerprints keep their value."""
    return {} if cfg.report.svg else {"svg": False}


def build(cfg: RunConfig) -> dict:
    """The structure (files by name and content) and the model (it relaxes the interface)."""
    structure = portable(cfg.structure_section(), "file")
    if cfg.structure.kind == "quartz-dense":
        structure.setdefault("file", None)  # the fingerprint of runs made before recipes
    inputs = {"structure": structure, "model": _calculator.fingerprint(cfg)}
    if cfg.structure.kind in ("file", "slab"):
        inputs["file_sha256"] = file_sha256(cfg.structure.file)
    for dotted, path in recipe_files(cfg.structure):
        if dotted != "file":
            inputs[f"{dotted}_sha256"] = file_sha256(path)
    return inputs


def scan(cfg: RunConfig) -> dict:
    """The scan section (less :data:`EXECUTION_ONLY`), the model and, for a pressure-range grid,
    the load bracket its columns must reach (the lowest and highest load of ``analysis.p_gpa``,
    ``ispes.grid_bracket.bracket_targets_gpa``), so a load added beyond the scanned range
    re-brackets the scan; and ``analysis.load_source`` when it is not the default, which the
    fold remedy reads folds with (:mod:`flatcontact.stages.fold_remedy`)."""
    section = {k: v for k, v in cfg.section("scan").items() if k not in EXECUTION_ONLY}
    inputs = {"scan": section, "model": _calculator.fingerprint(cfg)}
    if cfg.scan.p_range_gpa is not None:
        loads = [float(p) for p in cfg.analysis.p_gpa]
        inputs["bracket_loads_gpa"] = [min(loads), max(loads)] if loads else None
    if cfg.analysis.load_source != "energy":  # the default's fingerprints keep their value
        # the fold remedy re-relaxes the folds of the load as this source reads it
        inputs["fold_load_source"] = cfg.analysis.load_source
    return inputs


def analyze(cfg: RunConfig) -> dict:
    """The analysis section less ``threshold_gpa`` (the laws stage's: analyze fits no law)."""
    section = cfg.section("analysis")
    section.pop("threshold_gpa")
    return {"analysis": section, **_figures(cfg)}


def laws(cfg: RunConfig) -> dict:
    """The fit's upper load and the uncertainty section (the laws' intervals); the energy forms'
    tables come from the analyze stage's files (its fingerprint covers them)."""
    return {
        "threshold_gpa": cfg.analysis.threshold_gpa,
        "uncertainty": cfg.section("uncertainty"),
        **_figures(cfg),
    }


def elastic(cfg: RunConfig) -> dict:
    """The elastic section, the model and (but for quartz) the structure its bulk follows."""
    inputs = {"elastic": cfg.section("elastic"), "model": _calculator.fingerprint(cfg)}
    if cfg.structure.kind != "quartz-dense":  # the bulk crystal follows the recipe
        inputs["structure"] = cfg.section("structure")
    return inputs


def contact(cfg: RunConfig) -> dict:
    """The contact section (files by name) and the content of the files it names: the
    experiment, the quick preset's laws the comparison quotes, the curves to fit."""
    from flatcontact.stages.contact import QUARTZ_QUICK_LAWS_FILE

    section = dict(cfg.section("contact"))
    for sub in ("experiment", "fit"):  # their csv files enter by name and content, not place
        if isinstance(section.get(sub), dict):
            section[sub] = portable(section[sub], "csv")
    inputs = {
        "contact": section,
        **_figures(cfg),
    }
    if cfg.contact.experiment.csv:
        inputs["experiment_sha256"] = file_sha256(cfg.contact.experiment.csv)
    if cfg.contact.experiment.compare:  # the comparison quotes the quick preset's laws
        inputs["quartz_quick_laws_sha256"] = file_sha256(QUARTZ_QUICK_LAWS_FILE)
    if cfg.contact.fit.csv:
        inputs["fit_sha256"] = [file_sha256(f) for f in cfg.contact.fit.csv]
    return inputs


def report(cfg: RunConfig) -> dict:
    """The report section, the preset it names and the digest of the approximant study it
    tables, if any (the stages it reads: :func:`report_stages`)."""
    from flatcontact.stages.report import approximant_study_digest

    inputs = {"report": cfg.section("report"), "preset": cfg.preset}
    if cfg.report.approximant_study is not None:
        inputs["approximant_study"] = approximant_study_digest(cfg.report.approximant_study)
    return inputs


def report_stages(cfg: RunConfig) -> list[str]:
    """The stages whose fingerprints enter the report's: build to contact, the elastic stage
    (its Cij are tabled) and the asperity (its verdict is stated) when they are enabled."""
    names = ["build", "scan", "analyze", "laws", "contact"]
    return (
        names
        + (["elastic"] if cfg.elastic.enabled else [])
        + (["asperity"] if cfg.asperity.enabled else [])
    )


def asperity(cfg: RunConfig) -> dict:
    """The asperity section, the structure its tip is cut from and the model that runs it."""
    return {
        "asperity": cfg.section("asperity"),
        "structure": cfg.section("structure"),
        "model": _calculator.fingerprint(cfg),
    }


#: Each stage's settings inputs (:func:`settings_inputs`).
SETTINGS_INPUTS: dict[str, Callable[[RunConfig], dict]] = {
    "build": build,
    "scan": scan,
    "analyze": analyze,
    "laws": laws,
    "elastic": elastic,
    "contact": contact,
    "report": report,
    "asperity": asperity,
}


def settings_inputs(name: str, cfg: RunConfig) -> dict:
    """What stage ``name``'s fingerprint takes from the settings ``cfg``."""
    return SETTINGS_INPUTS[name](cfg)
