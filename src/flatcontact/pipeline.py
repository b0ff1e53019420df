"""The whole study as stages over a run directory: build → scan → analyze → laws → (elastic) → contact → report.

:class:`Pipeline` runs each stage through :meth:`flatcontact.rundir.RunDirectory.run_stage`
with the stage's inputs = its configuration section + the content of the files it reads
(potential coefficients, structure and measurement files) + the digest of the source code
that computes it (:data:`STAGE_CODE`) + the fingerprints of the stages it reads, so that

- a rerun skips every stage whose inputs are unchanged;
- an interrupted stage (Ctrl-C, kill -9) is resumed: the scan continues from its point
  store (``02-scan/points.db``) and loses nothing that finished;
- changing one setting reruns exactly the stages that depend on it (e.g.
  ``analysis.threshold_gpa`` reruns ``laws``, ``contact`` and ``report``, not the scan).

Settings that do not change numbers (``scan.executor``, ``scan.workers``,
``scan.dask_address``) are not part of any fingerprint.

Run directory layout (files of ``DESIGN.md``)::

    run.json  config.yaml  versions.json  run.log  report.html
    01-build/    interface.extxyz  build.json  fig1_interface.{png,svg}
    02-scan/     points.db  ispes.nc  scan.json  fig_scan_columns.{png,svg}
    03-analyze/  friction.csv  friction.nc  analyze.json  fig2_p<P>gpa.{png,svg}
    04-laws/     laws.json  fig3_laws.{png,svg}
    05-elastic/  elastic.json                       (only with elastic.enabled)
    06-contact/  contact.nc  summary.json  fig4_traction, fig5_force_stiffness(_rms), fig6_experiment
    07-report/   report.html  stage.json

Every stage is a public method returning Python objects (ASE Atoms, xarray Datasets,
pandas DataFrames, dicts), so a notebook can run the stages one by one::

    from flatcontact.config import load_config
    from flatcontact.pipeline import Pipeline
    pipe = Pipeline(load_config("run.yaml"), "my-run")
    atoms = pipe.build()
    ispes = pipe.scan()            # xarray Dataset (ispes.nc)
    friction = pipe.analyze()      # xarray Dataset (friction.nc)
    laws = pipe.laws()             # dict (laws.json)
    contact = pipe.contact()       # xarray Dataset (contact.nc)
    pipe.report()                  # Path of report.html
"""

from __future__ import annotations

import hashlib
import json
import logging
import shutil
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from flatcontact import __version__, units
from flatcontact.config import BUNDLED_DIR, BUNDLED_SNAP, PAPER_VALUES, RunConfig, to_yaml
from flatcontact.errors import InputError
from flatcontact.fileio import write_json_atomic, write_text_atomic
from flatcontact.rundir import RunDirectory, StageResult, code_digest, package_versions

log = logging.getLogger("flatcontact.run")

#: Stage names and their folder indices.
STAGES = {
    "build": 1,
    "scan": 2,
    "analyze": 3,
    "laws": 4,
    "elastic": 5,
    "contact": 6,
    "report": 7,
}
#: The flatcontact source each stage's numbers depend on (paths in the package, see
#: :func:`flatcontact.rundir.code_digest`). Editing one of them reruns the stage and, through
#: the fingerprints, every stage that reads it. The expensive stages (build, scan, elastic)
#: list the sub-packages that compute them, so an edit of the analysis, the contact model,
#: the plots or this module does not rerun a scan; the report takes the whole package.
STAGE_CODE: dict[str, tuple[str, ...]] = {
    "build": ("structures", "potentials", "ispes/toy.py", "units.py"),
    "scan": ("ispes", "potentials", "structures", "units.py"),
    "analyze": ("analysis", "ispes/contract.py", "plots", "pipeline.py", "units.py"),
    "laws": ("analysis", "plots", "pipeline.py", "units.py"),
    "elastic": ("elastic.py", "potentials", "structures", "units.py"),
    "contact": ("contact", "plots", "pipeline.py", "units.py"),
    "report": (".",),
}
RUN_MARKER = "run.json"
RUN_FORMAT = "flatcontact.run/1"
#: Scan settings that change how, not what, is computed (kept out of the fingerprint).
EXECUTION_ONLY = ("executor", "workers", "dask_address", "jobqueue")


