"""A report is about the run's material: no paper value outside the paper's α-quartz, the
elastic table of the material's own bulk, stackings named for its lattice, layer counts
and relaxation as built, one box per warning kind.

The stage folders are fixtures written here (the files each stage writes, with made-up
numbers); the Cu(111) interface is the fcc111 recipe's, built without relaxation.
"""

from __future__ import annotations

import json
import re

import pandas as pd
import pytest

from flatcontact.config.load import build_config
from flatcontact.foundation.layout import (
    ANALYZE_JSON,
    BUILD_FIGURE,
    BUILD_JSON,
    ELASTIC_JSON,
    FIG4_TRACTION,
    FIG5_FORCE_STIFFNESS,
    FRICTION_CSV,
    INTERFACE,
    LAWS_FIGURE,
    LAWS_JSON,
    SCAN_FIGURE,
    SCAN_JSON,
    SUMMARY_JSON,
    png,
)
from flatcontact.foundation.reference import PAPER, PAPER_LAW_KEYS
from flatcontact.ispes.work_of_separation import AT_PERFECT_STACKING
from flatcontact.report.assemble import build_sections
from flatcontact.report.html import render_html
from flatcontact.report.sections.laws import PAPER_COLUMN
from flatcontact.report.stacking_names import display_names
from flatcontact.structures.construct import build_interface
from flatcontact.structures.interface_io import write_interface

LOADS = [0.0, 0.5, 1.0, 1.5]
#: Cu(111) γ-surface energies per load (meV/Å²): perfect stacking lowest, the stacking
#: fault at Mishin's 44.4 mJ/m² (2.77 meV/Å²), the unstable fault, on-top.
CU_STACKINGS = "BA=0;AB=2.771;SP=10.25;AA=48.13"
DEGENERATE = (
    "DegenerateMinimaWarning: /tmp/run/02-scan/ispes.nc at P = {p:g} GPa: 2 minima, up to "
    "0.29 meV/Å² apart, are near-degenerate (within 0.0023 meV/Å² of the lowest) or "
    "symmetry-equivalent to one that is, so the slider's τ depends on which one it sits in"
)
NOISE = (
    "LoadNoiseWarning: /tmp/run/02-scan/ispes.nc at P = 1.5 GPa (energy load, internal form): "
    "energy noise 0.0131 meV/Å²"
)


def _laws(k, tau0, mu, sigma0):
    form = {
        "k_mpa_per_gpa": k,
        "tau0_mpa": tau0,
        "mu_mpa_per_gpa": mu,
        "sigma0_mpa": sigma0,
        "k_stderr_mpa_per_gpa": 0.3,
        "tau0_stderr_mpa": 0.3,
        "mu_stderr_mpa_per_gpa": 0.05,
        "sigma0_stderr_mpa": 0.05,
    }
    return {
        **form,
        "p_max_gpa": 1.5,
        "tau_linear_until_gpa": 1.5,
        "sigma_linear_until_gpa": 1.5,
        "warnings": [],
        "energy_form": "internal",
        "internal": form,
        "enthalpy": form,
        "uncertainty": {"coverage": 1.0},
    }


