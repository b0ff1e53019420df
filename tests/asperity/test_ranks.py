"""The asperity over MPI ranks (flatcontact.asperity.ranks): the same states as one rank within
the minimiser's tolerance, kill -9 / resume bit-identical on 2 ranks with no rank left behind,
memory counted per rank, and every failure one line naming its cause."""

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from tests.asperity.test_asperity_run import MODEL, RECIPE, SPEC
from tests.cli.cli_helpers import one_error_line, run_cli

from flatcontact.asperity import builder, ranks
from flatcontact.asperity.driver import (
    Protocol,
    group_commands,
    load_state,
    run_load,
    step_path,
)
from flatcontact.asperity.experiment import plan, target_force_ev_per_angstrom
from flatcontact.foundation.errors import InputError
from flatcontact.potentials.model import InteractionModel
from flatcontact.structures.recipe import parse_recipe

STEPS = 3


# ---------------------------------------------------------------- fast: checks and one-liners


@pytest.mark.parametrize("bad", [0, -1, ranks.MAX_RANKS + 1, 2.0, True, "2"])
def test_a_rank_count_outside_its_bounds_is_refused_in_one_line(bad):
    with pytest.raises(InputError, match=r"asperity.mpi_ranks: expected .* 1\.\.256") as err:
        ranks.check_ranks(bad)
    assert "\n" not in str(err.value)


def test_the_setting_is_bounded_by_the_same_constant():
    from pydantic import ValidationError

    from flatcontact.config.asperity import MAX_MPI_RANKS, AsperityConfig

    assert AsperityConfig().mpi_ranks == 1
    assert AsperityConfig(mpi_ranks=MAX_MPI_RANKS).mpi_ranks == ranks.MAX_RANKS
    for bad in (0, MAX_MPI_RANKS + 1):
        with pytest.raises(ValidationError):
            AsperityConfig(mpi_ranks=bad)


def test_memory_counts_every_rank_and_the_refusal_names_them(monkeypatch):
    n = 100_000
    assert ranks.rank_memory_bytes(n, 1) == 0
    two, four = ranks.rank_memory_bytes(n, 2), ranks.rank_memory_bytes(n, 4)
    assert four == 2 * two == 4 * (ranks.RANK_BASE_BYTES + n * ranks.RANK_BYTES_PER_ATOM)
    one = builder.check_machine(n, 100)
    # a machine with room for one rank's run but not for four ranks' Pythons
    monkeypatch.setattr(builder, "available_memory_bytes", lambda: int(2.5 * one))
    assert builder.check_machine(n, 100) == one
    with pytest.raises(InputError, match=r"need ~.* GB over 4 MPI ranks, more than 50%") as err:
        builder.check_machine(n, 100, ranks=4)
    assert "\n" not in str(err.value)


def test_no_mpiexec_is_one_line(monkeypatch, tmp_path):
    monkeypatch.setattr(sys, "executable", str(tmp_path / "python"))
    monkeypatch.setenv("PATH", str(tmp_path))
    with pytest.raises(InputError, match=r"no mpiexec beside .* install the mpich wheel"):
        ranks.mpiexec()


def test_error_line_prefers_the_ranks_own_line():
    said = "noise\nerror: asperity over MPI ranks: ERROR: Lost atoms: original 8 current 6\n"
    assert (
        ranks.error_line(1, said, 2)
        == "asperity over MPI ranks: ERROR: Lost atoms: original 8 current 6"
    )
    assert ranks.error_line(7, "a\n  hydra: cannot   launch \n\n", 3) == (
        "asperity: mpiexec -n 3 failed (hydra: cannot launch)"
    )
    assert ranks.error_line(9, "", 2) == "asperity: mpiexec -n 2 failed (exit code 9)"
    # two ranks' lines run together by mpiexec's forwarding
    merged = "error: asperity over MPI ranks: KeyError: 'b'error: asperity over MPI ranks: X\n"
    assert ranks.error_line(1, merged, 2) == "asperity over MPI ranks: X"


