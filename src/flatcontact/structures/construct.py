"""Building the interface of a recipe (:mod:`flatcontact.structures.recipe`).

:func:`build_interface` is the build stage's entry point for every ``kind``: the quartz
builder for ``quartz-dense``, the contract reader for ``file``, the toy
(:mod:`~flatcontact.structures.toy`) for ``toy-lj``, and for ``sheets``, ``crystal``,
``fcc111`` and ``slab`` the slab sources (:mod:`~flatcontact.structures.sources`), the
common in-plane cell (:mod:`~flatcontact.structures.match`) and the tagging
(:mod:`~flatcontact.structures.assemble`). Every check of the input runs before any
relaxation.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
from ase import Atoms

from flatcontact.foundation.errors import InputError, require
from flatcontact.structures.assemble import finish_interface, layer_plane, split_stack, stack_pair
from flatcontact.structures.build import build_quartz_interface
from flatcontact.structures.cell2d import lattice_is_invariant, standard_slab
from flatcontact.structures.crystal import crystal_slab, file_record, orient, read_bulk
from flatcontact.structures.dense import relax
from flatcontact.structures.interface_contract import CONTINUATION, thickness
from flatcontact.structures.interface_io import read_interface
from flatcontact.structures.lattice import LatticeChoice
from flatcontact.structures.layers import slab_layers
from flatcontact.structures.match import (
    apply_supercell,
    atom_count,
    coincidence_match,
    explicit_match,
    identity_match,
    strain_and_rotation,
    twist_match,
)
from flatcontact.structures.recipe import (
    SECTION,
    CrystalRecipe,
    FileRecipe,
    QuartzDenseRecipe,
    SheetSlab,
    SheetsRecipe,
    SlabFileRecipe,
    ToyRecipe,
    parse_recipe,
)
from flatcontact.structures.sheets import (
    BUILTIN_SHEETS,
    builtin_sheet,
    check_sheet,
    rotate_in_plane,
    rotation_centre,
)
from flatcontact.structures.sources import (
    crystal_source,
    fcc111_source,
    passivated_crystal_source,
    sheet_source,
)
from flatcontact.structures.structure_file import read_structure
from flatcontact.structures.toy import toy_interface


# --------------------------------------------------------------------------- sources
def _sheet_source(
    sheet: str,
    stacking: str,
    interlayer: float | None,
    field: str,
    lattice: LatticeChoice | None = None,
    slab: str = "slab1",
):
    if sheet in BUILTIN_SHEETS:
        atoms = builtin_sheet(sheet)
        record = {"sheet": sheet, "a_angstrom": BUILTIN_SHEETS[sheet].a_angstrom}
        interlayer = interlayer or BUILTIN_SHEETS[sheet].interlayer_angstrom
        material = sheet
    else:
        path = Path(sheet)
        require(
            path.is_file(),
            f"{field}.sheet: '{sheet}' is neither a built-in sheet ({', '.join(BUILTIN_SHEETS)}) nor a file",
        )
        raw = read_structure(path, f"{field}.sheet")
        atoms = check_sheet(raw, f"{field}.sheet '{path.name}'")
        require(
            interlayer is not None,
            f"{field}.interlayer_angstrom: required for a sheet read from a file",
        )
        record = file_record(path)
        material = atoms.get_chemical_formula(mode="hill")
    record = {**record, "stacking": stacking, "interlayer_angstrom": interlayer}
    if lattice is not None:
        fit = lattice.sheet(("sheet", sheet), atoms, material, interlayer)
        pot = fit.scaled(atoms)
        record["lattice"] = lattice.note(
            slab, fit, atoms.cell.array[:2, :2], pot.cell.array[:2, :2]
        )
        if lattice.use_potential:
            atoms = pot
            if "a_angstrom" in record:
                record["a_angstrom"] = float(np.linalg.norm(atoms.cell.array[0]))
    return sheet_source(atoms, material, stacking, interlayer, record, f"{field}.stacking")


def _faces(passivate_faces: str, interface_face: str) -> tuple[str, ...]:
    """Faces (bottom, top) of a slab to passivate: its interface face, or both."""
    return ("bottom", "top") if passivate_faces == "both" else (interface_face,)


def _crystal_source(
    bulk: str,
    miller,
    termination: int,
    field: str,
    passivate: str = "none",
    faces: tuple[str, ...] = (),
    same_material: bool = False,
    lattice: LatticeChoice | None = None,
    slab: str = "slab1",
):
    atoms = read_bulk(bulk, f"{field}.bulk")
    oriented = orient(atoms, miller, f"{field}.miller")
    material = f"{atoms.get_chemical_formula(mode='hill', empirical=True)}({''.join(str(v) for v in oriented.miller)})"
    record = {**file_record(bulk), **oriented.record, "termination": termination}
    n = len(oriented.cuts_angstrom)
    require(
        termination < n,
        f"{field}.termination={termination}: expected 0..{n - 1} ({n} distinct terminations)",
    )
    if lattice is not None:
        fit = lattice.bulk(("bulk", str(bulk)), atoms, material, oriented.miller)
        at_potential = orient(fit.scaled(atoms), miller, f"{field}.miller")
        cells = [
            crystal_slab(o, 1, termination).cell.array[:2, :2] for o in (oriented, at_potential)
        ]
        record["lattice"] = lattice.note(slab, fit, *cells)
        if lattice.use_potential:
            oriented = at_potential
            record["repeat_angstrom"] = oriented.repeat_angstrom
    if passivate != "none":
        return passivated_crystal_source(
            oriented,
            termination,
            faces,
            passivate,
            material,
            record,
            f"{field}.passivate",
            same_material,
        )
    return crystal_source(oriented, termination, material, record, f"{field}.termination")


def slab_sources(recipe, lattice: LatticeChoice | None = None) -> tuple[Any, Any | None, int, int]:
    """(source of slab 1, source of slab 2 or None for the same material, layers 1, layers 2).

    ``lattice``: each material at the run's model's lattice or the file's, recorded
    (:class:`~flatcontact.structures.lattice.LatticeChoice`); ``None``: the file's, unrecorded.
    """
    if isinstance(recipe, SheetsRecipe):
        s1 = _sheet_source(
            recipe.sheet, recipe.stacking, recipe.interlayer_angstrom, SECTION, lattice
        )
        s2 = None
        n2 = recipe.layers
        if recipe.slab2 is not None:
            s2 = _sheet_source(
                recipe.slab2.sheet,
                recipe.slab2.stacking,
                recipe.slab2.interlayer_angstrom,
                f"{SECTION}.slab2",
                lattice,
                "slab2",
            )
            n2 = recipe.slab2.layers
        return s1, s2, recipe.layers, n2
    if isinstance(recipe, CrystalRecipe):
        # slab 1's interface face is its top; slab 2's its bottom (its top before a flip)
        args = (recipe.bulk, recipe.miller, recipe.termination, SECTION, recipe.passivate)
        s1 = _crystal_source(*args, _faces(recipe.passivate_faces, "top"), lattice=lattice)
        e2 = recipe.slab2
        if e2 is None and recipe.passivate == "none":
            return s1, None, recipe.layers, recipe.layers
        if e2 is None:  # the same crystal, its own interface face passivated
            face2 = "top" if recipe.flip else "bottom"
            s2 = _crystal_source(
                *args, _faces(recipe.passivate_faces, face2), True, lattice, "slab2"
            )
            return s1, s2, recipe.layers, recipe.layers
        if isinstance(e2, SheetSlab):
            field2 = f"{SECTION}.slab2"
            s2 = _sheet_source(
                e2.sheet, e2.stacking, e2.interlayer_angstrom, field2, lattice, "slab2"
            )
            return s1, s2, recipe.layers, e2.layers
        s2 = _crystal_source(
            e2.bulk,
            e2.miller,
            e2.termination,
            f"{SECTION}.slab2",
            e2.passivate,
            _faces(e2.passivate_faces, "bottom"),
            lattice=lattice,
            slab="slab2",
        )
        return s1, s2, recipe.layers, e2.layers
    s1 = _fcc111_source(recipe.element, recipe.a_angstrom, lattice, "slab1")
    if recipe.slab2 is None:
        return s1, None, recipe.layers, recipe.layers
    e2 = recipe.slab2
    return s1, _fcc111_source(e2.element, e2.a_angstrom, lattice, "slab2"), recipe.layers, e2.layers


def _fcc111_source(element: str, a_angstrom: float | None, lattice, slab: str):
    """fcc(111) planes of ``element`` at ``a_angstrom`` (or ASE's), or at the model's lattice."""
    if lattice is None:
        return fcc111_source(element, a_angstrom, {"element": element})
    from ase.build import bulk as ase_bulk

    a_file = fcc111_source(element, a_angstrom, {}).record["a_angstrom"]
    crystal = ase_bulk(element, "fcc", a=a_file)  # primitive: (111) is its own (111)
    fit = lattice.bulk(("fcc", element, a_file), crystal, f"{element}(111)", (1, 1, 1))
    a_pot = a_file * float(np.linalg.norm(fit.potential_cell[0]) / np.linalg.norm(fit.file_cell[0]))
    cells = [fcc111_source(element, a, {}).cell2 for a in (a_file, a_pot)]
    rec = {"element": element, "lattice": lattice.note(slab, fit, *cells)}
    return fcc111_source(element, a_pot if lattice.use_potential else a_file, rec)


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
    path = Path(recipe.file)
    require(path.is_file(), f"{SECTION}.file: '{path}' not found")
    raw = read_structure(path, f"{SECTION}.file")
    raw.pbc = (True, True, False)
    try:
        slab = standard_slab(raw)
    except InputError as exc:
        raise InputError(f"{SECTION}.file '{path.name}': {exc}") from None
    layers, rule = slab_layers(slab, f"{SECTION}.file '{path.name}'")
    slab.arrays["layer"] = layers
    count = int(layers.max())
    require(
        count == 1 or count >= recipe.held_layers + 1,
        f"{SECTION}.held_layers={recipe.held_layers}: the slab has {count} layers ({rule})",
    )
    upper = _flip(slab, SECTION) if recipe.flip else slab.copy()
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


def _strain_vs_potential(match, s1, s2) -> dict:
    """``slab{i}_strain_vs_potential_percent``: the principal strains of each slab of a
    coincidence cell against its own potential lattice (the match's own strains are against
    the lattices used, which are the potential's unless ``structure.lattice: file``)."""
    out = {}
    for which, source in ((1, s1), (2, s2)):
        lat = source.record.get("lattice")
        if lat is None:
            continue
        cell2 = np.asarray(lat["in_plane_potential_cell_angstrom"], float)
        strains, _ = strain_and_rotation(match.deformation(which, cell2))
        out[f"slab{which}_strain_vs_potential_percent"] = [round(100 * v, 6) for v in strains]
    return out


def build_generic(recipe, lattice: LatticeChoice | None = None) -> tuple[Atoms, dict]:
    """Interface of a ``sheets``, ``crystal`` or ``fcc111`` recipe (unrelaxed) and its report.

    ``lattice``: the slabs' lattices (:func:`slab_sources`); with the file's kept, a slab
    strained beyond the threshold is refused here, before any relaxation."""
    s1, s2, n1, n2 = slab_sources(recipe, lattice)
    if lattice is not None:
        lattice.check(f"{SECTION}.lattice")
    for which, n in ((1, n1), (2, n2)):
        require(
            n == 1 or n >= recipe.held_layers + 1,
            f"{SECTION}.held_layers={recipe.held_layers}: slab {which} has {n} layers; expected "
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
    other = s2 is not None and not s2.same_material  # another material as slab 2
    material = f"{s1.material}/{s2.material}" if other else s1.material
    if recipe.twist is not None and other:
        raise InputError(
            f"{SECTION}.twist: a twist needs the same material in both slabs (no slab2)"
        )
    explicit = bounds.slab1_supercell is not None
    if explicit and (
        recipe.twist is not None or not other or np.allclose(s1.cell2, s2.cell2, atol=1e-6)
    ):
        raise InputError(
            f"{SECTION}.match.slab1_supercell: explicit supercells are for a coincidence lattice "
            "of two materials of different lattices (slab2 another material, no twist)"
        )
    continuation = s2 is None and recipe.twist is None and recipe.rotate_deg == 0 and not flip
    if continuation:
        match = identity_match(s1.cell2)
        require(
            atom_count(match, n1 * s1.atoms_per_layer, n2 * s1.atoms_per_layer) <= bounds.max_atoms,
            f"{SECTION}.match.max_atoms={bounds.max_atoms}: the interface has "
            f"{(n1 + n2) * s1.atoms_per_layer} atoms",
        )
        stack = s1.make(n1 + n2)
        if by == "planes":
            natural = layer_plane(stack, n1 + 1) - layer_plane(stack, n1)
        else:
            layer, z = np.asarray(stack.arrays["layer"]), stack.positions[:, 2]
            natural = float(z[layer == n1 + 1].min() - z[layer == n1].max())
        atoms = split_stack(stack, n1, spacing - natural)
        record["slab2_operation"] = CONTINUATION
        record["match"] = match.report(
            s1.cell2, s1.cell2, n1 * s1.atoms_per_layer, n2 * s1.atoms_per_layer
        )
        return finish_interface(atoms, recipe.held_layers, material, record), record
    src2 = s2 or s1
    slab1 = s1.make(n1)
    slab2 = src2.make(n2)
    operations = []
    if flip:
        slab2 = _flip(slab2, SECTION)
        operations.append("flipped upside down (180° about a1)")
    if recipe.rotate_deg:
        centre = rotation_centre(slab2[np.asarray(slab2.arrays["layer"]) == 1])
        try:
            slab2 = rotate_in_plane(slab2, recipe.rotate_deg, centre)
        except InputError as exc:
            raise InputError(f"{SECTION}.rotate_deg: {exc}") from None
        operations.append(
            f"rotated {recipe.rotate_deg:g}° about z through ({centre[0]:.4f}, {centre[1]:.4f}) Å"
        )
    na1, na2 = len(slab1), len(slab2)  # n_i layers x atoms per layer, + passivating atoms
    if recipe.twist is not None:
        match, theta = twist_match(s1.cell2, *recipe.twist, field=f"{SECTION}.twist")
        operations.append(f"twisted by {theta:.6f}° (commensurate (m, n) = {list(recipe.twist)})")
        record["twist_angle_deg"] = theta
    elif other and not np.allclose(s1.cell2, s2.cell2, atol=1e-6) and explicit:
        match = explicit_match(
            s1.cell2,
            s2.cell2,
            bounds.slab1_supercell,
            bounds.slab2_supercell,
            max_strain=bounds.max_strain_percent / 100.0,
            strain_on=bounds.strain_on,
            field=f"{SECTION}.match",
        )
    elif other and not np.allclose(s1.cell2, s2.cell2, atol=1e-6):
        match = coincidence_match(
            s1.cell2,
            s2.cell2,
            na1,
            na2,
            max_strain=bounds.max_strain_percent / 100.0,
            max_atoms=bounds.max_atoms,
            strain_on=bounds.strain_on,
            field=f"{SECTION}.slab2",
        )
    else:
        match = identity_match(s1.cell2)
    n_atoms = atom_count(match, na1, na2)
    require(
        n_atoms <= bounds.max_atoms,
        f"{SECTION}.match.max_atoms={bounds.max_atoms}: the interface has {n_atoms} atoms",
    )
    record["slab2_operation"] = "; ".join(operations) or (
        "none (another material)" if other else "translated copy"
    )
    record["match"] = match.report(s1.cell2, src2.cell2, na1, na2)
    if other:  # each slab's strain against its own potential lattice
        record["match"].update(_strain_vs_potential(match, s1, src2))
    if explicit:
        record["match"]["supercells"] = "given (structure.match.slab1_supercell, slab2_supercell)"
    slab1 = apply_supercell(slab1, match.p1, match.cell)
    slab2 = apply_supercell(slab2, match.p2, match.cell)
    atoms = stack_pair(slab1, slab2, spacing, by=by)
    return finish_interface(atoms, recipe.held_layers, material, record), record


# --------------------------------------------------------------------------- entry point
#: Largest increase of the interface thickness (Å) the build's relaxation may make: slabs
#: that move apart by more are not bound with the model (or the crystal's atoms overlap and
#: blew the cell apart): a reference that is no contact, refused.
MAX_RELAXED_SEPARATION_ANGSTROM = 5.0


def check_relaxed_separation(before_angstrom: float, after_angstrom: float) -> None:
    """Refuse a build relaxation that moved the slabs apart by more than
    :data:`MAX_RELAXED_SEPARATION_ANGSTROM` (one line naming both thicknesses and the bound)."""
    moved = after_angstrom - before_angstrom
    if not moved <= MAX_RELAXED_SEPARATION_ANGSTROM:  # NaN too
        raise InputError(
            f"{SECTION}: the build relaxation moved the slabs apart by {moved:.3g} Å (thickness "
            f"{before_angstrom:.4g} -> {after_angstrom:.4g} Å), more than the "
            f"{MAX_RELAXED_SEPARATION_ANGSTROM:g} Å a bound interface moves: the slabs are not "
            f"bound with this model, or atoms of the crystal overlap; check the model's "
            f"cross-interface coupling, {SECTION}.gap_angstrom and the crystal file"
        )


def build_interface(
    recipe: Any,
    *,
    potential: Any = None,
    relax_calculator: Any = None,
    lattice_calculator: Any = None,
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
    lattice_calculator
        ``sheets``/``crystal``/``fcc111``: callable(atoms) → the run's model as a
        single-crystal calculator. With it each slab material is relaxed first and the slabs
        are cut at the model's lattice (``recipe.lattice: potential``) or at the file's, the
        mismatch recorded and refused above the threshold (``file``;
        :mod:`flatcontact.structures.lattice`); ``report["lattice"]`` records both. Without
        it the slabs are at the file's lattice and nothing is recorded (geometry only).

    Every check of the input (files, Miller index, terminations, match bounds, atom count)
    runs before any relaxation; a bad value is a one-line InputError naming the field.
    """
    if isinstance(recipe, dict):
        recipe = parse_recipe(recipe)
    if isinstance(recipe, QuartzDenseRecipe):
        require(
            potential is not None,
            f"{SECTION}.kind=quartz-dense needs a potential to relax the dense slabs",
        )
        atoms, report = build_quartz_interface(
            potential,
            recipe.layers,
            source=recipe.source,
            gap_angstrom=recipe.gap_angstrom,
            fmax_ev_per_angstrom=recipe.fmax_ev_per_angstrom,
            lattice=recipe.lattice,
        )
        return atoms, report
    if isinstance(recipe, FileRecipe):
        atoms = read_interface(recipe.file)
        return atoms, {
            "source": file_record(recipe.file),
            "n_atoms": len(atoms),
            "thickness_angstrom": thickness(atoms),
        }
    if isinstance(recipe, ToyRecipe):
        atoms = toy_interface(recipe.layers, **recipe.params)
        atoms.arrays["held"] = np.isin(atoms.arrays["surface"], (1, 4))
        atoms.arrays["layer"] = np.arange(1, len(atoms) + 1)
        atoms.info["material"] = "toy LJ fcc(111)"
        # the label names the module the toy was first built in; kept so that build.json
        # stays byte-identical
        return atoms, {
            "source": "flatcontact.ispes.toy",
            "n_atoms": len(atoms),
            "thickness_angstrom": thickness(atoms),
        }
    lattice = None
    if isinstance(recipe, SlabFileRecipe):
        atoms, record = build_from_slab_file(recipe)
    else:
        lattice = (
            None
            if lattice_calculator is None
            else LatticeChoice(lattice_calculator, recipe.lattice)
        )
        atoms, record = build_generic(recipe, lattice)
    report: dict[str, Any] = {
        "recipe": record,
        "n_atoms": len(atoms),
        "material": atoms.info["material"],
    }
    if lattice is not None:
        report["lattice"] = lattice.record()
    if relax_calculator is not None:
        calc = (
            relax_calculator(atoms)
            if callable(relax_calculator) and not hasattr(relax_calculator, "get_potential_energy")
            else relax_calculator
        )
        before = thickness(atoms)
        report["interface_relaxation"] = relax(
            atoms, calc, fmax_ev_per_angstrom=recipe.fmax_ev_per_angstrom
        )
        atoms.calc = None
        check_relaxed_separation(before, thickness(atoms))
    record["thickness_angstrom"] = thickness(atoms)
    atoms.info["recipe"] = json.dumps(record, sort_keys=True)
    report["thickness_angstrom"] = thickness(atoms)
    return atoms, report