def file_sha256(path: str | Path) -> str:
    """SHA-256 of a file's bytes (input files enter fingerprints by content)."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def _save_figure(fig, stem: Path, svg: bool) -> list[Path]:
    """Save a figure as ``stem.png`` (+ ``stem.svg``) atomically and close it."""
    from flatcontact.plots import save_figure

    return save_figure(fig, stem, ("png", "svg") if svg else ("png",))


# --------------------------------------------------------------------------- figures of this module


def _draw_atoms(
    ax, xy: np.ndarray, symbols, depth: np.ndarray, palette: dict, scale: float
) -> None:
    """Atoms as circles in data units (covalent radius × ``scale``), far ones drawn first."""
    from ase.data import atomic_numbers, covalent_radii
    from matplotlib.patches import Circle

    for i in np.argsort(depth):
        r = scale * covalent_radii[atomic_numbers[symbols[i]]]
        ax.add_patch(
            Circle(xy[i], r, facecolor=palette.get(symbols[i], "#999999"), edgecolor="k", lw=0.5)
        )


def figure_interface(atoms):
    """Fig. 1 style: (a) side view of the interface (3 cells along a1, seen along y) with
    surfaces 1–4 marked, (b) top view of slab 1's inner face (surface 2) over 4×4 cells
    with the primitive cell dashed. Si blue, O red (other elements grey)."""
    import matplotlib.pyplot as plt

    palette = {"Si": "#3b6ea5", "O": "#d62728"}
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(12, 5.5), gridspec_kw={"width_ratios": [1, 1.3]})
    cell = atoms.cell.array
    side = atoms.repeat((3, 1, 1))
    pos = side.positions
    _draw_atoms(ax, pos[:, [0, 2]], side.get_chemical_symbols(), -pos[:, 1], palette, 0.55)
    surface = atoms.arrays["surface"]
    z = atoms.positions[:, 2]
    x_lo, x_hi = pos[:, 0].min() - 1.5, pos[:, 0].max() + 1.5
    for tag, color in ((1, "0.6"), (2, "tab:green"), (3, "tab:purple"), (4, "0.6")):
        sel = surface == tag
        if np.any(sel):
            zt = float(z[sel].mean())
            ax.axhline(zt, color=color, lw=0.8, ls="--")
            ax.text(
                x_hi + 0.3,
                zt,
                f"surface {tag}" + (" (fixed)" if tag in (1, 4) else ""),
                va="center",
                fontsize=8,
                color="k",
            )
    ax.set_xlim(x_lo, x_hi + 7)
    ax.set_ylim(z.min() - 2, z.max() + 2)
    ax.set_aspect("equal")
    ax.set_xlabel("x (Å)")
    ax.set_ylabel("z (Å)")
    ax.set_title("(a) side view: slab 1 below, slab 2 above")
    face = atoms[(atoms.arrays["slab"] == 1) & (surface == 2)]
    top = face.repeat((4, 4, 1))
    tp = top.positions
    _draw_atoms(bx, tp[:, :2], top.get_chemical_symbols(), tp[:, 2], palette, 0.55)
    a1, a2 = cell[0][:2], cell[1][:2]
    origin = a1 + a2
    corners = np.array([origin, origin + a1, origin + a1 + a2, origin + a2, origin])
    bx.plot(corners[:, 0], corners[:, 1], "k--", lw=1.2, label="primitive cell")
    bx.set_xlim(tp[:, 0].min() - 1.5, tp[:, 0].max() + 1.5)
    bx.set_ylim(tp[:, 1].min() - 1.5, tp[:, 1].max() + 1.5)
    bx.set_aspect("equal")
    bx.set_xlabel("x (Å)")
    bx.set_ylabel("y (Å)")
    bx.set_title("(b) top view of the inner face of slab 1 (surface 2)")
    for key, col in palette.items():
        if key in atoms.get_chemical_symbols():
            bx.plot([], [], "o", color=col, label=key)
    bx.legend(loc="upper left", fontsize=8)
    fig.tight_layout()
    return fig


def figure_scan_columns(ds, adhesion: dict | None = None):
    """Normal load p(z) and energy U(z) of every lateral point of the ISPES grid.

    Each thin line is one lateral shift; p rises as z falls on the repulsive branch.
    """
    import matplotlib.pyplot as plt

    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.2))
    z = ds["thickness"].values
    p = ds["normal_stress"].values.reshape(-1, z.size)
    e = ds["energy"].values.reshape(-1, z.size)
    area = float(ds.attrs["area"])
    e_min = np.nanmin(e)
    for k in range(p.shape[0]):
        ax.plot(z, p[k], color="tab:blue", lw=0.6, alpha=0.5)
        bx.plot(
            z,
            (e[k] - e_min) / area * units.EV_PER_A2_TO_MEV_PER_A2,
            color="tab:red",
            lw=0.6,
            alpha=0.5,
        )
    ax.axhline(0, color="grey", lw=0.6)
    ax.set_xlabel("thickness z, surface 1 to 4 (Å)")
    ax.set_ylabel("normal load p (GPa, + = compression)")
    ax.set_title(f"(a) p(z) at all {p.shape[0]} lateral shifts")
    if adhesion:
        ax.axvline(
            adhesion["equilibrium_thickness_angstrom"],
            color="k",
            ls=":",
            lw=0.8,
            label="p = 0 at the probe stacking",
        )
        ax.legend(fontsize=8)
    bx.set_xlabel("thickness z (Å)")
    bx.set_ylabel("U − min U (meV/Å²)")
    bx.set_title("(b) energy per area U(z)")
    fig.tight_layout()
    return fig


# --------------------------------------------------------------------------- the pipeline


class Pipeline:
    """The stages of one run over a run directory (see the module docstring).

    Parameters
    ----------
    config
        The validated run configuration (:func:`flatcontact.config.load_config`).
    root
        The run directory; created if missing. A non-empty directory that is not a
        flatcontact run is refused.
    console
        A rich Console for progress (``None``: no progress output).
    """

    def __init__(self, config: RunConfig, root: str | Path, console: Any = None):
        self.config = config
        self.root = Path(root)
        self.console = console
        self._check_root()
        self._check_config()
        self.rundir = RunDirectory(self.root)
        self.results: dict[str, StageResult] = {}
        self._handler: logging.Handler | None = None
        self._open_log()
        write_json_atomic(
            self.root / RUN_MARKER, {"format": RUN_FORMAT, "flatcontact_version": __version__}
        )
        write_text_atomic(self.root / "config.yaml", to_yaml(config))
        write_json_atomic(self.root / "versions.json", package_versions())

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
                data = json.loads(marker.read_text())
            except (OSError, json.JSONDecodeError):
                raise InputError(
                    f"{marker}: corrupt run marker; remove it only if {root} is a flatcontact run"
                ) from None
            if not isinstance(data, dict) or data.get("format") != RUN_FORMAT:
                raise InputError(
                    f"{marker}: not a flatcontact run marker (expected format {RUN_FORMAT})"
                )

    def _check_config(self) -> None:
        """Checks that need the file system or optional modules, before any work."""
        cfg = self.config
        if cfg.structure.kind == "file":
            from flatcontact.structures.interface import read_interface

            read_interface(cfg.structure.file)
        if cfg.contact.experiment_csv is not None:
            from flatcontact.contact.experiment import load_stiffness_csv

            load_stiffness_csv(cfg.contact.experiment_csv)
        if cfg.calculator is not None:
            from flatcontact.ispes.calculators import CalculatorFactory

            CalculatorFactory.from_target(cfg.calculator.target, **cfg.calculator.kwargs)
        if cfg.elastic.enabled:
            self._elastic_potential()

    def _elastic_potential(self) -> str:
        """The name :func:`flatcontact.elastic.quartz_contact_moduli` takes for this potential."""
        cfg = self.config
        intra = cfg.potential.intra
        if cfg.calculator is None and (intra == "vashishta" or intra.startswith("snap:")):
            return intra.removeprefix("snap:")
        raise InputError(
            "elastic.enabled: self-consistent moduli need potential.intra vashishta or snap:<name>, "
            f"got {intra if cfg.calculator is None else 'calculator ' + cfg.calculator.target}"
        )

    def _open_log(self) -> None:
        handler = logging.FileHandler(self.root / "run.log", encoding="utf-8")
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
        """Detach the run log."""
        if self._handler is not None:
            logging.getLogger("flatcontact").removeHandler(self._handler)
            self._handler.close()
            self._handler = None

    def __enter__(self) -> Pipeline:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # ---- helpers -----------------------------------------------------------------------
    def folder(self, name: str) -> Path:
        """The folder of stage ``name``."""
        return self.rundir.folder(STAGES[name], name)

    def _model_inputs(self) -> dict:
        cfg = self.config
        if cfg.calculator is not None:
            return {"calculator": cfg.section("calculator")}
        # by content: retraining a bundled SNAP or editing a coefficient file reruns the scan
        files = {Path(f).name: file_sha256(f) for f in cfg.potential.resolved.files}
        return {"potential": cfg.section("potential"), "files_sha256": files}

    def _factory(self):
        from flatcontact.ispes.calculators import CalculatorFactory, PotentialFactory

        cfg = self.config
        if cfg.calculator is not None:
            return CalculatorFactory.from_target(cfg.calculator.target, **cfg.calculator.kwargs)
        return PotentialFactory.from_spec(cfg.potential)

    def _upstream(self, name: str) -> StageResult:
        if name not in self.results:
            getattr(self, name)()
        return self.results[name]

    def _run(self, name: str, inputs: dict, work: Callable[[Path], None]) -> StageResult:
        say = self.console.print if self.console is not None else (lambda *a, **k: None)
        index = STAGES[name]
        inputs = {**inputs, "code_sha256": code_digest(STAGE_CODE[name])}
        say(f"[bold]{index}. {name}[/]", highlight=False)
        try:
            if self.console is not None and name != "scan":
                with self.console.status(f"{name} ..."):
                    result = self.rundir.run_stage(index, name, inputs, work)
            else:
                result = self.rundir.run_stage(index, name, inputs, work)
        except KeyboardInterrupt:
            log.warning("stage %s: interrupted; rerun to resume", name)
            raise
        except Exception as exc:
            log.error("stage %s: failed: %s", name, exc)
            raise
        self.results[name] = result
        detail = {"skipped": "unchanged, skipped", "resumed": "resumed", "ran": "done"}[
            result.action
        ]
        say(
            f"   {detail}" + (f" in {result.seconds:.1f} s" if result.action != "skipped" else ""),
            highlight=False,
        )
        return result

    # ---- stages ------------------------------------------------------------------------
    def build(self):
        """Stage 1: the relaxed reference interface (``01-build/interface.extxyz``).

        Returns
        -------
        ase.Atoms
            The interface (``slab``/``surface`` arrays, ``a1``/``a2``/``recipe`` info).
        """
        from flatcontact.structures.interface import read_interface, write_interface

        cfg = self.config
        inputs = {"structure": cfg.section("structure"), "model": self._model_inputs()}
        if cfg.structure.kind == "file":
            inputs["file_sha256"] = file_sha256(cfg.structure.file)

        def work(folder: Path) -> None:
            s = cfg.structure
            if s.kind == "quartz-dense":
                from flatcontact.structures.build import build_quartz_interface

                atoms, report = build_quartz_interface(
                    cfg.potential,
                    s.layers,
                    source=s.source,
                    gap_angstrom=s.gap_angstrom,
                    fmax_ev_per_angstrom=s.fmax_ev_per_angstrom,
                )
            elif s.kind == "toy-lj":
                from flatcontact.ispes.toy import toy_interface
                from flatcontact.structures.interface import thickness

                atoms = toy_interface(s.layers, **cfg.calculator.kwargs)
                report = {
                    "source": "flatcontact.ispes.toy",
                    "n_atoms": len(atoms),
                    "thickness_angstrom": thickness(atoms),
                }
            else:
                from flatcontact.structures.interface import thickness

                atoms = read_interface(s.file)
                report = {
                    "source": s.file,
                    "n_atoms": len(atoms),
                    "thickness_angstrom": thickness(atoms),
                }
            write_interface(atoms, folder / "interface.extxyz")
            write_json_atomic(folder / "build.json", report)
            _save_figure(figure_interface(atoms), folder / "fig1_interface", cfg.report.svg)

        result = self._run("build", inputs, work)
        return read_interface(result.folder / "interface.extxyz")

    def scan(self):
        """Stage 2: the ISPES grid (``02-scan/ispes.nc``, resumable ``points.db``).

        Returns
        -------
        xarray.Dataset
            The ``ispes.nc`` contract (energy, normal_stress, converged, force_calls).
        """
        from flatcontact.ispes.contract import open_ispes

        cfg = self.config
        build = self._upstream("build")
        scan_inputs = {k: v for k, v in cfg.section("scan").items() if k not in EXECUTION_ONLY}
        inputs = {"scan": scan_inputs, "model": self._model_inputs(), "build": build.fingerprint}

        def work(folder: Path) -> None:
            from flatcontact.ispes.scan import run_scan
            from flatcontact.structures.interface import read_interface

            s = cfg.scan
            reference = read_interface(build.folder / "interface.extxyz")
            factory = self._factory()
            if cfg.calculator is None:
                from flatcontact.potentials import check_elements

                check_elements(cfg.potential, reference)
            result = run_scan(
                reference,
                factory,
                s.grid_spec(),
                folder,
                s.relax_settings(),
                order=s.order,
                executor_options=s.executor_options(),
                progress=self.console is not None,
                console=self.console,
            )
            calls = result.force_calls_computed
            ds = result.dataset
            summary = {
                "points_total": result.points_total,
                "points_done": result.points_done,
                "points_computed_last_attempt": result.points_computed,
                "converged": int(ds["converged"].sum()),
                "force_calls_total": int(np.nansum(ds["force_calls"].values)),
                "median_force_calls_per_point": float(np.median(calls)) if calls else None,
                "thickness_angstrom": [float(z) for z in ds["thickness"].values],
                "area_angstrom2": float(ds.attrs["area"]),
                "potential": str(ds.attrs.get("potential", "")),
                "adhesion": result.adhesion,
                "notes": result.notes,
            }
            write_json_atomic(folder / "scan.json", summary)
            for note in result.notes:
                log.warning("scan: %s", note)
            _save_figure(
                figure_scan_columns(ds, result.adhesion),
                folder / "fig_scan_columns",
                cfg.report.svg,
            )

        result = self._run("scan", inputs, work)
        return open_ispes(result.folder / "ispes.nc")

    def scan_summary(self) -> dict:
        """``02-scan/scan.json``: counts, force calls, thicknesses, adhesion (work of separation)."""
        return json.loads((self._upstream("scan").folder / "scan.json").read_text())

    def analyze(self):
        """Stage 3: constant-pressure ISPES, sliding path, τ, σ_MSS, G_int per load.

        Writes ``friction.csv``, ``friction.nc``, ``analyze.json`` (warnings, timings) and
        Fig. 2 for every load of ``analysis.p_gpa``.

        Returns
        -------
        xarray.Dataset
            ``friction.nc`` (per-load values, paths, constant-pressure maps).
        """
        import xarray as xr

        cfg = self.config
        scan = self._upstream("scan")
        a = cfg.section("analysis")
        a.pop("threshold_gpa")  # used by the laws stage only
        inputs = {"analysis": a, "scan": scan.fingerprint}

        def work(folder: Path) -> None:
            from flatcontact.analysis.diagnostics import AnalysisWarning
            from flatcontact.analysis.outputs import friction_csv_text, friction_dataset
            from flatcontact.analysis.pipeline import analyze_ispes
            from flatcontact.fileio import atomic_path
            from flatcontact.ispes.contract import open_ispes
            from flatcontact.plots.analysis import figure_pressure

            s = cfg.analysis
            ds = open_ispes(scan.folder / "ispes.nc")
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always", AnalysisWarning)
                result = analyze_ispes(
                    ds,
                    s.p_gpa,
                    direction_deg=s.direction_deg,
                    form=s.energy_form,
                    load_source=s.load_source,
                    energy_zero=s.energy_zero,
                    allow_missing=s.allow_missing,
                    threshold_gpa=s.threshold_gpa,
                    with_mep=s.with_mep,
                    source=str(scan.folder / "ispes.nc"),
                )
            notes = [
                f"{w.category.__name__}: {w.message}"
                for w in caught
                if issubclass(w.category, AnalysisWarning)
            ]
            for note in notes:
                log.warning("analyze: %s", note)
            write_text_atomic(folder / "friction.csv", friction_csv_text(result))
            with atomic_path(folder / "friction.nc") as tmp:
                friction_dataset(result).to_netcdf(tmp, engine="h5netcdf")
            figures = []
            for pa in result.pressures:
                stem = folder / f"fig2_p{pa.p_gpa:g}gpa"
                figures.append(stem.name)
                _save_figure(figure_pressure(pa, result), stem, cfg.report.svg)
            sym = {
                f"{pa.p_gpa:g}": pa.symmetry.to_json()
                for pa in result.pressures
                if pa.symmetry is not None
            }
            write_json_atomic(
                folder / "analyze.json",
                {
                    "warnings": notes,
                    "timings_s": result.timings_s,
                    "fig2": figures,
                    "symmetry": sym,
                    "energy_reference_ev_per_a2": result.energy_reference_ev_per_a2,
                    "load_source": result.load_source,
                    "noise": result.noise.to_json(),
                },
            )

        result = self._run("analyze", inputs, work)
        with xr.open_dataset(result.folder / "friction.nc", engine="h5netcdf") as ds:
            return ds.load()

    def friction_table(self):
        """``03-analyze/friction.csv`` as a pandas DataFrame (one row per load)."""
        import pandas as pd

        return pd.read_csv(self._upstream("analyze").folder / "friction.csv")

    def laws(self) -> dict:
        """Stage 4: τ = k·P + τ0 and σ = μ·P + σ0 fitted on P ≤ ``analysis.threshold_gpa``.

        Returns
        -------
        dict
            ``laws.json`` (``k_mpa_per_gpa``, ``tau0_mpa``, ``mu_mpa_per_gpa``, ``sigma0_mpa``,
            standard errors, fitted range, end of the linear regime).
        """
        cfg = self.config
        analyze = self._upstream("analyze")
        inputs = {"threshold_gpa": cfg.analysis.threshold_gpa, "analyze": analyze.fingerprint}

        def work(folder: Path) -> None:
            from types import SimpleNamespace

            import pandas as pd

            from flatcontact.analysis.diagnostics import AnalysisWarning
            from flatcontact.analysis.laws import fit_load_laws
            from flatcontact.plots.analysis import figure_laws

            table = pd.read_csv(analyze.folder / "friction.csv")
            p = table["p_gpa"].to_numpy(float)
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always", AnalysisWarning)
                laws = fit_load_laws(
                    p,
                    table["tau_mpa"].to_numpy(float),
                    table["sigma_mss_mpa"].to_numpy(float),
                    cfg.analysis.threshold_gpa,
                )
            doc = laws.to_json()
            doc["warnings"] = [str(w.message) for w in caught]
            write_json_atomic(folder / "laws.json", doc)
            view = SimpleNamespace(
                p_gpa=p, laws=laws, column=lambda name: table[name].to_numpy(float)
            )
            _save_figure(figure_laws(view), folder / "fig3_laws", cfg.report.svg)

        result = self._run("laws", inputs, work)
        return json.loads((result.folder / "laws.json").read_text())

    def elastic(self) -> dict | None:
        """Stage 5 (optional): E* and G* from the potential (``05-elastic/elastic.json``).

        Returns ``None`` when ``elastic.enabled`` is false (the contact stage then uses
        ``contact.contact_modulus_gpa`` and ``contact.shear_modulus_gpa``).
        """
        cfg = self.config
        if not cfg.elastic.enabled:
            if self.console is not None:
                self.console.print(
                    f"[bold]{STAGES['elastic']}. elastic[/]\n   off: the contact model takes "
                    f"E* = {cfg.contact.contact_modulus_gpa:g} GPa, G* = "
                    f"{cfg.contact.shear_modulus_gpa:g} GPa from the configuration",
                    highlight=False,
                )
            return None
        inputs = {"elastic": cfg.section("elastic"), "model": self._model_inputs()}

        def work(folder: Path) -> None:
            from flatcontact.elastic import quartz_contact_moduli

            doc = quartz_contact_moduli(self._elastic_potential(), strain=cfg.elastic.strain)
            m = doc["moduli_gpa"]
            doc["contact_modulus_gpa"] = m["e_star"]
            doc["shear_modulus_gpa"] = m["g_star_paper"]
            write_json_atomic(folder / "elastic.json", doc)

        result = self._run("elastic", inputs, work)
        return json.loads((result.folder / "elastic.json").read_text())

    def contact_parameters(self):
        """The :class:`~flatcontact.contact.parameters.ContactParameters` the contact stage uses.

        k, τ0, μ, σ0 come from the fitted laws unless overridden in ``contact``; w is the
        scan's work of separation unless ``contact.work_of_adhesion_j_m2`` is given; E*, G*
        come from the elastic stage when enabled. Returns (parameters, provenance dict).
        """
        from flatcontact.contact.parameters import ContactParameters

        c = self.config.contact
        laws = json.loads((self._upstream("laws").folder / "laws.json").read_text())
        provenance = {}
        values = {}
        for key in ("k_mpa_per_gpa", "tau0_mpa", "mu_mpa_per_gpa", "sigma0_mpa"):
            given = getattr(c, key)
            if given is not None:
                values[key], provenance[key] = given, "config"
                continue
            fitted = laws.get(key)
            if fitted is None:
                why = "; ".join(laws.get("warnings", [])) or "too few loads"
                raise InputError(
                    f"contact.{key}: the load law could not be fitted ({why}); give contact.{key}"
                )
            # negative slopes pass through: the model takes k < 0, μ < 0 wherever τ > 0
            # and σ >= 0 on the contact, and refuses the p0 where they are not
            values[key], provenance[key] = fitted, "fitted laws"
        w = c.work_of_adhesion_j_m2
        provenance["work_of_adhesion_j_m2"] = "config"
        if w is None:
            adh = self.scan_summary().get("adhesion") or {}
            w = adh.get("work_of_separation_j_per_m2")
            provenance["work_of_adhesion_j_m2"] = "scan work of separation"
            if w is None or not w > 0:
                w, provenance["work_of_adhesion_j_m2"] = 0.0, "none (no probe column)"
        moduli = None
        if self.config.elastic.enabled:
            moduli = json.loads((self._upstream("elastic").folder / "elastic.json").read_text())
        e_star, g_star = c.contact_modulus_gpa, c.shear_modulus_gpa
        provenance["moduli"] = "config"
        if moduli is not None:
            e_star, g_star = moduli["contact_modulus_gpa"], moduli["shear_modulus_gpa"]
            provenance["moduli"] = "elastic stage"
        try:
            params = ContactParameters(
                radius_um=c.radius_um,
                contact_modulus_gpa=e_star,
                shear_modulus_gpa=g_star,
                work_of_adhesion_j_m2=float(w),
                **values,
            )
        except InputError as exc:  # e.g. a fitted τ0 < 0, or k < 0 with τ0 = 0
            sources = ", ".join(f"{k} from {provenance[k]}" for k in values)
            raise InputError(f"contact: {exc} ({sources})") from None
        return params, provenance

    def contact(self):
        """Stage 6: modified Mindlin contact at every ``contact.p0_gpa``.

        Writes ``contact.nc``, ``summary.json`` and Figs. 4, 5 (and 6 with measured data).

        Returns
        -------
        xarray.Dataset
            ``contact.nc``: Q(u) and stiffness curves and the per-p0 scalars.
        """
        import xarray as xr

        cfg = self.config
        laws = self._upstream("laws")
        scan = self._upstream("scan")
        elastic = self._upstream("elastic") if cfg.elastic.enabled else None
        # before any work: with k < 0 or μ < 0 the model is defined only where τ > 0 and
        # σ >= 0 on the whole contact (p0 < τ0/|k|, p0 <= σ0/|μ|)
        params, _ = self.contact_parameters()
        params.check_p0_gpa(cfg.contact.p0_gpa, "contact.p0_gpa")
        if cfg.contact.experiment_csv:
            params.check_p0_gpa(cfg.contact.experiment_p0_gpa, "contact.experiment_p0_gpa")
        inputs = {
            "contact": cfg.section("contact"),
            "laws": laws.fingerprint,
            "scan": scan.fingerprint,
            "elastic": elastic.fingerprint if elastic else None,
        }
        if cfg.contact.experiment_csv:
            inputs["experiment_sha256"] = file_sha256(cfg.contact.experiment_csv)

        def work(folder: Path) -> None:
            from flatcontact.contact import experiment as exp
            from flatcontact.contact.summary import analyse
            from flatcontact.plots.contact import (
                fig4_traction,
                fig5_force_and_stiffness,
                fig6_overlay,
            )

            c = cfg.contact
            params, provenance = self.contact_parameters()
            analysis = analyse(
                c.p0_gpa, params, knee_fraction=c.knee_fraction, p0_name="contact.p0_gpa"
            )
            paper = analyse(
                c.p0_gpa,
                params.replace(
                    k_mpa_per_gpa=PAPER_VALUES["k_mpa_per_gpa"],
                    tau0_mpa=PAPER_VALUES["tau0_mpa"],
                    mu_mpa_per_gpa=PAPER_VALUES["mu_mpa_per_gpa"],
                    sigma0_mpa=PAPER_VALUES["sigma0_mpa"],
                ),
                knee_fraction=c.knee_fraction,
            )
            doc = {
                "parameters": params.as_dict(),
                "provenance": provenance,
                "conventions": {
                    "shear_modulus": "paper: q0 = G* u/(pi a); Johnson's G*_J = G*/4",
                    "effective_shear_strength_mpa": "amplitude Q_peak/(pi a^2)",
                    "effective_shear_strength_rms_mpa": "Q_peak/(sqrt(2) pi a^2)",
                },
                "results": analysis.records(),
                "results_with_paper_laws": paper.records(),
            }
            p0_fig4 = 1.0 if 1.0 in analysis.p0_gpa else analysis.p0_gpa[0]
            figs = {
                "fig4_traction": fig4_traction(params, p0_fig4),
                "fig5_force_stiffness": fig5_force_and_stiffness(analysis, "amplitude"),
                "fig5_force_stiffness_rms": fig5_force_and_stiffness(analysis, "rms"),
            }
            if c.experiment_csv:
                measured = exp.load_stiffness_csv(c.experiment_csv)
                comparison = exp.compare_with_measurement(
                    measured,
                    c.experiment_p0_gpa,
                    params,
                    fraction=c.collapse_fraction,
                    measure=c.experiment_stress_measure,
                )
                tau0_fit = comparison.fitted_tau0_mpa
                fitted = comparison.fitted_params
                doc["experiment"] = comparison.to_json()
                figs["fig6_experiment"] = fig6_overlay(
                    measured,
                    c.experiment_p0_gpa,
                    {
                        f"τ0 = {params.tau0_mpa:.3g} MPa (run)": params,
                        f"fitted τ0 = {tau0_fit:.3g} MPa": fitted,
                    },
                    measure=c.experiment_stress_measure,
                    measured_collapse_mpa=doc["experiment"]["measured_collapse_stress_mpa"],
                )
            for name, fig in figs.items():
                _save_figure(fig, folder / name, cfg.report.svg)
            analysis.write_netcdf(folder / "contact.nc")
            write_json_atomic(folder / "summary.json", doc)

        result = self._run("contact", inputs, work)
        with xr.open_dataset(result.folder / "contact.nc", engine="h5netcdf") as ds:
            return ds.load()

    def contact_summary(self) -> dict:
        """``06-contact/summary.json``: parameters, their provenance and the per-p0 results."""
        return json.loads((self._upstream("contact").folder / "summary.json").read_text())

    def report(self) -> Path:
        """Stage 7: ``report.html`` (self-contained) in ``07-report/`` and the run directory."""
        cfg = self.config
        ups = {
            name: self._upstream(name) for name in ("build", "scan", "analyze", "laws", "contact")
        }
        inputs = {"report": cfg.section("report"), **{k: v.fingerprint for k, v in ups.items()}}

        def work(folder: Path) -> None:
            build_report(self, folder / "report.html")

        result = self._run("report", inputs, work)
        target = self.root / "report.html"
        tmp = target.with_name(".report.html.tmp")
        shutil.copyfile(result.folder / "report.html", tmp)
        tmp.replace(target)
        return target

    def run(self) -> Path:
        """Every stage in order; returns the path of ``report.html``."""
        for name in ("build", "scan", "analyze", "laws", "elastic", "contact"):
            getattr(self, name)()
        return self.report()


def run(config: RunConfig, root: str | Path, console: Any = None) -> Path:
    """Run the whole pipeline of ``config`` in ``root``; returns the report path."""
    with Pipeline(config, root, console=console) as pipe:
        return pipe.run()


# --------------------------------------------------------------------------- the report


def _fmt(value: Any, digits: int = 4) -> str:
    if value is None or (isinstance(value, float) and not np.isfinite(value)):
        return "n/a"
    if isinstance(value, float):
        return f"{value:.{digits}g}"
    return str(value)


def _pm(value: float | None, err: float | None) -> str:
    if value is None:
        return "n/a"
    return f"{value:.3g} ± {err:.2g}" if err is not None else f"{value:.3g}"


def compare_with_paper(laws: dict, config: RunConfig) -> list[tuple[str, str, str, str, str]]:
    """Rows (quantity, this run ± s.e., paper, difference, reading) for k, τ0, μ, σ0.

    The reading says whether the difference is within two standard errors of the fit
    and otherwise names the differences of set-up that can cause it.
    """
    rows = []
    for key, err_key, label in (
        ("k_mpa_per_gpa", "k_stderr_mpa_per_gpa", "k (MPa/GPa)"),
        ("tau0_mpa", "tau0_stderr_mpa", "τ0 (MPa)"),
        ("mu_mpa_per_gpa", "mu_stderr_mpa_per_gpa", "μ (MPa/GPa)"),
        ("sigma0_mpa", "sigma0_stderr_mpa", "σ0 (MPa)"),
    ):
        value, err, ref = laws.get(key), laws.get(err_key), PAPER_VALUES[key]
        if value is None:
            rows.append(
                (label, "n/a", f"{ref:g}", "n/a", "not fitted (too few loads below the threshold)")
            )
            continue
        diff = value - ref
        rel = f"{diff:+.3g} ({100 * diff / ref:+.0f} %)"
        if err is not None and abs(diff) <= 2 * err:
            reading = "consistent with the paper within 2 standard errors of the fit"
        else:
            reading = (
                "differs beyond 2 standard errors"
                if err is not None
                else "differs (no error estimate)"
            )
        rows.append((label, _pm(value, err), f"{ref:g}", rel, reading))
    return rows


def _setup_differences(pipe: Pipeline) -> list[str]:
    """Why this run's numbers can differ from the paper's: a list of concrete set-up differences."""
    cfg = pipe.config
    out = []
    if cfg.calculator is not None:
        out.append(
            f"The interaction model is the ASE calculator {cfg.calculator.target}, not the "
            "paper's SNAP + TS-vdW LJ."
        )
    elif not cfg.potential.intra.startswith("snap:"):
        out.append(
            f"The intra-slab model is '{cfg.potential.intra}', a classical potential, not the paper's "
            "SNAP trained on DFT (Erhard et al. 2022). Its lattice constant, surface relaxation and "
            "interfacial corrugation differ, and τ and σ are differences of the corrugation "
            "energy, so they inherit these differences directly (Vashishta: a = 4.829 Å vs 4.916 Å; "
            "the interface's lateral cell is the experimental 4.916 Å, so Vashishta slabs carry "
            "+1.8 % in-plane strain)."
        )
    elif cfg.potential.intra == f"snap:{BUNDLED_SNAP}":
        validation = json.loads((BUNDLED_DIR / BUNDLED_SNAP / "validation.json").read_text())
        e_star = validation["potential"]["elastic"]["moduli_gpa"]["e_star"]
        out.append(
            f"The intra-slab SNAP is flatcontact's bundled {BUNDLED_SNAP}, trained on CHGNet "
            "r2SCAN labels, not on the DFT data of Erhard et al. (2022) like the paper's; its "
            f"α-quartz follows CHGNet's, softer than experiment: E* = {e_star:.1f} GPa from its "
            "elastic constants (validation.json) vs the paper's 52.5 GPa. The interface's "
            "lateral cell is the experimental a = 4.916 Å; the SNAP's own α-quartz has "
            f"a = {validation['potential']['lattice']['a_angstrom']:.3f} Å, so the slabs carry "
            f"{100 * (4.916 / validation['potential']['lattice']['a_angstrom'] - 1):+.1f} % "
            "in-plane strain."
        )
    else:
        out.append(
            f"The intra-slab SNAP '{cfg.potential.intra}' is not the paper's (trained on the DFT "
            "data of Erhard et al. 2022)."
        )
    lj = cfg.potential.lj if cfg.calculator is None else None
    if lj is not None:
        out.append(_lj_difference(lj))
    if cfg.structure.kind != "quartz-dense":
        out.append("The interface is not the paper's α-quartz (0001) dense interface.")
    elif cfg.structure.layers != 6:
        out.append(f"Each slab has {cfg.structure.layers} O–Si–O layers (the paper: 6).")
    na, nb = cfg.scan.grid
    if na * nb < 144:
        out.append(
            f"The lateral grid is {na}×{nb} per primitive cell; the barrier heights and the "
            "largest slope (τ) of a coarse grid rely on the periodic interpolant."
        )
    n_fit = len([p for p in cfg.analysis.p_gpa if p <= cfg.analysis.threshold_gpa])
    out.append(
        f"The laws are fitted on {n_fit} loads with P ≤ {cfg.analysis.threshold_gpa:g} GPa; "
        "the paper does not list its loads or standard errors."
    )
    return out


def _lj_difference(lj) -> str:
    """How the cross-interface LJ compares with the paper's in-solid vdW-DFT C6, in numbers."""
    from flatcontact.config import QUARTZ_HAMAKER_ZJ
    from flatcontact.potentials.lj import (
        ALPHA_QUARTZ_NUMBER_DENSITY_PER_NM3,
        pairwise_hamaker_constant_zj,
    )

    try:
        table = lj.table(["O", "Si"], ["O", "Si"])
        a_zj = pairwise_hamaker_constant_zj(table, ALPHA_QUARTZ_NUMBER_DENSITY_PER_NM3)
    except InputError:
        return "The cross-interface LJ does not cover Si and O; the paper's C6 are for SiO₂."
    hamaker = (
        f"its C6 sum to a pairwise Hamaker constant of {a_zj:.0f} zJ for α-quartz, against "
        f"≈ {QUARTZ_HAMAKER_ZJ:.0f} zJ from Lifshitz theory (Bergström 1997)"
    )
    if lj.hamaker_zj is not None:
        return (
            "The paper took the LJ C6 from vdW-DFT of the solid (Hirshfeld-scaled TS), which we "
            "cannot run here; flatcontact scales the Tkatchenko–Scheffler C6 instead so that "
            f"their pairwise Hamaker constant for α-quartz is {a_zj:.0f} zJ "
            f"(potential.lj.hamaker_zj; Lifshitz theory: ≈ {QUARTZ_HAMAKER_ZJ:.0f} zJ, "
            "Bergström 1997). Free-atom C6 would give 411 zJ and about "
            "4–5× the adhesion and τ0: τ0 follows the LJ well depth almost linearly "
            "(measurements in docs/run.md)."
        )
    return (
        "The cross-interface LJ is not calibrated: "
        + hamaker
        + ". The paper took in-solid C6 from vdW-DFT, where cationic Si is far less polarisable "
        "than a free atom; adhesion and τ0 scale almost linearly with the C6 (docs/run.md). "
        "Set potential.lj.hamaker_zj to calibrate."
    )


