"""The whole study as stages over a run directory: build → scan → analyze → laws → (elastic) → contact → report.

:class:`Pipeline` runs each stage through :meth:`flatcontact.foundation.rundir.RunDirectory.run_stage`
with the stage's inputs = its configuration section + the content of the files it reads
(potential coefficients, structure and measurement files) + the digest of the source code
that computes it (:func:`stage_code_digest`: the stage module's import closure, figure
modules left out for build and scan, see :data:`~flatcontact.stages.fingerprints.FIGURE_MODULES`) + the fingerprints of the
stages it reads, so that

- a rerun skips every stage whose inputs are unchanged;
- an interrupted stage (Ctrl-C, kill -9) is resumed: the scan continues from its point
  store (``02-scan/points.db``) and loses nothing that finished;
- changing one setting reruns exactly the stages that depend on it (e.g.
  ``analysis.threshold_gpa`` reruns ``laws``, ``contact`` and ``report``, not the scan).

What each stage's fingerprint takes from the settings is :mod:`flatcontact.stages.fingerprints`
(everything the stage reads; settings that do not change numbers, ``scan.executor``,
``scan.workers``, ``scan.dask_address``, are not part of any fingerprint).

The run directory's folders and file names are :mod:`flatcontact.foundation.layout`.

This module keeps only the order of the stages and their fingerprints. What a stage computes
and writes is :mod:`flatcontact.stages` (``<stage>_stage(settings, inputs, folder)``), which
``flatcontact <stage>`` calls too; figures are in :mod:`flatcontact.plots`, the report's
content in :mod:`flatcontact.report`. The pipeline prints nothing: it tells an observer
(``on_event``, called with a :class:`StageEvent`) when a stage starts and ends, and
``flatcontact run`` (:mod:`flatcontact.cli.run`) shows these on the console.

Every stage is a public method returning Python objects (ASE Atoms, xarray Datasets,
pandas DataFrames, dicts), so a notebook can run the stages one by one::

    from flatcontact import Pipeline, load_config
    pipe = Pipeline(load_config("run.yaml"), "my-run")
    atoms = pipe.build()
    ispes = pipe.scan()            # xarray Dataset (ispes.nc)
    friction = pipe.analyze()      # xarray Dataset (friction.nc)
    laws = pipe.laws()             # dict (laws.json)
    contact = pipe.contact()       # xarray Dataset (contact.nc)
    pipe.report()                  # Path of report.html
"""

from __future__ import annotations

import json
import logging
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pandas as pd

from flatcontact import __version__
from flatcontact.config import RunConfig, to_yaml
from flatcontact.foundation.errors import InputError
from flatcontact.foundation.fileio import (
    link_file_atomic,
    open_nofollow,
    write_json_atomic,
    write_text_atomic,
)
from flatcontact.foundation.layout import (
    BUILD_JSON,
    CONFIG_YAML,
    CONTACT_NC,
    ELASTIC_JSON,
    FRICTION_CSV,
    FRICTION_NC,
    INTERFACE,
    ISPES_NC,
    LAWS_JSON,
    OTHER_FORM_JSON,
    REPORT_HTML,
    RUN_LOG,
    RUN_MARKER,
    SCAN_JSON,
    STAGES,
    SUMMARY_JSON,
    VERSIONS_JSON,
)
from flatcontact.foundation.result_json import read_result_json
from flatcontact.foundation.rundir import (
    RunDirectory,
    RunLock,
    StageResult,
    package_versions,
    writable,
)
from flatcontact.ispes.contract import check_grid, open_ispes
from flatcontact.ispes.shift_lattice import scanned_grid
from flatcontact.refused import refused_report
from flatcontact.stages import contact_range
from flatcontact.stages.analyze import AnalyzeInputs, analyze_stage, grid_note
from flatcontact.stages.build import BuildInputs, build_stage
from flatcontact.stages.contact import (
    ContactInputs,
    check_contact,
    contact_parameters,
    contact_stage,
)
from flatcontact.stages.elastic import ElasticInputs, elastic_stage
from flatcontact.stages.fingerprints import (
    FIGURE_MODULES,
    FIGURES_LEFT_OUT,
    PUBLIC_API_MODULE,
    STAGE_MODULES,
    report_stages,
    settings_inputs,
    stage_code,
    stage_code_digest,
)
from flatcontact.stages.gates import GateInputs, check_gates, evaluate_gates
from flatcontact.stages.laws import LawsInputs, laws_stage
from flatcontact.stages.preflight import check_inputs
from flatcontact.stages.report import ReportInputs, report_stage
from flatcontact.stages.result_files import CONTACT, FRICTION, open_result
from flatcontact.stages.scan import ScanInputs, scan_stage
from flatcontact.structures.interface_io import read_interface

