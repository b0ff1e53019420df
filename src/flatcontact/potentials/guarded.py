"""A user's ASE calculator whose failures are one line (:class:`CalculatorFailure`).

The calculators a user names (``potential.calculator.target``, ``intra: ase:module:factory``)
are code flatcontact does not control: ASE's EMT raises ``NotImplementedError`` for an element
it has no parameters for, a machine-learned model may raise ``KeyError`` for a species it was
not trained on or return NaN forces far from its data. :func:`guard_calculator` wraps one such
calculator (the instance: its type and its results are unchanged) so that an energy, forces
or a stress it is asked for is finite or raises :class:`CalculatorFailure`, an
:class:`~flatcontact.foundation.errors.InputError` naming the calculator, the elements it was
asked to evaluate and the exception's type and first line. :func:`failing_at` prefixes where
it happened (the stage, the grid point); :func:`evaluate_once` is the pre-run check (one
energy and forces of a structure, with any calculator).

Only what happens inside the calculator's own methods is converted: an error of
flatcontact's code around it keeps its traceback.
"""

from __future__ import annotations

import errno
import traceback
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np

from flatcontact.foundation.errors import InputError

#: Operating-system faults passed on unchanged (the command line names the limit).
_RESOURCE_ERRNOS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EFBIG})
#: The characters of the calculator's traceback a failure keeps (:attr:`CalculatorFailure.detail`).
TRACEBACK_CHARS = 4000
#: The properties whose values are checked finite, with their units for the message.
_CHECKED = (("energy", "eV"), ("forces", "eV/Å"), ("stress", "eV/Å³"))


class CalculatorFailure(InputError):
    """A user's calculator raised or returned non-finite numbers (one line).

    Attributes
    ----------
    calculator
        The calculator's name as the user gave it (``calculator 'ase.calculators.emt:EMT'``).
    elements
        The elements of the structure it was evaluating, in order of first appearance.
    reason
        ``"<exception type>: <first line of its message>"`` or ``"non-finite forces on 3 of
        27 atoms"``.
    where
        Where it happened (``"scan: point at shift (0.5, 0), thickness 11.2 Å"``), or ``""``.
    detail
        The calculator's own traceback (text, its last ``TRACEBACK_CHARS`` characters), for
        the run log; never printed on the console.
    """

    def __init__(
        self,
        calculator: str,
        elements: tuple[str, ...],
        reason: str,
        where: str = "",
        detail: str = "",
    ):
        self.calculator = calculator
        self.elements = tuple(elements)
        self.reason = reason
        self.where = where
        self.detail = detail
        text = f"{calculator} failed on {the_elements(self.elements)} ({reason})"
        super().__init__(f"{where}: {text}" if where else text)

    def __reduce__(self):  # crosses process boundaries (scan workers) with its fields
        fields = (self.calculator, self.elements, self.reason, self.where, self.detail)
        return (type(self), fields)

    def at(self, where: str) -> CalculatorFailure:
        """The same failure, ``where`` named before the places already named."""
        inner = f"{where}: {self.where}" if self.where else where
        return CalculatorFailure(self.calculator, self.elements, self.reason, inner, self.detail)


@contextmanager
def failing_at(where: str) -> Iterator[None]:
    """Name ``where`` in a :class:`CalculatorFailure` raised inside the block."""
    try:
        yield
    except CalculatorFailure as exc:
        raise exc.at(where) from None


def the_elements(elements: tuple[str, ...]) -> str:
    """``"the elements Si, O"``, ``"the element Ar"``."""
    noun = "element" if len(elements) == 1 else "elements"
    return f"the {noun} {', '.join(elements)}"


def elements_of(atoms: Any) -> tuple[str, ...]:
    """The chemical symbols of ``atoms`` in order of first appearance (``()`` without atoms)."""
    if atoms is None:
        return ()
    return tuple(dict.fromkeys(atoms.get_chemical_symbols()))


def first_line(exc: BaseException) -> str:
    """``"<type>: <first non-empty line of the message>"`` (at most 200 characters)."""
    lines = [ln.strip() for ln in str(exc).splitlines() if ln.strip()]
    said = lines[0][:200] if lines else ""
    return f"{type(exc).__name__}: {said}" if said else type(exc).__name__


def _raised(name: str, atoms: Any, exc: Exception) -> CalculatorFailure:
    """The :class:`CalculatorFailure` of ``exc``, raised by the calculator ``name`` on ``atoms``."""
    detail = "".join(traceback.format_exception(exc))[-TRACEBACK_CHARS:]
    return CalculatorFailure(name, elements_of(atoms), first_line(exc), detail=detail)


def _passed_on(exc: BaseException) -> bool:
    """Errors that are not the calculator's to answer for: a refusal already in one line,
    memory, a full disk (the command line names the limit)."""
    if isinstance(exc, InputError | MemoryError):
        return True
    return isinstance(exc, OSError) and exc.errno in _RESOURCE_ERRNOS


