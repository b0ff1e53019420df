"""From an interaction model (or a potential's name) to the ASE calculators that evaluate it.

- :func:`make_calculator`: the calculator of an :class:`~flatcontact.potentials.model.InteractionModel`
  for an interface, a slab or a bulk crystal (LAMMPS, ASE per slab + LJ, or the user's ASE
  calculator for the whole interface);
- :func:`check_setup`: the model set up for a structure without computing anything, so a
  setup its engine refuses (LAMMPS pair commands) is one line before any work;
- :func:`check_evaluation`: the same and one energy and forces of the structure, so a
  calculator that cannot evaluate its elements (it raises, or returns NaN) is one line
  before any work;
- :func:`calculator_factory`: the same as a picklable factory (:class:`ModelFactory`) for scan
  workers and Dask;
- :func:`bulk_calculator`: energy, forces and stress of a single crystal, from a model or from a
  potential's name (a bundled SNAP, a ``.snapcoeff`` path, ``vashishta``, ``tersoff``, a preset,
  or an offline teacher of :mod:`flatcontact.potentials.teachers`), so training, validation
  and the elastic stage use the same model as the scan.
"""

from __future__ import annotations

import dataclasses
import json
from functools import cached_property

from ase import Atoms

from flatcontact.foundation.errors import InputError
from flatcontact.potentials.calculator import (
    AseInterfaceCalculator,
    LammpsInterfaceCalculator,
    calculator_name,
)
from flatcontact.potentials.guarded import evaluate_once, guard_calculator
from flatcontact.potentials.loader import call_factory
from flatcontact.potentials.model import InteractionModel
from flatcontact.potentials.names import CLASSICAL, snapcoeff_path
from flatcontact.potentials.presets import PRESETS
from flatcontact.potentials.teachers import is_teacher, teacher_calculator


def make_calculator(model: InteractionModel, atoms: Atoms):
    """The calculator of ``model`` for ``atoms`` (an interface, a slab or a bulk crystal).

    Raises :class:`InputError` on an element mismatch before any LAMMPS instance is created.
    A user's ASE calculator is guarded (:func:`~flatcontact.potentials.guarded.guard_calculator`:
    an exception it raises or a NaN it returns is a one-line
    :class:`~flatcontact.potentials.guarded.CalculatorFailure` naming it).
    """
    if model.engine == "ase-interface":
        model.check_atoms(atoms)
        c = model.calculator
        return guard_calculator(call_factory(c.target, atoms, c.kwargs), calculator_name(model))
    if model.engine == "ase-slab":
        return AseInterfaceCalculator(model, atoms)
    return LammpsInterfaceCalculator(model, atoms)


def check_setup(model: InteractionModel, atoms: Atoms) -> None:
    """Refuse, in one line, a structure ``model`` cannot compute or whose setup fails.

    The element and LJ checks of :meth:`InteractionModel.check_atoms`; for the LAMMPS engine
    also its setup for ``atoms`` (box, types, ``pair_style``/``pair_coeff``: LAMMPS reads the
    potential files and checks the element map), then closed without computing. ASE
    calculators are not instantiated (some load models for seconds).
    """
    model.check_atoms(atoms)
    if model.engine == "lammps":
        _lammps_setup(model, atoms).close()


def _lammps_setup(model: InteractionModel, atoms: Atoms) -> LammpsInterfaceCalculator:
    """The LAMMPS calculator of ``model`` set up for ``atoms``; LAMMPS's refusal in one line."""
    try:
        return LammpsInterfaceCalculator(model, atoms)
    except InputError as exc:
        lines = [ln.strip() for ln in str(exc).splitlines() if ln.strip()]
        kept = [ln for ln in lines if not ln.startswith("For more information")]
        raise InputError("; ".join(kept)) from None


