"""Everything a stage reads from the settings is in its fingerprint (issue 31).

Each stage function (``<stage>_stage``) runs on the finished toy study's inputs with settings that
record every field read: an attribute (``settings.analysis.p_gpa`` -> ``analysis.p_gpa``) or a
dump of a section (``settings.section("scan")``, ``model_dump`` -> every leaf below it). Its
fingerprint's settings part (:func:`flatcontact.stages.fingerprints.settings_inputs`) is built
with the same recorder; a field is covered when that build read it, except the fields of a
dumped section that the fingerprint then leaves out (``analysis.threshold_gpa`` of analyze,
``scan.executor``): those count as covered only where they are present in its output. The
stages a stage reads (the upstream fingerprints in its ``stage.json`` record) cover it too.

Stated exceptions (:mod:`flatcontact.stages.fingerprints`): the scan's execution-only
settings, and the figure format in the stages whose figures follow with their next real rerun.
Not covered here: the asperity stage (it needs a LAMMPS model; the toy study has none) and
the elastic stage (off in the toy study); a copy of a settings object (``model_copy``) is not
recorded.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from pydantic import BaseModel
from tests.hardening.helpers import finished_toy_run

from flatcontact.config import load_config
from flatcontact.foundation.layout import (
    FRICTION_CSV,
    INTERFACE,
    ISPES_NC,
    OTHER_FORM_JSON,
    STAGES,
    VERSIONS_JSON,
)
from flatcontact.foundation.rundir import RunDirectory
from flatcontact.stages.analyze import AnalyzeInputs, analyze_stage
from flatcontact.stages.build import BuildInputs, build_stage
from flatcontact.stages.contact import contact_stage
from flatcontact.stages.fingerprints import (
    EXECUTION_ONLY,
    FIGURE_SETTINGS,
    FIGURES_LEFT_OUT,
    report_stages,
    settings_inputs,
)
from flatcontact.stages.laws import LawsInputs, laws_stage
from flatcontact.stages.report import ReportInputs, report_stage
from flatcontact.stages.scan import ScanInputs, scan_stage


def _leaves(value, prefix: str) -> set[str]:
    """Dotted paths of every leaf of a JSON-like dict (a list is a leaf)."""
    if isinstance(value, dict) and value:
        return set().union(
            *(_leaves(v, f"{prefix}.{k}" if prefix else k) for k, v in value.items())
        )
    return {prefix}


def _fields(model: BaseModel, prefix: str) -> set[str]:
    """Dotted paths of every field of a settings model, nested models expanded."""
    out = set()
    for name in type(model).model_fields:
        value = object.__getattribute__(model, name)
        path = f"{prefix}.{name}" if prefix else name
        out |= _fields(value, path) if isinstance(value, BaseModel) else {path}
    return out


def _related(a: str, b: str) -> bool:
    """Is one of the dotted paths the other or below it?"""
    return a == b or a.startswith(b + ".") or b.startswith(a + ".")


class SettingsReads:
    """Records which fields of one settings object are read (see the module docstring)."""

    def __init__(self, settings: BaseModel):
        self.paths: dict[int, str] = {}
        self.classes: set[type] = set()
        self._walk(settings, "")
        self.attributes: set[str] = set()
        self.dumps: set[str] = set()
        self.implied: set[str] = set()
        self.on = False

    def _walk(self, model: BaseModel, prefix: str) -> None:
        self.paths[id(model)] = prefix
        self.classes.add(type(model))
        for name in type(model).model_fields:
            value = getattr(model, name)
            items = value if isinstance(value, list | tuple) else [value]
            for item in items:
                if isinstance(item, BaseModel):
                    self._walk(item, f"{prefix}.{name}" if prefix else name)

    def install(self, monkeypatch) -> None:
        reads = self
        for cls in self.classes:
            get = cls.__getattribute__
            dump, dump_json = cls.model_dump, cls.model_dump_json

            def getattribute(obj, name, _get=get):
                value = _get(obj, name)
                if reads.on and not name.startswith("_"):
                    base = reads.paths.get(id(obj))
                    if base is not None and name in type(obj).model_fields:
                        if not isinstance(value, BaseModel):
                            reads.attributes.add(f"{base}.{name}" if base else name)
                return value

            def model_dump(obj, *args, _dump=dump, **kwargs):
                reads._dumped(obj)
                return _dump(obj, *args, **kwargs)

            def model_dump_json(obj, *args, _dump=dump_json, **kwargs):
                reads._dumped(obj)
                return _dump(obj, *args, **kwargs)

            monkeypatch.setattr(cls, "__getattribute__", getattribute)
            monkeypatch.setattr(cls, "model_dump", model_dump)
            monkeypatch.setattr(cls, "model_dump_json", model_dump_json)

    def _dumped(self, obj) -> None:
        base = self.paths.get(id(obj))
        if self.on and base is not None:
            self.on = False  # the dump itself reads every field: recorded once, as leaves
            try:
                dumped = _leaves(json.loads(type(obj).model_dump_json(obj)), base)
                self.dumps |= dumped
                # a field a dump leaves out at its default (``exclude_if``) is given by its
                # absence: read all the same
                self.implied |= {
                    p for p in _fields(obj, base) if not any(_related(p, d) for d in dumped)
                }
            finally:
                self.on = True

    def record(self, call):
        self.attributes, self.dumps, self.implied, self.on = set(), set(), set(), True
        try:
            result = call()
        finally:
            self.on = False
        return result, self.attributes | self.dumps | self.implied


@pytest.fixture(scope="module")
def toy(tmp_path_factory):
    conf, run = finished_toy_run(tmp_path_factory.mktemp("reads"))
    return load_config(conf / "run.yaml"), run


def _folder(run: Path, name: str) -> Path:
    return RunDirectory(run).folder(STAGES[name], name)


def _stage_call(name: str, cfg, run: Path, out: Path):
    """``<name>_stage`` on the finished toy run's inputs, writing into ``out``."""
    if name == "build":
        return lambda: build_stage(cfg, BuildInputs(), out)
    if name == "scan":
        return lambda: scan_stage(cfg, ScanInputs(_folder(run, "build") / INTERFACE), out)
    if name == "analyze":
        return lambda: analyze_stage(cfg, AnalyzeInputs(_folder(run, "scan") / ISPES_NC), out)
    if name == "laws":
        tables = _folder(run, "analyze")
        inputs = LawsInputs.read(tables / FRICTION_CSV, tables / OTHER_FORM_JSON)
        return lambda: laws_stage(cfg, inputs, out)
    if name == "contact":
        from flatcontact.pipeline import Pipeline

        with Pipeline(cfg, run) as pipe:  # the finished run: every stage is skipped
            inputs = pipe._contact_inputs(pipe.gates().to_json(cfg.contact.accept_untrusted))
        return lambda: contact_stage(cfg, inputs, out)
    if name == "report":
        folders = {stage: _folder(run, stage) for stage in STAGES}
        versions = json.loads((run / VERSIONS_JSON).read_text())
        return lambda: report_stage(cfg, ReportInputs(folders, versions, None), out)
    raise AssertionError(name)


