"""The report's sections in order, from the stage folders of a run.

:func:`build_sections` reads each stage's files once (the names are
:mod:`flatcontact.foundation.layout`'s) and hands them to the section of that stage
(:mod:`flatcontact.report.sections`); the report stage (:mod:`flatcontact.stages.report`)
renders the result (:mod:`flatcontact.report.html`). Editing the report's wording reruns
the report and nothing else.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd
from ase.io import read

from flatcontact.foundation.errors import InputError
from flatcontact.foundation.fileio import read_json_file
from flatcontact.foundation.layout import (
    ANALYZE_JSON,
    ASPERITY_JSON,
    BUILD_JSON,
    ELASTIC_JSON,
    FRICTION_CSV,
    INTERFACE,
    LAWS_JSON,
    SCAN_JSON,
    SUMMARY_JSON,
)
from flatcontact.foundation.reference import is_paper_material
from flatcontact.foundation.result_json import CONTRACTS, MAX_BYTES, read_result_json
from flatcontact.report.html import Section
from flatcontact.report.sections.analysis import analysis_section
from flatcontact.report.sections.approximant_study import (
    approximant_study_section,
    read_approximant_study,
)
from flatcontact.report.sections.asperity import asperity_section
from flatcontact.report.sections.build import interface_material, interface_section
from flatcontact.report.sections.comparison import own_results_section, paper_section
from flatcontact.report.sections.contact import contact_section
from flatcontact.report.sections.experiment import experiment_section
from flatcontact.report.sections.gates import gates_section
from flatcontact.report.sections.laws import laws_section
from flatcontact.report.sections.refusal import refusal_section
from flatcontact.report.sections.scan import scan_section
from flatcontact.report.sections.summary import summary_section
from flatcontact.report.stacking_names import stacking_family


def _json(path: Path, **expect) -> dict:
    """A stage's JSON file, checked against its contract where it has one
    (:mod:`flatcontact.foundation.result_json`; ``expect``: what the settings say it holds);
    ``build.json`` as a complete JSON mapping."""
    if path.name in CONTRACTS:
        return read_result_json(path, **expect)
    doc = read_json_file(path, path.name, MAX_BYTES)
    if not isinstance(doc, dict):
        raise InputError(f"{path}: not a mapping; remove {path.parent} and rerun to recompute it")
    return doc


def _elastic(cfg, folder: Path | None) -> dict | None:
    """The elastic stage's ``elastic.json`` when the stage is on and has written it."""
    if folder is None or not cfg.elastic.enabled or not (folder / ELASTIC_JSON).exists():
        return None
    return _json(folder / ELASTIC_JSON)


def build_sections(
    cfg,
    folders: dict[str, Path],
    stage_rows: list[tuple[str, str, str, str]],
    refusal: dict | None = None,
) -> list[Section]:
    """The report's sections from the stage folders (``folders[name]``; figures embedded).

    ``stage_rows``: (stage, state, seconds, finished) of the summary table. The section
    next to the summary compares the run with the paper when its slabs are the paper's
    α-quartz (:func:`flatcontact.foundation.reference.is_paper_material`), else shows its results alone;
    only then does any section show a value of the paper, except the experiment section
    (:mod:`flatcontact.report.sections.experiment`), which a run asks for with
    ``contact.experiment.compare`` and which sets its collapse stress against the paper's
    measurements and quartz laws. A validity gate passed with
    ``contact.accept_untrusted`` (``summary.json["gates"]``) puts a box above everything
    (:mod:`flatcontact.report.sections.gates`). Stackings are named for the
    interface's family (:func:`flatcontact.report.stacking_names.stacking_family`).

    A run refused after the scan (``refusal``,
    :func:`flatcontact.report.sections.refusal.refusal_record`) has folders for the stages
    that finished only (build and scan at least): the refusal comes first, then the sections
    of those stages; the results sections need the contact stage and are left out.
    """
    f_build, f_scan = folders["build"], folders["scan"]
    f_an, f_laws, f_ct = folders.get("analyze"), folders.get("laws"), folders.get("contact")
    build = _json(f_build / BUILD_JSON)
    scan = _json(f_scan / SCAN_JSON, grid=cfg.scan.grid)
    analyze = _json(f_an / ANALYZE_JSON) if f_an is not None else None
    laws = (
        _json(f_laws / LAWS_JSON, energy_form=cfg.analysis.energy_form)
        if f_laws is not None
        else None
    )
    contact = (
        _json(f_ct / SUMMARY_JSON, p0_gpa=list(cfg.contact.p0_gpa)) if f_ct is not None else None
    )
    table = pd.read_csv(f_an / FRICTION_CSV) if f_an is not None else None
    interface = read(f_build / INTERFACE)
    model = cfg.potential.label
    material = interface_material(interface)
    paper = is_paper_material(cfg, set(interface.get_chemical_symbols()))
    family = stacking_family(build)
    sections = [refusal_section(refusal)] if refusal is not None else []
    gates = gates_section(contact) if contact is not None else None  # above everything
    sections += [gates] if gates is not None else []
    sections.append(summary_section(cfg, material, model, scan, stage_rows))
    if contact is not None and laws is not None:
        if paper:
            sections.append(paper_section(cfg, laws, scan, contact))
        else:
            sections.append(
                own_results_section(cfg, material, model, laws, scan, contact, table, family)
            )
        experiment = experiment_section(contact, build)  # contact.experiment.compare
        if experiment is not None:
            sections.append(experiment)
    study = cfg.report.approximant_study  # the sequence toward the incommensurate contact
    if study is not None:
        sections.append(approximant_study_section(read_approximant_study(study), study, build))
    sections += [
        interface_section(cfg, build, f_build, interface, paper),
        scan_section(scan, f_scan),
    ]
    if analyze is not None:
        sections.append(analysis_section(cfg, analyze, table, f_an, family))
    if laws is not None:
        sections.append(laws_section(laws, f_laws, paper))
    if contact is not None:
        sections.append(contact_section(cfg, contact, _elastic(cfg, folders.get("elastic")), f_ct))
    f_asp = folders.get("asperity")
    if cfg.asperity.enabled and f_asp is not None and (f_asp / ASPERITY_JSON).exists():
        doc = read_json_file(f_asp / ASPERITY_JSON, ASPERITY_JSON, 256 * 1024 * 1024)
        sections.append(asperity_section(doc, f_asp))
    return sections