def check_evaluation(model: InteractionModel, atoms: Atoms) -> None:
    """:func:`check_setup`, then one energy and forces of ``atoms`` with the model's calculator.

    The user's ASE calculator is instantiated (a machine-learned model loads its weights:
    seconds) and evaluated once; LAMMPS computes once on the setup :func:`check_setup` makes
    (milliseconds for a reference interface).

    Raises
    ------
    InputError
        :func:`check_setup`'s refusals, and a
        :class:`~flatcontact.potentials.guarded.CalculatorFailure` when the calculator raises
        (``NotImplementedError: No EMT-potential for Si``) or returns a non-finite energy or
        forces.
    """
    model.check_atoms(atoms)
    calc = (
        _lammps_setup(model, atoms) if model.engine == "lammps" else make_calculator(model, atoms)
    )
    try:
        evaluate_once(calc, atoms, calculator_name(model))
    finally:
        close = getattr(calc, "close", None)
        if model.engine != "ase-interface" and close is not None:
            close()


@dataclasses.dataclass(frozen=True)
class ModelFactory:
    """``factory(atoms)`` -> the model's ASE calculator; built from the model's JSON form.

    Attributes
    ----------
    model_json
        ``InteractionModel.model_dump_json()``; pickles as a string to any worker.
    """

    model_json: str

    @cached_property
    def model(self) -> InteractionModel:
        return InteractionModel.model_validate_json(self.model_json)

    def __call__(self, atoms):
        return make_calculator(self.model, atoms)

    @cached_property
    def fingerprint(self) -> str:
        """JSON of :meth:`InteractionModel.fingerprint` (content-based, no absolute paths).

        Computed once per factory (it reads and hashes the model's files) and pickled with
        it, so a scan worker, which gets a fresh copy with every task, keys its calculator
        cache by the driver's fingerprint without validating the model again (that cost
        about 1 ms per grid point).
        """
        return json.dumps({"potential": self.model.fingerprint()}, sort_keys=True)

    @property
    def label(self) -> str:
        return self.model.label

    def __getstate__(self):
        return {"model_json": self.model_json, "fingerprint": self.fingerprint}

    def __setstate__(self, state):
        object.__setattr__(self, "model_json", state["model_json"])
        if "fingerprint" in state:
            self.__dict__["fingerprint"] = state["fingerprint"]


def calculator_factory(model: InteractionModel) -> ModelFactory:
    """A picklable factory: ``factory(atoms)`` -> ASE calculator; ``.label``, ``.fingerprint``."""
    return ModelFactory(model.model_dump_json())


def _named_model(name_or_path: str) -> InteractionModel:
    """The model of a potential's name or ``.snapcoeff`` path (its intra model alone)."""
    if name_or_path not in CLASSICAL:
        coeff = None
        try:
            coeff = snapcoeff_path(name_or_path)
        except InputError:
            if name_or_path not in PRESETS:
                raise
        if coeff is not None:
            param = coeff.with_suffix(".snapparam")
            if not param.is_file():
                raise InputError(f"{param}: the .snapparam beside {coeff.name} is missing")
            name_or_path = f"snap:{coeff}"
    return InteractionModel(intra=name_or_path)


def bulk_calculator(model: InteractionModel | str, atoms: Atoms | None = None):
    """An ASE calculator (energy, forces, stress) for a single crystal ``atoms``.

    ``model`` is an :class:`~flatcontact.potentials.model.InteractionModel` or a potential's
    name (module docstring). The intra model alone (no slab split, no coupling); for an
    interlayer model the layers (``atoms.arrays["layer"]``, or atomic planes found along z)
    get the interlayer potential between them. An ASE calculator model gives its calculator,
    a teacher's name a fresh CPU calculator of that teacher.
    """
    if isinstance(model, str):
        if is_teacher(model):
            return teacher_calculator(model)
        model = _named_model(model)
    if model.calculator is not None:
        c = model.calculator
        return guard_calculator(call_factory(c.target, atoms, c.kwargs), calculator_name(model))
    if model.engine == "ase-slab":
        target = model.intra.removeprefix("ase:")
        return guard_calculator(call_factory(target, None, {}), calculator_name(model))
    if not model.intra_styles:
        raise InputError(f"potential {model.label}: no intra model to compute a bulk crystal with")
    return LammpsInterfaceCalculator(model, atoms, bulk=True)
