"""Size bounds of a run, checked before any work, and how to raise them deliberately.

A request far beyond what a run can finish (``grid: [100000, 100000]`` is 1e10
relaxations; ``build --layers 100000000`` is gigabytes of atoms) is a typo or a
misunderstanding, not a study: it is refused in one line naming the field, the value, the
bound and the environment variable that raises it. The defaults follow from the physics of
the ISPES and from a workstation:

=====================  =======  ==========================================================
bound                  default  why
=====================  =======  ==========================================================
``grid_axis``          256      lateral points along a1 or a2: 0.02 Å spacing on a 5 Å cell,
                                far below the ~0.1 Å at which U(x, y) stops changing
``scan_points``        200000   grid points × thicknesses: ~1 day at ~0.5 s per relaxation
                                on one core (the paper preset: 2880)
``thicknesses``        500      thicknesses z (``thickness_angstrom``, ``p_range_gpa.n``)
``layers``             200      layers per slab (``structure.layers``, ``build --layers``)
``atoms``              100000   atoms in an interface file (structure.file) — a few GB of
                                neighbour lists per LAMMPS worker beyond that
``structure_mb``       200      size of a structure file in MB (10⁶ bytes): 100 000 atoms of
                                extended XYZ with a dozen per-atom columns is ~20 MB
``workers``            4×cores  local worker processes (more only share the same cores)
``loads``              1000     pressures per list (``analysis.p_gpa``, ``contact.p0_gpa``)
``search_seconds``     120      seconds a structure search (coincidence lattices, twists,
                                approximants) may take before it stops and says which
                                setting to change (:class:`Deadline`)
=====================  =======  ==========================================================

Raise one with ``FLATCONTACT_MAX_<NAME>`` (e.g. ``FLATCONTACT_MAX_SCAN_POINTS=1000000``) in
the environment of the command; it is read every time a bound is checked.
"""

from __future__ import annotations

import os
import time

from flatcontact.foundation.errors import InputError

#: Default bounds (``workers`` is per core, see :func:`bound`).
DEFAULTS: dict[str, int] = {
    "grid_axis": 256,
    "scan_points": 200_000,
    "thicknesses": 500,
    "layers": 200,
    "atoms": 100_000,
    "structure_mb": 200,
    "workers_per_core": 4,
    "loads": 1000,
    "search_seconds": 120,
}


def env_name(name: str) -> str:
    """The environment variable that raises bound ``name``."""
    return f"FLATCONTACT_MAX_{name.upper()}"


def bound(name: str) -> int:
    """The current bound ``name``: ``FLATCONTACT_MAX_<NAME>`` if set, else the default.

    ``workers`` is ``workers_per_core`` × the number of cores unless FLATCONTACT_MAX_WORKERS
    is set.

    Raises
    ------
    InputError
        If the environment variable is set but is not a positive integer.
    """
    var = env_name(name)
    raw = os.environ.get(var)
    if raw is not None:
        try:
            value = int(raw)
        except ValueError:
            value = 0
        if value < 1:
            raise InputError(f"{var}={raw!r}: expected a positive integer")
        return value
    if name == "workers":
        return DEFAULTS["workers_per_core"] * (os.cpu_count() or 1)
    return DEFAULTS[name]


def check(name: str, value: float, field: str, what: str = "") -> None:
    """Refuse ``value`` above bound ``name`` in one line naming ``field`` and the way to raise it.

    Parameters
    ----------
    name
        Key of the bound (``grid_axis``, ``scan_points``, ...).
    value
        The requested size.
    field
        The config field or flag the user wrote (``scan.grid``, ``--layers``).
    what
        What ``value`` counts, for the message (``"grid points x thicknesses"``).
    """
    limit = bound(name)
    if value > limit:
        counted = f" ({what})" if what else ""
        shown = str(int(value)) if float(value).is_integer() else f"{value:g}"
        raise InputError(
            f"{field}: {shown}{counted} exceeds the bound {limit}; if you really mean it, "
            f"set {env_name(name)}={int(value) if value == int(value) else value} "
            "(see docs/run.md, 'Limits and errors')"
        )


def message(name: str, value: float, what: str = "") -> str:
    """The text of :func:`check`'s refusal without the field (for pydantic validators)."""
    try:
        check(name, value, "", what)
    except InputError as exc:
        return str(exc).removeprefix(": ")
    return ""


class SearchTimeout(InputError):
    """A search stopped by its :class:`Deadline` (not "nothing found": a caller that turns
    "nothing found" into another message lets this one through)."""


class Deadline:
    """The time bound of one search (``search_seconds``, read when the search starts).

    Parameters
    ----------
    what
        The search and the settings it runs on, first in the message
        (``"structure.slab2: the coincidence search (max_atoms 400, strain 3 %)"``).
    advice
        Which setting to change for a search that ends sooner (``"lower
        structure.match.max_atoms or raise structure.match.max_strain_percent"``).
    """

    def __init__(self, what: str, advice: str):
        self.what, self.advice = what, advice
        self.seconds = bound("search_seconds")
        self._end = time.monotonic() + self.seconds

    def check(self) -> None:
        """Raise the one-line :class:`InputError` once the bound has passed."""
        if time.monotonic() > self._end:
            raise SearchTimeout(
                f"{self.what}: no answer within {self.seconds} s; {self.advice}, or set "
                f"{env_name('search_seconds')}={4 * self.seconds} to search longer"
            )
