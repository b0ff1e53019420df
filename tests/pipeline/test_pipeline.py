"""End to end on a tiny configuration (Vashishta α-quartz dense interface, 6×6×6 grid).

One run (module fixture) goes through every stage; the tests check its files and
their physical sanity, then rerun it: unchanged → every stage skipped; one setting
changed → exactly the dependent stages rerun; kill -9 in the middle of the scan →
the rerun keeps every finished point and matches the uninterrupted run; corrupt or
foreign stores, records and run directories are refused with one line.
"""

from __future__ import annotations

import html
import json
import os
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from flatcontact.config import build_config
from flatcontact.foundation.errors import InputError
from flatcontact.foundation.layout import STAGES
from flatcontact.ispes.contract import open_ispes
from flatcontact.pipeline import Pipeline
from flatcontact.stages.fingerprints import settings_inputs

TINY = {
    "structure": {"kind": "quartz-dense", "layers": 5, "source": "seed"},
    "potential": {"intra": "vashishta"},
    "scan": {
        "grid": [6, 6],
        "p_range_gpa": {"lo_gpa": -1.2, "hi_gpa": 3.5, "n": 6},
        "fmax_ev_per_angstrom": 0.01,  # pinned: this file must not follow the quick preset
        # pinned too: with two loads (threshold 0.6 GPa) μ's sign is the relaxation's noise,
        # and a negative μ rightly refuses p0 = 2 GPa before the stale-warning check is reached
        # (ASE's iterates: no preconditioner, whose iterates give μ < 0 here)
        "optimizer": "LBFGS",
        "precondition": False,
        "executor": "serial",
    },
    "analysis": {"p_gpa": [0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0]},
    "contact": {"p0_gpa": [0.5, 1.0, 2.0]},
    "report": {"svg": False},
}


def _merge(base: dict, change: dict) -> dict:
    out = json.loads(json.dumps(base))
    for key, value in change.items():
        out[key] = {**out.get(key, {}), **value} if isinstance(value, dict) else value
    return out


def _actions(pipe: Pipeline) -> dict[str, str]:
    return {name: res.action for name, res in pipe.results.items()}


@pytest.fixture(scope="module")
def tiny_run(tmp_path_factory):
    root = tmp_path_factory.mktemp("run") / "tiny"
    with Pipeline(build_config(TINY), root) as pipe:
        report = pipe.run()
        actions = _actions(pipe)
    return root, report, actions


def test_every_stage_ran_and_wrote_its_files(tiny_run):
    root, report, actions = tiny_run
    assert actions == {n: "ran" for n in STAGES if n not in ("elastic", "asperity")}
    expected = {
        "01-build": ["interface.extxyz", "build.json", "fig1_interface.png"],
        "02-scan": ["points.db", "ispes.nc", "scan.json", "fig_scan_columns.png"],
        "03-analyze": [
            "friction.csv",
            "friction.nc",
            "analyze.json",
            "other_form.json",
            "fig2_p1gpa.png",
        ],
        "04-laws": ["laws.json", "fig3_laws.png"],
        "06-contact": [
            "contact.nc",
            "summary.json",
            "fig4_traction.png",
            "fig5_force_stiffness.png",
        ],
        "07-report": ["report.html"],
    }
    for folder, files in expected.items():
        for name in files:
            assert (root / folder / name).is_file(), f"{folder}/{name}"
        record = json.loads((root / folder / "stage.json").read_text())
        assert record["state"] == "done"
    for name in ("run.json", "config.yaml", "versions.json", "run.log", "report.html"):
        assert (root / name).is_file()
    assert report == root / "report.html"
    log = (root / "run.log").read_text()
    assert "stage scan: done" in log and "stage report: done" in log

    # the symmetry of each constant-P surface, structured in analyze.json and tabled in the report
    symmetry = json.loads((root / "03-analyze" / "analyze.json").read_text())["symmetry"]
    for doc in symmetry.values():
        assert set(doc["kept"]) <= set(doc["deviation_percent"])
        assert all(doc["deviation_percent"][n] < doc["tolerance_percent"] for n in doc["kept"])
    assert "symmetry operations of the cell kept" in (root / "report.html").read_text()


def test_scan_is_physical(tiny_run):
    root, _, _ = tiny_run
    ds = open_ispes(root / "02-scan" / "ispes.nc")
    assert bool(ds["converged"].all())
    assert np.all(np.isfinite(ds["energy"].values))
    p = ds["normal_stress"].values  # (shift_a, shift_b, thickness), z ascending
    assert np.all(np.diff(ds["thickness"].values) > 0)
    # the load rises as the slabs are pressed together, at every stacking
    assert np.all(np.diff(p, axis=-1) < 0)
    assert p.max() > 3.0 and p.min() < 0.0
    scan = json.loads((root / "02-scan" / "scan.json").read_text())
    adh = scan["adhesion"]
    assert adh["separated"]
    # the probe's pull-off work: energy difference and -∫p dz agree (both J/m², positive)
    assert adh["pull_off_work_j_per_m2"] > 0
    assert adh["pull_off_work_integral_j_per_m2"] == pytest.approx(
        adh["pull_off_work_j_per_m2"], rel=0.02
    )
    assert adh["work_of_separation_j_per_m2"] > 0


