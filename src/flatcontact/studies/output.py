"""A study's files: ``study.json``, ``study.csv``, one figure per quantity, ``uncertainty.yaml``.

``study.csv`` has one row per variant and load (variant, setting, level, label, value,
p_gpa, tau_mpa, sigma_mss_mpa, work_of_separation_j_per_m2, force_calls, scan_action).
``uncertainty.yaml`` is an ``uncertainty:`` block a run configuration accepts
(:class:`flatcontact.config.uncertainty.UncertaintyConfig`): the convergence study fills
``convergence_<form>`` (:mod:`flatcontact.studies.convergence`), the models study
``model_spread_<form>`` (:mod:`flatcontact.studies.models`), both with ``measured_on`` (the
fingerprints of the structure and model measured, :mod:`flatcontact.stages.measured_on`) and
``provenance``.
"""

from __future__ import annotations

import csv
import datetime
import io
import json
import math
from pathlib import Path

import yaml

from flatcontact import __version__
from flatcontact.config.run import RunConfig
from flatcontact.fileio import write_json_atomic, write_text_atomic
from flatcontact.plots import save_figure
from flatcontact.plots.study import QUANTITY_LABELS, figure_study
from flatcontact.stages.measured_on import measured_on

STUDY_JSON = "study.json"
STUDY_CSV = "study.csv"
UNCERTAINTY_YAML = "uncertainty.yaml"
CSV_COLUMNS = (
    "variant",
    "setting",
    "level",
    "label",
    "value",
    "p_gpa",
    "tau_mpa",
    "sigma_mss_mpa",
    "work_of_separation_j_per_m2",
    "force_calls",
    "scan_action",
)


def _sig3(x: float) -> float:
    return float(f"{x:.3g}") if math.isfinite(x) else 0.0


def csv_text(doc: dict) -> str:
    """``study.csv`` of the study document ``doc`` (one row per variant and load)."""
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(CSV_COLUMNS)
    for v in doc["variants"]:
        value = v["values"].get(v["setting"], "") if v["setting"] != "base" else ""
        for row in v["loads"]:
            writer.writerow(
                [
                    v["name"],
                    v["setting"],
                    v["level"],
                    v["label"],
                    value,
                    row["p_gpa"],
                    row["tau_mpa"],
                    row["sigma_mss_mpa"],
                    v["work_of_separation_j_per_m2"],
                    v["force_calls"],
                    v["scan_action"],
                ]
            )
    return buf.getvalue()


def uncertainty_block(doc: dict, cfg: RunConfig, command: str) -> dict:
    """The ``uncertainty`` block the study ``doc`` measured on ``cfg`` (three significant figures)."""
    if doc["study"] == "convergence":
        parts = {
            f"convergence_{f}": {k: _sig3(v) for k, v in d.items()} for f, d in doc["delta"].items()
        }
        what = (
            f"largest change of each law coefficient over the last refinement step of "
            f"{', '.join(doc['settings']) or 'no setting'} (tolerance {doc['tolerance_pct']:g} %; "
            + ("all converged" if doc["converged"] else "NOT all converged: see study.json")
            + ")"
        )
    else:
        parts = {
            f"model_spread_{f}": {k: _sig3(v) for k, v in d.items()}
            for f, d in doc["spread"].items()
        }
        what = f"half the max - min range of each law coefficient over {', '.join(doc['models'])}"
    return {
        **parts,
        "coverage": 1.0,
        "source": f"flatcontact study {doc['study']}: {what}",
        "measured_on": measured_on(cfg),
        "provenance": {
            "study": doc["study"],
            "command": command,
            "date": datetime.date.today().isoformat(),
            "flatcontact_version": __version__,
            "variants": [v["name"] for v in doc["variants"]],
            "rounding": "three significant figures",
        },
    }


def write_study(doc: dict, cfg: RunConfig, out: str | Path, command: str) -> list[Path]:
    """Write the study's files into ``out``; returns their paths."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    block = uncertainty_block(doc, cfg, command)
    doc = {**doc, "uncertainty": block}
    files = [
        write_json_atomic(out / STUDY_JSON, json.loads(json.dumps(doc, default=float))),
        write_text_atomic(out / STUDY_CSV, csv_text(doc)),
        write_text_atomic(
            out / UNCERTAINTY_YAML,
            "# measured by flatcontact study; paste into a run configuration\n"
            + yaml.safe_dump({"uncertainty": block}, sort_keys=False, allow_unicode=True),
        ),
    ]
    for quantity in QUANTITY_LABELS:
        fig = figure_study(doc, quantity)
        files += save_figure(fig, out / f"study_{quantity}", formats=("png",))
    return files
