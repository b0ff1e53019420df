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
from flatcontact.foundation.fileio import write_json_atomic, write_text_atomic
from flatcontact.foundation.layout import STUDY_JSON
from flatcontact.plots import save_figure
from flatcontact.plots.study import QUANTITY_LABELS, figure_study
from flatcontact.stages.measured_on import measured_on
from flatcontact.studies.compare import counts_in_delta

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
        states = {s: st.get("state", "") for s, st in doc["settings"].items()}
        used = [
            s
            + (
                f" (step {st['last_step'][1]}; the next failed)"
                if st.get("state") == "failed"
                else ""
            )
            + (
                f" (its finest variant {st['noisier']:g}x noisier than the base: may be relaxation error)"
                if st.get("noisier")
                else ""
            )
            for s, st in doc["settings"].items()
            if counts_in_delta(st)
        ]
        open_ = [f"{s} ({state})" for s, state in states.items() if state != "converged"]
        what = (
            f"largest change of each law coefficient from the base to the finest analysable level of "
            f"{', '.join(used) or 'no setting'} (tolerance {doc['tolerance_pct']:g} %; "
            + (
                "all converged"
                if doc["converged"]
                else f"NOT converged: {', '.join(open_)}; see study.json"
            )
            + ")"
        )
    else:
        parts = {
            f"model_spread_{f}": {k: _sig3(v) for k, v in d.items()}
            for f, d in doc["spread"].items()
        }
        spread_over = [v.get("model", v["name"]) for v in doc["variants"]]
        what = f"half the max - min range of each law coefficient over {', '.join(spread_over)}"
        if doc.get("failed"):
            what += f" (failed, not in the spread: {', '.join(doc['failed'])})"
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


def cost_line(cost: dict) -> str:
    """The console line of a convergence study's force calls: stored by its runs (what the
    study cost, whichever invocation ran them) against each setting's ladder from scratch,
    and how many of them this invocation computed (a rerun or a study after ``--estimate``
    reuses the rest)."""
    stored, now = cost["force_calls_stored"], cost["force_calls_study"]
    reused = "" if now == stored else f"; {now} computed by this invocation, the rest reused"
    return (
        f"force calls: {stored} in {cost['variants']} runs against "
        f"{cost['force_calls_from_scratch']} for each setting's ladder from scratch{reused}"
    )


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


APPROXIMANTS_CSV = "approximants.csv"
#: One row per cell of ``flatcontact study approximants`` (strains: the largest principal
#: strain of each slab in %, absolute; k and μ in MPa/GPa; barrier: the ISPES corrugation
#: at the lowest load; noise: the engine's round-off floor of single-point energies;
#: relax_noise: the relaxation's floor, round-off and force tolerance
#: (:mod:`flatcontact.ispes.relax_noise`; empty/nan when the scan relaxes nothing); floor: the
#: larger of the two; resolved: barrier >= 10 x floor; gates: the validity gates that fired,
#: ``;``-separated).
APPROXIMANTS_COLUMNS = (
    "label",
    "atoms",
    "twist_deg",
    "angle_error_deg",
    "strain_percent_slab1",
    "strain_percent_slab2",
    "shift_lattice_index",
    "grid",
    "tau0_mpa",
    "k_mpa_per_gpa",
    "sigma0_mpa",
    "mu_mpa_per_gpa",
    "barrier_mev_per_a2",
    "noise_mev_per_a2",
    "relax_noise_mev_per_a2",
    "floor_mev_per_a2",
    "resolved",
    "force_calls",
    "wall_s",
    "gates",
    "error",
)


def approximants_csv_text(doc: dict) -> str:
    """``approximants.csv`` of an approximant study document (one row per cell)."""
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(APPROXIMANTS_COLUMNS)
    for c in doc["cells"]:
        failed = "error" in c
        writer.writerow(
            [
                c["label"],
                c["n_atoms"],
                f"{c['twist_deg']:.6f}",
                f"{c['angle_error_deg']:.6f}",
                c["strain_percent_slab1"],
                c["strain_percent_slab2"],
                c["shift_lattice_index"],
                "x".join(str(g) for g in c["grid"]),
                *(
                    [""] * 9
                    if failed
                    else [
                        c["tau0_mpa"],
                        c["k_mpa_per_gpa"],
                        c["sigma0_mpa"],
                        c["mu_mpa_per_gpa"],
                        c["barrier_mev_per_a2"],
                        c["noise_mev_per_a2"],
                        c["relax_noise_mev_per_a2"],
                        c["floor_mev_per_a2"],
                        c["resolved"],
                    ]
                ),
                "" if failed else c["force_calls"],
                "" if failed else f"{c['wall_s']:.1f}",
                "" if failed else ";".join(c["gates"]["fired"]),
                c.get("error", ""),
            ]
        )
    return buf.getvalue()


def write_approximants(doc: dict, out: str | Path, command: str) -> list[Path]:
    """``study.json``, ``approximants.csv`` and ``approximants.png`` of an approximant study."""
    from flatcontact.plots.approximants import figure_approximants

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    doc = {
        **doc,
        "provenance": {
            "command": command,
            "date": datetime.date.today().isoformat(),
            "flatcontact_version": __version__,
        },
    }
    files = [
        write_json_atomic(out / STUDY_JSON, json.loads(json.dumps(doc, default=float))),
        write_text_atomic(out / APPROXIMANTS_CSV, approximants_csv_text(doc)),
    ]
    files += save_figure(figure_approximants(doc), out / "approximants", formats=("png",))
    return files