def test_a_failing_rank_is_one_line_through_mpiexec(tmp_path):
    # real mpiexec, real ranks: the atoms lack the per-atom 'block' array the driver needs
    atoms, _, _ = _small()
    del atoms.arrays["block"]
    protocol = Protocol(1.0, 0.1, 1)
    with pytest.raises(InputError) as err:
        ranks.run_steps(_model(), atoms, protocol, tmp_path, 0, None, 2)
    assert str(err.value) == "asperity over MPI ranks: KeyError: 'block'"
    assert not (tmp_path / ranks.JOB_FILE).exists()  # the job file does not outlive the run
    assert not list(tmp_path.glob("step_*.npz"))


# ---------------------------------------------------------------- slow: the same physics


def _model():
    return InteractionModel.model_validate(MODEL)


def _small():
    atoms, sizes, _ = plan(SPEC, parse_recipe(RECIPE), 100)
    axis = float(np.linalg.norm(atoms.cell.array[0]))
    return atoms, sizes, target_force_ev_per_angstrom(SPEC, SPEC.p0_gpa[0], axis)


def _protocol(target):
    return Protocol(target, SPEC.step_angstrom, STEPS, SPEC.fmax_ev_per_angstrom)


@pytest.fixture(scope="module")
def one_and_two(tmp_path_factory):
    atoms, _, target = _small()
    out = {}
    for n in (1, 2):
        folder = tmp_path_factory.mktemp(f"ranks{n}")
        out[n] = (folder, run_load(_model(), atoms, _protocol(target), folder, ranks=n))
    return atoms, out


@pytest.mark.slow
def test_two_ranks_give_the_one_rank_states_within_the_minimiser_tolerance(one_and_two):
    _, out = one_and_two
    fmax = SPEC.fmax_ev_per_angstrom
    (_, one), (_, two) = out[1], out[2]
    assert [s.ranks for s in one] == [1] * (STEPS + 1)
    assert [s.ranks for s in two] == [2] * (STEPS + 1)
    for a, b in zip(one, two, strict=True):
        assert a.converged and b.converged
        assert a.displacement_angstrom == b.displacement_angstrom
        # the same minimum: positions, the block's force and the force the tip exerts on
        # every atom agree to well inside what the tolerance fmax leaves free
        assert np.max(np.abs(a.positions - b.positions)) < 1e-3
        assert np.max(np.abs(a.tip_force - b.tip_force)) < fmax
        assert np.max(np.abs(a.cross_force - b.cross_force)) < fmax
    # and the run moved: Q changed over the slide by far more than the tolerance
    assert abs(one[-1].tip_force[1] - one[0].tip_force[1]) > 10 * fmax


_CHILD = textwrap.dedent(
    """
    import sys
    from pathlib import Path
    sys.path[:0] = [{src!r}, {root!r}]
    from tests.asperity import test_ranks as t
    from flatcontact.asperity.driver import run_load
    atoms, _, target = t._small()
    run_load(t._model(), atoms, t._protocol(target), Path(sys.argv[1]), ranks=2)
    """
)


def _ranks_of(job: Path) -> list[int]:
    """Processes whose command line names ``job`` (the ranks of that run)."""
    pids = []
    for proc in Path("/proc").iterdir():
        try:
            if proc.name.isdigit() and str(job) in (proc / "cmdline").read_text():
                pids.append(int(proc.name))
        except OSError:
            continue
    return pids


