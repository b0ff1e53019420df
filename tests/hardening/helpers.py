"""Shared by the hardening corpus: run the CLI in-process, check the one-line refusal and
that a refused command wrote nothing (no stage started, nothing outside --out)."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from flatcontact.cli import main

#: A tiny study on the toy Lennard-Jones interface: the whole run takes seconds. Its 3×3
#: grid trips the contact stage's trust gates (broken_symmetry: 36 % on 3×3 points;
#: negative_slope of σ_MSS; on 5×5, in_slab_slip and degenerate_minima), which these tests,
#: about files and faults, accept.
TOY_YAML = """\
structure: {kind: toy-lj, layers: 3}
potential: {calculator: {target: "flatcontact.ispes.toy:toy_calculator"}}
scan:
  grid: [3, 3]
  p_range_gpa: {lo_gpa: -0.2, hi_gpa: 1.5, n: 4}
  executor: serial
analysis: {p_gpa: [0.0, 0.5, 1.0]}
contact: {p0_gpa: [0.5, 1.0], accept_untrusted: [broken_symmetry, negative_slope, in_slab_slip, degenerate_minima]}
report: {svg: false}
"""


def run_cli(argv, capsys):
    """Run ``flatcontact argv`` in-process; (exit code, stdout, stderr)."""
    with pytest.raises(SystemExit) as info:
        main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return info.value.code, out, err


def tree(root: Path) -> dict[str, tuple[int, int]]:
    """Every file and directory below ``root`` with its size and mtime (ns)."""
    out = {}
    for dirpath, dirnames, filenames in os.walk(root):
        for name in dirnames + filenames:
            p = Path(dirpath) / name
            st = p.lstat()
            out[str(p.relative_to(root))] = (st.st_size if p.is_file() else 0, st.st_mtime_ns)
    return out


def refused(code, err, *names):
    """Assert exit 2 and one ``error:`` line naming every string of ``names``; return it."""
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), err
    assert "Traceback" not in err and "Warning" not in err
    for name in names:
        assert name in lines[0], (name, lines[0])
    return lines[0]


def assert_refused_cleanly(argv, capsys, where: Path, names, out: Path | None = None):
    """Run ``argv`` in ``where``: refused in one line naming ``names``; nothing written in
    ``where`` (so nothing outside --out) and no stage folder under ``out``."""
    before = tree(where)
    code, _, err = run_cli(argv, capsys)
    line = refused(code, err, *names)
    assert tree(where) == before, "a refused command wrote files"
    if out is not None:
        assert not any(out.glob("0*-*")), "a stage started"
    return line


def finished_toy_run(base: Path) -> tuple[Path, Path]:
    """(config folder, run directory) of one finished toy study (:data:`TOY_YAML`) in ``base``."""
    from flatcontact.cli import main

    conf = base / "conf"
    conf.mkdir()
    (conf / "run.yaml").write_text(TOY_YAML)
    with pytest.raises(SystemExit) as info:
        main(["run", str(conf / "run.yaml"), "--out", str(base / "run")])
    assert info.value.code == 0
    return conf, base / "run"
