"""The figures never touch pyplot's global state: importing and saving keep the user's backend."""

from __future__ import annotations

import subprocess
import sys

import numpy as np

from flatcontact.analysis.laws import fit_load_laws
from flatcontact.plots import save_figure
from flatcontact.plots.analysis import figure_laws

SCRIPT = """
import sys
import matplotlib
matplotlib.use("pdf")
import flatcontact.plots, flatcontact.plots.analysis, flatcontact.plots.scan
import flatcontact.plots.structures, flatcontact.plots.contact, flatcontact.plots.cycle
import flatcontact.report.assemble, flatcontact.training.train
assert matplotlib.get_backend() == "pdf", matplotlib.get_backend()
assert "matplotlib.pyplot" not in sys.modules, "a figure module imported pyplot"
print("ok")
"""


def test_importing_the_figure_modules_keeps_the_users_backend():
    out = subprocess.run(
        [sys.executable, "-c", SCRIPT],
        capture_output=True,
        text=True,
        check=False,
        env={"PYTHONPATH": ":".join(sys.path)},
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "ok"


def test_a_saved_figure_is_a_real_png_and_svg(tmp_path):
    p = np.array([0.5, 1.0, 2.0, 3.0])
    tau = 4.0 * p + 20.0
    sigma = 0.3 * p + 10.0
    laws = fit_load_laws(p, tau, sigma)
    written = save_figure(figure_laws(p, tau, sigma, laws), tmp_path / "fig3")
    assert [w.suffix for w in written] == [".png", ".svg"]
    assert written[0].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert b"<svg" in written[1].read_bytes()[:400]


def test_no_module_of_the_package_imports_pyplot():
    """pyplot is global state (a backend, a registry of open figures): the package never uses it."""
    import ast
    from pathlib import Path

    import flatcontact

    offenders = []
    for path in Path(flatcontact.__file__).parent.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            names = []
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.module:
                names = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
            if any(n == "matplotlib.pyplot" for n in names):
                offenders.append(f"{path.name}:{node.lineno}")
    assert not offenders, offenders
