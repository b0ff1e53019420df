"""Folds from relaxation error are remedied before anything refuses (issue 32,
:mod:`flatcontact.ispes.rerelax`): the fold's window is relaxed again at fmax / 10, once.

Two constructed stores on the toy LJ interface (2 × 2 grid, thicknesses from a load range):

- one point of a column is moved off its minimum (its free atoms displaced sideways, its
  energy and load those of the displaced atoms, as a relaxation stopped short would leave
  it): the energy-derived load folds there; a real re-relaxation from the stored positions
  returns the point to its minimum and the fold is gone;
- a calculator with a fold of its own (a thickness-only term, ``tests/ispes/fold_toy.py``):
  the fold survives the re-relaxation and the analysis refuses it, naming the survival and
  the remedies.
"""

from __future__ import annotations

import json
import shutil
import warnings

import numpy as np
import pytest

from flatcontact.foundation.errors import InputError
from flatcontact.foundation.layout import POINTS_DB, RERELAX_DB
from flatcontact.ispes import scan as ispes_scan
from flatcontact.ispes.grid import GridSpec
from flatcontact.ispes.grid_bracket import node_loads_gpa
from flatcontact.ispes.relax import RelaxSettings, normal_stress_gpa
from flatcontact.ispes.rerelax import FMAX_FACTOR, fold_windows, rerelax_folds
from flatcontact.ispes.store import PointStore
from flatcontact.ispes.toy import toy_calculator

LOADS_GPA = [0.0, 0.5, 1.0, 1.5]
GRID = GridSpec(2, 2, p_range_gpa=(-0.2, 1.5, 6))
RELAX = RelaxSettings(0.005)


@pytest.fixture(scope="module")
def toy_scan(tmp_path_factory, toy_reference, toy_factory):
    """A finished toy scan (its folder) and its store settings."""
    out = tmp_path_factory.mktemp("toy-scan")
    ispes_scan.run_scan(
        toy_reference,
        toy_factory,
        GRID,
        out,
        RELAX,
        executor_options={"kind": "serial"},
        bracket_loads_gpa=LOADS_GPA,
    )
    return out, ispes_scan.scan_settings(toy_reference, toy_factory, GRID, RELAX)


def _displace(store_path, reference, index, shift_angstrom=0.05):
    """Move the free atoms of the stored point ``index`` sideways (slab 2 against slab 1) and
    store the displaced atoms' real energy and load: a point above its minimum. Returns
    (energy before, energy after) in eV."""
    import ase.db

    db = ase.db.connect(str(store_path), type="db", use_lock_file=False)
    with db:  # one connection, closed: no -wal, -shm left beside the store
        return _displace_in(db, reference, index, shift_angstrom)


def _displace_in(db, reference, index, shift_angstrom):
    from ase.calculators.singlepoint import SinglePointCalculator

    row = db.get(i_a=index[0], i_b=index[1], i_z=index[2])
    atoms = row.toatoms()
    for key in ("slab", "surface"):
        atoms.arrays[key] = reference.arrays[key]
    free = ~np.isin(reference.arrays["surface"], (1, 4))
    sign = np.where(reference.arrays["slab"] == 2, -1.0, 1.0)
    atoms.positions[free, 0] += shift_angstrom * sign[free]
    atoms.calc = toy_calculator()
    energy, forces = float(atoms.get_potential_energy()), atoms.get_forces()
    moved = atoms.copy()
    moved.calc = SinglePointCalculator(moved, energy=energy)
    db.update(
        row.id,
        atoms=moved,
        normal_stress_gpa=normal_stress_gpa(atoms, forces),
        max_force_ev_per_a=float(np.linalg.norm(forces[free], axis=1).max()),
    )
    return float(row.energy), energy


def _dataset(folder, settings, reference):
    with PointStore(folder / POINTS_DB, settings, reference) as store:
        return store.assemble()


def _node_loads(ds, i, j):
    e = ds["energy"].values[i, j][None, :]
    s = ds["normal_stress"].values[i, j][None, :]
    return node_loads_gpa(ds["thickness"].values, e, s, float(ds.attrs["area"]))[0]