def _elastic_tables(pipe: Pipeline) -> list:
    """The elastic stage's Cij and moduli (when it ran), for the contact section."""
    from flatcontact.report import Table

    path = pipe.folder("elastic") / "elastic.json"
    if not pipe.config.elastic.enabled or not path.exists():
        return []
    doc = json.loads(path.read_text())
    cij = doc.get("cij_gpa", {})
    moduli = doc.get("moduli_gpa", {})
    return [
        Table(
            ("α-quartz with the potential", "value"),
            [
                ("a, c (Å)", f"{_fmt(doc.get('a_angstrom'))}, {_fmt(doc.get('c_angstrom'))}"),
                *((f"{k} (GPa)", _fmt(v)) for k, v in cij.items()),
                *(
                    (f"{k} (GPa)" if k != "poisson_ratio" else k, _fmt(v))
                    for k, v in moduli.items()
                ),
            ],
        )
    ]


_LOAD_SOURCE_TEXT = {
    "energy": "−(1/A) dU/dz of each column's energy spline (analysis.load_source = energy)",
    "stress": "the stored normal stress (analysis.load_source = stress)",
}
_ENERGY_ZERO_TEXT = {
    "lowest-p": "the global minimum at the lowest load analysed",
    "each": "the global minimum at each load",
    "none": "none (energies as computed, per area)",
}