def _stage_folders(tmp_path, atoms, build_record, laws, stackings, elastic=None, grid=(6, 6)):
    folders = {name: tmp_path / name for name in ("build", "scan", "analyze", "laws", "contact")}
    for folder in folders.values():
        folder.mkdir()
    for folder, stem in (
        ("build", BUILD_FIGURE),
        ("scan", SCAN_FIGURE),
        ("laws", LAWS_FIGURE),
        ("contact", FIG4_TRACTION),
        ("contact", FIG5_FORCE_STIFFNESS),
    ):
        (folders[folder] / png(stem)).write_bytes(b"\x89PNG\r\n\x1a\n")
    write_interface(atoms, folders["build"] / INTERFACE)
    (folders["build"] / BUILD_JSON).write_text(json.dumps(build_record))
    scan = {
        "points_total": 3 * grid[0] * grid[1],
        "points_done": 3 * grid[0] * grid[1],
        "converged": 180,
        "force_calls_total": 9000,
        "thickness_angstrom": [14.0, 14.5, 15.0],
        "area_angstrom2": float(
            abs(atoms.cell[0][0] * atoms.cell[1][1] - atoms.cell[0][1] * atoms.cell[1][0])
        ),
        "adhesion": {
            "work_of_separation_j_per_m2": 2.48,
            "work_of_separation_stacking": AT_PERFECT_STACKING,
        },
        "notes": [],
        "warnings": [],
    }
    (folders["scan"] / SCAN_JSON).write_text(json.dumps(scan))
    analyze = {
        "warnings": [DEGENERATE.format(p=p) for p in LOADS] + [NOISE],
        "symmetry": {},
        "load_source": "energy",
    }
    (folders["analyze"] / ANALYZE_JSON).write_text(json.dumps(analyze))
    pd.DataFrame(
        {
            "p_gpa": LOADS,
            "tau_mpa": [3770.0, 3769.0, 3768.5, 3768.0],
            "tau_period_mpa": [3770.0] * 4,
            "sigma_mss_mpa": [1099.0] * 4,
            "shear_stiffness_gpa_per_nm": [50.0] * 4,
            "tau_limited_by": ["barrier top"] * 4,
            "n_jumps": [0] * 4,
            "force_noise_mpa": [0.1] * 4,
            "start_stacking": ["BA"] * 4,
            "zero_shift_stacking": ["BA"] * 4,  # the perfect crystal, by geometry
            "stacking_energies_mev_per_a2": [stackings] * 4,
            "lowest_barrier_mev_per_a2": [10.25] * 4,
        }
    ).to_csv(folders["analyze"] / FRICTION_CSV, index=False)
    (folders["laws"] / LAWS_JSON).write_text(json.dumps(laws))
    contact = {
        "parameters": {
            "radius_um": 5.0,
            "contact_modulus_gpa": 73.0,
            "shear_modulus_gpa": 57.7,
            "k_mpa_per_gpa": laws["k_mpa_per_gpa"],
            "tau0_mpa": laws["tau0_mpa"],
            "mu_mpa_per_gpa": laws["mu_mpa_per_gpa"],
            "sigma0_mpa": laws["sigma0_mpa"],
            "work_of_adhesion_j_per_m2": 2.48,
        },
        "provenance": {"moduli": "elastic stage", "work_of_adhesion_j_per_m2": "scan"},
        # Hertz at p0 = 1 GPa, R = 5 µm, E* = 73 GPa: a = pi p0 R / (2 E*), P = 2/3 pi a^2 p0
        "results": [
            {
                "p0_gpa": 1.0,
                "contact_radius_nm": 107.59,
                "normal_load_un": 24.24,
                "effective_shear_strength_mpa": 2206.0,
            }
        ],
        "results_with_paper_laws": [{"p0_gpa": 1.0, "effective_shear_strength_mpa": 30.0}],
    }
    (folders["contact"] / SUMMARY_JSON).write_text(json.dumps(contact))
    if elastic is not None:
        folders["elastic"] = tmp_path / "elastic"
        folders["elastic"].mkdir()
        (folders["elastic"] / ELASTIC_JSON).write_text(json.dumps(elastic))
    return folders


def _cu_config(**structure):
    return build_config(
        {
            "structure": {"kind": "fcc111", "element": "Cu", "a_angstrom": 3.615, **structure},
            "potential": {"preset": "cu-eam"},
            "scan": {"grid": [6, 6], "relax_mode": "normal"},
            "analysis": {"p_gpa": LOADS},
            "elastic": {"enabled": True},
            "contact": {"p0_gpa": [1.0]},
        }
    )


def _cu_report(tmp_path, layers=4):
    cfg = _cu_config(layers=layers)
    atoms, report = build_interface(cfg.structure)
    build = {**report, "interface_relaxation": None}
    elastic = {
        "crystal": {"crystal": "fcc Cu"},
        "potential": "cu-eam",
        "cellpar": [2.556191, 2.556191, 2.556191, 60.0, 60.0, 60.0],
        "tensor_gpa": [
            [170.2, 122.9, 122.9, 0, 0, 0],
            [122.9, 170.2, 122.9, 0, 0, 0],
            [122.9, 122.9, 170.2, 0, 0, 0],
            [0, 0, 0, 76.2, 0, 0],
            [0, 0, 0, 0, 76.2, 0],
            [0, 0, 0, 0, 0, 76.2],
        ],
        "moduli_gpa": {"e_star": 73.0, "poisson_ratio": 0.34},
    }
    folders = _stage_folders(
        tmp_path,
        atoms,
        build,
        _laws(-0.9, 3770.0, -0.51, 1099.0),
        CU_STACKINGS,
        elastic,
        grid=tuple(cfg.scan.grid),
    )
    return render_html("Cu(111)", build_sections(cfg, folders, []))


