"""The Python door for a notebook or a script: scan the calculator in hand, get a Dataset.

A user of ASE holds an interface and a calculator; this module turns them into the tool's
results without a configuration file, a run directory or a calculator factory:

>>> from ase.build import fcc111
>>> from ase.calculators.emt import EMT
>>> from flatcontact import analyze_ispes, contact_from_laws, make_interface, scan_interface
>>> slab = fcc111("Cu", size=(1, 1, 3), a=3.59, orthogonal=False, periodic=True)
>>> interface = make_interface(slab, gap_angstrom=2.1, face_atoms=1)
>>> ispes = scan_interface(interface, EMT(), grid=(3, 3), p_range_gpa=(-1.0, 3.0, 5))
>>> ispes["energy"].dims
('shift_a', 'shift_b', 'thickness')
>>> result = analyze_ispes(ispes, [0.0, 0.5, 1.0, 1.5])
>>> result.p_gpa.tolist()
[0.0, 0.5, 1.0, 1.5]
>>> contact = contact_from_laws(result.laws, [0.5], radius_um=5.0,
...                             contact_modulus_gpa=70.0, shear_modulus_gpa=100.0)
>>> round(contact.records()[0]["contact_radius_nm"], 1)   # Hertz: a = pi p0 R / (2 E*)
56.1

(A 3 × 3 grid of a six-atom cell, seconds on one core: enough to show the calls, not to
resolve τ; the moduli here are placeholders, give your material's.)

The three doors and their conventions:

- :func:`scan_interface` — the ISPES ``U(x, y, z)``, ``p(x, y, z)`` of an interface that
  follows the interface contract (:func:`flatcontact.structures.assemble.make_interface`
  builds one from a slab; ``flatcontact build`` writes one), as the ``ispes.nc`` Dataset
  (:mod:`flatcontact.ispes.contract`: energies in eV per cell, normal stress in GPa, positive
  when pressed). Serial with a calculator object; with a picklable factory (``factory(atoms)``
  -> calculator, a module-level function or class) on ``workers`` processes.
- :func:`flatcontact.analysis.analyze.analyze_ispes` and
  :func:`flatcontact.analysis.laws.fit_load_laws` (already public) — τ, σ_MSS and the laws.
- :func:`contact_from_laws` — the modified Mindlin contact (Hertz + adhesion, stick and slip
  zones) at peak pressures ``p0_gpa`` with the fitted laws.

Nothing here prints; progress goes to a callback ``progress(done, total)``.

A calculator is code flatcontact does not control, so :func:`scan_interface` evaluates it
once (energy and forces of the interface) before any work, and guards it
(:func:`flatcontact.potentials.guarded.guard_calculator`, in place): one that raises or
returns a non-finite number is a one-line
:class:`~flatcontact.potentials.guarded.CalculatorFailure` (an ``InputError``) naming the
calculator, the elements and its exception, and, mid-scan, the point
(``point at shift (0.5, 0), thickness 10.75 Å: calculator 'EMT' failed on ...``); its own
traceback is kept in the failure's ``detail``.
"""

from __future__ import annotations

import json
import tempfile
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path
from typing import Any

from flatcontact.foundation.errors import InputError

#: Relaxation modes of :class:`flatcontact.ispes.relax.RelaxSettings` (``scan.relax_mode``).
RELAX_MODES = ("full", "normal", "rigid-layers", "rigid")