__all__ = [
    "FIGURES_LEFT_OUT",
    "FIGURE_MODULES",
    "PUBLIC_API_MODULE",
    "STAGES",
    "STAGE_MODULES",
    "Pipeline",
    "StageEvent",
    "run",
    "stage_code",
    "stage_code_digest",
]

log = logging.getLogger("flatcontact.run")

RUN_FORMAT = "flatcontact.run/1"


class _NoFollowFileHandler(logging.FileHandler):
    """The run log, appended to without following a link planted at ``run.log``."""

    def _open(self):
        return open(open_nofollow(self.baseFilename, append=True), "a", encoding=self.encoding)


@dataclass(frozen=True)
class StageEvent:
    """One step of a run, for the observer of :class:`Pipeline` (``on_event``).

    ``kind`` is ``"start"`` (the stage begins: its fingerprint is being checked),
    ``"end"`` (``action`` is ``"ran"``, ``"resumed"`` or ``"skipped"``, ``seconds`` its
    wall time; ``message``: the analyze stage's grid verdict when its grid does not resolve τ),
    ``"failed"`` (an exception, ``"interrupted"`` for Ctrl-C, leaves the stage;
    it propagates after the event) or ``"off"`` (a disabled stage; ``message`` says what
    replaces it). ``index`` is the stage's folder index (:data:`flatcontact.foundation.layout.STAGES`).
    """

    kind: str
    name: str
    index: int
    action: str | None = None
    seconds: float | None = None
    message: str = ""