def _symmetry_table(symmetry: dict):
    """Table of analyze.json's ``symmetry`` (per P: tolerance, kept operations, deviations)."""
    from flatcontact.report import Table

    tolerance = next(iter(symmetry.values()), {}).get("tolerance_percent", float("nan"))
    rows = [
        (
            p,
            ", ".join(doc["kept"]) or "none",
            ", ".join(f"{name} {dev:.2g}%" for name, dev in doc["deviation_percent"].items()),
        )
        for p, doc in symmetry.items()
    ]
    return Table(
        (
            "P (GPa)",
            f"symmetry operations of the cell kept (rms change < {tolerance:g} %)",
            "rms change of every operation",
        ),
        rows,
    )


def build_report(pipe: Pipeline, path: Path) -> Path:
    """Assemble ``report.html`` from the stage folders of ``pipe`` (figures embedded)."""
    from flatcontact.report import Figure, Section, Table, write_report

    cfg = pipe.config
    f_build, f_scan = pipe.folder("build"), pipe.folder("scan")
    f_an, f_laws, f_ct = pipe.folder("analyze"), pipe.folder("laws"), pipe.folder("contact")
    build = json.loads((f_build / "build.json").read_text())
    scan = json.loads((f_scan / "scan.json").read_text())
    analyze = json.loads((f_an / "analyze.json").read_text())
    laws = json.loads((f_laws / "laws.json").read_text())
    contact = json.loads((f_ct / "summary.json").read_text())
    table = pipe.friction_table()
    model = (
        f"ASE calculator {cfg.calculator.target}"
        if cfg.calculator is not None
        else cfg.potential.label
    )
    sections = []

    # ---- summary
    stage_rows = []
    for name in STAGES:
        rec = RunDirectory.read_record(pipe.folder(name)) if pipe.folder(name).exists() else None
        if rec is None or name == "report":
            continue
        stage_rows.append(
            (name, rec.get("state", "?"), _fmt(rec.get("seconds")), rec.get("finished", ""))
        )
    sections.append(
        Section(
            "Summary",
            paragraphs=[
                f"Interaction model: {model}. Structure: {cfg.structure.kind}"
                + (
                    f", {cfg.structure.layers} layers per slab"
                    if cfg.structure.kind != "file"
                    else ""
                )
                + f". Preset: {cfg.preset}. ISPES grid {cfg.scan.grid[0]}×{cfg.scan.grid[1]} lateral × "
                f"{len(scan['thickness_angstrom'])} thicknesses. Loads analysed: "
                + ", ".join(f"{p:g}" for p in cfg.analysis.p_gpa)
                + " GPa.",
                "Conventions: P > 0 is compression; z is the distance between surfaces 1 and 4; energies per "
                "area in meV/Å²; stresses in MPa; the contact model uses the paper's q0 = G*·u/(πa) "
                "(G* = 4 × Johnson's G*_J).",
            ],
            tables=[
                Table(
                    ("stage", "state", "seconds (last run)", "finished (UTC)"),
                    stage_rows,
                    "Stages of this run directory",
                )
            ],
        )
    )

    # ---- comparison with the paper
    rows = compare_with_paper(laws, cfg)
    w = (scan.get("adhesion") or {}).get("work_of_separation_j_per_m2")
    rows.append(
        (
            "work of separation W (J/m²)",
            _fmt(w),
            "not reported",
            "",
            "from the probe column: [U(separated) − U(z_eq)]/A",
        )
    )
    res = contact["results"]
    ref = contact["results_with_paper_laws"]
    for r_run, r_pap in zip(res, ref, strict=True):
        rows.append(
            (
                f"effective shear strength Q_peak/πa² at p0 = {r_run['p0_gpa']:g} GPa (MPa)",
                _fmt(r_run["effective_shear_strength_mpa"]),
                _fmt(r_pap["effective_shear_strength_mpa"]),
                f"{r_run['effective_shear_strength_mpa'] - r_pap['effective_shear_strength_mpa']:+.3g}",
                "paper column: the same contact model with the paper's k, τ0, μ, σ0",
            )
        )
    sections.append(
        Section(
            "This run next to the paper",
            paragraphs=[
                "Paper (Dong, Uluca, Cross, Sanvito): τ = k·P + τ0 with k = 4.52 MPa/GPa, τ0 = 26.7 MPa; "
                "σ = μ·P + σ0 with μ = 0.21 MPa/GPa, σ0 = 11.1 MPa (SNAP + TS-vdW LJ, P < 3 GPa).",
            ],
            notes=["Why the numbers can differ: " + " ".join(_setup_differences(pipe))],
            tables=[Table(("quantity", "this run", "paper", "difference", "reading"), rows)],
        )
    )

    # ---- interface
    rel = build.get("interface_relaxation", {})
    checks = build.get("interface_verification") or {}
    verified = bool(checks) and all(v.get("dense") for v in checks.values())
    sections.append(
        Section(
            "1. Interface",
            paragraphs=[
                f"{build.get('n_atoms', '?')} atoms; reference thickness z = {_fmt(build.get('thickness_angstrom'))} Å"
                + (
                    f"; interface relaxation {'converged' if rel.get('converged') else 'NOT converged'}"
                    f" in {rel.get('steps', '?')} steps to {cfg.structure.fmax_ev_per_angstrom:g} eV/Å"
                    if rel
                    else ""
                )
                + (
                    "; the dense surface verified on both slabs after the interface relaxation"
                    if verified
                    else ""
                )
                + ". Surfaces 1 and 4 (outer faces) are held fixed during the scan; surfaces 2, 3 and the "
                "inner atoms relax at every grid point.",
            ],
            figures=[
                Figure(
                    f_build / "fig1_interface.png",
                    "Fig. 1 style: side view and the top view of the inner face.",
                )
            ],
        )
    )

    # ---- scan
    adh = scan.get("adhesion") or {}
    scan_rows = [
        ("grid points", f"{scan['points_done']} of {scan['points_total']}"),
        ("converged", str(scan["converged"])),
        ("force calls (total)", str(scan["force_calls_total"])),
        ("thicknesses z (Å)", ", ".join(f"{z:.4f}" for z in scan["thickness_angstrom"])),
    ]
    for key, label in (
        ("equilibrium_thickness_angstrom", "z at p = 0 (Å)"),
        ("max_tension_gpa", "maximum tension (GPa)"),
        ("work_of_separation_j_per_m2", "work of separation, energy (J/m²)"),
        ("work_of_separation_integral_j_per_m2", "work of separation, −∫p dz (J/m²)"),
    ):
        if key in adh:
            scan_rows.append((label, _fmt(adh[key])))
    sections.append(
        Section(
            "2. ISPES scan",
            tables=[Table(("quantity", "value"), scan_rows)],
            notes=scan.get("notes", []),
            figures=[
                Figure(
                    f_scan / "fig_scan_columns.png",
                    "p(z) and U(z) at every lateral shift: the load rises as the slabs are pressed together.",
                )
            ],
        )
    )

    # ---- constant-pressure ISPES
    ps = cfg.report.fig2_p_gpa
    if ps is None:
        allp = cfg.analysis.p_gpa
        ps = sorted({allp[0], allp[len(allp) // 2], allp[-1]})
    figs = [
        Figure(
            f_an / f"fig2_p{p:g}gpa.png",
            f"Fig. 2 at P = {p:g} GPa: (a) constant-pressure ISPES with the sliding path (white) and "
            "the 1×2 rectangular cell (red dotted); (b) energy along the path, barriers ΔU_i "
            "(arrows); (c) force per area with the shear stiffness (dashed) and τ (circle).",
        )
        for p in ps
        if (f_an / f"fig2_p{p:g}gpa.png").exists()
    ]
    rows = [
        (
            _fmt(r.p_gpa),
            _fmt(r.tau_mpa),
            _fmt(r.tau_period_mpa),
            _fmt(r.sigma_mss_mpa),
            _fmt(r.shear_stiffness_gpa_per_nm),
            str(r.tau_limited_by),
            str(r.n_jumps),
        )
        for r in table.itertuples()
    ]
    sections.append(
        Section(
            "3. Constant-pressure ISPES, sliding path, τ and σ",
            paragraphs=[
                f"Pulling direction {cfg.analysis.direction_deg:g}° from x; energy form "
                f"'{cfg.analysis.energy_form}' (the paper's is 'internal'). τ is the paper's "
                "shear strength (largest force before leaving the initial minimum); τ_period is "
                "the largest force over a whole period, the pull needed for sustained sliding "
                "(always ≥ σ_MSS). The load laws use τ.",
                f"Load at each z from {_LOAD_SOURCE_TEXT[analyze.get('load_source', 'stress')]}. "
                f"Energy zero of the maps and profiles: {_ENERGY_ZERO_TEXT[cfg.analysis.energy_zero]}.",
            ],
            notes=analyze.get("warnings", []),
            tables=[
                Table(
                    (
                        "P (GPa)",
                        "τ (MPa)",
                        "τ_period (MPa)",
                        "σ_MSS (MPa)",
                        "G_int (GPa/nm)",
                        "τ limited by",
                        "jumps",
                    ),
                    rows,
                ),
                _symmetry_table(analyze.get("symmetry", {})),
            ],
            figures=figs,
        )
    )

    # ---- laws
    sections.append(
        Section(
            "4. Load laws",
            paragraphs=[
                f"τ = ({_pm(laws.get('k_mpa_per_gpa'), laws.get('k_stderr_mpa_per_gpa'))}) MPa/GPa · P + "
                f"({_pm(laws.get('tau0_mpa'), laws.get('tau0_stderr_mpa'))}) MPa; "
                f"σ = ({_pm(laws.get('mu_mpa_per_gpa'), laws.get('mu_stderr_mpa_per_gpa'))}) MPa/GPa · P + "
                f"({_pm(laws.get('sigma0_mpa'), laws.get('sigma0_stderr_mpa'))}) MPa, fitted on P ≤ "
                f"{_fmt(laws.get('p_max_gpa'))} GPa (± one standard error). τ linear up to "
                f"{_fmt(laws.get('tau_linear_until_gpa'))} GPa, σ up to {_fmt(laws.get('sigma_linear_until_gpa'))} GPa.",
            ],
            notes=laws.get("warnings", []),
            figures=[
                Figure(f_laws / "fig3_laws.png", "Fig. 3: τ and σ against P with the linear fits.")
            ],
        )
    )

    # ---- contact
    params = contact["parameters"]
    prov = contact["provenance"]
    keys = [
        ("contact_radius_nm", "Hertz contact radius a (nm)"),
        ("normal_load_un", "normal load P (µN)"),
        ("contact_radius_change_dmt_percent", "DMT radius change vs Hertz (%)"),
        ("peak_lateral_force_un", "peak lateral force Q_peak (µN)"),
        ("saturated_lateral_force_un", "gross-sliding force Q_sat (µN)"),
        ("effective_shear_strength_mpa", "effective shear strength Q_peak/πa² (MPa)"),
        ("gross_sliding_stress_mpa", "gross sliding Q_sat/πa² (MPa)"),
        ("uniform_shear_strength_mpa", "τ at the mean pressure 2p0/3 (MPa)"),
        ("overshoot", "overshoot (Q_peak > Q_sat)"),
        ("knee_stress_amplitude_mpa", "stiffness knee, amplitude stress (MPa)"),
    ]
    keys = [k for k in keys if k[0] in res[0]]
    ct_rows = [(label, *(_fmt(r[k]) for r in res)) for k, label in keys]
    contact_figs = [
        Figure(
            f_ct / "fig4_traction.png",
            "Fig. 4: τ(r), σ(r) and the full-stick q(r) at 60 % of the displacement at the peak "
            "force (p0 = 1 GPa, or the first p0); stick and slip zones.",
        ),
        Figure(
            f_ct / "fig5_force_stiffness.png",
            "Fig. 5: (a) Q(u) per p0 (dots: peak); (b) oscillatory stiffness vs mean shear stress (amplitude).",
        ),
    ]
    notes = [
        "Where the parameters come from: "
        + "; ".join(f"{k}: {v}" for k, v in prov.items() if k != "moduli")
        + "."
    ]
    if "experiment" in contact:
        e = contact["experiment"]
        contact_figs.append(
            Figure(
                f_ct / "fig6_experiment.png",
                f"Fig. 6: measured stiffness ({e['source']}) at p0 = {e['p0_gpa']:g} GPa with the model.",
            )
        )
        notes.append(
            f"Measured collapse {e['measured_collapse_stress_mpa']:.3g} MPa, model "
            f"{e['model_collapse_stress_mpa']:.3g} MPa ({e['stress_measure']} stress); τ0 that "
            f"matches the data: {e['fitted_tau0_mpa']:.3g} MPa."
        )
    sections.append(
        Section(
            "5. Modified Mindlin contact",
            paragraphs=[
                f"R = {params['radius_um']:g} µm, E* = {params['contact_modulus_gpa']:g} GPa, G* = "
                f"{params['shear_modulus_gpa']:g} GPa ({prov.get('moduli')}); k = {params['k_mpa_per_gpa']:.3g} "
                f"MPa/GPa, τ0 = {params['tau0_mpa']:.3g} MPa, μ = {params['mu_mpa_per_gpa']:.3g} MPa/GPa, "
                f"σ0 = {params['sigma0_mpa']:.3g} MPa ; "
                f"w = {params['work_of_adhesion_j_m2']:.3g} J/m² ({prov.get('work_of_adhesion_j_m2')}).",
            ],
            notes=notes,
            tables=[
                Table(("quantity", *(f"p0 = {r['p0_gpa']:g} GPa" for r in res)), ct_rows),
                *_elastic_tables(pipe),
            ],
            figures=contact_figs,
        )
    )
    versions = json.loads((pipe.root / "versions.json").read_text())
    footer = (
        "flatcontact " + __version__ + " · " + ", ".join(f"{k} {v}" for k, v in versions.items())
    )
    return write_report(path, cfg.report.title, sections, footer)
