"""A scan interrupted inside its probe resumes it from ``probe.json``: the finished units
(rows of single points, chains, segments, the work of separation) are reused, only the
rest is recomputed, and the resumed ispes.nc is the uninterrupted one."""

import json
import warnings

import numpy as np
import pytest

from flatcontact.foundation.errors import InputError
from flatcontact.foundation.layout import PROBE_JSON
from flatcontact.ispes import probe_units as units_module
from flatcontact.ispes import relax as relax_module
from flatcontact.ispes.contract import open_ispes
from flatcontact.ispes.executors import SerialExecutor
from flatcontact.ispes.grid import GridSpec
from flatcontact.ispes.probe_units import ProbeUnitsRepaired, ProbeUnitsReused
from flatcontact.ispes.relax import RelaxSettings
from flatcontact.ispes.scan import run_scan
from flatcontact.ispes.scan_probe import MANY_WORKERS
from flatcontact.ispes.store import discard_store
from flatcontact.structures.toy import ToyPairCalculator

SETTINGS = RelaxSettings(fmax_ev_per_angstrom=1e-4, optimizer="FIRE")
GRID = GridSpec(3, 3, p_range_gpa=(-0.05, 0.5, 4))


class ManySerial(SerialExecutor):
    """The driver's many-worker probe (:func:`flatcontact.ispes.scan_probe.probe_many`: segments,
    row blocks), each task run at submission in this process so its force calls are counted."""

    workers = MANY_WORKERS


class Calls:
    """Counts the toy's force calls in this process; raises KeyboardInterrupt at call ``stop``.
    ``at_put`` holds the count each time a probe unit is written to ``probe.json``."""

    def __init__(self, monkeypatch):
        self.n = 0
        self.stop = None
        self.at_put: list[int] = []
        self.keys: list[str] = []
        inner = ToyPairCalculator.calculate
        put = units_module.ProbeUnits.put

        def calculate(calc, *args, **kwargs):
            self.n += 1
            if self.stop is not None and self.n >= self.stop:
                self.stop = None
                raise KeyboardInterrupt
            return inner(calc, *args, **kwargs)

        def counted_put(units, kind, inputs, value):
            self.at_put.append(self.n)
            self.keys.append(units_module.unit_key(kind, *inputs))
            return put(units, kind, inputs, value)

        monkeypatch.setattr(ToyPairCalculator, "calculate", calculate)
        # the driver's calculators are built anew, so that they call the counted calculate
        monkeypatch.setattr(relax_module._local, "calculators", {}, raising=False)
        monkeypatch.setattr(units_module.ProbeUnits, "put", counted_put)

    def run(self, fn, stop=None):
        """The force calls of ``fn()`` (interrupted at its call ``stop`` if given)."""
        self.n, self.at_put, self.keys = 0, [], []
        self.stop = stop
        if stop is None:
            fn()
        else:
            with pytest.raises(KeyboardInterrupt):
                fn()
        return self.n


def _same_ispes(a, b, exact=True):
    a, b = open_ispes(a), open_ispes(b)
    assert sorted(a.data_vars) == sorted(b.data_vars)
    for name in a.data_vars:
        if exact:
            np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)
        else:
            np.testing.assert_allclose(a[name].values, b[name].values, atol=1e-9, err_msg=name)
    np.testing.assert_array_equal(a.thickness.values, b.thickness.values)
    assert a.attrs.keys() == b.attrs.keys()
    for key in a.attrs:
        if key in ("seconds", "created"):
            continue
        np.testing.assert_array_equal(a.attrs[key], b.attrs[key], err_msg=key)


def _reused(record) -> dict:
    return {
        kind: int(n)
        for part in str(record[0].message).split("(")[1].rstrip(")").split(", ")
        for kind, n in [part.split()]
    }


@pytest.mark.parametrize("stop_fraction", [0.05, 0.3, 0.6, 0.95])
def test_a_probe_interrupted_in_serial_resumes_exactly_the_unfinished_units(
    tmp_path, monkeypatch, toy_reference, toy_factory, stop_fraction
):
    """Interrupted anywhere in the probe (the rigid rows, the columns' chains, the work of
    separation), the resumed scan recomputes exactly the force calls of the units that
    had not finished, and its ispes.nc is the uninterrupted scan's bit for bit."""
    calls = Calls(monkeypatch)

    def scan(out):
        return lambda: run_scan(
            toy_reference, toy_factory, GRID, out, SETTINGS, executor=SerialExecutor()
        )

    whole = calls.run(scan(tmp_path / "whole"))
    probe_calls = calls.at_put[-1]  # the last unit written ends the probe
    assert 0 < probe_calls < whole
    stop = max(2, int(stop_fraction * probe_calls))
    calls.run(scan(tmp_path / "cut"), stop=stop)
    written = len(calls.at_put)
    finished = calls.at_put[-1] if written else 0
    assert written >= 1  # the rows of single points come first: 3 calls each
    with pytest.warns(ProbeUnitsReused) as record:
        resumed = calls.run(scan(tmp_path / "cut"))
    # the units finished before the interruption cost nothing now; everything else is redone
    assert resumed == whole - finished
    assert sum(_reused(record).values()) == written
    _same_ispes(tmp_path / "whole" / "ispes.nc", tmp_path / "cut" / "ispes.nc")


