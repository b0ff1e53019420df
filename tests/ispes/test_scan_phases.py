"""The scan driver times its serial phases (issue 33): probe, ideal work of separation,
symmetry, grid, write; the benchmark prints them. The clock observes: it changes nothing."""

from __future__ import annotations

import logging

import numpy as np
import pytest

from flatcontact.ispes.executors import SerialExecutor
from flatcontact.ispes.grid import GridSpec
from flatcontact.ispes.phases import phase, recording
from flatcontact.ispes.reduction import SymmetrySettings
from flatcontact.ispes.relax import RelaxSettings
from flatcontact.ispes.scan import run_scan

SETTINGS = RelaxSettings(fmax_ev_per_angstrom=1e-4, optimizer="FIRE")
TOP = ("open store", "probe", "overlap check", "symmetry", "grid", "assemble", "extend", "write")


def test_a_probed_scan_reports_each_phase_once_and_they_add_up(
    tmp_path, toy_reference, toy_factory, caplog
):
    grid = GridSpec(3, 3, p_range_gpa=(-0.05, 0.5, 4))
    with caplog.at_level(logging.DEBUG, logger="flatcontact.ispes.phases"):
        r = run_scan(
            toy_reference,
            toy_factory,
            grid,
            tmp_path,
            SETTINGS,
            executor=SerialExecutor(),
            symmetry=SymmetrySettings(enabled=True),
        )
    ph = r.phase_seconds
    assert set(TOP) <= set(ph) and {"probe/rigid points", "probe/ideal W"} <= set(ph)
    assert all(s >= 0 for s in ph.values())
    # the parts within their phase, the top-level phases within the scan's wall time
    assert ph["probe/rigid points"] + ph["probe/ideal W"] <= ph["probe"]
    assert ph.get("grid/verification", 0.0) <= ph["grid"]
    assert sum(ph[k] for k in TOP) <= r.seconds
    # the log carries the same phases, each entry "<name> <seconds>"
    logged: dict[str, float] = {}
    for rec in caplog.records:
        name, seconds = rec.getMessage().rsplit(" ", 1)
        logged[name] = logged.get(name, 0.0) + float(seconds)
    assert logged.keys() == ph.keys()
    np.testing.assert_allclose([logged[k] for k in ph], list(ph.values()), atol=2e-6)
    # a rerun on the finished store computes nothing: no probe work, a grid of no points
    again = run_scan(
        toy_reference, toy_factory, grid, tmp_path, SETTINGS, executor=SerialExecutor(),
        symmetry=SymmetrySettings(enabled=True),
    )  # fmt: skip
    assert "probe/rigid points" not in again.phase_seconds
    np.testing.assert_array_equal(again.dataset.energy.values, r.dataset.energy.values)


def test_phase_outside_a_scan_does_nothing_and_nested_recordings_are_apart():
    with phase("alone"):
        pass
    with recording() as outer:
        with phase("a"):
            with recording() as inner, phase("b"):
                pass
        with phase("a"):
            pass
    assert list(outer.seconds) == ["a"] and list(inner.seconds) == ["b"]


def test_with_workers_the_probes_single_points_run_while_the_driver_computes_the_hessian(
    tmp_path, toy_reference, toy_factory, monkeypatch
):
    """The rigid single points need no Hessian: with worker processes they are submitted
    before the driver computes it, and their values (``probe.json``'s rigid units) are the
    serial scan's bit for bit, so are the thicknesses and the grid."""
    import json

    from benchmarks.schedule_replay import task_key

    from flatcontact.ispes import shared_hessian
    from flatcontact.ispes.executors import ProcessExecutor

    events: list[str] = []
    computing = shared_hessian.HessianSharing.context

    def logged(self, executor):
        events.append("hessian")
        return computing(self, executor)

    monkeypatch.setattr(shared_hessian.HessianSharing, "context", logged)

    class Logging(ProcessExecutor):
        def submit(self, fn, *args):
            events.append(task_key(fn, args)[0])
            return super().submit(fn, *args)

    grid = GridSpec(3, 3, p_range_gpa=(-0.05, 0.5, 4))
    settings = RelaxSettings(fmax_ev_per_angstrom=1e-4)
    pool = Logging(2)
    try:
        two = run_scan(toy_reference, toy_factory, grid, tmp_path / "two", settings, executor=pool)
    finally:
        pool.close()
    first_hessian = events.index("hessian")
    assert "rigid_rows_task" in events[:first_hessian]
    assert "rigid_rows_task" not in events[first_hessian:]
    serial = run_scan(
        toy_reference, toy_factory, grid, tmp_path / "one", settings, executor=SerialExecutor()
    )

    def rigid_units(folder):
        units = json.loads((folder / "probe.json").read_text())["units"]
        return {key: value for key, value in units.items() if key.startswith('["rigid"')}

    assert len(rigid_units(tmp_path / "two")) == grid.n_a  # one unit per lateral row
    assert rigid_units(tmp_path / "two") == rigid_units(tmp_path / "one")
    np.testing.assert_array_equal(two.dataset.thickness.values, serial.dataset.thickness.values)
    np.testing.assert_array_equal(two.dataset.energy.values, serial.dataset.energy.values)


def test_the_timeline_counts_idle_core_seconds_and_the_drivers_cpu():
    """``python -m benchmarks scantimeline``'s accounting on samples of known CPU: idle =
    cores × wall − CPU used, over the intervals inside the window only; a process that
    starts between two samples counts from its first."""
    from benchmarks.bench_scantimeline import usage

    s = 1_000_000_000  # ns per CPU second
    rows = [
        (0.0, {1: 0}),
        (1.0, {1: s // 2, 2: 0}),  # driver half busy, worker 2 appears
        (2.0, {1: s // 2, 2: s, 3: 0}),  # worker 2 fully busy, worker 3 appears
        (3.0, {1: s, 2: 2 * s, 3: s // 2}),  # 0.5 + 1 + 0.5 CPU s in the last second
    ]
    idle, driver = usage(rows, 1, 0.0, 3.0)  # used 0.5, 1.0, 2.0 CPU s
    assert idle == pytest.approx(2 * 3.0 - 3.5) and driver == pytest.approx(1.0)
    idle, driver = usage(rows, 1, 0.5, 3.0)  # the first interval is not inside
    assert idle == pytest.approx(2 * 2.0 - 3.0) and driver == pytest.approx(0.5)
