"""The ``structure:`` section of a run: recipes for the interface and :func:`build_interface`.

One pydantic model per ``kind`` (:data:`StructureRecipe`, discriminated by ``kind``):

``quartz-dense``  the paper's α-quartz (0001) dense interface (today's numbers);
``file``          a prepared ``interface.extxyz`` following the contract;
``slab``          a prepared slab file, two copies facing each other (layers found from it);
``toy-lj``        the two-slab Lennard-Jones toy (tests and demos);
``sheets``        2D monolayers (built-in graphene, h-BN, MoS2 or a file), N per slab;
``crystal``       a bulk crystal file (CIF, POSCAR, extxyz, ...) + Miller index + termination;
``fcc111``        fcc(111) metal slabs (Cu, Ni, Al, ...) by element.

For ``sheets``, ``crystal`` and ``fcc111`` slab 2 is by default the continuation of slab 1
(the stacking sequence of sheets, the bulk crystal across the cut), or: another material
(``slab2``, on a coincidence lattice within ``match`` bounds), the same one rotated
(``rotate_deg``, a symmetry of its lattice, e.g. 180° for h-BN AA′), twisted
(``twist: [m, n]``, commensurate), or flipped upside down (``flip``, crystals). The
choice, strains, rotation and atom count are recorded in ``info["recipe"]``.

Entry points: :func:`parse_recipe` (dict → model, one-line InputError naming the field),
:func:`resolve_paths`, :func:`input_files`; the interface itself:
:func:`flatcontact.structures.construct.build_interface` (model → tagged interface + report).
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import (
    BaseModel,
    ConfigDict,
    Discriminator,
    Field,
    Tag,
    TypeAdapter,
    ValidationError,
    field_validator,
    model_validator,
)

from flatcontact.foundation import limits
from flatcontact.foundation.errors import InputError
from flatcontact.foundation.numbers import Bounds, physical, state_bounds
from flatcontact.structures.quartz_layers import MIN_LAYERS, check_shipped_layers
from flatcontact.structures.sheet_catalog import BUILTIN_SHEETS

#: Name of the config section, the prefix of every field named in an error.
SECTION = "structure"


#: Bounds of the recipe's floats (:func:`~flatcontact.foundation.numbers.physical`: finite, no
#: subnormals, printed by ``flatcontact config --show-default``). A gap or spacing from
#: touching cores (0.5 Å, below any bond) to twice the longest vdW cutoff (20 Å); an fcc
#: lattice constant from 1 to 10 Å (Cu 3.61, Pb 4.95, Ca 5.58 Å); a relaxation's force
#: tolerance as the scan's (1e-6..10 eV/Å); a rotation within one turn either way.
GapAngstrom = physical(0.5, 20.0, "Å")
LatticeAngstrom = physical(1.0, 10.0, "Å")
FmaxEvPerAngstrom = physical(1e-6, 10.0, "eV/Å")
AngleDeg = physical(-360.0, 360.0, "deg")
StrainPercent = physical(1e-3, 20.0, "%")

#: Parameters of the toy LJ (:class:`flatcontact.structures.toy.ToyPairCalculator` and
#: :func:`~flatcontact.structures.toy.toy_interface`) and their bounds: well depths of a
#: physisorbed or metallic pair (no cross-interface attraction: 0), σ of an atom, the cutoff
#: in σ (below 1.2σ the shifted force has no minimum), the initial gap in layer spacings and
#: the force tolerance of the initial relaxation.
TOY_PARAMS: dict[str, Bounds] = {
    "eps_intra_ev": Bounds(1e-4, 10.0, "eV"),
    "eps_cross_ev": Bounds(1e-4, 10.0, "eV", or_zero=True),
    "sigma_angstrom": Bounds(0.5, 10.0, "Å"),
    "cutoff_sigma": Bounds(1.2, 5.0),
    "gap_factor": Bounds(0.5, 5.0),
    "relax_fmax_ev_per_angstrom": Bounds(1e-8, 1.0, "eV/Å"),
}


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    @classmethod
    def __pydantic_init_subclass__(cls, **kwargs: Any) -> None:
        """State the bounds of the recipe's bounded floats in their descriptions."""
        super().__pydantic_init_subclass__(**kwargs)
        state_bounds(cls)