def _text(html: str) -> str:
    """The report's text without the embedded figures."""
    return re.sub(r'src="data:[^"]*"', "", html)


def test_a_cu111_report_has_no_paper_value_and_names_its_own_bulk(tmp_path):
    text = _text(_cu_report(tmp_path))
    paper = [f"{PAPER[k]:g}" for k in PAPER_LAW_KEYS]
    assert paper == ["4.52", "26.7", "0.21", "11.1"]
    for value in (*paper, PAPER_COLUMN, "α-quartz"):
        assert value not in text, value
    # the elastic table is headed by the bulk it was computed for, with its cubic a = a_p·√2
    assert "fcc Cu with cu-eam" in text
    assert "cubic lattice parameter a (Å)</td><td>3.615" in text
    assert "C44 (GPa)</td><td>76.2" in text and "C14" not in text


def test_fcc111_stackings_are_the_gamma_surface_names(tmp_path):
    text = _text(_cu_report(tmp_path))
    assert (
        "perfect stacking 0, intrinsic stacking fault 2.771, unstable stacking fault 10.25, "
        "on-top stacking 48.13" in text
    )
    assert not re.search(r"\b(AB|BA|SP|AA) \d", text)
    # where W is taken, in the results table and the scan section
    import html

    plain = html.unescape(text)
    assert f"work of separation W (J/m²), at the {AT_PERFECT_STACKING}" in plain
    assert f"work of separation taken at</td><td>{AT_PERFECT_STACKING}" in plain


def test_layer_counts_and_relaxation_are_those_built(tmp_path):
    text = _text(_cu_report(tmp_path))
    assert "4 layers per slab" in text
    assert "Slab 1: Cu(111), 4 layers; slab 2: Cu(111), 4 layers" in text
    assert "layer 1 from the outer face held, layers 2, 3 and 4 free" in text
    assert "relax along z only" in text
    assert "overstate those of an incommensurate contact" in text


def test_a_one_layer_slab_is_one_layer_and_held_whole(tmp_path):
    cfg = _cu_config(layers=1)
    atoms, report = build_interface(cfg.structure)
    folders = _stage_folders(
        tmp_path, atoms, report, _laws(1.0, 2.0, 0.5, 1.0), CU_STACKINGS, grid=tuple(cfg.scan.grid)
    )
    text = _text(render_html("Cu", build_sections(cfg, folders, [])))
    assert "1 layers" not in text and "1 layer per slab" in text
    assert "slab 1: 1 layer, held (rigid)" in text
    assert "Every atom is held" in text and "relax along z" not in text


def test_one_box_per_warning_kind_with_its_loads(tmp_path):
    text = _cu_report(tmp_path)
    boxes = re.findall(r'<p class="note">(.*?)</p>', text, re.DOTALL)
    degenerate = [b for b in boxes if "minima" in b and "apart" in b]
    assert len(degenerate) == 1
    assert degenerate[0].startswith("Degenerate minima at P = 0, 0.5, 1, 1.5 GPa:")
    assert degenerate[0].count("up to 0.29 meV/Å² apart") == 4
    assert "/tmp/run" not in degenerate[0]
    assert sum(b.startswith("Load noise at P = 1.5 GPa:") for b in boxes) == 1


def test_the_quartz_report_still_compares_with_the_paper(tmp_path):
    cfg = build_config({"analysis": {"p_gpa": LOADS}, "contact": {"p0_gpa": [1.0]}})
    atoms, _ = build_interface(_cu_config(layers=2).structure)
    folders = _stage_folders(
        tmp_path,
        atoms,
        {"n_atoms": 36, "layers": 6, "thickness_angstrom": 20.0},
        _laws(14.4, 30.5, 5.0, 7.0),
        "min1=0;min2=0.243;saddle1=0.244;AA=0.591",
        grid=tuple(cfg.scan.grid),
    )
    text = _text(render_html("quartz", build_sections(cfg, folders, [])))
    assert "This run next to the paper" in text
    assert f"<th>{PAPER_COLUMN}</th>" in text
    for value in ("4.52", "26.7", "0.21", "11.1"):
        assert f"<td>{value}</td>" in text