class CalculatorInHand:
    """A scan factory for one ASE calculator object: ``factory(atoms)`` returns it.

    The scan driver asks for a factory with a ``label`` and a ``fingerprint`` (the content
    that keys a resumable point store); a calculator object has neither, so this wrapper
    derives them: the label from the calculator's class, the fingerprint from its class and
    its parameters (``calc.todict()``, ASE's own record of them), so a store scanned with
    other parameters is refused on resume instead of mixed. The object itself is not
    pickled to workers: a calculator in hand scans serially.

    Parameters
    ----------
    calculator
        An ASE calculator (``get_potential_energy``, ``get_forces``, ``get_stress``).
    label
        Name in records and the report (default: the class name).
    """

    def __init__(self, calculator: Any, label: str | None = None):
        if not hasattr(calculator, "get_forces"):
            raise InputError(
                f"calculator: expected an ASE calculator (with get_forces) or a factory "
                f"callable(atoms) -> calculator, got {type(calculator).__name__}"
            )
        self.calculator = calculator
        self.label = label or type(calculator).__name__
        #: how a failure names it (:class:`~flatcontact.potentials.guarded.CalculatorFailure`)
        self.name = f"calculator {self.label!r}"
        kind = type(calculator)
        parameters = calculator.todict() if hasattr(calculator, "todict") else {}
        self.fingerprint = json.dumps(
            {
                "calculator": f"{kind.__module__}.{kind.__qualname__}",
                "parameters": json.loads(json.dumps(parameters, sort_keys=True, default=repr)),
                "label": self.label,
            },
            sort_keys=True,
        )

    def __call__(self, atoms=None):
        from flatcontact.potentials.guarded import guard_calculator

        return guard_calculator(self.calculator, self.name)

    def __reduce__(self):
        raise InputError(
            "calculator: a calculator object scans serially (workers=1); for workers give a "
            "picklable factory, a module-level callable(atoms) -> calculator"
        )


class FactoryInHand:
    """A scan factory for a user's picklable ``factory(atoms) -> calculator``.

    Fingerprint: the factory's module and qualified name and ``label`` (a factory's
    parameters are its own business: change ``label`` when they change, or the store of an
    earlier scan would be resumed with the new calculator).
    """

    def __init__(self, factory: Callable[[Any], Any], label: str | None = None):
        name = getattr(factory, "__qualname__", type(factory).__qualname__)
        module = getattr(factory, "__module__", type(factory).__module__)
        self.factory = factory
        self.label = label or name
        self.name = f"calculator {self.label!r}"
        self.fingerprint = json.dumps(
            {"factory": f"{module}.{name}", "label": self.label}, sort_keys=True
        )

    def __call__(self, atoms=None):
        """The factory's calculator for ``atoms``, guarded; a factory that raises or returns
        no calculator is one line naming it."""
        from flatcontact.potentials.guarded import first_line, guard_calculator
        from flatcontact.potentials.loader import is_calculator

        try:
            made = self.factory(atoms)
        except (InputError, MemoryError, OSError):
            raise
        except Exception as exc:
            raise InputError(
                f"calculator: factory {self.label!r} failed: {first_line(exc)}"
            ) from None
        if not is_calculator(made):
            raise InputError(
                f"calculator: factory {self.label!r} returned {type(made).__name__}, expected "
                "an ASE calculator (with get_potential_energy and get_forces)"
            )
        return guard_calculator(made, self.name)


def _scan_factory(calculator: Any, workers: int, label: str | None):
    """The scan factory of ``calculator`` (object, factory, model or potential name)."""
    from flatcontact.potentials.engines import calculator_factory
    from flatcontact.potentials.model import InteractionModel

    if isinstance(calculator, str):
        return calculator_factory(InteractionModel(intra=calculator))
    if isinstance(calculator, InteractionModel):
        calculator.check_couples_slabs("calculator.coupling")  # per slab, nothing across: flat
        return calculator_factory(calculator)
    if hasattr(calculator, "get_forces"):
        if workers != 1:
            raise InputError(
                f"workers: {workers} with a calculator object; a calculator in hand scans "
                "serially (workers=1), or give a picklable factory(atoms) -> calculator"
            )
        return CalculatorInHand(calculator, label)
    if callable(calculator):
        return FactoryInHand(calculator, label)
    raise InputError(
        "calculator: expected an ASE calculator, a factory callable(atoms) -> calculator, an "
        f"InteractionModel or a potential's name, got {type(calculator).__name__}"
    )


def _fresh(failure):
    """A copy of the :class:`~flatcontact.potentials.guarded.CalculatorFailure` ``failure``,
    to raise here: the notebook's traceback ends in this module, not deep in the scan."""
    f = failure
    return type(f)(f.calculator, f.elements, f.reason, f.where, f.detail)


