"""The report's sections in order, from the stage folders of a run.

:func:`build_sections` reads each stage's files once (the names are
:mod:`flatcontact.layout`'s) and hands them to the section of that stage
(:mod:`flatcontact.report.sections`); the report stage (:mod:`flatcontact.stages.report`)
renders the result (:mod:`flatcontact.report.html`). Editing the report's wording reruns
the report and nothing else.
"""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd
from ase.io import read

from flatcontact.layout import (
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
from flatcontact.reference import is_paper_material
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
from flatcontact.report.sections.scan import scan_section
from flatcontact.report.sections.summary import summary_section
from flatcontact.report.stacking_names import stacking_family


def _json(path: Path) -> dict:
    return json.loads(path.read_text())


def _elastic(cfg, folder: Path | None) -> dict | None:
    """The elastic stage's ``elastic.json`` when the stage is on and has written it."""
    if folder is None or not cfg.elastic.enabled or not (folder / ELASTIC_JSON).exists():
        return None
    return _json(folder / ELASTIC_JSON)


def build_sections(
    cfg, folders: dict[str, Path], stage_rows: list[tuple[str, str, str, str]]
) -> list[Section]:
    """The report's sections from the stage folders (``folders[name]``; figures embedded).

    ``stage_rows``: (stage, state, seconds, finished) of the summary table. The section
    next to the summary compares the run with the paper when its slabs are the paper's
    α-quartz (:func:`flatcontact.reference.is_paper_material`), else shows its results alone;
    only then does any section show a value of the paper, except the experiment section
    (:mod:`flatcontact.report.sections.experiment`), which a run asks for with
    ``contact.experiment.compare`` and which sets its collapse stress against the paper's
    measurements and quartz laws. A validity gate passed with
    ``contact.accept_untrusted`` (``summary.json["gates"]``) puts a box above everything
    (:mod:`flatcontact.report.sections.gates`). Stackings are named for the
    interface's family (:func:`flatcontact.report.stacking_names.stacking_family`).
    """
    f_build, f_scan = folders["build"], folders["scan"]
    f_an, f_laws, f_ct = folders["analyze"], folders["laws"], folders["contact"]
    build = _json(f_build / BUILD_JSON)
    scan = _json(f_scan / SCAN_JSON)
    analyze = _json(f_an / ANALYZE_JSON)
    laws = _json(f_laws / LAWS_JSON)
    contact = _json(f_ct / SUMMARY_JSON)
    table = pd.read_csv(f_an / FRICTION_CSV)
    interface = read(f_build / INTERFACE)
    model = cfg.potential.label
    material = interface_material(interface)
    paper = is_paper_material(cfg, set(interface.get_chemical_symbols()))
    family = stacking_family(build)
    gates = gates_section(contact)  # above everything: which numbers are not to be trusted
    sections = [gates] if gates is not None else []
    sections.append(summary_section(cfg, material, model, scan, stage_rows))
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
    tail = []
    f_asp = folders.get("asperity")
    if cfg.asperity.enabled and f_asp is not None and (f_asp / ASPERITY_JSON).exists():
        tail.append(asperity_section(_json(f_asp / ASPERITY_JSON), f_asp))
    return [
        *sections,
        interface_section(cfg, build, f_build, interface, paper),
        scan_section(scan, f_scan),
        analysis_section(cfg, analyze, table, f_an, family),
        laws_section(laws, f_laws, paper),
        contact_section(cfg, contact, _elastic(cfg, folders.get("elastic")), f_ct),
        *tail,
    ]
