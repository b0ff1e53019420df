"""A finished point is committed at once: ``kill -9`` of the driver right after a write
loses nothing that was written (the write-ahead log survives the process)."""

import signal
import subprocess
import sys
import textwrap

from flatcontact.ispes.store import PointStore
from flatcontact.structures.toy import toy_interface

WRITER = textwrap.dedent(
    """
    import sys, time
    import numpy as np
    from flatcontact.ispes.relax import PointResult
    from flatcontact.ispes.store import PointStore
    from flatcontact.structures.toy import toy_interface

    ref = toy_interface(layers=3)
    store = PointStore(sys.argv[1], {"test": "crash"}, ref)
    for k in range(25):
        store.write(PointResult(index=(k, 0, 0), shift_a=k / 25, shift_b=0.0, thickness=10.0,
                                energy_ev=-float(k), normal_stress_gpa=0.0,
                                reaction_stress_gpa=0.0, force_calls=1, steps=0,
                                converged=True, max_force_ev_per_a=0.0, seconds=0.0,
                                positions=ref.positions + 0.001 * k, start_index=None))
    print("written", flush=True)
    time.sleep(600)
    """
)


def write_and_kill(db) -> None:
    """:data:`WRITER` stores 25 points in ``db`` and is killed with SIGKILL right after."""
    proc = subprocess.Popen(
        [sys.executable, "-c", WRITER, str(db)], stdout=subprocess.PIPE, text=True
    )
    try:
        assert proc.stdout.readline().strip() == "written"
    finally:
        proc.send_signal(signal.SIGKILL)
        proc.wait()


def test_points_written_before_a_kill_9_are_all_kept(tmp_path):
    db = tmp_path / "points.db"
    write_and_kill(db)
    ref = toy_interface(layers=3)
    with PointStore(db, {"test": "crash"}, ref) as store:
        assert len(store) == 25
        for k in (0, 24):
            assert abs(store.positions((k, 0, 0)) - (ref.positions + 0.001 * k)).max() < 1e-12


def test_record_of_a_fresh_write_equals_the_record_read_back(tmp_path):
    """The driver keeps the record it wrote (no read-back); a resumed store reads it from the
    database: both must be the same, to the last bit, or a resumed scan would differ."""
    import math

    from flatcontact.ispes.relax import PointResult

    ref = toy_interface(layers=3)
    db = tmp_path / "points.db"
    values = dict(
        index=(2, 1, 0),
        shift_a=1 / 3,
        shift_b=math.pi / 7,
        thickness=10.123456789012345,
        energy_ev=-123.45678901234567,
        normal_stress_gpa=1.0 / 3.0,
        reaction_stress_gpa=0.1,
        force_calls=17,
        steps=16,
        converged=True,
        max_force_ev_per_a=0.004,
        seconds=0.5,
        positions=ref.positions,
        start_index=(2, 1, 1),
    )
    with PointStore(db, {"test": "record"}, ref) as store:
        store.write(PointResult(**values))
        fresh = store.record((2, 1, 0))
    with PointStore(db, {"test": "record"}, ref) as store:
        assert store.record((2, 1, 0)) == fresh
    assert fresh["energy_ev"] == values["energy_ev"] and fresh["start"] == (2, 1, 1)