def _evaluate_once(interface, factory) -> None:
    """One energy and forces of ``interface`` with ``factory``'s calculator, before any work
    (the command line's pre-run evaluation): the interface contract first, then a
    :class:`~flatcontact.potentials.guarded.CalculatorFailure` or an InputError naming
    ``calculator`` when the calculator cannot evaluate it."""
    from flatcontact.potentials.engines import ModelFactory, check_evaluation
    from flatcontact.potentials.guarded import CalculatorFailure, evaluate_once
    from flatcontact.structures.interface_contract import validate_interface

    validate_interface(interface, "interface")
    try:
        if isinstance(factory, ModelFactory):  # a potential's name or an InteractionModel
            check_evaluation(factory.model, interface)
        else:
            evaluate_once(factory(interface), interface, factory.name)
    except CalculatorFailure as exc:
        raise (_fresh(exc) if str(exc).startswith("calculator") else exc.at("calculator")) from None
    except InputError as exc:
        if str(exc).startswith("calculator"):
            raise
        raise InputError(f"calculator: {exc}") from None


def scan_interface(
    interface,
    calculator: Any,
    *,
    grid: Sequence[int] = (6, 6),
    thickness_angstrom: Sequence[float] | None = None,
    p_range_gpa: Sequence[float] | None = None,
    out: str | Path | None = None,
    workers: int = 1,
    fmax_ev_per_angstrom: float = 0.01,
    relax_mode: str = "full",
    label: str | None = None,
    progress: Callable[[int, int], None] | None = None,
):
    """Scan the ISPES of ``interface`` with ``calculator``; return the ``ispes.nc`` Dataset.

    Parameters
    ----------
    interface : ase.Atoms
        Two slabs following the interface contract (``arrays["slab"]`` 1/2,
        ``arrays["surface"]`` 1-4; :func:`flatcontact.structures.assemble.make_interface`
        builds one from a slab, :func:`flatcontact.structures.io.read_interface` reads
        ``interface.extxyz``). Slab 2 at shift (0, 0) is the reference registry.
    calculator
        An ASE calculator object (serial), a picklable ``factory(atoms) -> calculator`` (any
        ``workers``), an :class:`~flatcontact.potentials.model.InteractionModel` or a
        potential's name (``"vashishta"``, ``"snap:sio2-snap"``).
    grid
        Lateral points ``(n_a, n_b)`` over one interface cell, shifts ``i/n_a``, ``j/n_b``.
    thickness_angstrom, p_range_gpa
        Exactly one: explicit thicknesses z (Å, surface 1 to surface 4), or ``(lo, hi, n)``:
        n thicknesses whose loads span lo..hi GPa at the probed stackings.
    out
        Folder of the resumable point store (``points.db``) and ``ispes.nc``: a rerun with
        the same arguments resumes where it stopped. ``None``: a temporary folder, removed
        when the scan is done (the Dataset is returned in memory).
    workers
        Processes (1: serial, in this process; no ``if __name__ == "__main__"`` guard needed).
    fmax_ev_per_angstrom
        Relaxation tolerance on the largest force component (eV/Å) at every point.
    relax_mode
        ``full`` (inner atoms relax in 3D; the paper's), ``normal`` (z only), ``rigid-layers``
        or ``rigid``.
    label
        The calculator's name in the records (default: its class or factory name).
    progress
        ``progress(done, total)`` after every grid point.

    Returns
    -------
    xarray.Dataset
        The ``ispes.nc`` contract: ``energy`` (eV), ``normal_stress`` (GPa, positive when
        pressed), ``converged``, ``force_calls`` over ``(shift_a, shift_b, thickness)``.

    Raises
    ------
    InputError
        One line naming the parameter: a bad grid, both or neither of the thickness
        choices, an interface that breaks the contract, a calculator that is none, an
        InteractionModel under which the slabs do not interact (per slab, ``coupling:
        none``: ``calculator.coupling``, a flat ISPES).
    flatcontact.potentials.guarded.CalculatorFailure
        An ``InputError``, one line: the calculator raised or returned a non-finite energy or
        forces, before the scan (its one evaluation of ``interface``: ``calculator 'EMT'
        failed on the elements Si, O (NotImplementedError: No EMT-potential for Si)``) or at
        a grid point (named first: ``point at shift (0.5, 0), thickness 10.75 Å: ...``; the
        points relaxed before it stay in ``out``). ``.elements``, ``.reason`` and ``.detail``
        (the calculator's traceback) hold the parts.
    """
    from flatcontact.ispes.contract import open_ispes
    from flatcontact.ispes.grid import GridSpec
    from flatcontact.ispes.relax import RelaxSettings
    from flatcontact.ispes.scan import run_scan
    from flatcontact.potentials.guarded import CalculatorFailure

    if len(grid) != 2:
        raise InputError(f"grid: expected two lateral counts (n_a, n_b), got {list(grid)}")
    if relax_mode not in RELAX_MODES:
        raise InputError(
            f"relax_mode: expected one of {', '.join(RELAX_MODES)}, got {relax_mode!r}"
        )
    if int(workers) != workers or workers < 1:
        raise InputError(f"workers: expected an integer >= 1, got {workers!r}")
    factory = _scan_factory(calculator, int(workers), label)
    spec = GridSpec(
        int(grid[0]),
        int(grid[1]),
        thickness_angstrom=None if thickness_angstrom is None else tuple(thickness_angstrom),
        p_range_gpa=None if p_range_gpa is None else tuple(p_range_gpa),
    )
    relax = RelaxSettings(fmax_ev_per_angstrom=fmax_ev_per_angstrom, mode=relax_mode)
    options = {"kind": "serial"} if workers == 1 else {"kind": "processes", "workers": workers}
    _evaluate_once(interface, factory)

    def scan(folder: Path):
        try:
            result = run_scan(
                interface, factory, spec, folder, relax, executor_options=options, progress=progress
            )
        except CalculatorFailure as exc:  # named where it happened (the point), raised here
            raise _fresh(exc) from None
        return open_ispes(result.ispes_path).load()

    if out is not None:
        return scan(Path(out))
    with tempfile.TemporaryDirectory(prefix="flatcontact-scan-") as folder:
        return scan(Path(folder))