#: Surface passivation of a crystal cut (:mod:`flatcontact.structures.passivate`).
Passivation = Literal["none", "H", "OH"]
#: Which faces of a slab are passivated: the one towards the other slab, or both.
PassivatedFaces = Literal["interface", "both"]
_PASSIVATE_DOC = (
    "none | H (one H per dangling bond) | OH (hydroxyl on oxides: OH on a cation missing an "
    "O, H on an O missing a cation) on the dangling bonds of the cut"
)
_FACES_DOC = "interface: only the face towards the other slab; both: the held outer face too"


class MatchSettings(_Model):
    """Bounds of the coincidence-lattice search (hetero-interfaces) and of the atom count."""

    max_strain_percent: StrainPercent = Field(
        3.0, description="largest principal strain put on either slab (%)"
    )
    max_atoms: int = Field(400, ge=2, description="largest number of atoms of the interface")
    strain_on: Literal["slab2", "both"] = Field(
        "slab2",
        description="slab2: slab 1 keeps its lattice, slab 2 takes the strain; "
        "both: the common cell is the mean of the two",
    )
    # the two supercells are left out of the dumped recipe while unset, so the fingerprints
    # of existing runs are unchanged
    slab1_supercell: tuple[tuple[int, int], tuple[int, int]] | None = Field(
        None,
        exclude_if=lambda value: value is None,
        description="two materials: slab 1's supercell (2×2 integers, rows in its primitive "
        "cell) in place of the smallest match, e.g. from flatcontact's approximant sequence; "
        "with slab2_supercell",
    )
    slab2_supercell: tuple[tuple[int, int], tuple[int, int]] | None = Field(
        None,
        exclude_if=lambda value: value is None,
        description="two materials: slab 2's supercell, with slab1_supercell",
    )

    @field_validator("max_atoms")
    @classmethod
    def _atoms_within_bound(cls, value: int) -> int:
        """The search's candidates grow with the square of its largest cell: bounded before
        it starts (``FLATCONTACT_MAX_ATOMS``)."""
        if value > limits.bound("atoms"):
            raise ValueError(limits.message("atoms", value, "atoms of the largest cell"))
        return value

    @model_validator(mode="after")
    def _supercells(self) -> MatchSettings:
        given = (self.slab1_supercell is not None, self.slab2_supercell is not None)
        if given[0] != given[1]:
            missing = "slab2_supercell" if given[0] else "slab1_supercell"
            raise ValueError(f"{missing}: required with the other slab's supercell")
        for name in ("slab1_supercell", "slab2_supercell"):
            p = getattr(self, name)
            if p is not None and p[0][0] * p[1][1] - p[0][1] * p[1][0] <= 0:
                raise ValueError(
                    f"{name}: expected a positive determinant (a right-handed supercell), "
                    f"got {[list(r) for r in p]}"
                )
            # cells of the primitive cell, each at least one atom: bounded before anything
            # is allocated (a 100001 supercell tried 224 GiB, a larger one overflowed)
            if p is not None and p[0][0] * p[1][1] - p[0][1] * p[1][0] > limits.bound("atoms"):
                det = p[0][0] * p[1][1] - p[0][1] * p[1][0]
                raise ValueError(
                    f"{name}: "
                    + limits.message("atoms", det, "primitive cells, at least one atom each")
                )
        return self


#: Where the slabs' lattice comes from (:mod:`flatcontact.structures.lattice`).
LatticeSource = Literal["potential", "file"]


class _LatticeOption(_Model):
    """The one declaration of ``structure.lattice`` (every recipe that cuts or stacks a
    material: ``sheets``, ``crystal``, ``fcc111``, ``quartz-dense``)."""

    lattice: LatticeSource = Field(
        "potential",
        description="potential: the slabs at the interaction model's own equilibrium lattice "
        "(the bulk, or a sheet's in-plane cell, relaxed with the run's model first); file: at "
        "the structure file's (or built-in) lattice, the mismatch and its lateral stress "
        "reported, refused above 2 % in-plane",
    )


