"""``study approximants --list``: each cell's cost in seconds from a timed force call, the
study's wall time on its executor, and when it needs Dask (``studies/approximant_cost``)."""

from __future__ import annotations

import json
import time

import pytest
from tests.cli.cli_helpers import run_cli
from tests.studies.test_approximants_study import TBG

from flatcontact.config.load import build_config
from flatcontact.studies import approximant_cost as cost
from flatcontact.studies.approximants import plan


def test_a_timed_force_call_is_the_cost_of_the_cells_own_calculator():
    """The timed call of the (1, 2) and (3, 4) rigid twisted graphene cells: the atoms are all
    held (one sheet per slab: every mode is a rigid scan), and the CPU per call grows with the
    atoms (REBO + KC: 28 against 148 atoms) while staying what the same calculator takes
    when timed here by hand (within 5x: the machine is shared)."""
    from flatcontact.config.run import RunConfig
    from flatcontact.potentials.engines import make_calculator
    from flatcontact.stages import _calculator
    from flatcontact.structures.construct import build_interface

    cells = plan(build_config(TBG))
    small = cost.time_force_call(cells[0]["config"])
    large = cost.time_force_call(cells[2]["config"])
    assert small["n_atoms"] == 28 and large["n_atoms"] == 148
    assert small["all_held"] and large["all_held"]
    assert large["cpu_s"] > small["cpu_s"] > 0
    cfg = RunConfig.model_validate(cells[2]["config"])
    atoms, _ = build_interface(cfg.structure)
    atoms.calc = make_calculator(_calculator.model(cfg), atoms)
    atoms.get_forces()
    spent = []
    for k in range(5):
        atoms.positions[1, 2] += 1e-4 * (-1) ** k
        c0 = time.process_time()
        atoms.get_forces()
        spent.append(time.process_time() - c0)
    by_hand = sorted(spent)[2]
    assert by_hand / 5 < large["cpu_s"] < 5 * by_hand


def _fake_timing(cpu_s_per_atom: float):
    def timed(config: dict) -> dict:
        from flatcontact.config.run import RunConfig
        from flatcontact.structures.construct import build_interface

        atoms, _ = build_interface(RunConfig.model_validate(config).structure)
        n = len(atoms)
        return {
            "cpu_s": cpu_s_per_atom * n,
            "wall_s": cpu_s_per_atom * n,
            "n_atoms": n,
            "all_held": True,
        }

    return timed


def test_seconds_wall_and_the_dask_verdict_follow_the_stated_model(monkeypatch):
    """seconds = points·(calls/point·t_call + overhead) + fixed per cell; the wall time on W
    workers is max(Σ/W, largest cell); above the threshold on the local cores the study is
    said to need Dask, and a single cell above it is named as one more workers cannot
    shorten."""
    monkeypatch.setattr(cost, "time_force_call", _fake_timing(1e-3))
    cfg = build_config({**TBG, "scan": {**TBG["scan"], "executor": "processes", "workers": 2}})
    cells = plan(cfg)
    est = cost.estimate_cost(cfg, cells)
    for c, r in zip(cells, est["cells"], strict=True):
        expected = c["points_planned"] * (1e-3 * c["n_atoms"] + cost.POINT_OVERHEAD_S)
        assert r["seconds"] == pytest.approx(expected + cost.CELL_FIXED_S, rel=1e-12)
        assert r["calls_per_point"] == 1.0 and r["force_calls"] == c["points_planned"]
    total = sum(r["seconds"] for r in est["cells"])
    assert est["cpu_seconds"] == pytest.approx(total)
    assert est["workers"] == 2
    assert est["wall_seconds"] == pytest.approx(max(total / 2, est["largest_cell_s"]))
    assert not est["needs_dask"]
    lines = cost.cost_lines(est)
    assert "fits the local cores" in lines[-1] and "8.0 h" in lines[-1]
    # a model 2000x costlier per atom: the (3, 4) cell alone ~12 h, beyond the threshold
    monkeypatch.setattr(cost, "time_force_call", _fake_timing(2.0))
    slow = cost.estimate_cost(cfg, cells)
    assert slow["needs_dask"] and slow["largest_cell_s"] > cost.DASK_THRESHOLD_S
    verdict = cost.cost_lines(slow)[-1]
    assert "needs a Dask cluster (docs/cluster.md" in verdict
    assert "more workers do not shorten it" in verdict