class Pipeline:
    """The stages of one run over a run directory (see the module docstring).

    Parameters
    ----------
    config
        The validated run configuration (:func:`flatcontact.config.load_config`).
    root
        The run directory; created if missing. A non-empty directory that is not a
        flatcontact run is refused.
    on_event
        Observer of the run, called as ``on_event(StageEvent(...))`` when a stage starts,
        ends, fails or is off (``None``: nobody is told; the run log has every stage).
    scan_progress
        Observer of the scan, called as ``scan_progress(done, total)``; if it is a context
        manager the scan stage runs inside it (the CLI's progress bar).
    source
        What the configuration came from, named first in a refusal of the pre-run checks
        (:func:`flatcontact.stages.preflight.check_inputs`): the file the user gave.
    """

    def __init__(
        self,
        config: RunConfig,
        root: str | Path,
        on_event: Callable[[StageEvent], None] | None = None,
        scan_progress: Callable[[int, int], None] | None = None,
        source: str = "config",
    ):
        self.config = config
        self.source = source
        self.root = Path(root)
        self.on_event = on_event
        self.scan_progress = scan_progress
        self._check_root()
        self._check_config()
        self.results: dict[str, StageResult] = {}
        self._refusal: InputError | None = None  # the last stage's own refusal (run())
        self._handler: logging.Handler | None = None
        self._lock: RunLock | None = None
        # a finished run on a read-only mount is read, never written (run_stage says so)
        read_only = writable(self.root) if (self.root / RUN_MARKER).is_file() else None
        self.rundir = RunDirectory(self.root, read_only=read_only)
        if read_only is not None:  # no run.log: the progress lines are the record
            self._handler = logging.NullHandler()
            logging.getLogger("flatcontact").addHandler(self._handler)
            return
        self._lock = RunLock(self.root).acquire()  # one writer per run directory
        self._open_log()
        write_json_atomic(
            self.root / RUN_MARKER, {"format": RUN_FORMAT, "flatcontact_version": __version__}
        )
        write_text_atomic(self.root / CONFIG_YAML, to_yaml(config))
        write_json_atomic(self.root / VERSIONS_JSON, package_versions())

    # ---- setup -------------------------------------------------------------------------
    def _check_root(self) -> None:
        root = self.root
        if root.exists() and not root.is_dir():
            raise InputError(f"{root}: exists and is not a directory")
        if root.is_dir() and any(root.iterdir()):
            marker = root / RUN_MARKER
            if not marker.is_file():
                raise InputError(
                    f"{root}: not a flatcontact run directory (no {RUN_MARKER}); choose another --out"
                )
            try:
                data = json.loads(marker.read_bytes().decode("utf-8"))
            except (OSError, UnicodeDecodeError, json.JSONDecodeError):
                raise InputError(
                    f"{marker}: corrupt run marker; remove it only if {root} is a flatcontact run"
                ) from None
            if not isinstance(data, dict) or data.get("format") != RUN_FORMAT:
                raise InputError(
                    f"{marker}: not a flatcontact run marker (expected format {RUN_FORMAT})"
                )

    def _check_config(self) -> None:
        """Checks that need the file system or optional modules, before any work."""
        check_inputs(self.config, self.source)

    def _open_log(self) -> None:
        handler = _NoFollowFileHandler(self.root / RUN_LOG, encoding="utf-8")
        handler.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(name)s: %(message)s"))
        logger = logging.getLogger("flatcontact")
        logger.addHandler(handler)
        if logger.level == logging.NOTSET or logger.level > logging.INFO:
            logger.setLevel(logging.INFO)
        self._handler = handler
        log.info(
            "run directory %s, flatcontact %s, preset %s",
            self.root,
            __version__,
            self.config.preset,
        )

    def close(self) -> None:
        """Detach the run log and give up the run directory's lock."""
        if self._handler is not None:
            logging.getLogger("flatcontact").removeHandler(self._handler)
            self._handler.close()
            self._handler = None
        if self._lock is not None:
            self._lock.release()
            self._lock = None

    def __enter__(self) -> Pipeline:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # ---- helpers -----------------------------------------------------------------------
    def folder(self, name: str) -> Path:
        """The folder of stage ``name``."""
        return self.rundir.folder(STAGES[name], name)

    def _upstream(self, name: str) -> StageResult:
        if name not in self.results:
            getattr(self, name)()
        return self.results[name]

    def _json(self, name: str, file: str) -> dict:
        """A stage's JSON file checked against its contract (:mod:`flatcontact.foundation.result_json`)
        and against what this run knows: the scan's grid from its stage record, the energy
        form and the loads p0 from the settings."""
        folder = self._upstream(name).folder
        expect: dict[str, Any] = {}
        if name == "scan":
            record = self.rundir.read_record(folder) or {}
            grid = ((record.get("inputs") or {}).get("scan") or {}).get("grid")
            if grid is not None:
                expect["grid"] = grid
        elif name == "laws":
            expect["energy_form"] = self.config.analysis.energy_form
        elif name == "contact":
            expect["p0_gpa"] = list(self.config.contact.p0_gpa)
        return read_result_json(folder / file, **expect)

    def _tell(self, kind: str, name: str, **details: Any) -> None:
        if self.on_event is not None:
            self.on_event(StageEvent(kind, name, STAGES[name], **details))

    def _refused(self, check: Callable, *args: Any) -> Any:  # InputError: a refusal, run()
        try:
            return check(*args)
        except InputError as exc:
            self._refusal = exc
            raise

    def _run(self, name: str, inputs: dict, work: Callable[[Path], Any]) -> StageResult:
        index = STAGES[name]
        inputs = {**inputs, "code_sha256": stage_code_digest(name)}
        self._tell("start", name)
        try:
            result = self.rundir.run_stage(index, name, inputs, lambda f: self._refused(work, f))
        except KeyboardInterrupt:
            log.warning("stage %s: interrupted; rerun to resume", name)
            self._tell("failed", name, action="interrupted")
            raise
        except Exception as exc:
            log.error("stage %s: failed: %s", name, exc)
            self._tell("failed", name, message=str(exc))
            raise
        self.results[name] = result
        note = grid_note(result.folder) if name == "analyze" else ""
        self._tell("end", name, action=result.action, seconds=result.seconds, message=note)
        return result

    # ---- stages ------------------------------------------------------------------------
    def build(self):
        """Stage 1: the relaxed reference interface (``01-build/interface.extxyz``).

        Returns
        -------
        ase.Atoms
            The interface (``slab``/``surface`` arrays, ``a1``/``a2``/``recipe`` info).
        """
        cfg = self.config
        inputs = settings_inputs("build", cfg)

        def work(folder: Path) -> None:
            for line in build_stage(cfg, BuildInputs(), folder).warnings:
                log.warning("build: %s", line)

        result = self._run("build", inputs, work)
        return read_interface(result.folder / INTERFACE)

    def scan(self):
        """Stage 2: the ISPES grid (``02-scan/ispes.nc``, resumable ``points.db``).

        Returns
        -------
        xarray.Dataset
            The ``ispes.nc`` contract (energy, normal_stress, converged, force_calls).
        """
        cfg = self.config
        build = self._upstream("build")
        inputs = {**settings_inputs("scan", cfg), "build": build.fingerprint}

        def work(folder: Path) -> None:
            stage_inputs = ScanInputs(build.folder / INTERFACE)
            bar = self.scan_progress
            if hasattr(bar, "__enter__"):
                with bar:
                    scan_stage(cfg, stage_inputs, folder, progress=bar)
            else:
                scan_stage(cfg, stage_inputs, folder, progress=bar)

        result = self._run("scan", inputs, work)
        ds = open_ispes(result.folder / ISPES_NC)
        check_grid(ds, scanned_grid(ds, self.config.scan.grid), str(result.folder / ISPES_NC))
        return ds

    def scan_summary(self) -> dict:
        """``02-scan/scan.json``: counts, force calls, thicknesses, adhesion (work of separation)."""
        return self._json("scan", SCAN_JSON)

    def analyze(self):
        """Stage 3: constant-pressure ISPES, sliding path, τ, σ_MSS, G_int per load.

        Writes ``friction.csv``, ``friction.nc``, ``analyze.json`` (warnings, timings) and
        Fig. 2 for every load of ``analysis.p_gpa``.

        Returns
        -------
        xarray.Dataset
            ``friction.nc`` (per-load values, paths, constant-pressure maps).
        """
        cfg = self.config
        scan = self._upstream("scan")
        inputs = {**settings_inputs("analyze", cfg), "scan": scan.fingerprint}

        def work(folder: Path) -> None:
            analyze_stage(cfg, AnalyzeInputs(scan.folder / ISPES_NC), folder)

        result = self._run("analyze", inputs, work)
        return open_result(result.folder / FRICTION_NC, FRICTION, cfg.analysis.p_gpa)

    def friction_table(self):
        """``03-analyze/friction.csv`` as a pandas DataFrame (one row per load)."""
        return pd.read_csv(self._upstream("analyze").folder / FRICTION_CSV)

    def laws(self) -> dict:
        """Stage 4: τ = k·P + τ0 and σ = μ·P + σ0 fitted on P ≤ ``analysis.threshold_gpa``.

        Returns
        -------
        dict
            ``laws.json`` (``k_mpa_per_gpa``, ``tau0_mpa``, ``mu_mpa_per_gpa``, ``sigma0_mpa``,
            standard errors, fitted range, end of the linear regime, warnings).
        """
        cfg = self.config
        analyze = self._upstream("analyze")
        inputs = {**settings_inputs("laws", cfg), "analyze": analyze.fingerprint}

        def work(folder: Path) -> None:
            tables = analyze.folder
            laws_stage(
                cfg, LawsInputs.read(tables / FRICTION_CSV, tables / OTHER_FORM_JSON), folder
            )

        self._run("laws", inputs, work)
        return self._json("laws", LAWS_JSON)

    def elastic(self) -> dict | None:
        """Stage 5 (optional): E* and G* from the potential (``05-elastic/elastic.json``).

        Returns ``None`` when ``elastic.enabled`` is false (the contact stage then uses
        ``contact.contact_modulus_gpa`` and ``contact.shear_modulus_gpa``).
        """
        cfg = self.config
        if not cfg.elastic.enabled:
            self._tell(
                "off",
                "elastic",
                message=f"the contact model takes E* = {cfg.contact.contact_modulus_gpa:g} GPa, "
                f"G* = {cfg.contact.shear_modulus_gpa:g} GPa from the configuration",
            )
            return None
        inputs = settings_inputs("elastic", cfg)
        self._run("elastic", inputs, lambda folder: elastic_stage(cfg, ElasticInputs(), folder))
        return self._json("elastic", ELASTIC_JSON)

    def gates(self):
        """The validity gates on the scan, the analysis and the laws
        (:func:`flatcontact.stages.gates.evaluate_gates`; a
        :class:`flatcontact.analysis.gates.GateReport`)."""
        return evaluate_gates(
            GateInputs(
                interface=self._upstream("build").folder / INTERFACE,
                scan_json=self._upstream("scan").folder / SCAN_JSON,
                friction_nc=self._upstream("analyze").folder / FRICTION_NC,
                laws_json=self._upstream("laws").folder / LAWS_JSON,
                symmetry_tolerance_angstrom=self.config.scan.symmetry.tolerance_angstrom,
                spread_compression=self.config.scan.relax_mode != "rigid",
            )
        )

    def _contact_inputs(self, gates: dict | None = None):
        adhesion = self.scan_summary().get("adhesion") or {}
        return ContactInputs(
            laws=self._json("laws", LAWS_JSON),
            work_of_separation_j_per_m2=adhesion.get("work_of_separation_j_per_m2"),
            from_scan=True,
            moduli=self._json("elastic", ELASTIC_JSON) if self.config.elastic.enabled else None,
            gates=gates,
            interface=contact_range.facts(
                self._upstream("build").folder / INTERFACE,
                self._upstream("build").folder / BUILD_JSON,
                open_result(self._upstream("analyze").folder / FRICTION_NC, FRICTION),
            ),
        )

    def contact_parameters(self):
        """The :class:`~flatcontact.contact.parameters.ContactParameters` the contact stage uses
        and their provenance (see :func:`flatcontact.stages.contact.contact_parameters`)."""
        return contact_parameters(self.config, self._contact_inputs())

    def contact(self):
        """Stage 6: modified Mindlin contact at every ``contact.p0_gpa``.

        Writes ``contact.nc``, ``summary.json`` and Figs. 4, 5 (and 6 with measured data).

        Returns
        -------
        xarray.Dataset
            ``contact.nc``: Q(u) and stiffness curves and the per-p0 scalars.
        """
        cfg = self.config
        laws = self._upstream("laws")
        scan = self._upstream("scan")
        elastic = self._upstream("elastic") if cfg.elastic.enabled else None
        # before the stage folder is touched: a gate that fired, or a refused p0, stops the
        # run with the finished stages kept (rerun with contact.accept_untrusted to go on)
        gates = self.gates()
        self._refused(check_gates, cfg, gates)
        stage_inputs = self._contact_inputs(gates.to_json(cfg.contact.accept_untrusted))

        def checks() -> None:  # a refusal here gets the refused run's report
            params = contact_parameters(cfg, stage_inputs)[0]
            check_contact(cfg, params)
            contact_range.adhesion_of(cfg, stage_inputs, params)  # where no model applies

        self._refused(checks)
        inputs = {
            **settings_inputs("contact", cfg),
            "laws": laws.fingerprint,
            "scan": scan.fingerprint,
            "elastic": elastic.fingerprint if elastic else None,
        }
        if stage_inputs.gates["fired"] or stage_inputs.gates["notes"]:
            inputs["gates"] = stage_inputs.gates  # the recorded verdict (a clean run: no key)

        result = self._run("contact", inputs, lambda f: contact_stage(cfg, stage_inputs, f))
        return open_result(result.folder / CONTACT_NC, CONTACT, cfg.contact.p0_gpa)

    def contact_summary(self) -> dict:
        """``06-contact/summary.json``: parameters, their provenance and the per-p0 results."""
        return self._json("contact", SUMMARY_JSON)

    def report(self, refusal: dict | None = None) -> Path:
        """Stage 7: ``report.html`` in ``07-report/`` and the run directory (``refusal``: of a
        run refused after the scan, its finished stages only, :mod:`flatcontact.refused`)."""
        cfg = self.config
        names = [  # a refused run: its finished stages (the asperity never runs after one)
            n
            for n in report_stages(cfg)
            if refusal is None or (n in refusal["finished"] and n != "asperity")
        ]
        ups = {name: self._upstream(name) for name in names}
        inputs = {**settings_inputs("report", cfg), **{k: v.fingerprint for k, v in ups.items()}}
        if refusal is not None:
            inputs["refusal"] = refusal
        folders = {name: self.folder(name) for name in STAGES}
        versions = json.loads((self.root / VERSIONS_JSON).read_text())

        def work(folder: Path) -> None:
            # the files the report reads, checked against this run's record and settings
            self.scan_summary()
            if refusal is None:
                self.contact_summary()
            report_stage(cfg, ReportInputs(folders, versions, refusal), folder)

        result = self._run("report", inputs, work)
        target = self.root / REPORT_HTML
        if self.rundir.read_only is not None:  # a finished run on a read-only mount
            return target if target.is_file() else result.folder / REPORT_HTML
        # one file under two names: the report is stored once
        return link_file_atomic(result.folder / REPORT_HTML, target)

    def asperity(self) -> dict | None:
        """Stage 8 (optional, ``asperity.enabled``): the asperity in atoms against the model
        (``08-asperity/asperity.json``); its saved states resume an interrupted stage."""
        from flatcontact.foundation.layout import ASPERITY_JSON
        from flatcontact.stages.asperity import AsperityInputs, asperity_stage

        cfg = self.config
        if not cfg.asperity.enabled:
            self._tell("off", "asperity", message="asperity.enabled is false")
            return None
        laws = self._upstream("laws")
        inputs = {**settings_inputs("asperity", cfg), "laws": laws.fingerprint}
        e_star = None
        if cfg.elastic.enabled:
            inputs["elastic"] = self._upstream("elastic").fingerprint
            e_star = float(self._json("elastic", ELASTIC_JSON)["contact_modulus_gpa"])
        doc = self._json("laws", LAWS_JSON)

        def work(folder: Path) -> None:
            asperity_stage(cfg, AsperityInputs(laws=doc, contact_modulus_gpa=e_star), folder)

        self._run("asperity", inputs, work)
        return self._json("asperity", ASPERITY_JSON)

    def run(self) -> Path:
        """Every stage in order; ``report.html`` (also of a refusal after the scan, named in it)."""
        for name in ("build", "scan", "analyze", "laws", "elastic", "contact", "asperity"):
            try:
                getattr(self, name)()
            except InputError as exc:
                if exc is not self._refusal or "scan" not in self.results or self.rundir.read_only:
                    raise  # not a stage's refusal after the scan (a run-directory defect)
                raise InputError(f"{exc} (report: {refused_report(self, name, exc)})") from None
        return self.report()


def run(
    config: RunConfig, root: str | Path, on_event: Callable[[StageEvent], None] | None = None
) -> Path:
    """Run the whole pipeline of ``config`` in ``root``; returns the report path."""
    with Pipeline(config, root, on_event=on_event) as pipe:
        return pipe.run()