class _PairOptions(_LatticeOption):
    held_layers: int = Field(1, ge=1, description="outer layers held (rigid) per slab")
    rotate_deg: AngleDeg = Field(
        0.0,
        description="slab 2 rotated about z by this angle (a symmetry of its lattice, e.g. 180); "
        "for sheets about the midpoint of the shortest unlike bond",
    )
    twist: tuple[int, int] | None = Field(
        None,
        description="commensurate twist (m, n) of a hexagonal lattice: slab 2 rotated by "
        "acos((m²+4mn+n²)/(2(m²+mn+n²))), (1, 2) → 21.787°",
    )
    match: MatchSettings = Field(
        default_factory=MatchSettings,
        description="bounds of the coincidence-lattice search and of the atom count",
    )
    fmax_ev_per_angstrom: FmaxEvPerAngstrom = Field(
        0.01,
        description="force tolerance of the reference relaxation (when a calculator is given)",
    )

    @field_validator("twist")
    @classmethod
    def _twist_within_bound(cls, value):
        """(m, n) makes m² + mn + n² primitive cells per layer: bounded before it is built."""
        if value is not None:
            m, n = value
            cells = m * m + m * n + n * n
            if cells > limits.bound("atoms"):
                raise ValueError(
                    limits.message("atoms", cells, "primitive cells per layer of the twist")
                )
        return value


class SheetSlab(_Model):
    """One slab of 2D sheets."""

    sheet: str = Field(description="built-in graphene | h-BN | MoS2, or a monolayer file")
    layers: int = Field(1, ge=1, description="sheets in this slab")
    stacking: str = Field("AB", description="stacking letters of this slab (see docs)")
    interlayer_angstrom: GapAngstrom | None = Field(
        None,
        description="distance between adjacent sheets (mean planes); built-ins: bulk value",
    )


class SheetsRecipe(_PairOptions):
    """2D monolayers stacked into two slabs."""

    kind: Literal["sheets"] = Field("sheets", description="recipe kind")
    sheet: str = Field(description="built-in graphene | h-BN | MoS2, or a monolayer file")
    layers: int = Field(1, ge=1, description="sheets per slab")
    stacking: str = Field(
        "AB",
        description="letters A, B, C (optionally primed) for the whole stack, slab 1 then slab 2, "
        "repeated: AB = Bernal, AA' = h-BN AA′ / 2H-MoS2",
    )
    interlayer_angstrom: GapAngstrom | None = Field(
        None, description="distance between adjacent sheets"
    )
    interface_spacing_angstrom: GapAngstrom | None = Field(
        None,
        description="distance between the facing sheets of the two slabs (default: the interlayer distance, mean of the two materials)",
    )
    slab2: SheetSlab | None = Field(None, description="another material for slab 2")


class CrystalSlab(_Model):
    """One slab cut from a bulk crystal file."""

    bulk: str = Field(description="bulk crystal file, any format ASE reads (CIF, POSCAR, extxyz)")
    miller: tuple[int, int, int] = Field(description="Miller index in the file's cell")
    layers: int = Field(3, ge=1, description="bulk repeats along the normal")
    termination: int = Field(
        0, ge=0, description="which cut (0 = widest gap between atomic planes)"
    )
    passivate: Passivation = Field("none", description=_PASSIVATE_DOC)
    passivate_faces: PassivatedFaces = Field("interface", description=_FACES_DOC)


def _slab2_kind(value: Any) -> str:
    has_sheet = isinstance(value, dict) and "sheet" in value
    return "sheet" if has_sheet or isinstance(value, SheetSlab) else "bulk"


#: slab 2 of a crystal recipe: a crystal (``bulk:``) or 2D sheets (``sheet:``).
_CrystalOrSheetSlab = Annotated[
    Annotated[CrystalSlab, Tag("bulk")] | Annotated[SheetSlab, Tag("sheet")],
    Discriminator(_slab2_kind),
]