def test_friction_and_laws_are_physical(tiny_run):
    root, _, _ = tiny_run
    table = Pipeline(build_config(TINY), root).friction_table()
    assert list(table["p_gpa"]) == TINY["analysis"]["p_gpa"]
    tau, sigma = table["tau_mpa"].to_numpy(), table["sigma_mss_mpa"].to_numpy()
    assert np.all(np.isfinite(tau)) and np.all(np.isfinite(sigma))
    assert np.all(sigma > 0)
    # static exceeds kinetic: the largest resisting force bounds the mean dissipated one
    assert np.all(tau >= sigma)
    laws = json.loads((root / "04-laws" / "laws.json").read_text())
    for key in ("k_mpa_per_gpa", "tau0_mpa", "mu_mpa_per_gpa", "sigma0_mpa"):
        assert laws[key] is not None and np.isfinite(laws[key])
    assert laws["n_points_tau"] == 7 and laws["p_max_gpa"] == 3.0
    # the fitted lines pass through the data they were fitted to (least squares: mean residual 0)
    p = table["p_gpa"].to_numpy()
    resid = tau - (laws["k_mpa_per_gpa"] * p + laws["tau0_mpa"])
    assert abs(resid.mean()) < 1e-6 * np.abs(tau).max()


def test_contact_uses_the_fitted_laws(tiny_run):
    root, _, _ = tiny_run
    summary = json.loads((root / "06-contact" / "summary.json").read_text())
    laws = json.loads((root / "04-laws" / "laws.json").read_text())
    params, prov = summary["parameters"], summary["provenance"]
    # every fitted coefficient is used as fitted, a negative slope included
    for key in ("k_mpa_per_gpa", "tau0_mpa", "mu_mpa_per_gpa", "sigma0_mpa"):
        assert prov[key] == "fitted laws"
        assert params[key] == pytest.approx(laws[key])
    scan = json.loads((root / "02-scan" / "scan.json").read_text())
    assert params["work_of_adhesion_j_per_m2"] == pytest.approx(
        scan["adhesion"]["work_of_separation_j_per_m2"]
    )
    with xr.open_dataset(root / "06-contact" / "contact.nc", engine="h5netcdf") as ds:
        assert list(ds["p0"].values) == TINY["contact"]["p0_gpa"]
        q = ds["lateral_force"].values
        assert np.all(np.isfinite(q)) and np.all(q >= 0)
    k, tau0 = params["k_mpa_per_gpa"], params["tau0_mpa"]
    mu, sigma0 = params["mu_mpa_per_gpa"], params["sigma0_mpa"]
    for rec in summary["results"]:
        # Q_sat/πa² is the mean slip friction σ0 + (2/3)μ p0; Q_peak >= Q_sat, and Q_peak/πa²
        # (a mean traction: < τ where stuck, σ where slipping) is below the largest local
        # τ or σ, at the centre or the edge (either sign of k and μ)
        # p0 of the Hertzian pressure over the adhesive radius: the pressure the model sees
        p0 = rec["contact_peak_pressure_gpa"]
        assert p0 >= rec["p0_gpa"]
        eff = rec["effective_shear_strength_mpa"]
        assert rec["gross_sliding_stress_mpa"] == pytest.approx(sigma0 + 2 / 3 * mu * p0)
        assert rec["gross_sliding_stress_mpa"] <= eff * (1 + 1e-12)
        assert eff < max(k * p0 + tau0, tau0, mu * p0 + sigma0, sigma0)


def test_report_is_self_contained_and_compares_with_the_paper(tiny_run):
    root, _, _ = tiny_run
    html = (root / "report.html").read_text()
    assert html.count("data:image/png;base64,") >= 7
    assert "http://" not in html and "https://" not in html
    for text in ("4.52", "26.7", "0.21", "11.1", "work of separation", "vashishta"):
        assert text in html


def test_rerun_skips_every_stage(tiny_run):
    root, _, _ = tiny_run
    before = {p: p.stat().st_mtime_ns for p in root.glob("0*/*") if p.is_file()}
    with Pipeline(build_config(TINY), root) as pipe:
        pipe.run()
        assert set(_actions(pipe).values()) == {"skipped"}
    after = {p: p.stat().st_mtime_ns for p in root.glob("0*/*") if p.is_file()}
    assert before == after


