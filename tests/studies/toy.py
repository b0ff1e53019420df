"""The toy Lennard-Jones interface the studies' tests share (seconds per variant).

Three-layer slabs of the toy LJ crystal (:mod:`flatcontact.ispes.toy`) on a 3×3 grid, four
thicknesses from −0.2 to 1.5 GPa, serial scan: cheap enough to run a study of several
variants in a test. Import by full name (tests/README.md): ``from tests.studies.toy import``.
"""

from __future__ import annotations

import copy
from pathlib import Path

import yaml

from flatcontact.config.load import build_config
from flatcontact.config.run import RunConfig

TOY = {
    "structure": {"kind": "toy-lj", "layers": 3},
    "potential": {"calculator": {"target": "flatcontact.ispes.toy:toy_calculator"}},
    "scan": {
        "grid": [3, 3],
        "p_range_gpa": {"lo_gpa": -0.2, "hi_gpa": 1.5, "n": 4},
        "executor": "serial",
    },
    "analysis": {"p_gpa": [0.0, 0.5, 1.0]},
    "contact": {"p0_gpa": [0.5, 1.0]},
    "report": {"svg": False},
}
#: the toy's cross-interface LJ depth (eV, ``eps_cross_ev`` of flatcontact.ispes.toy): two
#: models of the same interface, the second doubles it
EPS_CROSS = {"a": 0.01, "b": 0.02}


def toy_data(**sections) -> dict:
    """A fresh copy of :data:`TOY` with whole ``sections`` laid over it (``refine={...}``)."""
    return {**copy.deepcopy(TOY), **copy.deepcopy(sections)}


def toy_config(**refine) -> RunConfig:
    """The toy's validated configuration with the ``refine`` section ``refine``."""
    return build_config(toy_data(refine=refine), None, "toy")


def toy_model(eps_cross_ev: float) -> dict:
    """The toy's ``potential`` section with cross-interface LJ depth ``eps_cross_ev``."""
    pot = copy.deepcopy(TOY["potential"])
    pot["calculator"]["kwargs"] = {"eps_cross_ev": eps_cross_ev}
    return pot


def write_yaml(path: Path, data: dict) -> Path:
    """Write ``data`` as YAML to ``path``; returns ``path``."""
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def toy_scan(out: Path, grid: int, n_thicknesses: int, fmax_ev_per_angstrom: float):
    """A serial scan of the 3-layer toy LJ interface on a ``grid`` × ``grid`` lateral grid and
    ``n_thicknesses`` thicknesses from 0.3 Å below to 1.5 Å above its reference, into ``out``
    (the :func:`flatcontact.ispes.scan.run_scan` result)."""
    import numpy as np

    from flatcontact.ispes.grid import GridSpec
    from flatcontact.ispes.relax import RelaxSettings
    from flatcontact.ispes.scan import run_scan
    from flatcontact.potentials.engines import calculator_factory
    from flatcontact.potentials.model import InteractionModel
    from flatcontact.structures.interface_contract import thickness
    from flatcontact.structures.toy import toy_interface

    ref = toy_interface(layers=3)
    z = thickness(ref) + np.linspace(-0.3, 1.5, n_thicknesses)
    factory = calculator_factory(InteractionModel(calculator=TOY["potential"]["calculator"]))
    return run_scan(
        ref,
        factory,
        GridSpec(grid, grid, thickness_angstrom=tuple(z)),
        out,
        RelaxSettings(fmax_ev_per_angstrom),
        executor_options={"kind": "serial"},
    )