def contact_from_laws(
    laws,
    p0_gpa: Sequence[float],
    *,
    radius_um: float,
    contact_modulus_gpa: float,
    shear_modulus_gpa: float,
    work_of_separation_j_per_m2: float = 0.0,
):
    """The modified Mindlin contact at peak pressures ``p0_gpa`` with the fitted laws.

    Parameters
    ----------
    laws : LoadLaws or dict
        :func:`flatcontact.analysis.laws.fit_load_laws`'s result, or a mapping with
        ``k_mpa_per_gpa``, ``tau0_mpa``, ``mu_mpa_per_gpa``, ``sigma0_mpa`` (``laws.json``).
    p0_gpa
        Hertz peak pressures (GPa): a sequence, or one number.
    radius_um, contact_modulus_gpa, shear_modulus_gpa
        Tip radius R (µm), Hertz contact modulus E* (GPa) and the paper's shear modulus G*
        (GPa, = 4 G*_J of Johnson; :mod:`flatcontact.contact.moduli`).
    work_of_separation_j_per_m2
        Work of adhesion w for the DMT/JKR radii (0: none).

    Returns
    -------
    flatcontact.contact.summary.ContactAnalysis
        ``.records()``: one dict per p0 (contact radius, Q_peak, effective shear strength,
        stiffness, with units in the keys).
    """
    from flatcontact.contact.parameters import ContactParameters
    from flatcontact.contact.summary import analyse

    numbers = _law_numbers(laws)
    params = ContactParameters(
        radius_um=radius_um,
        contact_modulus_gpa=contact_modulus_gpa,
        shear_modulus_gpa=shear_modulus_gpa,
        work_of_adhesion_j_per_m2=work_of_separation_j_per_m2,
        **numbers,
    )
    single = isinstance(p0_gpa, str) or not isinstance(p0_gpa, Iterable)
    return analyse([p0_gpa] if single else list(p0_gpa), params)


def _law_numbers(laws) -> dict[str, float]:
    """k, τ0, μ, σ0 of a :class:`~flatcontact.analysis.laws.LoadLaws` (through its
    ``laws.json`` form, :meth:`~flatcontact.analysis.laws.LoadLaws.to_json`) or a mapping."""
    from flatcontact.foundation.reference import PAPER_LAW_KEYS

    doc = laws if isinstance(laws, dict) else getattr(laws, "to_json", dict)()
    missing = [k for k in PAPER_LAW_KEYS if doc.get(k) is None]
    if missing:
        raise InputError(
            f"laws: missing {', '.join(missing)} (a mapping as laws.json, or "
            "fit_load_laws(...)'s result with both τ and σ laws fitted)"
        )
    numbers = {}
    for key in PAPER_LAW_KEYS:
        try:
            numbers[key] = float(doc[key])
        except (TypeError, ValueError):
            raise InputError(f"laws: {key}: expected a number, got {doc[key]!r}") from None
    return numbers