@pytest.mark.slow
def test_kill_and_resume_on_two_ranks_is_bit_identical(one_and_two, tmp_path):
    _, out = one_and_two
    reference, _ = out[2]
    root = Path(__file__).parents[2]
    script = tmp_path / "child.py"
    script.write_text(_CHILD.format(src=str(root / "src"), root=str(root)))
    folder = tmp_path / "load"
    child = subprocess.Popen([sys.executable, str(script), str(folder)])
    deadline = time.monotonic() + 600
    while not step_path(folder, 1).exists() and child.poll() is None:
        assert time.monotonic() < deadline
        time.sleep(0.05)
    os.kill(child.pid, signal.SIGKILL)
    child.wait()
    # mpiexec dies with its parent, and its ranks with it: nothing writes behind our back
    job = folder / ranks.JOB_FILE
    deadline = time.monotonic() + 10
    while _ranks_of(job) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not _ranks_of(job)
    assert not step_path(folder, STEPS).exists()
    subprocess.run([sys.executable, str(script), str(folder)], check=True)
    for k in range(STEPS + 1):
        a, b = load_state(step_path(folder, k)), load_state(step_path(reference, k))
        assert np.array_equal(a.positions, b.positions)
        assert np.array_equal(a.tip_force, b.tip_force)
        assert np.array_equal(a.cross_force, b.cross_force)


@settings(max_examples=200, deadline=None)
@given(st.lists(st.integers(0, 2), min_size=1, max_size=60))
def test_block_groups_as_id_ranges_hold_exactly_the_block(block):
    block = np.array(block)
    for line, value in zip(group_commands(block), (1, 2), strict=True):
        words = line.split()
        assert words[:3] == ["group", ("flatblock", "tipblock")[value - 1], "id"]
        ids = set()
        for w in words[3:]:
            a, _, b = w.partition(":")
            ids.update(range(int(a), int(b or a) + 1))
        assert ids == set((np.flatnonzero(block == value) + 1).tolist())


# ---------------------------------------------------------------- the command and the stage


def _config(tmp_path, ranks_line: str) -> Path:
    from tests.asperity.test_asperity_cli import CU_LJ

    config = tmp_path / "c.yaml"
    config.write_text(CU_LJ.replace("steps: 1}", f"steps: 1, {ranks_line}}}"))
    return config


@pytest.mark.parametrize("value", ["0", "257", "two"])
def test_a_bad_rank_count_is_one_line_naming_the_setting(tmp_path, capsys, value):
    config = _config(tmp_path, f"mpi_ranks: {value}")
    code, _, err = run_cli(["asperity", str(config), "--out", str(tmp_path / "o")], capsys)
    assert "asperity.mpi_ranks" in one_error_line(code, err)
    assert not (tmp_path / "o").exists()


def test_ranks_without_mpiexec_are_refused_before_any_work(tmp_path, capsys, monkeypatch):
    from flatcontact.config import build_config
    from flatcontact.stages.preflight import check_asperity

    monkeypatch.setattr(sys, "executable", str(tmp_path / "python"))
    monkeypatch.setenv("PATH", str(tmp_path))
    config = _config(tmp_path, "mpi_ranks: 2")
    code, _, err = run_cli(["asperity", str(config), "--out", str(tmp_path / "o")], capsys)
    assert "asperity.mpi_ranks: no mpiexec" in one_error_line(code, err)
    assert not (tmp_path / "o").exists()
    cfg = build_config({"asperity": {"enabled": True, "mpi_ranks": 2}})
    with pytest.raises(InputError, match=r"^config: asperity.mpi_ranks: no mpiexec"):
        check_asperity(cfg)


@pytest.mark.slow
def test_the_command_runs_over_two_ranks_and_says_so(tmp_path, capsys):
    import json

    config = _config(tmp_path, "mpi_ranks: 2")
    code, out, err = run_cli(["asperity", str(config), "--out", str(tmp_path / "o")], capsys)
    assert code in (0, None), err
    # rank 0's progress reaches the console, step by step
    assert "step 1/2" in out and "step 2/2" in out
    doc = json.loads((tmp_path / "o" / "asperity.json").read_text())
    assert doc["mpi_ranks"] == 2
    folder = tmp_path / "o" / "state" / "load_0"
    assert [load_state(step_path(folder, k)).ranks for k in (0, 1)] == [2, 2]
    assert not (folder / ranks.JOB_FILE).exists()