@pytest.mark.parametrize(
    ("change", "rerun"),
    [
        # refitted on P <= 2 GPa the tiny run's σ_MSS falls 29 %: the negative_slope gate
        # stops it (5-layer seed slabs, fmax 0.01); this test is about what reruns
        (
            {
                "analysis": {"threshold_gpa": 2.0},
                "contact": {"accept_untrusted": ["negative_slope"]},
            },
            {"laws", "contact", "report"},
        ),
        ({"contact": {"p0_gpa": [1.0, 1.77]}}, {"contact", "report"}),
        ({"report": {"title": "another title"}}, {"report"}),
        ({"scan": {"workers": 2, "executor": "processes"}}, set()),  # how, not what
    ],
)
def test_a_change_reruns_exactly_the_dependent_stages(tiny_run, tmp_path, change, rerun):
    import shutil

    src, _, _ = tiny_run
    root = tmp_path / "copy"
    shutil.copytree(src, root)
    with Pipeline(build_config(_merge(TINY, change)), root) as pipe:
        pipe.run()
        actions = _actions(pipe)
    assert {n for n, a in actions.items() if a != "skipped"} == rerun
    assert all(actions[n] == "ran" for n in rerun)


@pytest.mark.parametrize(
    ("edited", "rerun"),
    [
        ("contact/mindlin.py", {"contact", "report"}),
        ("analysis/friction.py", {"analyze", "laws", "contact", "report"}),
        ("ispes/relax.py", {"scan", "analyze", "laws", "contact", "report"}),
        # the report's wording and the contact figures are in no upstream stage's digest
        ("report/sections/laws.py", {"report"}),
        ("plots/contact.py", {"contact", "report"}),
        ("analysis/laws.py", {"analyze", "laws", "contact", "report"}),
    ],
)
def test_a_code_edit_reruns_exactly_the_stages_it_can_change(
    tiny_run, tmp_path, monkeypatch, edited, rerun
):
    """Editing a development install's source reruns what the edit can change (same settings)."""
    import shutil

    import flatcontact.pipeline as pipeline_module
    from flatcontact.pipeline import stage_code, stage_code_digest

    module = "flatcontact." + edited.removesuffix(".py").replace("/", ".")

    def edited_digest(name):
        # the digest as if `edited` had new content: changed for every stage whose code has it
        touched = module in stage_code(name)
        return stage_code_digest(name) + ("+edited" if touched else "")

    src, _, _ = tiny_run
    root = tmp_path / "copy"
    shutil.copytree(src, root)
    monkeypatch.setattr(pipeline_module, "stage_code_digest", edited_digest)
    with Pipeline(build_config(TINY), root) as pipe:
        pipe.run()
        actions = _actions(pipe)
    assert {n for n, a in actions.items() if a != "skipped"} == rerun


def test_each_stage_digest_covers_its_stage_module_and_nothing_of_the_report():
    """Fingerprints hold the code a stage runs: its own stage module always, the report's
    content module only in the report's digest."""
    from flatcontact.pipeline import STAGES, stage_code

    for name in STAGES:
        modules = stage_code(name)
        assert f"flatcontact.stages.{name}" in modules, name
        assert ("flatcontact.report.assemble" in modules) == (name == "report"), name
        assert "flatcontact.pipeline" not in modules, name


def test_a_changed_threshold_leaves_no_stale_fit_warning(tiny_run, tmp_path):
    """analyze fits no law: a threshold that leaves two loads warns in laws.json and the report;
    back at the default threshold neither analyze.json, laws.json nor the report keeps it."""
    import shutil

    src, _, _ = tiny_run
    root = tmp_path / "copy"
    shutil.copytree(src, root)
    stale = "at P <= 0.6 GPa"
    with Pipeline(build_config(_merge(TINY, {"analysis": {"threshold_gpa": 0.6}})), root) as pipe:
        pipe.run()
        assert {n for n, a in _actions(pipe).items() if a != "skipped"} == {
            "laws",
            "contact",
            "report",
        }
    laws = json.loads((root / "04-laws" / "laws.json").read_text())
    assert any(stale in w for w in laws["warnings"])  # two loads: no standard errors
    assert html.escape(stale) in (root / "report.html").read_text()
    with Pipeline(build_config(TINY), root) as pipe:
        pipe.run()
    analyze = json.loads((root / "03-analyze" / "analyze.json").read_text())
    assert not any("LinearFitWarning" in w or "0.6" in w for w in analyze["warnings"])
    laws = json.loads((root / "04-laws" / "laws.json").read_text())
    assert not any(stale in w for w in laws["warnings"])
    assert html.escape(stale) not in (root / "report.html").read_text()


