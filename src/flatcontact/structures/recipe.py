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

Entry points: :func:`parse_recipe` (dict → model, one-line InputError naming the field)
and :func:`build_interface` (model → tagged interface + report).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from ase import Atoms
from pydantic import BaseModel, ConfigDict, Field, TypeAdapter, ValidationError, model_validator

from flatcontact.errors import InputError, require

_FIELD = "structure"


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


class MatchSettings(_Model):
    """Bounds of the coincidence-lattice search (hetero-interfaces) and of the atom count."""

    max_strain_percent: float = Field(
        3.0, gt=0, le=20, description="largest principal strain put on either slab (%)"
    )
    max_atoms: int = Field(400, ge=2, description="largest number of atoms of the interface")
    strain_on: Literal["slab2", "both"] = Field(
        "slab2",
        description="slab2: slab 1 keeps its lattice, slab 2 takes the strain; "
        "both: the common cell is the mean of the two",
    )


class _PairOptions(_Model):
    held_layers: int = Field(1, ge=1, description="outer layers held (rigid) per slab")
    rotate_deg: float = Field(
        0.0,
        description="slab 2 rotated about z by this angle (a symmetry of its lattice, e.g. 180); "
        "for sheets about the midpoint of the shortest unlike bond",
    )
    twist: tuple[int, int] | None = Field(
        None,
        description="commensurate twist (m, n) of a hexagonal lattice: slab 2 rotated by "
        "acos((m²+4mn+n²)/(2(m²+mn+n²))), (1, 2) → 21.787°",
    )
    match: MatchSettings = Field(default_factory=MatchSettings)
    fmax_ev_per_angstrom: float = Field(
        0.01,
        gt=0,
        description="force tolerance of the reference relaxation (when a calculator is given)",
    )


class SheetSlab(_Model):
    """One slab of 2D sheets."""

    sheet: str = Field(description="built-in graphene | h-BN | MoS2, or a monolayer file")
    layers: int = Field(1, ge=1, description="sheets in this slab")
    stacking: str = Field("AB", description="stacking letters of this slab (see docs)")
    interlayer_angstrom: float | None = Field(
        None,
        gt=0,
        description="distance between adjacent sheets (mean planes); built-ins: bulk value",
    )