def test_a_finished_cell_calibrates_the_force_calls_per_point(tmp_path, monkeypatch):
    """A relaxing scan's calls per point are assumed until a cell of the study has finished;
    then the smallest finished cell's median calls per point (its scan.json, as the scan stage
    writes it) replaces the assumption for every cell; the seconds follow (round trip)."""

    def not_held(config):
        return {**_fake_timing(1e-3)(config), "all_held": False}

    monkeypatch.setattr(cost, "time_force_call", not_held)
    cfg = build_config({**TBG, "scan": {**TBG["scan"], "relax_mode": "normal"}})
    cells = plan(cfg)
    assumed = cost.estimate_cost(cfg, cells, tmp_path)
    assert assumed["calibration"] is None
    assert assumed["cells"][0]["calls_per_point"] == cost.ASSUMED_CALLS_PER_POINT["normal"]
    assert "assumed" in assumed["cells"][0]["calls_source"]
    for label, median in (("twist-2-3", 9.0), ("twist-1-2", 12.0)):
        scan_dir = tmp_path / "runs" / label / "02-scan"
        scan_dir.mkdir(parents=True)
        (scan_dir / "scan.json").write_text(
            json.dumps(
                {
                    "points_total": 144,
                    "points_done": 144,
                    "points_computed": 144,
                    "thickness_angstrom": [9.0 + 0.1 * i for i in range(4)],
                    "area_angstrom2": 52.4,
                    "force_calls_total": int(144 * median),
                    "median_force_calls_per_point": median,
                }
            )
        )
        record = {"stage": "scan", "fingerprint": "0" * 64, "state": "done", "seconds": 80.0}
        (scan_dir / "stage.json").write_text(json.dumps(record))
    est = cost.estimate_cost(cfg, cells, tmp_path)
    assert est["calibration"]["label"] == "twist-1-2"  # the smallest finished cell
    r = est["cells"][1]
    assert r["calls_per_point"] == 12.0 and r["calls_source"] == "measured on twist-1-2"
    expected = r["points"] * (12.0 * 1e-3 * 76 + cost.POINT_OVERHEAD_S) + cost.CELL_FIXED_S
    assert r["seconds"] == pytest.approx(expected)
    assert "measured on the finished cell twist-1-2" in "\n".join(cost.cost_lines(est))


def test_list_prints_seconds_per_cell_and_the_study_wall(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    cfg = tmp_path / "tbg.yaml"
    cfg.write_text(json.dumps(TBG))
    code, out, _ = run_cli(["study", "approximants", str(cfg), "--list"], capsys)
    assert code in (0, None)
    assert "twist-3-4: ~144 force calls (1 per point, exact (nothing relaxes))" in out
    assert "ms CPU (timed" in out
    assert "CPU (one core, all cells one after another)" in out
    assert "wall on serial with 1 worker(s)" in out
    assert "fits the local cores (Dask, docs/cluster.md, pays above 8.0 h)" in out
    assert not (tmp_path / "flatcontact-study").exists()


@pytest.mark.slow
def test_the_estimate_matches_the_study_it_precedes(tmp_path):
    """The rigid twisted graphene (1, 2), (2, 3) cells (~2 min on the loaded machine, serial:
    in this process): the estimate printed before is within a factor 2 of the CPU seconds the
    study spent (measured 23.7 s; the constants are CPU seconds of the same cells)."""
    from flatcontact.studies.approximants import run_approximants

    cfg = build_config({**TBG, "approximants": {"max_cells": 2}})
    cells = plan(cfg)
    before = cost.estimate_cost(cfg, cells)["cpu_seconds"]
    t0 = time.process_time()
    run_approximants(cfg, tmp_path)
    spent = time.process_time() - t0
    assert spent / 2 < before < 2 * spent, (before, spent)