class CrystalRecipe(_PairOptions):
    """Slabs cut from a bulk crystal."""

    kind: Literal["crystal"] = Field("crystal", description="recipe kind")
    bulk: str = Field(description="bulk crystal file, any format ASE reads (CIF, POSCAR, extxyz)")
    miller: tuple[int, int, int] = Field(description="Miller index in the file's cell")
    layers: int = Field(6, ge=1, description="bulk repeats (layers) per slab")
    termination: int = Field(
        0, ge=0, description="which cut (0 = widest gap between atomic planes)"
    )
    gap_angstrom: GapAngstrom | None = Field(
        None, description="highest atom of slab 1 to lowest of slab 2 (default: the bulk's)"
    )
    flip: bool = Field(False, description="slab 2 = slab 1 upside down (rotated 180° about a1)")
    slab2: _CrystalOrSheetSlab | None = Field(
        None, description="another crystal (bulk: ...) or 2D sheets (sheet: ...) for slab 2"
    )
    passivate: Passivation = Field(
        "none", description=_PASSIVATE_DOC + " (slab 1; and slab 2 without slab2)"
    )
    passivate_faces: PassivatedFaces = Field("interface", description=_FACES_DOC)

    @model_validator(mode="after")
    def _gap_of_prepared_faces(self) -> CrystalRecipe:
        prepared = self.passivate != "none" or (
            isinstance(self.slab2, CrystalSlab) and self.slab2.passivate != "none"
        )
        if self.gap_angstrom is None and (prepared or isinstance(self.slab2, SheetSlab)):
            raise ValueError(
                "gap_angstrom: required with a passivated face or a sheet as slab 2 (the bulk's "
                "gap across the cut is then not the distance between the faces), e.g. 2.6 for "
                "H against graphene"
            )
        return self


class Fcc111Slab(_Model):
    element: str = Field(description="fcc element of slab 2")
    a_angstrom: LatticeAngstrom | None = Field(
        None, description="lattice constant (default: ASE's reference)"
    )
    layers: int = Field(6, ge=1, description="close-packed planes of slab 2")


class Fcc111Recipe(_PairOptions):
    """fcc(111) metal slabs (ase.build.fcc111), one close-packed plane per layer."""

    kind: Literal["fcc111"] = Field("fcc111", description="recipe kind")
    element: str = Field(description="Cu, Ni, Al, ... (fcc)")
    a_angstrom: LatticeAngstrom | None = Field(
        None, description="lattice constant (default: ASE's reference)"
    )
    layers: int = Field(6, ge=1, description="close-packed planes per slab")
    gap_angstrom: GapAngstrom | None = Field(
        None,
        description="distance between the facing planes (default a/√3: the perfect crystal)",
    )
    slab2: Fcc111Slab | None = Field(None, description="another fcc metal for slab 2")


class QuartzDenseRecipe(_LatticeOption):
    """The paper's α-quartz (0001) dense interface (flatcontact.structures.build)."""

    kind: Literal["quartz-dense"] = Field("quartz-dense", description="recipe kind")
    layers: int = Field(
        6, description="O-Si-O layers per slab (>= 5; with source shipped 6, 9, 12, ...)"
    )
    source: Literal["auto", "shipped", "seed"] = Field(
        "auto",
        description="starting slab: shipped (CHGNet-relaxed 6-layer slab; 9, 12, ... layers by "
        "inserting whole alpha-quartz c-repeats relaxed with the potential into its interior), "
        "seed (seeded dense reconstruction relaxed with the potential) or auto (shipped if "
        "present and it reaches layers, else seed)",
    )
    gap_angstrom: GapAngstrom = Field(
        3.0, description="initial gap between the slabs before the interface relaxation (Å)"
    )
    fmax_ev_per_angstrom: FmaxEvPerAngstrom = Field(
        0.01, description="force tolerance of the slab and interface relaxations (eV/Å)"
    )

    @model_validator(mode="after")
    def _layers(self) -> QuartzDenseRecipe:
        if self.layers < MIN_LAYERS:
            raise ValueError(
                f"layers={self.layers}: the dense quartz interface needs >= {MIN_LAYERS}"
            )
        if self.source == "shipped":
            try:
                check_shipped_layers(self.layers)
            except InputError as exc:
                raise ValueError(str(exc)) from None
        return self


class FileRecipe(_Model):
    """A prepared interface.extxyz following the contract."""

    kind: Literal["file"] = Field("file", description="recipe kind")
    file: str = Field(description="path of an interface.extxyz")


class SlabFileRecipe(_Model):
    """A prepared slab file: two copies facing each other, layers found from the structure."""

    kind: Literal["slab"] = Field("slab", description="recipe kind")
    file: str = Field(
        description="slab file (any format ASE reads), periodic along cell vectors 1, 2"
    )
    gap_angstrom: GapAngstrom = Field(
        3.0, description="highest atom of slab 1 to lowest of slab 2 (Å)"
    )
    held_layers: int = Field(1, ge=1, description="outer layers held (rigid) per slab")
    flip: bool = Field(False, description="slab 2 = slab 1 upside down (rotated 180° about a1)")
    fmax_ev_per_angstrom: FmaxEvPerAngstrom = Field(
        0.01,
        description="force tolerance of the reference relaxation (when a calculator is given)",
    )