@pytest.mark.parametrize(
    ("family", "expected"),
    [
        ("bilayer", {"AB": "AB", "BA": "BA", "SP": "SP", "AA": "AA"}),
        ("antiparallel", {"BA": "AA′", "AB": "AB1′", "AA": "AB2′", "SP": "saddle"}),
        ("generic", {"BA": "minimum 1", "AB": "minimum 2", "SP": "saddle 1", "AA": "maximum 1"}),
    ],
)
def test_stacking_names_per_family(family, expected):
    energies = {"BA": 0.0, "AB": 1.22, "SP": 1.415, "AA": 5.6}
    assert display_names(energies, family) == expected


def _results_row(html: str, label: str) -> str:
    """The cell of the 'Results for' table's row ``label`` (the first table that has it)."""
    m = re.search(re.escape(label) + r"</td><td>([^<]*)</td>", html)
    assert m is not None, label
    return m.group(1)


def test_results_table_gives_the_study_intervals_beside_the_fit_error(tmp_path):
    """A run with a study's uncertainty block (Ni(111) as a new user ran it: the table showed
    k = -1.73 ± 0.93, the fit alone, where laws.json's interval with convergence and model
    spread is [-7.45, 3.98], and Q_peak/πa² with no interval): each law row carries the
    interval of laws.json (law_intervals over the fit, convergence and model parts combined
    by law_half_widths) and Q_peak/πa² the contact stage's interval; without a study's parts
    the rows are the fit's ± alone."""
    from flatcontact.analysis.uncertainty import law_components, law_half_widths, law_intervals

    cfg = _cu_config(layers=4)
    atoms, report = build_interface(cfg.structure)
    laws = _laws(-0.9, 3770.0, -0.51, 1099.0)
    conv = {"k_mpa_per_gpa": 3.64, "tau0_mpa": 131.0, "mu_mpa_per_gpa": 1.25, "sigma0_mpa": 2.1}
    models = {"k_mpa_per_gpa": 4.31, "tau0_mpa": 52.0, "mu_mpa_per_gpa": 1.52, "sigma0_mpa": 209}
    hw = law_half_widths(laws, convergence=conv, model=models)
    laws["intervals"] = law_intervals(
        laws, hw, law_components(laws, convergence=conv, model=models)
    )
    folders = _stage_folders(
        tmp_path,
        atoms,
        {**report, "interface_relaxation": None},
        laws,
        CU_STACKINGS,
        grid=tuple(cfg.scan.grid),
    )
    summary = json.loads((folders["contact"] / SUMMARY_JSON).read_text())
    q = {"value": 2206.0, "low": 2080.0, "high": 2330.0}
    summary["intervals"] = {
        "half_widths": hw,
        "results": [
            {
                "p0_gpa": 1.0,
                "effective_shear_strength_mpa": q,
                "collapse_stress_mpa": q,
                "knee_stress_amplitude_mpa": q,
            }
        ],
    }
    (folders["contact"] / SUMMARY_JSON).write_text(json.dumps(summary))
    html = render_html("Ni", build_sections(cfg, folders, []))
    for key, label in (("k_mpa_per_gpa", "k (MPa/GPa)"), ("sigma0_mpa", "σ0 (MPa)")):
        iv = laws["intervals"][key]
        cell = _results_row(html, label)
        assert cell.endswith(f"; [{iv['low']:.3g}, {iv['high']:.3g}]"), cell
    cell = _results_row(html, "effective shear strength Q_peak/πa² at p0 = 1 GPa (MPa)")
    assert cell == "2206 [2080, 2330]"
    # the same run without a study's parts: the fit's ± alone, as before
    (tmp_path / "plain").mkdir()
    plain = _cu_report(tmp_path / "plain")
    assert _results_row(plain, "k (MPa/GPa)") == "-0.9 ± 0.3"
    assert _results_row(plain, "effective shear strength Q_peak/πa² at p0 = 1 GPa (MPa)") == "2206"