def non_finite(name: str, value: Any) -> str | None:
    """``"non-finite forces on 3 of 27 atoms"`` (or energy, stress) when ``value`` has a NaN
    or ±inf; ``None`` when every number is finite (or ``value`` is no number)."""
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        return None
    bad = ~np.isfinite(arr)
    if not bad.any():
        return None
    if name == "forces" and arr.ndim == 2:
        return f"non-finite forces on {int(bad.any(axis=1).sum())} of {len(arr)} atoms"
    unit = dict(_CHECKED).get(name, "")
    shown = arr.ravel()[np.flatnonzero(bad.ravel())[0]]
    return f"non-finite {name} ({shown} {unit})".replace(" )", ")")


def _check_results(results: dict, name: str, atoms: Any, asked=()) -> None:
    """Refuse a non-finite energy, forces or stress in ``results`` (cached: ASE hands them
    out later without a new calculation). A non-finite stress that was not ``asked`` for is
    dropped instead (a calculator may fill one nobody uses for a cell that is not 3-D
    periodic); asked for later, it is computed again and checked then."""
    for key, _ in _CHECKED:
        if key not in results:
            continue
        reason = non_finite(key, results[key])
        if reason is None:
            continue
        if key == "stress" and key not in asked:
            del results[key]
            continue
        raise CalculatorFailure(name, elements_of(atoms), reason)


def _called(method, name: str, structure: Any, *args, **kwargs):
    """``method(*args, **kwargs)``; an exception it raises (other than those passed on) as
    the :class:`CalculatorFailure` of ``name`` on ``structure``."""
    try:
        return method(*args, **kwargs)
    except Exception as exc:
        if _passed_on(exc):
            raise
        raise _raised(name, structure, exc) from None


def guard_calculator(calc: Any, name: str) -> Any:
    """Make ``calc`` fail in one line: its exceptions and non-finite results become
    :class:`CalculatorFailure` naming ``name``; returns ``calc`` itself.

    An ASE :class:`~ase.calculators.calculator.Calculator` (``calculate`` and ``results``)
    is wrapped at ``calculate``, which ASE calls once per new structure, so cached results
    cost nothing more; any other object with ``get_potential_energy`` and ``get_forces`` at
    those methods (and ``get_stress``). Guarding a calculator twice changes nothing.
    """
    if getattr(calc, "_flatcontact_guard", None) is not None:
        return calc
    try:
        calc._flatcontact_guard = name
    except AttributeError:  # no instance attributes (__slots__): taken as it is
        return calc
    if callable(getattr(calc, "calculate", None)) and isinstance(
        getattr(calc, "results", None), dict
    ):
        inner = calc.calculate

        def calculate(atoms=None, *args, **kwargs):
            structure = atoms if atoms is not None else getattr(calc, "atoms", None)
            out = _called(inner, name, structure, atoms, *args, **kwargs)
            asked = args[0] if args else kwargs.get("properties", ())
            _check_results(calc.results, name, structure, asked or ())
            return out

        calc.calculate = calculate
    else:
        for method, key in (
            ("get_potential_energy", "energy"),
            ("get_forces", "forces"),
            ("get_stress", "stress"),
        ):
            if callable(getattr(calc, method, None)):
                setattr(calc, method, _guarded_getter(calc, getattr(calc, method), key, name))
    return calc


def _guarded_getter(calc: Any, inner, key: str, name: str):
    """``inner(atoms, ...)`` (a ``get_*`` method) with :func:`guard_calculator`'s checks."""

    def getter(atoms=None, *args, **kwargs):
        structure = atoms if atoms is not None else getattr(calc, "atoms", None)
        value = _called(inner, name, structure, atoms, *args, **kwargs)
        _check_results({key: value}, name, structure, (key,))
        return value

    return getter


def evaluate_once(calc: Any, atoms: Any, name: str) -> tuple[float, np.ndarray]:
    """One energy (eV) and forces (eV/Å) of ``atoms`` (not modified) with ``calc``.

    Any calculator (a guarded one, flatcontact's own LAMMPS engine): an exception it raises
    or a non-finite number it returns is a :class:`CalculatorFailure` naming ``name`` and
    the elements of ``atoms``.
    """
    work = atoms.copy()
    work.set_constraint()
    work.calc = calc
    elements = elements_of(atoms)
    try:
        energy = work.get_potential_energy()
        forces = work.get_forces()
    except CalculatorFailure:
        raise
    except Exception as exc:
        if _passed_on(exc):
            raise
        raise _raised(name, atoms, exc) from None
    finally:
        work.calc = None
    for key, value in (("energy", energy), ("forces", forces)):
        reason = non_finite(key, value)
        if reason is not None:
            raise CalculatorFailure(name, elements, reason)
    return float(energy), np.asarray(forces, dtype=float)
