"""``kill -9`` of a real `run` in the scan and in the contact stage: the rerun's results equal
an uninterrupted run's and no temporary file (``.*.part``, ``.*.tmp``) is left anywhere.

Slow (two toy studies and an interrupted one per case): in ``make test-all``. The fast
suite covers the same mechanism with the leftovers planted by hand
(``test_links_and_writes.py``).
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import pytest
from tests.hardening.helpers import TOY_YAML, run_cli, stored_rows
from tests.hardening.test_run_directory import _same_content

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux only"),
]

CONFIG = TOY_YAML.replace("grid: [3, 3]", "grid: [5, 5]")
OUTPUTS = ("02-scan/ispes.nc", "03-analyze/friction.nc", "04-laws/laws.json")
OUTPUTS += ("06-contact/summary.json", "06-contact/contact.nc")


@pytest.fixture(scope="module")
def uninterrupted(tmp_path_factory):
    from flatcontact.cli import main

    base = tmp_path_factory.mktemp("whole")
    (base / "run.yaml").write_text(CONFIG)
    with pytest.raises(SystemExit) as info:
        main(["run", str(base / "run.yaml"), "--out", str(base / "run")])
    assert info.value.code == 0
    return base / "run"


@pytest.mark.parametrize("stage", ["02-scan", "06-contact"])
def test_kill_9_then_rerun_equals_an_uninterrupted_run(uninterrupted, tmp_path, capsys, stage):
    config = tmp_path / "run.yaml"
    config.write_text(CONFIG)
    run = tmp_path / "run"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    argv = ["run", str(config), "--out", str(run)]
    driver = subprocess.Popen(
        [sys.executable, "-c", "from flatcontact.cli import main; main()", *argv],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        env=env,
        start_new_session=True,
    )
    try:
        end = time.monotonic() + 300
        while driver.poll() is None and time.monotonic() < end:
            if stage == "02-scan" and stored_rows(run / "02-scan" / "points.db") >= 5:
                break
            if stage == "06-contact" and (run / stage).is_dir():
                break
            time.sleep(0.05)
        os.killpg(driver.pid, signal.SIGKILL)
        driver.wait(timeout=30)
    finally:
        if driver.poll() is None:
            os.killpg(driver.pid, signal.SIGKILL)
    code, _, err = run_cli(["run", config, "--out", run], capsys)
    assert code == 0, err
    left = [p for p in run.rglob("*") if p.name.endswith((".part", ".tmp"))]
    assert left == [], left
    for name in OUTPUTS:
        _same_content(run / name, uninterrupted / name)