def _covered(name: str, cfg, reads: SettingsReads) -> set[str]:
    """The settings fields stage ``name``'s own fingerprint inputs cover (for the report, also
    the choice of the stages whose fingerprints it takes)."""
    (inputs, _), read = reads.record(
        lambda: (settings_inputs(name, cfg), report_stages(cfg) if name == "report" else None)
    )
    dropped = set()
    for section, value in inputs.items():
        if isinstance(value, dict):  # a dumped section: only what the fingerprint kept
            kept = _leaves(value, section)
            dropped |= {p for p in reads.dumps if p.startswith(section + ".") and p not in kept}
    return read - dropped


def _is_covered(path: str, covered: set[str]) -> bool:
    return any(_related(path, c) for c in covered)


STAGES_READ = ("build", "scan", "analyze", "laws", "contact", "report")


def test_every_setting_a_stage_reads_is_in_its_fingerprint(toy, tmp_path, monkeypatch):
    cfg, run = toy
    reads = SettingsReads(cfg)
    calls = {name: _stage_call(name, cfg, run, tmp_path / name) for name in STAGES_READ}
    reads.install(monkeypatch)
    covered: dict[str, set[str]] = {}
    found = {}
    for name in STAGES_READ:
        record = RunDirectory.read_record(_folder(run, name))
        upstream = [k for k in record["inputs"] if k in STAGES and k != name]
        covered[name] = _covered(name, cfg, reads).union(*(covered.get(u, set()) for u in upstream))
        _, read = reads.record(calls[name])
        assert read, f"{name}: the recorder saw no read (it records nothing?)"
        exempt = {f"scan.{k}" for k in EXECUTION_ONLY}
        if name in FIGURES_LEFT_OUT:
            exempt |= set(FIGURE_SETTINGS)
        outside = sorted(p for p in read - exempt if not _is_covered(p, covered[name]))
        if outside:
            found[name] = outside
    assert not found, f"settings read outside the stage's fingerprint: {found}"


def test_the_recorder_sees_a_read_outside_a_fingerprint(toy, monkeypatch):
    """The check can fail: a stand-in stage reading the threshold, which the analyze
    fingerprint leaves out, is caught; one reading the loads is not."""
    cfg, _ = toy
    reads = SettingsReads(cfg)
    reads.install(monkeypatch)
    covered = _covered("analyze", cfg, reads)
    _, read = reads.record(lambda: cfg.analysis.threshold_gpa + cfg.analysis.p_gpa[0])
    assert read == {"analysis.threshold_gpa", "analysis.p_gpa"}
    assert not _is_covered("analysis.threshold_gpa", covered)
    assert _is_covered("analysis.p_gpa", covered)
    _, read = reads.record(lambda: cfg.section("scan"))
    assert {"scan.executor", "scan.grid"} <= read
    assert not _is_covered("scan.executor", _covered("scan", cfg, reads))