def test_a_retrained_potential_file_reruns_from_the_build(tmp_path):
    """Coefficient files enter the fingerprint by content, not by name."""
    from flatcontact.potentials.files import BUNDLED_DIR

    bundled = BUNDLED_DIR / "sio2-snap"
    for suffix in (".snapcoeff", ".snapparam"):
        shutil_copy = (tmp_path / f"my{suffix}").write_bytes
        shutil_copy((bundled / f"sio2-snap{suffix}").read_bytes())
    cfg = _merge(TINY, {"potential": {"intra": f"snap:{tmp_path / 'my.snapcoeff'}"}})
    config = build_config(cfg)
    before = settings_inputs("build", config)["model"]  # the model's part of the build's inputs
    coeff = tmp_path / "my.snapcoeff"
    coeff.write_text(coeff.read_text() + "\n")
    after = settings_inputs("build", config)["model"]
    assert before["model"] == after["model"]
    assert before["files_sha256"]["my.snapparam"] == after["files_sha256"]["my.snapparam"]
    assert before["files_sha256"]["my.snapcoeff"] != after["files_sha256"]["my.snapcoeff"]


def test_foreign_or_corrupt_run_directories_are_refused(tiny_run, tmp_path):
    import shutil

    cfg = build_config(TINY)
    foreign = tmp_path / "foreign"
    foreign.mkdir()
    (foreign / "notes.txt").write_text("mine")
    with pytest.raises(InputError, match="not a flatcontact run directory"):
        Pipeline(cfg, foreign)
    src, _, _ = tiny_run
    root = tmp_path / "copy"
    shutil.copytree(src, root)
    (root / "run.json").write_text("{not json")
    with pytest.raises(InputError, match="corrupt run marker"):
        Pipeline(cfg, root)
    (root / "run.json").write_text(json.dumps({"format": "flatcontact.run/1"}))
    (root / "03-analyze" / "stage.json").write_text("garbage")
    with Pipeline(cfg, root) as pipe, pytest.raises(InputError, match="corrupt stage record"):
        pipe.run()


def test_corrupt_or_foreign_point_store_is_refused(tiny_run, tmp_path):
    import shutil

    src, _, _ = tiny_run
    cfg = build_config(TINY)
    root = tmp_path / "copy"
    shutil.copytree(src, root)
    record = root / "02-scan" / "stage.json"
    rec = json.loads(record.read_text())
    rec["state"] = "running"  # as if interrupted: the next run resumes from the store
    record.write_text(json.dumps(rec))
    (root / "02-scan" / "points.db").write_bytes(b"this is not sqlite" * 100)
    with Pipeline(cfg, root) as pipe, pytest.raises(InputError, match=r"points\.db") as info:
        pipe.run()
    assert "\n" not in str(info.value)
    # a store from another grid, dropped into this run's scan folder
    other = tmp_path / "other"
    with Pipeline(build_config(_merge(TINY, {"scan": {"grid": [3, 3]}})), other) as pipe:
        pipe.scan()
    shutil.copyfile(other / "02-scan" / "points.db", root / "02-scan" / "points.db")
    with (
        Pipeline(cfg, root) as pipe,
        pytest.raises(InputError, match="different settings") as info,
    ):
        pipe.run()
    assert "grid" in str(info.value)


def _rows(db: Path) -> int:
    try:
        with sqlite3.connect(f"file:{db}?mode=ro", uri=True, timeout=0.1) as con:
            return int(con.execute("select count(*) from systems").fetchone()[0])
    except sqlite3.Error:
        return 0


def _points(db: Path) -> dict:
    import ase.db

    with ase.db.connect(str(db)) as con:
        return {(r.i_a, r.i_b, r.i_z): (r.energy, r.normal_stress_gpa) for r in con.select()}


def test_kill_9_mid_scan_then_rerun_loses_nothing(tiny_run, tmp_path):
    src, _, _ = tiny_run
    # another recipe kind replaces the structure section whole (the quartz keys do not apply)
    data = {
        **TINY,
        "structure": {"kind": "file", "file": str(src / "01-build" / "interface.extxyz")},
    }
    cfg_path = tmp_path / "run.yaml"
    cfg_path.write_text(json.dumps(data))  # JSON is YAML
    root = tmp_path / "killed"
    code = (
        "import sys; from flatcontact.cli import main; "
        f"main(['run', {str(cfg_path)!r}, '--out', {str(root)!r}])"
    )
    proc = subprocess.Popen(
        [sys.executable, "-c", code],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        # every point committed as it is stored, so that the rows read while the scan runs
        # show where it is (by default they are committed in 0.5 s batches: this grid of
        # 2-3 ms points would show nothing until 205 of its 216 points were done)
        env={**os.environ, "OMP_NUM_THREADS": "1", "FLATCONTACT_COMMIT_INTERVAL_S": "0"},
    )
    db = root / "02-scan" / "points.db"
    total = 6 * 6 * 6
    deadline = time.monotonic() + 120
    while _rows(db) < total // 3 and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    stored = _points(db)
    assert 0 < len(stored) < total, "the kill did not land in the middle of the scan"
    assert json.loads((root / "02-scan" / "stage.json").read_text())["state"] == "running"

    from flatcontact.config import load_config

    with Pipeline(load_config(cfg_path), root) as pipe:
        pipe.run()
        actions = _actions(pipe)
    assert actions["build"] == "skipped" and actions["scan"] == "resumed"
    scan = json.loads((root / "02-scan" / "scan.json").read_text())
    assert scan["points_computed"] == total - len(stored)  # nothing recomputed
    after = _points(db)
    assert {k: after[k] for k in stored} == stored  # nothing finished was lost or changed
    ref = open_ispes(src / "02-scan" / "ispes.nc")
    got = open_ispes(root / "02-scan" / "ispes.nc")
    np.testing.assert_allclose(got["energy"].values, ref["energy"].values, rtol=0, atol=1e-6)
    np.testing.assert_allclose(
        got["normal_stress"].values, ref["normal_stress"].values, rtol=0, atol=1e-5
    )
    laws_ref = json.loads((src / "04-laws" / "laws.json").read_text())
    laws_got = json.loads((root / "04-laws" / "laws.json").read_text())
    assert laws_got["tau0_mpa"] == pytest.approx(laws_ref["tau0_mpa"], abs=1e-3)