class ToyRecipe(_Model):
    """The toy two-slab Lennard-Jones interface (:mod:`flatcontact.structures.toy`)."""

    kind: Literal["toy-lj"] = Field("toy-lj", description="recipe kind")
    layers: int = Field(3, ge=3, description="atomic layers per slab (>= 3)")
    params: dict[str, float] = Field(
        default_factory=dict,
        description="ToyPairCalculator parameters ["
        + ", ".join(f"{k}: {b.text()}" for k, b in TOY_PARAMS.items())
        + "]",
    )

    @field_validator("params")
    @classmethod
    def _params(cls, value: dict[str, float]) -> dict[str, float]:
        for key, number in value.items():
            if key not in TOY_PARAMS:
                raise ValueError(
                    f"unknown parameter {key!r}: expected one of {', '.join(TOY_PARAMS)}"
                )
            try:
                TOY_PARAMS[key].check(number)
            except ValueError as exc:
                raise ValueError(f"{key}: {exc}") from None
        return value


StructureRecipe = Annotated[
    QuartzDenseRecipe
    | FileRecipe
    | SlabFileRecipe
    | ToyRecipe
    | SheetsRecipe
    | CrystalRecipe
    | Fcc111Recipe,
    Field(discriminator="kind"),
]
_ADAPTER: TypeAdapter = TypeAdapter(StructureRecipe)
KINDS = ("quartz-dense", "file", "slab", "toy-lj", "sheets", "crystal", "fcc111")

#: (dotted field path, recipe kind) of every field that names a file, for path resolution.
FILE_FIELDS = ("file", "bulk", "slab2.bulk", "sheet", "slab2.sheet")


def parse_recipe(data: dict[str, Any], field: str = SECTION) -> Any:
    """A recipe model from a dict; one-line InputError naming the first bad field."""
    try:
        return _ADAPTER.validate_python(data)
    except ValidationError as exc:
        err = exc.errors()[0]
        if err["type"] in ("union_tag_not_found", "union_tag_invalid"):
            raise InputError(
                f"{field}.kind={data.get('kind')!r}: expected one of {', '.join(KINDS)}"
            ) from None
        parts = [str(p) for p in err["loc"]]
        if parts and parts[0] in KINDS:  # the union's tag, not a field
            parts = parts[1:]
        if parts[:1] == ["slab2"] and parts[1:2] in (["bulk"], ["sheet"]):  # slab2's tag
            parts = parts[:1] + parts[2:]
        loc = ".".join(parts)
        msg = str(err["msg"]).removeprefix("Value error, ")  # pydantic's, not the user's
        if err["type"] == "extra_forbidden":
            msg = "unknown field"
        raise InputError(f"{field}.{loc}: {msg}" if loc else f"{field}: {msg}") from None


def input_files(recipe: Any) -> list[Path]:
    """Files whose content enters the interface (for fingerprints): bulk, sheet and interface files."""
    out = []
    for dotted in FILE_FIELDS:
        obj = recipe
        for part in dotted.split("."):
            obj = getattr(obj, part, None)
            if obj is None:
                break
        if isinstance(obj, str) and obj not in BUILTIN_SHEETS:
            out.append(Path(obj))
    return out


def resolve_paths(recipe: Any, base_dir: str | Path) -> Any:
    """A copy of ``recipe`` with relative file fields made relative to ``base_dir``."""
    base = Path(base_dir)

    def fix(value: str) -> str:
        if value in BUILTIN_SHEETS or Path(value).is_absolute():
            return value
        return str(base / value)

    data = recipe.model_dump()
    for dotted in FILE_FIELDS:
        parts = dotted.split(".")
        holder = data
        for part in parts[:-1]:
            holder = holder.get(part) if isinstance(holder, dict) else None
        if isinstance(holder, dict) and isinstance(holder.get(parts[-1]), str):
            holder[parts[-1]] = fix(holder[parts[-1]])
    return parse_recipe(data)
