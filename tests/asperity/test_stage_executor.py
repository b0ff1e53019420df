"""The asperity stage runs several loads as jobs on the scan's executor settings, one load in
process (the executors' equality with a sequential run: test_asperity_jobs.py, slow)."""

import pytest
import yaml

from flatcontact.config import load_config
from flatcontact.foundation.errors import InputError
from flatcontact.stages.asperity import _executor


def _settings(tmp_path, p0, **scan):
    doc = {"asperity": {"enabled": True, "p0_gpa": p0, "contact_modulus_gpa": 70.0}}
    if scan:
        doc["scan"] = scan
    path = tmp_path / "run.yaml"
    path.write_text(yaml.safe_dump(doc))
    return load_config(path)


@pytest.mark.parametrize(
    ("p0", "scan", "expected"),
    [
        ([1.0], {}, None),  # one load: in process, per-step progress
        ([0.5, 1.0], {"executor": "serial"}, None),  # inline: the in-process loop
        ([0.5, 1.0], {"executor": "processes", "workers": 1}, None),
        ([0.5, 1.0], {"executor": "processes", "workers": 2}, ("processes", 2)),
        ([0.5, 1.0, 1.5], {"executor": "processes"}, ("processes", None)),
    ],
)
def test_the_loads_go_to_the_scans_executor(tmp_path, p0, scan, expected):
    settings = _settings(tmp_path, p0, **scan)
    with _executor(settings, len(settings.asperity.p0_gpa)) as ex:
        if expected is None:
            assert ex is None
        else:
            assert ex.name == expected[0]
            # default: one worker per load, at most one per core
            assert ex.workers == (expected[1] or min(len(p0), ex.workers))
            assert 1 <= ex.workers <= len(p0)


def test_an_unreachable_dask_scheduler_is_one_line_naming_the_setting(tmp_path):
    settings = _settings(tmp_path, [0.5, 1.0], dask_address="tcp://127.0.0.1:9")
    with pytest.raises(InputError) as info:
        with _executor(settings, len(settings.asperity.p0_gpa)):
            pass
    assert str(info.value).startswith("scan.dask_address tcp://127.0.0.1:9: no Dask scheduler")
    assert "\n" not in str(info.value)