@pytest.mark.parametrize("stop_fraction", [0.2, 0.7])
def test_a_probe_interrupted_with_many_workers_resumes_and_gives_the_same_grid(
    tmp_path, monkeypatch, toy_reference, toy_factory, stop_fraction
):
    """The many-worker probe (row blocks, compression segments, the work of separation
    beside the grid): a resumed probe submits only the units not in probe.json and gives the
    uninterrupted scan's ispes.nc (the join does not depend on which segments ran)."""
    calls = Calls(monkeypatch)

    def scan(out):
        return lambda: run_scan(
            toy_reference, toy_factory, GRID, out, SETTINGS, executor=ManySerial()
        )

    calls.run(scan(tmp_path / "whole"))
    probe_calls = calls.at_put[-2]  # the work of separation is collected after the grid
    stop = max(2, int(stop_fraction * probe_calls))
    calls.run(scan(tmp_path / "cut"), stop=stop)
    finished = set(calls.keys)
    assert finished
    with pytest.warns(ProbeUnitsReused) as record:
        calls.run(scan(tmp_path / "cut"))
    assert sum(_reused(record).values()) == len(finished)
    # no finished unit is computed again (which extra segments run depends on the order the
    # workers finish in, so the total of force calls is not a fixed number)
    assert not finished & set(calls.keys)
    _same_ispes(tmp_path / "whole" / "ispes.nc", tmp_path / "cut" / "ispes.nc", exact=False)


def test_a_unit_is_reused_only_under_its_own_inputs(
    tmp_path, monkeypatch, toy_reference, toy_factory
):
    """After a finished scan, a rerun with another HI (the store removed: its grid differs)
    reuses the rows of single points, the stretchings (which do not depend on HI) and the
    work of separation, recomputes the compressions, and equals a scan from scratch; other
    relaxation settings reuse nothing."""
    calls = Calls(monkeypatch)
    out = tmp_path / "scan"
    run_scan(toy_reference, toy_factory, GRID, out, SETTINGS, executor=SerialExecutor())
    discard_store(out / "points.db")
    other = GridSpec(3, 3, p_range_gpa=(-0.05, 0.8, 4))
    fresh = calls.run(
        lambda: run_scan(
            toy_reference,
            toy_factory,
            other,
            tmp_path / "fresh",
            SETTINGS,
            executor=SerialExecutor(),
        )
    )
    with pytest.warns(ProbeUnitsReused) as record:
        rerun = calls.run(
            lambda: run_scan(
                toy_reference, toy_factory, other, out, SETTINGS, executor=SerialExecutor()
            )
        )
    assert _reused(record) == {"rigid": 3, "stretch": 2, "work": 1}
    assert rerun < fresh
    _same_ispes(tmp_path / "fresh" / "ispes.nc", out / "ispes.nc")

    discard_store(out / "points.db")
    looser = RelaxSettings(fmax_ev_per_angstrom=2e-4, optimizer="FIRE")
    with warnings.catch_warnings():
        warnings.simplefilter("error", ProbeUnitsReused)
        run_scan(toy_reference, toy_factory, other, out, looser, executor=SerialExecutor())
    kept = json.loads((out / PROBE_JSON).read_text())
    assert kept["settings"]["relax"]["fmax_ev_per_a"] == 2e-4


def test_a_probe_record_that_is_not_one_is_refused_in_one_line(
    tmp_path, toy_reference, toy_factory
):
    out = tmp_path / "scan"
    out.mkdir()
    (out / PROBE_JSON).write_text('{"format": "something else"}')
    with pytest.raises(InputError, match=r"probe\.json: expected a probe record"):
        run_scan(toy_reference, toy_factory, GRID, out, SETTINGS, executor=SerialExecutor())
    (out / PROBE_JSON).write_text("{not json")
    with pytest.raises(InputError, match=r"probe\.json: not a readable probe record"):
        run_scan(toy_reference, toy_factory, GRID, out, SETTINGS, executor=SerialExecutor())


def test_a_unit_that_fails_validation_is_recomputed_with_one_warning(
    tmp_path, toy_reference, toy_factory
):
    """A chain whose energies were damaged (NaN) and a row cut short are dropped and
    recomputed (one warning each); the scan equals the undamaged one."""
    out = tmp_path / "scan"
    run_scan(toy_reference, toy_factory, GRID, out, SETTINGS, executor=SerialExecutor())
    record = json.loads((out / PROBE_JSON).read_text())
    keys = list(record["units"])
    chain = next(k for k in keys if k.startswith('["compress"'))
    record["units"][chain]["energy_ev"][0] = None
    record["units"][keys[0]]["normal_stress_gpa"] = record["units"][keys[0]]["normal_stress_gpa"][
        :1
    ]
    (out / PROBE_JSON).write_text(json.dumps(record))
    discard_store(out / "points.db")
    with pytest.warns(ProbeUnitsRepaired) as record:
        run_scan(toy_reference, toy_factory, GRID, out, SETTINGS, executor=SerialExecutor())
    repaired = [str(w.message) for w in record if w.category is ProbeUnitsRepaired]
    assert len(repaired) == 2
    assert "unreadable" in repaired[0]  # a row of 1 value for 3 shifts
    assert "a chain holds a value that is not finite" in repaired[1]
    reused = [w for w in record if w.category is ProbeUnitsReused]
    assert _reused(reused) == {"rigid": 2, "compress": 1, "stretch": 2, "work": 1}
    run_scan(
        toy_reference, toy_factory, GRID, tmp_path / "ref", SETTINGS, executor=SerialExecutor()
    )
    _same_ispes(tmp_path / "ref" / "ispes.nc", out / "ispes.nc")
