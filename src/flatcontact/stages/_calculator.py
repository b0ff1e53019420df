"""The run's interaction model as the stages see it: the one place they touch
:class:`flatcontact.potentials.InteractionModel` (``settings.potential``).

Everything goes through the model's API (``label``, ``fingerprint()``, ``check_atoms``) and
its engines (:mod:`flatcontact.potentials.engines`); nothing here branches on the kind of model.
"""

from __future__ import annotations

import logging
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

from flatcontact.foundation.errors import InputError

log = logging.getLogger("flatcontact.run")

#: The elements the elastic stage's crystal (α-quartz) needs.
QUARTZ_ELEMENTS = frozenset({"Si", "O"})


def model(settings) -> Any:
    """The run's :class:`~flatcontact.potentials.InteractionModel`."""
    return settings.potential


def label(settings) -> str:
    """Human-readable name of the run's interaction model."""
    return settings.potential.label


def fingerprint(settings) -> dict:
    """The model's part of a stage fingerprint: content-based (files by name and SHA-256)."""
    return settings.potential.fingerprint()


def factory(settings) -> Any:
    """The picklable calculator factory of the scan workers (``factory(atoms)``)."""
    # imported here: `flatcontact --help` imports this module (cli/build.py -> stages/build.py)
    # and must not load numpy, ASE and pydantic before the CLI has set its thread settings
    from flatcontact.potentials.engines import calculator_factory

    return calculator_factory(settings.potential)


def bulk_factory(settings) -> Any:
    """``callable(atoms)`` -> the model as a single-crystal calculator (energy, forces,
    stress: :func:`flatcontact.potentials.engines.bulk_calculator`), as the elastic stage
    uses it; the build relaxes each slab material's lattice with it."""

    def bulk(atoms):
        from flatcontact.potentials.engines import bulk_calculator

        return bulk_calculator(settings.potential, atoms)

    return bulk


def check_atoms(settings, atoms) -> None:
    """One-line InputError when the model cannot compute ``atoms`` (element, LJ table)."""
    settings.potential.check_atoms(atoms)


def check_setup(settings, atoms) -> None:
    """:func:`check_atoms` and the engine's setup for ``atoms``, nothing computed (one line)."""
    # imported here for the same reason as in :func:`factory`
    from flatcontact.potentials.engines import check_setup as check_model_setup

    check_model_setup(settings.potential, atoms)


def check_evaluation(settings, atoms) -> None:
    """:func:`check_setup` and one energy and forces of ``atoms`` with the model's calculator
    (:func:`flatcontact.potentials.engines.check_evaluation`; a calculator that raises or
    returns NaN is a :class:`~flatcontact.potentials.guarded.CalculatorFailure`)."""
    from flatcontact.potentials.engines import check_evaluation as check_model_evaluation

    check_model_evaluation(settings.potential, atoms)


def _field(settings) -> tuple[str, str]:
    """The settings path naming the model's calculator and how it is written there:
    ``potential.calculator.target``, ``potential.intra`` (``ase:...``) or ``potential``."""
    m = settings.potential
    if m.calculator is not None:
        return "potential.calculator.target", m.calculator.target
    if m.engine == "ase-slab":
        return "potential.intra", m.intra
    return "potential", m.label


def evaluation_refusal(settings, failure, source: str, what: str) -> InputError:
    """The one line of a pre-run evaluation that failed as an InputError.

    ``failure`` a :class:`~flatcontact.potentials.guarded.CalculatorFailure`: ``<source>:
    <settings path>: <calculator> cannot evaluate the elements Si, O of <what> (<reason>)``;
    any other InputError of the model's setup keeps its text after ``<source>:`` and the
    settings path it concerns (``potential.calculator.target`` for a calculator factory that
    failed, ``potential`` for the rest, unless it names one itself)."""
    # imported here for the same reason as in :func:`factory`
    from flatcontact.potentials.guarded import CalculatorFailure, the_elements

    field, name = _field(settings)
    if isinstance(failure, CalculatorFailure):
        return InputError(
            f"{source}: {field}: {name} cannot evaluate {the_elements(failure.elements)} of "
            f"{what} ({failure.reason})"
        )
    text = str(failure)
    if text.startswith("potential"):
        return InputError(f"{source}: {text}")
    if not text.startswith(("calculator ", "ASE calculator factory ")):
        field = "potential"
    return InputError(f"{source}: {field}: {text}")


@contextmanager
def failing_at(stage: str) -> Iterator[None]:
    """A user's calculator that fails inside the block (an exception, a NaN:
    :class:`~flatcontact.potentials.guarded.CalculatorFailure`) names ``stage`` first:
    ``scan: point at shift (0.5, 0), thickness 11.2 Å: calculator '...' failed on ...``;
    its own traceback goes to the run log (INFO: nowhere without one, not the console)."""
    # imported here for the same reason as in :func:`factory`
    from flatcontact.potentials.guarded import CalculatorFailure
    from flatcontact.potentials.guarded import failing_at as name_the_place

    try:
        with name_the_place(stage):
            yield
    except CalculatorFailure as exc:
        if exc.detail:  # the run log (``flatcontact run``) keeps the calculator's traceback
            log.info("%s; the calculator's traceback:\n%s", exc, exc.detail)
        raise


def toy_kwargs(settings) -> dict:
    """Keyword arguments of the toy interface: the toy calculator's (they set its LJ)."""
    calc = settings.potential.calculator
    return dict(calc.kwargs) if calc is not None else {}


def check_elastic(settings) -> None:
    """The elastic stage computes α-quartz: the model must know Si and O (when it says)."""
    known = settings.potential.elements
    if known is not None and not QUARTZ_ELEMENTS <= known:
        raise InputError(
            f"elastic.enabled: the model {settings.potential.label} has no parameters for "
            f"{sorted(QUARTZ_ELEMENTS - known)}; the elastic stage computes alpha-quartz"
        )


def same_model(settings, built: Any) -> bool:
    """Whether an interface's recorded model is the run's."""
    return built == settings.potential


def same_intra(settings, intra: str) -> bool:
    """Whether an interface's recorded intra-slab name (older recipes) is the run's."""
    m = settings.potential
    return m.calculator is None and m.intra == intra


def check(settings) -> None:
    """Checks of the model that need the file system or imports, before any work."""
    if settings.elastic.enabled:
        check_elastic(settings)
