"""Stage 1, build: the relaxed reference interface.

Files: ``interface.extxyz`` (the interface contract), ``build.json`` (:meth:`BuildResult.to_json`:
the builder's report) and ``fig1_interface.png`` (+ ``.svg`` with ``report.svg``).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from flatcontact.errors import InputError
from flatcontact.fileio import write_json_atomic
from flatcontact.stages import _calculator
from flatcontact.stages._common import save

INTERFACE = "interface.extxyz"
BUILD_JSON = "build.json"
FIGURE_STEM = "fig1_interface"
#: Depth of each tagged face of a ``structure.kind: slab`` interface (Å) when not given.
SLAB_FACE_DEPTH_ANGSTROM = 2.0


@dataclass(frozen=True)
class BuildInputs:
    """The build reads no upstream stage; a ``structure.file`` is named in the settings."""


@dataclass
class BuildResult:
    """The interface and the builder's report (``build.json``)."""

    atoms: Any
    report: dict
    warnings: list[str] = field(default_factory=list)
    files: list[Path] = field(default_factory=list)

    def to_json(self) -> dict:
        """``build.json``: the builder's report (source, relaxations, thickness, ...)."""
        return json.loads(json.dumps(self.report, default=float))


def unconverged_warnings(report: dict, fmax_ev_per_angstrom: float) -> list[str]:
    """One line per relaxation of ``report`` that stopped before reaching its tolerance."""
    out = []
    for key in ("slab_relaxation", "interface_relaxation"):
        outcome = report.get(key)
        if isinstance(outcome, dict) and not outcome.get("converged", True):
            fmax = outcome.get("max_force_ev_per_angstrom")
            got = f" (max force {fmax:.3g} eV/Å)" if isinstance(fmax, float) else ""
            out.append(
                f"the {key.replace('_', ' ')} did not converge to {fmax_ev_per_angstrom:g} eV/Å "
                f"in {outcome.get('steps', '?')} steps{got}; the interface is written but is "
                "not a relaxed reference"
            )
    return out


def _read_slab(path: str):
    from ase.io import read

    if not Path(path).is_file():
        raise InputError(f"structure.file {path}: file not found")
    try:
        return read(path)
    except Exception as exc:
        raise InputError(f"structure.file {path}: cannot read it ({type(exc).__name__})") from None


def run_build(settings, inputs: BuildInputs, folder: Path | None, progress=None) -> BuildResult:
    """Build the interface of ``settings.structure`` with the run's interaction model.

    ``structure.kind``: ``quartz-dense`` (the paper's α-quartz (0001) dense interface),
    ``slab`` (any slab file, its faces tagged by depth), ``file`` (a finished interface) or
    ``toy-lj``. Errors name the settings path (``structure.file``).
    """
    from flatcontact.structures.interface import read_interface, thickness, write_interface

    s = settings.structure
    if s.kind == "quartz-dense":
        from flatcontact.structures.build import build_quartz_interface

        atoms, report = build_quartz_interface(
            _calculator.model(settings),
            s.layers,
            source=s.source,
            gap_angstrom=s.gap_angstrom,
            fmax_ev_per_angstrom=s.fmax_ev_per_angstrom,
        )
    elif s.kind == "slab":
        from flatcontact.structures.build import interface_from_slab

        atoms, report = interface_from_slab(
            _read_slab(s.file),
            _calculator.model(settings),
            normal_axis=2 if s.normal_axis is None else s.normal_axis,
            face_depth_angstrom=(
                SLAB_FACE_DEPTH_ANGSTROM if s.face_depth_angstrom is None else s.face_depth_angstrom
            ),
            gap_angstrom=s.gap_angstrom,
            fmax_ev_per_angstrom=s.fmax_ev_per_angstrom,
            source=str(s.file),
        )
    elif s.kind == "toy-lj":
        from flatcontact.ispes.toy import toy_interface

        atoms = toy_interface(s.layers, **_calculator.toy_kwargs(settings))
        report = {
            "source": "flatcontact.ispes.toy",
            "n_atoms": len(atoms),
            "thickness_angstrom": thickness(atoms),
        }
    else:
        atoms = read_interface(s.file)
        report = {"source": s.file, "n_atoms": len(atoms), "thickness_angstrom": thickness(atoms)}
    result = BuildResult(atoms, report, unconverged_warnings(report, s.fmax_ev_per_angstrom))
    if folder is not None:
        from flatcontact.plots.structures import figure_interface

        folder.mkdir(parents=True, exist_ok=True)
        result.files.append(write_interface(atoms, folder / INTERFACE))
        result.files.append(write_json_atomic(folder / BUILD_JSON, result.to_json()))
        result.files += save(figure_interface(atoms), folder, FIGURE_STEM, settings.report.svg)
    return result