def test_measured_stiffness_reruns_contact_and_report_and_recovers_tau0(tiny_run, tmp_path):
    """A CSV made by the model with a known τ0 (others as fitted) gives that τ0 back (Fig. 6)."""
    import shutil

    from flatcontact.contact import experiment as exp
    from flatcontact.contact.parameters import ContactParameters

    src, _, _ = tiny_run
    root = tmp_path / "copy"
    shutil.copytree(src, root)
    fitted = json.loads((root / "06-contact" / "summary.json").read_text())["parameters"]
    truth = ContactParameters(**fitted).replace(tau0_mpa=1.5 * fitted["tau0_mpa"])
    p0_pa = 1.77e9
    collapse = exp.model_collapse_stress(p0_pa, truth)
    # a ramp with dense points through the collapse, as a careful measurement would take
    stress = np.sort(np.concatenate([np.linspace(0.02, 1.2, 60), 1 + 0.001 * np.arange(-10, 11)]))
    stress = stress * collapse
    stiffness = exp.model_stiffness_at_stress(stress, p0_pa, truth)
    csv = tmp_path / "measured.csv"
    rows = "\n".join(f"{s / 1e6:.9g},{k:.9g}" for s, k in zip(stress, stiffness, strict=True))
    csv.write_text("mean_shear_stress_mpa,lateral_stiffness_n_per_m\n" + rows + "\n")

    with Pipeline(
        build_config(_merge(TINY, {"contact": {"experiment": {"csv": str(csv)}}})), root
    ) as pipe:
        pipe.run()
        actions = _actions(pipe)
    assert {n for n, a in actions.items() if a != "skipped"} == {"contact", "report"}
    summary = json.loads((root / "06-contact" / "summary.json").read_text())
    assert summary["experiment"]["fitted_tau0_mpa"] == pytest.approx(truth.tau0_mpa, rel=2e-3)
    assert (root / "06-contact" / "fig6_experiment.png").is_file()
    assert (
        "Fig. 6: measured stiffness (measured.csv)"
        in (root / "07-report" / "report.html").read_text()
    )


def _range_flags(root) -> list[str]:
    """The run's facts for the contact's range as `flatcontact contact` flags: z0 exactly as
    the stage takes it (the built interface's gap), γ_us and b of its sliding path."""
    import xarray as xr

    from flatcontact.stages.contact_range import interface_gap_angstrom, path_facts
    from flatcontact.structures.interface_io import read_interface

    gap = interface_gap_angstrom(read_interface(root / "01-build" / "interface.extxyz"))
    with xr.open_dataset(root / "03-analyze" / "friction.nc", engine="h5netcdf") as ds:
        path = path_facts(ds)
    return [
        f"--equilibrium-separation-angstrom={gap!r}",
        f"--unstable-stacking-mj-per-m2={1e3 * path['unstable_stacking_j_per_m2']!r}",
        f"--burgers-angstrom={path['burgers_angstrom']!r}",
    ]


