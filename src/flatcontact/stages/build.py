"""Stage 1, build: the relaxed reference interface.

Files: ``interface.extxyz`` (the interface contract), ``build.json`` (:meth:`BuildResult.to_json`:
the builder's report) and ``fig1_interface.png`` (+ ``.svg`` with ``report.svg``).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from flatcontact.foundation.fileio import write_json_atomic
from flatcontact.foundation.layout import BUILD_FIGURE, BUILD_JSON, INTERFACE
from flatcontact.stages import _calculator
from flatcontact.stages._common import save

#: Recipes whose interface is relaxed once with the run's model (cut surfaces reconstruct).
RELAXED_KINDS = ("slab", "crystal")
#: Recipes kept at their ideal geometry: a relaxation at the reference stacking would imprint
#: that stacking on the held (rigid) layers, e.g. the 0.0025 Å buckling of AB graphene, and
#: AB and BA would stop being equivalent (measured: 0.08 meV/Å² apart with REBO + KC).
IDEAL_KINDS = ("sheets", "fcc111")
IDEAL_GEOMETRY = (
    "ideal: sheets at their built-in (or file) geometry, fcc planes of the perfect crystal; "
    "not relaxed at the reference stacking, so symmetry-equivalent stackings stay equivalent"
)


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


def _relax_calculator(settings):
    """A callable(atoms) -> the model's calculator that first checks the model knows ``atoms``
    (one line naming element and model), so a bad pair fails before the relaxation."""
    factory = _calculator.factory(settings)

    def calculator(atoms):
        _calculator.check_atoms(settings, atoms)
        return factory(atoms)

    return calculator


def build_stage(settings, inputs: BuildInputs, folder: Path | None, progress=None) -> BuildResult:
    """Build the interface of the recipe ``settings.structure`` with the run's interaction model.

    Every kind goes through :func:`flatcontact.structures.construct.build_interface`:
    ``quartz-dense`` (the paper's α-quartz (0001) dense interface, relaxed by its builder),
    ``file`` (a finished interface), ``toy-lj``, and ``slab``, ``sheets``, ``crystal``,
    ``fcc111`` (relaxed once with the run's model, no atom held, after the model's element
    check). ``sheets``, ``crystal``, ``fcc111`` and ``quartz-dense`` are cut at the model's
    own lattice (``structure.lattice: potential``) or the file's (``file``: mismatch and
    lateral stress in ``build.json["lattice"]``, refused above
    :data:`flatcontact.structures.lattice.MAX_FILE_MISMATCH_PERCENT`). Errors name the
    settings path (``structure.bulk``, ``structure.miller``, ``structure.lattice``, ...).
    """
    from flatcontact.structures.construct import build_interface
    from flatcontact.structures.interface_io import write_interface
    from flatcontact.structures.recipe import QuartzDenseRecipe, ToyRecipe

    s = settings.structure
    if isinstance(s, ToyRecipe) and not s.params:
        # the toy's geometry follows its calculator's LJ (calculator.kwargs), as before recipes
        s = s.model_copy(update={"params": _calculator.toy_kwargs(settings)})
    lattice = {"lattice_calculator": _calculator.bulk_factory(settings)}
    # a user's calculator that fails in a relaxation: one line naming the stage
    with _calculator.failing_at("build"):
        if isinstance(s, QuartzDenseRecipe):
            atoms, report = build_interface(s, potential=_calculator.model(settings))
        elif s.kind in RELAXED_KINDS:
            atoms, report = build_interface(
                s, relax_calculator=_relax_calculator(settings), **lattice
            )
        elif s.kind in IDEAL_KINDS:
            atoms, report = build_interface(s, **lattice)
        else:
            atoms, report = build_interface(s)
            if s.kind in IDEAL_KINDS:
                report["interface_relaxation"] = None
                report["reference_geometry"] = IDEAL_GEOMETRY
    _calculator.check_atoms(settings, atoms)
    fmax = getattr(s, "fmax_ev_per_angstrom", 0.0)
    warnings = unconverged_warnings(report, fmax) + list(
        (report.get("lattice") or {}).get("warnings", [])
    )
    result = BuildResult(atoms, report, warnings)
    if folder is not None:
        from flatcontact.plots.structures import figure_interface

        folder.mkdir(parents=True, exist_ok=True)
        result.files.append(write_interface(atoms, folder / INTERFACE))
        result.files.append(write_json_atomic(folder / BUILD_JSON, result.to_json()))
        result.files += save(figure_interface(atoms), folder, BUILD_FIGURE, settings.report.svg)
    return result


def structure_elements(recipe) -> set[str] | None:
    """The elements of a recipe read from its files (``file``, ``slab``, ``crystal``), cheaply
    and before any work; ``None`` when only the build knows them."""
    from flatcontact.structures.structure_file import read_structure

    path = {"file": "file", "slab": "file", "crystal": "bulk"}.get(recipe.kind)
    if path is None:
        return None
    elements = set(
        read_structure(getattr(recipe, path), f"structure.{path}").get_chemical_symbols()
    )
    if recipe.kind == "crystal":
        elements |= _crystal_extra_elements(recipe)
    return elements


def _crystal_extra_elements(recipe) -> set[str]:
    """Elements a crystal recipe adds to its bulk file: slab 2's material and the passivating
    H (an OH adds O only where the crystal has O)."""
    from ase.formula import Formula

    from flatcontact.structures.sheet_catalog import BUILTIN_SHEETS
    from flatcontact.structures.structure_file import read_structure

    out: set[str] = set()
    slab2 = recipe.slab2
    if recipe.passivate != "none" or getattr(slab2, "passivate", "none") != "none":
        out.add("H")
    if slab2 is None:
        return out
    if hasattr(slab2, "bulk"):
        atoms = read_structure(slab2.bulk, "structure.slab2.bulk")
        return out | set(atoms.get_chemical_symbols())
    if slab2.sheet in BUILTIN_SHEETS:
        return out | set(Formula(BUILTIN_SHEETS[slab2.sheet].formula).count())
    return out | set(read_structure(slab2.sheet, "structure.slab2.sheet").get_chemical_symbols())