def test_a_fold_from_a_point_stopped_above_its_minimum_is_re_relaxed_away(
    toy_scan, toy_reference, toy_factory, tmp_path, monkeypatch
):
    folder, settings = toy_scan
    work = tmp_path / "scan"
    shutil.copytree(folder, work)
    clean = _dataset(work, settings, toy_reference)
    assert fold_windows(clean, LOADS_GPA) == []  # the scan as stored does not fold
    with PointStore(work / POINTS_DB, settings, toy_reference) as store:
        z = np.asarray(store.resolved["thickness_angstrom"])
    k = 2  # the third thickness (ascending): p ≈ 0.8 GPa at (0, 0)
    index = (0, 0, int(np.argsort(z)[k]))
    stored, raised = _displace(work / POINTS_DB, toy_reference, index)
    assert 1e-3 < raised - stored < 1e-2  # a few meV above the minimum
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the displaced row still meets the store contract
        ds = _dataset(work, settings, toy_reference)
    (window,) = fold_windows(ds, LOADS_GPA)
    assert window.column == (0, 0) and k in window.nodes and window.p_gpa > window.p_below_gpa
    assert np.any(np.diff(_node_loads(ds, 0, 0)[: k + 3]) > 0)
    fixed, done = rerelax_folds(
        toy_reference, toy_factory, ds, work / POINTS_DB, settings, RELAX, LOADS_GPA
    )
    assert done.fmax_ev_per_angstrom == pytest.approx(RELAX.fmax_ev_per_angstrom * FMAX_FACTOR)
    # both stores closed, each one file (a run directory is copied and kept): no -wal, -shm
    assert sorted(p.name for p in work.glob("*.db*")) == [POINTS_DB, RERELAX_DB]
    assert done.surviving == [] and [w.column for w in done.remedied] == [(0, 0)]
    assert fold_windows(fixed, LOADS_GPA) == []
    # the load falls with z again along the whole compressed side of the column
    loads = _node_loads(fixed, 0, 0)
    m = int(np.argmin(loads))
    assert np.all(np.diff(loads[: m + 1]) < 0)
    # the displaced point is back at its minimum: the scan's own energy, to within what
    # fmax 0.005 eV/Å leaves (the tighter minimum lies at or below it)
    again = fixed["energy"].values[0, 0, k]
    assert -1e-4 < again - stored <= 1e-9
    assert len(done.points) == len(window.nodes) and all(p["converged"] for p in done.points)
    assert fixed.attrs["fold_rerelaxed_points"] == len(window.nodes)
    # the scan's own store is left as it was; the re-relaxed points are a store of their own
    # (same row contract, the tighter fmax in its settings), which reopens without repair
    assert _dataset(work, settings, toy_reference)["energy"].values[0, 0, k] == raised
    tight = {**settings, "relax": {**settings["relax"], "fmax_ev_per_a": done.fmax_ev_per_angstrom}}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with PointStore(work / RERELAX_DB, tight, toy_reference) as store:
            assert len(store) == len(window.nodes)
    # a second call (a resumed stage) relaxes nothing again and gives the same grid
    import flatcontact.ispes.rerelax as rerelax

    def refuse(*args, **kwargs):
        raise AssertionError("a stored re-relaxed point was relaxed again")

    monkeypatch.setattr(rerelax, "relax_point", refuse)
    repeat, _ = rerelax_folds(
        toy_reference, toy_factory, ds, work / POINTS_DB, settings, RELAX, LOADS_GPA
    )
    np.testing.assert_array_equal(repeat["energy"].values, fixed["energy"].values)


@pytest.mark.parametrize("top_gpa", [0.0, 0.1, 0.3, 0.5, 1.0, 1.5])
def test_a_window_is_re_relaxed_exactly_where_the_analysis_would_refuse(
    toy_scan, toy_reference, tmp_path, top_gpa
):
    """fold_windows agrees with the analysis's own refusal
    (:func:`flatcontact.analysis.constant_pressure.constant_pressure`) for every set of loads:
    loads the analysis reads past the fold need no remedy."""
    from flatcontact.analysis.constant_pressure import constant_pressure

    folder, settings = toy_scan
    work = tmp_path / "scan"
    shutil.copytree(folder, work)
    with PointStore(work / POINTS_DB, settings, toy_reference) as store:
        z = np.asarray(store.resolved["thickness_angstrom"])
    _displace(work / POINTS_DB, toy_reference, (0, 0, int(np.argsort(z)[2])))
    ds = _dataset(work, settings, toy_reference)
    loads = [0.0, top_gpa]
    found = fold_windows(ds, loads)
    refused = None
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            constant_pressure(ds, loads, form="internal")
    except InputError as exc:
        refused = str(exc)
    assert bool(found) == (refused is not None), refused
    if refused is not None:
        assert "fold" in refused or "not monotonic" in refused