def test_negative_slope_runs_and_a_p0_beyond_its_limit_is_refused(tiny_run, tmp_path):
    """k < 0 (a shear strength falling with load) is taken as given; a p0 at which
    τ(centre) = k·p0 + τ0 <= 0 is refused in one line naming contact.p0_gpa and the
    limit τ0/|k|, before the contact stage runs (its previous output is kept)."""
    import shutil

    src, _, _ = tiny_run
    root = tmp_path / "copy"
    shutil.copytree(src, root)
    tau0 = json.loads((root / "04-laws" / "laws.json").read_text())["tau0_mpa"]
    k = -tau0 / 1.5  # τ(centre) > 0 below 1.5 GPa; the centre slips first above 0.75 GPa
    good = _merge(TINY, {"contact": {"k_mpa_per_gpa": k, "p0_gpa": [0.5, 1.0]}})
    with Pipeline(build_config(good), root) as pipe:
        pipe.run()
    summary = json.loads((root / "06-contact" / "summary.json").read_text())
    assert summary["parameters"]["k_mpa_per_gpa"] == pytest.approx(k)
    assert summary["provenance"]["k_mpa_per_gpa"] == "config"
    for rec in summary["results"]:
        p1 = rec["contact_peak_pressure_gpa"]  # the adhesive contact's Hertzian peak
        assert rec["uniform_shear_strength_mpa"] == pytest.approx(k * 2 / 3 * p1 + tau0)
        assert 0 < rec["peak_lateral_force_un"] and np.isfinite(rec["knee_stress_amplitude_mpa"])
    before = (root / "06-contact" / "summary.json").read_text()
    bad = _merge(TINY, {"contact": {"k_mpa_per_gpa": k, "p0_gpa": [0.5, 2.0]}})
    with Pipeline(build_config(bad), root) as pipe, pytest.raises(InputError) as err:
        pipe.run()
    msg = str(err.value)
    assert "\n" not in msg and msg.startswith("contact.p0_gpa = 2 GPa")
    assert "τ0/|k| = 1.5 GPa" in msg
    assert (root / "06-contact" / "summary.json").read_text() == before


def test_elastic_stage_feeds_the_contact_model_and_the_report(tiny_run, tmp_path):
    """elastic.enabled: E*, G* of the potential's α-quartz replace the configured moduli and
    the report shows its Cij; the scan is not rerun."""
    import shutil

    src, _, _ = tiny_run
    root = tmp_path / "copy"
    shutil.copytree(src, root)
    with Pipeline(build_config(_merge(TINY, {"elastic": {"enabled": True}})), root) as pipe:
        pipe.run()
        actions = _actions(pipe)
        params, provenance = pipe.contact_parameters()
    assert actions["scan"] == "skipped" and actions["elastic"] == "ran"
    doc = json.loads((root / "05-elastic" / "elastic.json").read_text())
    moduli = doc["moduli_gpa"]
    assert provenance["moduli"] == "elastic stage"
    assert params.contact_modulus_gpa == pytest.approx(moduli["e_star"])
    # the paper's convention: G* = 4 G*_J
    assert params.shear_modulus_gpa == pytest.approx(4 * moduli["g_star_johnson"])
    # two identical bodies: 1/E* = 2(1 − ν²)/E; a mechanically stable crystal
    e, nu = moduli["youngs_modulus"], moduli["poisson_ratio"]
    assert moduli["e_star"] == pytest.approx(e / (2 * (1 - nu**2)), rel=1e-9)
    tensor = np.array(doc["tensor_gpa"])
    assert np.all(np.linalg.eigvalsh(0.5 * (tensor + tensor.T)) > 0)
    html = (root / "report.html").read_text()
    assert "α-quartz with " in html and "C11 (GPa)" in html


# ---- one door per stage: `flatcontact <stage>` writes what `flatcontact run` writes ------------


def _cli(argv: list[str]) -> None:
    from flatcontact.cli import main

    with pytest.raises(SystemExit) as info:
        main(argv)
    assert info.value.code == 0


def _same_json(a: Path, b: Path, ignore: tuple[str, ...] = ()) -> None:
    da, db = json.loads(a.read_text()), json.loads(b.read_text())
    for key in ignore:
        da.pop(key, None), db.pop(key, None)
    assert da == db, a.name


def _same_netcdf(a: Path, b: Path) -> None:
    with xr.open_dataset(a, engine="h5netcdf") as da, xr.open_dataset(b, engine="h5netcdf") as db:
        xr.testing.assert_identical(da.load(), db.load())


def _figures(folder: Path) -> set[str]:
    return {p.name for p in folder.iterdir() if p.suffix in (".png", ".svg")}