class SheetsRecipe(_PairOptions):
    """2D monolayers stacked into two slabs."""

    kind: Literal["sheets"] = "sheets"
    sheet: str = Field(description="built-in graphene | h-BN | MoS2, or a monolayer file")
    layers: int = Field(1, ge=1, description="sheets per slab")
    stacking: str = Field(
        "AB",
        description="letters A, B, C (optionally primed) for the whole stack, slab 1 then slab 2, "
        "repeated: AB = Bernal, AA' = h-BN AA′ / 2H-MoS2",
    )
    interlayer_angstrom: float | None = Field(
        None, gt=0, description="distance between adjacent sheets"
    )
    interface_spacing_angstrom: float | None = Field(
        None,
        gt=0,
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


class CrystalRecipe(_PairOptions):
    """Slabs cut from a bulk crystal."""

    kind: Literal["crystal"] = "crystal"
    bulk: str = Field(description="bulk crystal file, any format ASE reads (CIF, POSCAR, extxyz)")
    miller: tuple[int, int, int] = Field(description="Miller index in the file's cell")
    layers: int = Field(6, ge=1, description="bulk repeats (layers) per slab")
    termination: int = Field(
        0, ge=0, description="which cut (0 = widest gap between atomic planes)"
    )
    gap_angstrom: float | None = Field(
        None, gt=0, description="highest atom of slab 1 to lowest of slab 2 (default: the bulk's)"
    )
    flip: bool = Field(False, description="slab 2 = slab 1 upside down (rotated 180° about a1)")
    slab2: CrystalSlab | None = Field(None, description="another crystal for slab 2")


class Fcc111Slab(_Model):
    element: str
    a_angstrom: float | None = Field(None, gt=0)
    layers: int = Field(6, ge=1)


class Fcc111Recipe(_PairOptions):
    """fcc(111) metal slabs (ase.build.fcc111), one close-packed plane per layer."""

    kind: Literal["fcc111"] = "fcc111"
    element: str = Field(description="Cu, Ni, Al, ... (fcc)")
    a_angstrom: float | None = Field(
        None, gt=0, description="lattice constant (default: ASE's reference)"
    )
    layers: int = Field(6, ge=1, description="close-packed planes per slab")
    gap_angstrom: float | None = Field(
        None,
        gt=0,
        description="distance between the facing planes (default a/√3: the perfect crystal)",
    )
    slab2: Fcc111Slab | None = Field(None, description="another fcc metal for slab 2")


class QuartzDenseRecipe(_Model):
    """The paper's α-quartz (0001) dense interface (flatcontact.structures.build)."""

    kind: Literal["quartz-dense"] = "quartz-dense"
    layers: int = Field(6, description="O-Si-O layers per slab (>= 5)")
    source: Literal["auto", "shipped", "seed"] = "auto"
    gap_angstrom: float = Field(3.0, gt=0)
    fmax_ev_per_angstrom: float = Field(0.01, gt=0)

    @model_validator(mode="after")
    def _layers(self) -> QuartzDenseRecipe:
        from flatcontact.structures.build import MIN_LAYERS

        if self.layers < MIN_LAYERS:
            raise ValueError(
                f"layers={self.layers}: the dense quartz interface needs >= {MIN_LAYERS}"
            )
        return self


class FileRecipe(_Model):
    """A prepared interface.extxyz following the contract."""

    kind: Literal["file"] = "file"
    file: str = Field(description="path of an interface.extxyz")


class SlabFileRecipe(_Model):
    """A prepared slab file: two copies facing each other, layers found from the structure."""

    kind: Literal["slab"] = "slab"
    file: str = Field(
        description="slab file (any format ASE reads), periodic along cell vectors 1, 2"
    )
    gap_angstrom: float = Field(
        3.0, gt=0, description="highest atom of slab 1 to lowest of slab 2 (Å)"
    )
    held_layers: int = Field(1, ge=1, description="outer layers held (rigid) per slab")
    flip: bool = Field(False, description="slab 2 = slab 1 upside down (rotated 180° about a1)")
    fmax_ev_per_angstrom: float = Field(
        0.01,
        gt=0,
        description="force tolerance of the reference relaxation (when a calculator is given)",
    )


class ToyRecipe(_Model):
    """The toy two-slab Lennard-Jones interface (flatcontact.ispes.toy)."""

    kind: Literal["toy-lj"] = "toy-lj"
    layers: int = Field(3, ge=3)
    params: dict[str, float] = Field(
        default_factory=dict, description="ToyPairCalculator parameters"
    )


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


def parse_recipe(data: dict[str, Any], field: str = _FIELD) -> Any:
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
        loc = ".".join(parts)
        raise InputError(
            f"{field}.{loc}: {err['msg']}" if loc else f"{field}: {err['msg']}"
        ) from None


def input_files(recipe: Any) -> list[Path]:
    """Files whose content enters the interface (for fingerprints): bulk, sheet and interface files."""
    from flatcontact.structures.sheets import BUILTIN_SHEETS

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
    from flatcontact.structures.sheets import BUILTIN_SHEETS

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


# --------------------------------------------------------------------------- sources
def _sheet_source(sheet: str, stacking: str, interlayer: float | None, field: str):
    from flatcontact.structures.crystal import file_record
    from flatcontact.structures.sheets import BUILTIN_SHEETS, builtin_sheet, check_sheet
    from flatcontact.structures.sources import sheet_source

    if sheet in BUILTIN_SHEETS:
        atoms = builtin_sheet(sheet)
        record = {"sheet": sheet, "a_angstrom": BUILTIN_SHEETS[sheet].a_angstrom}
        interlayer = interlayer or BUILTIN_SHEETS[sheet].interlayer_angstrom
        material = sheet
    else:
        from ase.io import read

        path = Path(sheet)
        require(
            path.is_file(),
            f"{field}.sheet: '{sheet}' is neither a built-in sheet ({', '.join(BUILTIN_SHEETS)}) nor a file",
        )
        try:
            raw = read(path)
        except Exception as exc:  # any reader error
            raise InputError(
                f"{field}.sheet: '{path}' is not a structure file ASE can read ({type(exc).__name__}: {exc})"
            ) from None
        atoms = check_sheet(raw, f"{field}.sheet '{path.name}'")
        require(
            interlayer is not None,
            f"{field}.interlayer_angstrom: required for a sheet read from a file",
        )
        record = file_record(path)
        material = atoms.get_chemical_formula(mode="hill")
    record = {**record, "stacking": stacking, "interlayer_angstrom": interlayer}
    return sheet_source(atoms, material, stacking, interlayer, record, f"{field}.stacking")


def _crystal_source(bulk: str, miller, termination: int, field: str):
    from flatcontact.structures.crystal import file_record, orient, read_bulk
    from flatcontact.structures.sources import crystal_source

    atoms = read_bulk(bulk, f"{field}.bulk")
    oriented = orient(atoms, miller, f"{field}.miller")
    material = f"{atoms.get_chemical_formula(mode='hill', empirical=True)}({''.join(str(v) for v in oriented.miller)})"
    record = {**file_record(bulk), **oriented.record, "termination": termination}
    n = len(oriented.cuts_angstrom)
    require(
        termination < n,
        f"{field}.termination={termination}: expected 0..{n - 1} ({n} distinct terminations)",
    )
    return crystal_source(oriented, termination, material, record, f"{field}.termination")


def _sources(recipe) -> tuple[Any, Any | None, int, int]:
    """(source of slab 1, source of slab 2 or None for the same material, layers 1, layers 2)."""
    from flatcontact.structures.sources import fcc111_source

    if isinstance(recipe, SheetsRecipe):
        s1 = _sheet_source(recipe.sheet, recipe.stacking, recipe.interlayer_angstrom, _FIELD)
        s2 = None
        n2 = recipe.layers
        if recipe.slab2 is not None:
            s2 = _sheet_source(
                recipe.slab2.sheet,
                recipe.slab2.stacking,
                recipe.slab2.interlayer_angstrom,
                f"{_FIELD}.slab2",
            )
            n2 = recipe.slab2.layers
        return s1, s2, recipe.layers, n2
    if isinstance(recipe, CrystalRecipe):
        s1 = _crystal_source(recipe.bulk, recipe.miller, recipe.termination, _FIELD)
        if recipe.slab2 is None:
            return s1, None, recipe.layers, recipe.layers
        s2 = _crystal_source(
            recipe.slab2.bulk, recipe.slab2.miller, recipe.slab2.termination, f"{_FIELD}.slab2"
        )
        return s1, s2, recipe.layers, recipe.slab2.layers
    s1 = fcc111_source(recipe.element, recipe.a_angstrom, {"element": recipe.element})
    if recipe.slab2 is None:
        return s1, None, recipe.layers, recipe.layers
    e2 = recipe.slab2
    return (
        s1,
        fcc111_source(e2.element, e2.a_angstrom, {"element": e2.element}),
        recipe.layers,
        e2.layers,
    )


# --------------------------------------------------------------------------- assembly
def _spacing(recipe, s1, s2) -> tuple[float, str]:
    """Distance across the interface and how it is measured (planes | atoms)."""
    default = (
        s1.spacing_angstrom if s2 is None else 0.5 * (s1.spacing_angstrom + s2.spacing_angstrom)
    )
    if isinstance(recipe, SheetsRecipe):
        return recipe.interface_spacing_angstrom or default, "planes"
    if isinstance(recipe, CrystalRecipe):
        return recipe.gap_angstrom or default, "atoms"
    return recipe.gap_angstrom or default, "planes"


def _flip(slab: Atoms, field: str) -> Atoms:
    """``slab`` rotated by 180° about the x axis (a1): z → −z, y → −y, layers renumbered."""
    from flatcontact.structures.cell2d import lattice_is_invariant

    require(
        lattice_is_invariant(slab.cell.array[:2, :2], np.diag([1.0, -1.0])),
        f"{field}.flip: the in-plane lattice is not symmetric under y -> -y; slab 2 cannot be "
        "flipped onto the same cell",
    )
    out = slab.copy()
    out.positions[:, 1] *= -1.0
    out.positions[:, 2] = (
        out.positions[:, 2].max() + out.positions[:, 2].min() - out.positions[:, 2]
    )
    layer = np.asarray(out.arrays["layer"])
    out.arrays["layer"] = layer.max() + 1 - layer
    out.wrap()
    return out


def build_from_slab_file(recipe: SlabFileRecipe) -> tuple[Atoms, dict]:
    """Two copies of a slab file facing each other (slab 2 translated, or flipped)."""
    from ase.io import read

    from flatcontact.structures.assemble import finish_interface, stack_pair
    from flatcontact.structures.cell2d import standard_slab
    from flatcontact.structures.crystal import file_record
    from flatcontact.structures.layers import slab_layers

    path = Path(recipe.file)
    require(path.is_file(), f"{_FIELD}.file: '{path}' not found")
    try:
        raw = read(path)
    except Exception as exc:  # any reader error
        raise InputError(
            f"{_FIELD}.file: '{path}' is not a structure file ASE can read ({type(exc).__name__}: {exc})"
        ) from None
    raw.pbc = (True, True, False)
    try:
        slab = standard_slab(raw)
    except InputError as exc:
        raise InputError(f"{_FIELD}.file '{path.name}': {exc}") from None
    layers, rule = slab_layers(slab, f"{_FIELD}.file '{path.name}'")
    slab.arrays["layer"] = layers
    count = int(layers.max())
    require(
        count == 1 or count >= recipe.held_layers + 1,
        f"{_FIELD}.held_layers={recipe.held_layers}: the slab has {count} layers ({rule})",
    )
    upper = _flip(slab, _FIELD) if recipe.flip else slab.copy()
    atoms = stack_pair(slab, upper, recipe.gap_angstrom, by="atoms")
    material = slab.get_chemical_formula(mode="hill", empirical=True)
    record = {
        "kind": "slab",
        **file_record(path),
        "layers_per_slab": count,
        "layer_rule": rule,
        "held_layers": recipe.held_layers,
        "gap_angstrom": recipe.gap_angstrom,
        "slab2_operation": "flipped upside down (180° about a1)"
        if recipe.flip
        else "translated copy",
    }
    return finish_interface(atoms, recipe.held_layers, material, record), record


def build_generic(recipe) -> tuple[Atoms, dict]:
    """Interface of a ``sheets``, ``crystal`` or ``fcc111`` recipe (unrelaxed) and its report."""
    from flatcontact.structures.assemble import finish_interface, split_stack, stack_pair
    from flatcontact.structures.match import (
        apply_supercell,
        atom_count,
        coincidence_match,
        identity_match,
        twist_match,
    )
    from flatcontact.structures.sheets import rotate_in_plane, rotation_centre

    s1, s2, n1, n2 = _sources(recipe)
    for which, n in ((1, n1), (2, n2)):
        require(
            n == 1 or n >= recipe.held_layers + 1,
            f"{_FIELD}.held_layers={recipe.held_layers}: slab {which} has {n} layers; expected "
            "one layer (held whole) or at least held_layers + 1 (a free face layer)",
        )
    spacing, by = _spacing(recipe, s1, s2)
    bounds = recipe.match
    flip = getattr(recipe, "flip", False)
    record: dict[str, Any] = {
        "kind": recipe.kind,
        "slab1": {**s1.record, "material": s1.material, "layers": n1},
        "slab2": {**(s2 or s1).record, "material": (s2 or s1).material, "layers": n2},
        "held_layers": recipe.held_layers,
        "interface_spacing_angstrom": spacing,
        "spacing_measured_between": "mean planes" if by == "planes" else "closest atoms",
    }
    material = s1.material if s2 is None else f"{s1.material}/{s2.material}"
    if recipe.twist is not None and s2 is not None:
        raise InputError(
            f"{_FIELD}.twist: a twist needs the same material in both slabs (no slab2)"
        )
    continuation = s2 is None and recipe.twist is None and recipe.rotate_deg == 0 and not flip
    if continuation:
        match = identity_match(s1.cell2)
        require(
            atom_count(match, n1 * s1.atoms_per_layer, n2 * s1.atoms_per_layer) <= bounds.max_atoms,
            f"{_FIELD}.match.max_atoms={bounds.max_atoms}: the interface has "
            f"{(n1 + n2) * s1.atoms_per_layer} atoms",
        )
        stack = s1.make(n1 + n2)
        from flatcontact.structures.assemble import layer_plane

        if by == "planes":
            natural = layer_plane(stack, n1 + 1) - layer_plane(stack, n1)
        else:
            layer, z = np.asarray(stack.arrays["layer"]), stack.positions[:, 2]
            natural = float(z[layer == n1 + 1].min() - z[layer == n1].max())
        atoms = split_stack(stack, n1, spacing - natural)
        record["slab2_operation"] = "continuation of slab 1's stacking"
        record["match"] = match.report(
            s1.cell2, s1.cell2, n1 * s1.atoms_per_layer, n2 * s1.atoms_per_layer
        )
        return finish_interface(atoms, recipe.held_layers, material, record), record
    src2 = s2 or s1
    slab1 = s1.make(n1)
    slab2 = src2.make(n2)
    operations = []
    if flip:
        slab2 = _flip(slab2, _FIELD)
        operations.append("flipped upside down (180° about a1)")
    if recipe.rotate_deg:
        centre = rotation_centre(slab2[np.asarray(slab2.arrays["layer"]) == 1])
        try:
            slab2 = rotate_in_plane(slab2, recipe.rotate_deg, centre)
        except InputError as exc:
            raise InputError(f"{_FIELD}.rotate_deg: {exc}") from None
        operations.append(
            f"rotated {recipe.rotate_deg:g}° about z through ({centre[0]:.4f}, {centre[1]:.4f}) Å"
        )
    na1, na2 = n1 * s1.atoms_per_layer, n2 * src2.atoms_per_layer
    if recipe.twist is not None:
        match, theta = twist_match(s1.cell2, *recipe.twist, field=f"{_FIELD}.twist")
        operations.append(f"twisted by {theta:.6f}° (commensurate (m, n) = {list(recipe.twist)})")
        record["twist_angle_deg"] = theta
    elif s2 is not None and not np.allclose(s1.cell2, s2.cell2, atol=1e-6):
        match = coincidence_match(
            s1.cell2,
            s2.cell2,
            na1,
            na2,
            max_strain=bounds.max_strain_percent / 100.0,
            max_atoms=bounds.max_atoms,
            strain_on=bounds.strain_on,
            field=f"{_FIELD}.slab2",
        )
    else:
        match = identity_match(s1.cell2)
    n_atoms = atom_count(match, na1, na2)
    require(
        n_atoms <= bounds.max_atoms,
        f"{_FIELD}.match.max_atoms={bounds.max_atoms}: the interface has {n_atoms} atoms",
    )
    record["slab2_operation"] = "; ".join(operations) or "none (another material)"
    record["match"] = match.report(s1.cell2, src2.cell2, na1, na2)
    slab1 = apply_supercell(slab1, match.p1, match.cell)
    slab2 = apply_supercell(slab2, match.p2, match.cell)
    atoms = stack_pair(slab1, slab2, spacing, by=by)
    return finish_interface(atoms, recipe.held_layers, material, record), record


# --------------------------------------------------------------------------- entry point
def build_interface(
    recipe: Any,
    *,
    potential: Any = None,
    relax_calculator: Any = None,
) -> tuple[Atoms, dict]:
    """The reference interface of ``recipe`` and a JSON-ready report (build stage).

    Parameters
    ----------
    recipe
        A model of :data:`StructureRecipe` (or a dict, parsed with :func:`parse_recipe`),
        file paths already resolved (:func:`resolve_paths`).
    potential
        ``quartz-dense`` only: the potential spec the dense slabs are relaxed and
        verified with (:func:`flatcontact.structures.build.build_quartz_interface`).
    relax_calculator
        ``sheets``/``crystal``/``fcc111``/``slab``: an ASE calculator or a callable(atoms) → calculator;
        when given, the whole interface is relaxed once (no atom held, FIRE to the recipe's
        ``fmax_ev_per_angstrom``), as the quartz builder does; without it the interface is the
        ideal stacking.

    Every check of the input (files, Miller index, terminations, match bounds, atom count)
    runs before any relaxation; a bad value is a one-line InputError naming the field.
    """
    if isinstance(recipe, dict):
        recipe = parse_recipe(recipe)
    if isinstance(recipe, QuartzDenseRecipe):
        from flatcontact.structures.build import build_quartz_interface

        require(
            potential is not None,
            f"{_FIELD}.kind=quartz-dense needs a potential to relax the dense slabs",
        )
        atoms, report = build_quartz_interface(
            potential,
            recipe.layers,
            source=recipe.source,
            gap_angstrom=recipe.gap_angstrom,
            fmax_ev_per_angstrom=recipe.fmax_ev_per_angstrom,
        )
        return atoms, report
    if isinstance(recipe, FileRecipe):
        from flatcontact.structures.crystal import file_record
        from flatcontact.structures.interface import read_interface, thickness

        atoms = read_interface(recipe.file)
        return atoms, {
            "source": file_record(recipe.file),
            "n_atoms": len(atoms),
            "thickness_angstrom": thickness(atoms),
        }
    if isinstance(recipe, ToyRecipe):
        from flatcontact.ispes.toy import toy_interface
        from flatcontact.structures.interface import thickness

        atoms = toy_interface(recipe.layers, **recipe.params)
        atoms.arrays["held"] = np.isin(atoms.arrays["surface"], (1, 4))
        atoms.arrays["layer"] = np.arange(1, len(atoms) + 1)
        atoms.info["material"] = "toy LJ fcc(111)"
        return atoms, {
            "source": "flatcontact.ispes.toy",
            "n_atoms": len(atoms),
            "thickness_angstrom": thickness(atoms),
        }
    if isinstance(recipe, SlabFileRecipe):
        atoms, record = build_from_slab_file(recipe)
    else:
        atoms, record = build_generic(recipe)
    report: dict[str, Any] = {
        "recipe": record,
        "n_atoms": len(atoms),
        "material": atoms.info["material"],
    }
    if relax_calculator is not None:
        from flatcontact.structures.dense import relax

        calc = (
            relax_calculator(atoms)
            if callable(relax_calculator) and not hasattr(relax_calculator, "get_potential_energy")
            else relax_calculator
        )
        report["interface_relaxation"] = relax(
            atoms, calc, fmax_ev_per_angstrom=recipe.fmax_ev_per_angstrom
        )
        atoms.calc = None
    from flatcontact.structures.interface import thickness

    record["thickness_angstrom"] = thickness(atoms)
    atoms.info["recipe"] = json.dumps(record, sort_keys=True)
    report["thickness_angstrom"] = thickness(atoms)
    return atoms, report