FOLDED = {"z0_angstrom": 11.1, "width_angstrom": 0.05, "bump_gpa": 1.5}


def test_a_fold_of_the_interaction_survives_and_the_analysis_refuses_it_with_the_remedy(
    toy_scan, toy_reference, tmp_path
):
    """The same thicknesses with a calculator whose load itself folds: re-relaxed at fmax/10
    the fold stays, and the analysis's refusal says so and names the remedies."""
    from flatcontact.analysis.constant_pressure import constant_pressure
    from flatcontact.potentials.engines import calculator_factory
    from flatcontact.potentials.model import InteractionModel
    from flatcontact.stages.analyze import _folds_named

    folder, settings = toy_scan
    with PointStore(folder / POINTS_DB, settings, toy_reference) as store:
        z = sorted(store.resolved["thickness_angstrom"])
    factory = calculator_factory(
        InteractionModel(calculator={"target": "tests.ispes.fold_toy:folded_toy", "kwargs": FOLDED})
    )
    grid = GridSpec(2, 2, thickness_angstrom=tuple(z))
    out = tmp_path / "scan"
    result = ispes_scan.run_scan(
        toy_reference, factory, grid, out, RELAX, executor_options={"kind": "serial"}
    )
    store_settings = ispes_scan.scan_settings(toy_reference, factory, grid, RELAX)
    found = fold_windows(result.dataset, LOADS_GPA)
    assert (0, 0) in {w.column for w in found}  # (the other stackings fold above 1.5 GPa)
    assert all(11.0 < w.z_below_angstrom < w.z_angstrom < 11.2 for w in found)
    fixed, done = rerelax_folds(
        toy_reference, factory, result.dataset, out / POINTS_DB, store_settings, RELAX, LOADS_GPA
    )
    assert done.remedied == [] and {w.column for w in done.surviving} == {w.column for w in found}
    assert all("the fold survived" in line for line in done.lines()[: len(found)])
    # the analysis refuses the loads above the fold; the scan's record makes it say why
    record = {  # the required keys of scan.json's contract (flatcontact.foundation.result_json)
        "points_total": int(fixed["energy"].size),
        "points_done": int(fixed["energy"].size),
        "force_calls_total": 1,
        "thickness_angstrom": fixed["thickness"].values.tolist(),
        "area_angstrom2": float(fixed.attrs["area"]),
    }
    (out / "scan.json").write_text(json.dumps({**record, "fold_rerelaxation": done.record()}))
    with pytest.raises(InputError) as info, _folds_named(out / "scan.json"):
        constant_pressure(fixed, LOADS_GPA, form="internal")
    line = str(info.value)
    assert "\n" not in line and "fold" in line
    assert f"at fmax {done.fmax_ev_per_angstrom:g} eV/Å and the fold survived" in line
    assert "scan.relax_mode: normal" in line and "scan.thickness_angstrom" in line
    assert "analysis.p_gpa" in line


FOLDED_RUN = """\
structure: {kind: toy-lj, layers: 3}
potential:
  calculator:
    target: "tests.ispes.fold_toy:folded_toy"
    kwargs: {z0_angstrom: 11.1, width_angstrom: 0.05, bump_gpa: 1.5}
scan:
  grid: [3, 3]
  thickness_angstrom: [10.95, 11.0, 11.05, 11.1, 11.15, 11.2, 11.25, 11.3, 11.35, 11.4, 11.5, 11.6, 11.7]
  executor: serial
analysis: {p_gpa: [0.0, 0.5, 1.0, 1.5]}
contact: {p0_gpa: [0.5, 1.0]}
report: {svg: false}
"""