def test_each_stage_through_the_cli_writes_the_files_of_the_run(tiny_run, tmp_path):
    """build, scan, analyze (+ laws) and contact through their commands with the run's settings
    write the run's files, with the same names and contents (wall times excepted)."""
    import shutil

    from flatcontact.structures.interface_io import read_interface

    src, _, _ = tiny_run
    config = tmp_path / "tiny.yaml"
    config.write_text(json.dumps(TINY))  # JSON is YAML

    # build: the run's structure and potential as flags
    out = tmp_path / "build"
    _cli(["build", "--layers", "5", "--source", "seed", "--potential", "vashishta",
          "--no-svg", "--out", str(out)])  # fmt: skip
    assert sorted(p.name for p in out.iterdir()) == sorted(
        p.name for p in (src / "01-build").iterdir() if p.name != "stage.json"
    )
    _same_json(out / "build.json", src / "01-build" / "build.json")
    ours, run = (
        read_interface(out / "interface.extxyz"),
        read_interface(src / "01-build" / "interface.extxyz"),
    )
    np.testing.assert_allclose(ours.positions, run.positions, rtol=0, atol=1e-8)
    assert ours.info["recipe"] == run.info["recipe"]

    # scan: the run's config file; the run's store is taken over (the store refuses any other
    # settings), so nothing is recomputed and the files must match
    out = tmp_path / "scan"
    out.mkdir()
    shutil.copyfile(src / "02-scan" / "points.db", out / "points.db")
    interface = src / "01-build" / "interface.extxyz"
    _cli(["scan", str(config), "--interface", str(interface), "--out", str(out), "--json"])
    assert _figures(out) == _figures(src / "02-scan") == {"fig_scan_columns.png"}
    _same_netcdf(out / "ispes.nc", src / "02-scan" / "ispes.nc")
    _same_json(
        out / "scan.json",
        src / "02-scan" / "scan.json",
        ignore=("points_computed", "median_force_calls_per_point"),
    )

    # analyze + laws: the run's analysis section as flags, into one folder
    out = tmp_path / "analyze"
    p_gpa = ",".join(f"{p:g}" for p in TINY["analysis"]["p_gpa"])
    ispes = src / "02-scan" / "ispes.nc"
    _cli(["analyze", str(ispes), "--p-gpa", p_gpa, "--no-svg", "--out", str(out)])
    assert (out / "friction.csv").read_text() == (src / "03-analyze" / "friction.csv").read_text()
    _same_netcdf(out / "friction.nc", src / "03-analyze" / "friction.nc")
    _same_json(out / "analyze.json", src / "03-analyze" / "analyze.json", ignore=("timings_s",))
    _same_json(out / "other_form.json", src / "03-analyze" / "other_form.json")
    _same_json(out / "laws.json", src / "04-laws" / "laws.json")
    assert _figures(out) == _figures(src / "03-analyze") | _figures(src / "04-laws")

    # contact: the fitted laws and the scan's work of separation given as flags
    out = tmp_path / "contact"
    laws = json.loads((src / "04-laws" / "laws.json").read_text())
    w = json.loads((src / "02-scan" / "scan.json").read_text())["adhesion"]
    flags = [f"--{k.replace('_', '-')}={laws[k]!r}" for k in
             ("k_mpa_per_gpa", "tau0_mpa", "mu_mpa_per_gpa", "sigma0_mpa")]  # fmt: skip
    p0 = ",".join(f"{p:g}" for p in TINY["contact"]["p0_gpa"])
    # the run's z0 (the built interface's gap) and its sliding path's γ_us, b as flags
    flags += _range_flags(src)
    _cli(["contact", "--p0-gpa", p0, *flags, "--no-svg", "--out", str(out),
          f"--work-of-adhesion-j-per-m2={w['work_of_separation_j_per_m2']!r}"])  # fmt: skip
    _same_netcdf(out / "contact.nc", src / "06-contact" / "contact.nc")
    ours = json.loads((out / "summary.json").read_text())
    run = json.loads((src / "06-contact" / "summary.json").read_text())
    assert run.pop("provenance")["tau0_mpa"] == "fitted laws"
    assert ours.pop("provenance")["tau0_mpa"] == "config"
    # the validity gates judge a run's own scan and laws; numbers given as flags have none
    assert run.pop("gates")["fired"] == [] and "gates" not in ours
    # the same regime and sizes; only where z0, γ_us and b came from differ (γ_us given in
    # mJ/m² on the command line: equal to round-off)
    source = "equilibrium_separation_source"
    assert ours["adhesion_regime"].pop(source) != run["adhesion_regime"].pop(source)
    run["adhesion_regime"].pop("sentence"), ours["adhesion_regime"].pop("sentence")
    # the run's model is Vashishta: the paper's SNAP moduli are named as another potential's
    assert "vashishta" in run.pop("moduli_note") and "moduli_note" not in ours
    ours_slip, run_slip = ours.pop("slip_size"), run.pop("slip_size")
    assert ours_slip["structure"] == run_slip["structure"] == "commensurate"
    for a, b in zip(ours_slip["results"], run_slip["results"], strict=True):
        assert a.keys() == b.keys()
        for key, value in a.items():
            if isinstance(value, float):
                assert value == pytest.approx(b[key], rel=1e-12), key
            else:
                assert value == b[key], key
    # the fitted laws carry their intervals into the contact outputs; numbers given as flags
    # have none: same central values, zero width from the CLI
    ours_iv, run_iv = ours.pop("intervals"), run.pop("intervals")
    assert not any(ours_iv["half_widths"].values()) and all(run_iv["half_widths"].values())
    for a, b in zip(ours_iv["results"], run_iv["results"], strict=True):
        for key, value in a.items():
            if isinstance(value, dict):
                assert value["low"] == value["value"] == value["high"] == b[key]["value"]
                assert b[key]["low"] < b[key]["value"] < b[key]["high"]
    assert ours == run
    assert _figures(out) == _figures(src / "06-contact")


def test_cycle_and_fit_in_a_run_match_the_cli_and_the_fit_file_content_reruns_contact(
    tiny_run, tmp_path, capsys
):
    """contact.cycle/model/fit_* in the run config: only contact and report rerun; the run's
    cycle rows and fit equal ``flatcontact contact`` with the run's parameters as flags;
    new content in the same fit file (its sha256 is in the fingerprint) reruns contact."""
    import shutil

    from flatcontact.cli import main
    from flatcontact.contact import fit
    from flatcontact.contact.cycle import CycleModel
    from flatcontact.contact.measured import LoadCurve
    from flatcontact.contact.parameters import ContactParameters

    src, _, _ = tiny_run
    root = tmp_path / "copy"
    shutil.copytree(src, root)
    fitted = json.loads((root / "06-contact" / "summary.json").read_text())["parameters"]
    truth = ContactParameters(**fitted).replace(tau0_mpa=1.3 * fitted["tau0_mpa"])

    def write_data(path, prm):
        lines = ["mean shear stress [MPa],lateral stiffness [N/m],p0 [GPa]"]
        for p0 in (1.0, 2.0):
            mdl = CycleModel("modified", p0 * 1e9, prm)
            stress = np.linspace(0.05, 1.1, 10) * mdl.gross / (np.pi * mdl.a**2)
            k = fit.model_stiffness(LoadCurve(p0, stress, np.zeros(10), "t"), prm)
            lines += [f"{s / 1e6:.10g},{v:.10g},{p0}" for s, v in zip(stress, k, strict=True)]
        path.write_text("\n".join(lines) + "\n")

    csv = tmp_path / "curves.csv"
    write_data(csv, truth)
    change = {
        "cycle": {"enabled": True, "amplitude_fractions": [0.4, 0.8]},
        "fit": {"csv": [str(csv)]},
    }
    cfg = build_config(_merge(TINY, {"contact": change}))
    with Pipeline(cfg, root) as pipe:
        pipe.run()
        actions = _actions(pipe)
    assert {n for n, a in actions.items() if a != "skipped"} == {"contact", "report"}
    summary = json.loads((root / "06-contact" / "summary.json").read_text())
    assert len(summary["cycle"]) == 2 * len(TINY["contact"]["p0_gpa"])
    assert summary["fit"]["modified"]["fitted"]["tau0_mpa"] == pytest.approx(
        truth.tau0_mpa, rel=1e-3
    )
    assert (root / "06-contact" / "fit.json").is_file()
    assert "Multi-load fit of curves.csv" in (root / "07-report" / "report.html").read_text()

    flags = [f"--{k.replace('_', '-')}={v!r}" for k, v in fitted.items()] + _range_flags(root)
    argv = ["contact", "--p0-gpa", ",".join(map(str, TINY["contact"]["p0_gpa"])), *flags]
    argv += ["--cycle", "--cycle-amplitude-fractions", "0.4,0.8", "--fit-csv", str(csv), "--json"]
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code in (0, None)
    cli = json.loads(capsys.readouterr().out)
    assert cli["cycle"] == summary["cycle"]
    assert cli["fit"] == summary["fit"]

    write_data(csv, truth.replace(tau0_mpa=1.6 * fitted["tau0_mpa"]))  # same name, new content
    with Pipeline(cfg, root) as pipe:
        pipe.run()
        actions = _actions(pipe)
    assert {n for n, a in actions.items() if a != "skipped"} == {"contact", "report"}
    again = json.loads((root / "06-contact" / "summary.json").read_text())
    assert again["fit"]["modified"]["fitted"]["tau0_mpa"] == pytest.approx(
        1.6 * fitted["tau0_mpa"], rel=1e-3
    )


def test_the_scan_fingerprint_holds_the_load_bracket_it_reads(tmp_path):
    """The scan brackets ``analysis.p_gpa`` with its thicknesses (pressure-range grids): a load
    beyond the scanned ones changes the scan's inputs, so the scan re-brackets instead of the
    analysis failing later outside the data; a load inside them, or any load of a grid of
    explicit thicknesses (which brackets nothing), leaves the scan alone."""

    def inputs(change: dict) -> dict:
        return settings_inputs("scan", build_config(_merge(TINY, change)))

    base = inputs({})
    assert base["bracket_loads_gpa"] == [0.0, 3.0]
    assert inputs({"analysis": {"p_gpa": [0.0, 0.25, 1.0, 3.0]}}) == base
    assert inputs({"analysis": {"p_gpa": [0.0, 1.0, 3.4]}}) != base
    explicit = {"scan": {"p_range_gpa": None, "thickness_angstrom": [17.0, 17.5, 18.0, 18.5]}}
    assert "bracket_loads_gpa" not in inputs(explicit)
    assert inputs(explicit) == inputs(_merge(explicit, {"analysis": {"p_gpa": [0.0, 9.0]}}))