def test_a_run_whose_fold_survives_is_refused_with_a_report_that_says_so(tmp_path):
    """The whole run: the scan stage re-relaxes the folding columns' windows (scan.json,
    rerelax.db, run.log), the analysis refuses the fold that survived, and the refused run's
    report states the re-relaxation and leaves the tighter fmax out of its remedies."""
    from flatcontact.config.load import load_config
    from flatcontact.pipeline import Pipeline

    (tmp_path / "run.yaml").write_text(FOLDED_RUN)
    run = tmp_path / "run"
    with (
        Pipeline(load_config(tmp_path / "run.yaml"), run) as pipe,
        pytest.raises(InputError) as info,
    ):
        pipe.run()
    line = str(info.value)
    assert "\n" not in line and "the fold survived" in line and "report.html" in line
    scan = json.loads((run / "02-scan" / "scan.json").read_text())
    redone = scan["fold_rerelaxation"]
    assert redone["fmax_ev_per_angstrom"] == pytest.approx(0.005 * FMAX_FACTOR)
    assert (
        redone["found"]
        and redone["remedied"] == []
        and len(redone["surviving"]) == len(redone["found"])
    )
    assert (run / "02-scan" / RERELAX_DB).is_file()
    assert any("re-relaxed at fmax 0.0005" in w for w in scan["warnings"])
    assert "the fold survived" in (run / "run.log").read_text()
    refusal = json.loads((run / "07-report" / "refusal.json").read_text())
    assert refusal["stage"] == "analyze" and refusal["finished"] == ["build", "scan"]
    assert refusal["fold_rerelaxation"] == redone
    assert not any(r.startswith("tighten scan.fmax") for r in refusal["remedies"])
    assert any("more thicknesses around the fold" in r for r in refusal["remedies"])
    page = (run / "report.html").read_text()
    assert "Before refusing, the scan re-relaxed the windows of" in page
    assert "survived" in page


def test_recorded_windows_are_the_columns_the_scans_grid_check_records(
    toy_scan, toy_reference, tmp_path
):
    """With ``recorded``, the windows are exactly the columns the scan's grid check
    (:func:`flatcontact.ispes.grid_bracket.check_grid`) records in ``load_folds``, which the
    ``load_fold`` gate refuses whatever the analysis loads."""
    from flatcontact.ispes.grid_bracket import check_grid

    folder, settings = toy_scan
    work = tmp_path / "scan"
    shutil.copytree(folder, work)
    with PointStore(work / POINTS_DB, settings, toy_reference) as store:
        z = np.asarray(store.resolved["thickness_angstrom"])
    _displace(work / POINTS_DB, toy_reference, (0, 0, int(np.argsort(z)[2])))
    _displace(work / POINTS_DB, toy_reference, (1, 1, int(np.argsort(z)[-3])), 0.03)
    ds = _dataset(work, settings, toy_reference)
    n_z = ds["thickness"].size
    shifts = [(float(a), float(b)) for a in ds["shift_a"].values for b in ds["shift_b"].values]
    verdict = check_grid(
        ds["thickness"].values,
        ds["energy"].values.reshape(-1, n_z),
        ds["normal_stress"].values.reshape(-1, n_z),
        float(ds.attrs["area"]),
        shifts,
        GRID.p_range_gpa,
        [0.0],
    )
    named = {f.column.rsplit(" (", 1)[0] for f in verdict.folds}  # less its load source
    windows = fold_windows(ds, [0.0], recorded=True)
    assert {w.name for w in windows} == named and named
    assert {w.name for w in fold_windows(ds, [0.0])} <= named


def test_a_rigid_scan_has_nothing_to_re_relax_and_says_so(toy_scan, toy_reference, tmp_path):
    folder, settings = toy_scan
    work = tmp_path / "scan"
    shutil.copytree(folder, work)
    with PointStore(work / POINTS_DB, settings, toy_reference) as store:
        z = np.asarray(store.resolved["thickness_angstrom"])
    _displace(work / POINTS_DB, toy_reference, (0, 0, int(np.argsort(z)[2])))
    ds = _dataset(work, settings, toy_reference)
    rigid = RelaxSettings(0.005, mode="rigid")
    same, done = rerelax_folds(
        toy_reference, None, ds, work / POINTS_DB, settings, rigid, LOADS_GPA
    )
    assert same is ds and done.points == [] and not (work / RERELAX_DB).exists()
    assert done.surviving == [] and done.remedied == [] and len(done.left) == 1
    assert done.lines() == [
        "grid column at shift (0, 0): fold not re-relaxed (a rigid scan relaxes nothing)"
    ]
    assert done.record()["left"] == [
        {"column": "grid column at shift (0, 0)", "why": "a rigid scan relaxes nothing"}
    ]
