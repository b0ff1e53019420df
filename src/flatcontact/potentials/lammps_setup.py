"""Compile an :class:`~flatcontact.potentials.model.InteractionModel` into LAMMPS commands.

Given the atoms (their elements and the ``slab``/``layer`` arrays) this decides the atom
types, the molecule ids and the ``pair_style``/``pair_coeff`` commands (the typing and
``NULL``-mapping rules are in :mod:`flatcontact.potentials.model`'s docstring):

- **intra**: each intra style gets one ``hybrid/overlay`` instance per group (slab or layer;
  a single instance over all types for ``coupling: same`` or a bulk crystal), its element map
  naming the element on that group's types it has parameters for and ``NULL`` elsewhere;
- **lj**: ``lj/cut`` with ``pair_modify shift yes`` on the type pairs of different slabs only;
- **interlayer**: one instance of each interlayer style over all types, ``atom_style full``
  with molecule id = layer (interlayer styles act between different molecule ids only);
  a style with ``pair_coeff_pairs`` (e.g. ``coul/shield`` with its shielding per element
  pair) gets ``pair_coeff I J`` lines per type pair instead, and ``charges`` set the charge
  of each atom by element.
A single instance and no coupling is written as a plain ``pair_style`` (no hybrid).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from flatcontact.foundation.errors import InputError
from flatcontact.potentials.lammps_engine import NEIGHBOR_SKIN_ANGSTROM, LammpsSetup
from flatcontact.potentials.lj import LJPair, pair_key
from flatcontact.potentials.model import slab_ids
from flatcontact.potentials.styles import style_cutoff_angstrom

#: Largest atom number density of a solid that sizes the neighbour capacity (atoms/Å³;
#: diamond 0.176, α-quartz 0.080, Cu 0.085).
MAX_ATOM_DENSITY_PER_A3 = 0.2
#: LAMMPS's default ``neigh_modify one`` (neighbours one atom may have).
LAMMPS_DEFAULT_NEIGHBOURS = 2000
#: The capacity the interlayer potentials (16 Å cutoffs) were measured to need.
INTERLAYER_NEIGHBOURS = 20000


def neighbour_capacity(cutoff_angstrom: float) -> int:
    """Neighbours one atom can have within ``cutoff_angstrom`` + the skin in the densest solid.

    ``ceil(4/3 π (r_c + skin)³ ρ_max)`` with ρ_max = :data:`MAX_ATOM_DENSITY_PER_A3` and the
    engine's skin (:data:`flatcontact.potentials.lammps_engine.NEIGHBOR_SKIN_ANGSTROM`): a
    bound on LAMMPS's per-atom list length (``neigh_modify one``), which caps memory only.
    The paper preset's LJ at 18 Å fits the default 2000 on quartz; 26 Å overflowed it in the
    quartz convergence study's cutoff step (needs 16,490 here).
    """
    r = cutoff_angstrom + NEIGHBOR_SKIN_ANGSTROM
    return math.ceil(4.0 / 3.0 * math.pi * r**3 * MAX_ATOM_DENSITY_PER_A3)


def layer_ids(atoms, fallback_planes: bool = False) -> np.ndarray:
    """``atoms.arrays["layer"]``; else the slab ids; else (``fallback_planes``) z-planes.

    The plane fallback (bulk crystals of layered materials) starts a new layer after a gap
    of more than 2 Å along the sorted z (graphite 3.35 Å, MoS₂'s S–S gap ≈ 3 Å, while the
    Mo–S planes of one MoS₂ layer are 1.6 Å apart).
    """
    if "layer" in atoms.arrays:
        return np.asarray(atoms.arrays["layer"], dtype=int)
    if "slab" in atoms.arrays and not fallback_planes:
        return np.asarray(atoms.arrays["slab"], dtype=int)
    z = atoms.positions[:, 2]
    order = np.argsort(z)
    ids = np.empty(len(atoms), dtype=int)
    current = 1
    for k, i in enumerate(order):
        if k and z[i] - z[order[k - 1]] > 2.0:
            current += 1
        ids[i] = current
    return ids


def plane_ids(z: np.ndarray, groups: np.ndarray, symbols: list[str]) -> list[int]:
    """Index of the atomic plane of each atom among the atoms of its group and element.

    Planes are found along the sorted z of those atoms, a new one after a gap > 1 Å (for
    ``ilp/tmd``, whose normals use neighbours of the same LAMMPS type: the top and bottom
    chalcogen planes of a TMD layer must be different types).
    """
    out = [0] * len(z)
    sym = np.asarray(symbols)
    for g in set(groups.tolist()):
        for e in set(symbols):
            idx = np.flatnonzero((groups == g) & (sym == e))
            order = idx[np.argsort(z[idx])]
            plane = 0
            for k, i in enumerate(order):
                if k and z[i] - z[order[k - 1]] > 1.0:
                    plane += 1
                out[i] = plane
    return out


@dataclass(frozen=True)
class _Types:
    """The LAMMPS atom types of one structure: each atom's type, and per type (index t - 1) its
    element, its group (one set of intra-slab pair styles) and its slab (0: none)."""

    types: list[int]
    type_elements: list[str]
    type_group: list[int]
    type_slab: list[int]
    group_ids: list[int]

    @property
    def n(self) -> int:
        return len(self.type_elements)

    def cross_pairs(self):
        """Type pairs ``ti < tj`` in two different slabs (the LJ across the interface)."""
        slab = self.type_slab
        for ti in range(1, self.n + 1):
            for tj in range(ti + 1, self.n + 1):
                if slab[ti - 1] and slab[tj - 1] and slab[ti - 1] != slab[tj - 1]:
                    yield ti, tj


def compile_setup(model, atoms, bulk: bool = False) -> LammpsSetup:
    """The :class:`LammpsSetup` of ``model`` for ``atoms`` (see the module docstring)."""
    symbols = atoms.get_chemical_symbols()
    slabs = slab_ids(atoms) if not bulk else np.ones(len(atoms), dtype=int)
    interlayer = model.coupling == "interlayer"
    layers = (
        layer_ids(atoms, fallback_planes=bulk)
        if interlayer or model.intra_scope == "layer"
        else None
    )
    if model.coupling == "same":
        groups = np.ones(len(atoms), dtype=int)
    elif model.intra_scope == "layer":
        groups = layers  # a layered bulk crystal keeps its layers apart too
    elif bulk:
        groups = np.ones(len(atoms), dtype=int)
    else:
        groups = slabs
    t = _atom_types(model, atoms, symbols, groups, slabs)
    single = model.coupling == "same" or (bulk and model.intra_scope != "layer")
    instances, pair_lines = _style_instances(model, t, single, interlayer)
    lj_table = None
    if model.coupling == "lj" and not bulk and len(set(slabs.tolist())) > 1:
        sym = np.array(symbols)
        lj_table = model.lj.table(sorted(set(sym[slabs == 1])), sorted(set(sym[slabs != 1])))
    if not instances and lj_table is None:
        raise InputError(
            f"potential {model.label}: nothing to compute (no intra model and no cross-slab LJ)"
        )
    cutoff = model.lj.cutoff_angstrom
    commands = _pair_commands(t, instances, pair_lines, lj_table, cutoff)
    # 16 Å interlayer cutoffs in small periodic cells, or a long cross-interface LJ or
    # interlayer cutoff (a convergence study's cutoff ladder): more neighbours per atom than
    # LAMMPS's default capacity (2000; "Neighbor list overflow")
    style_cutoffs = [style_cutoff_angstrom(s) for s, _, _ in instances]
    longest = max((c for c in style_cutoffs if c is not None), default=0.0)
    one = max(
        INTERLAYER_NEIGHBOURS if interlayer else 0,
        neighbour_capacity(cutoff) if lj_table is not None else 0,
        neighbour_capacity(longest) if longest else 0,
    )
    if one > LAMMPS_DEFAULT_NEIGHBOURS:
        commands.append(f"neigh_modify one {one} page {20 * one}")
    return LammpsSetup(
        types=tuple(t.types),
        type_elements=tuple(t.type_elements),
        commands=tuple(commands),
        atom_style="full" if interlayer else "atomic",
        molecules=tuple(int(v) for v in layers) if interlayer else None,
        charges=tuple(float(model.charges.get(s, 0.0)) for s in symbols) if model.charges else None,
    )


def _atom_types(model, atoms, symbols: list[str], groups: np.ndarray, slabs: np.ndarray) -> _Types:
    """One type per (group, element), or per (group, element, plane) for ``type_per_plane``."""
    elements = sorted(set(symbols))
    ne = len(elements)
    group_ids = sorted(set(groups.tolist()))
    if model.type_per_plane:
        planes = plane_ids(atoms.positions[:, 2], groups, symbols)
        keys = sorted({(g, s, p) for g, s, p in zip(groups.tolist(), symbols, planes, strict=True)})
        index = {k: n + 1 for n, k in enumerate(keys)}
        types = [index[k] for k in zip(groups.tolist(), symbols, planes, strict=True)]
        type_elements = [k[1] for k in keys]
        type_group = [k[0] for k in keys]
    else:  # every group with every element (types stable across structures of one material)
        gindex = {g: k for k, g in enumerate(group_ids)}
        eindex = {e: k for k, e in enumerate(elements)}
        types = [
            gindex[g] * ne + eindex[s] + 1 for g, s in zip(groups.tolist(), symbols, strict=True)
        ]
        type_elements = [e for _ in group_ids for e in elements]
        type_group = [g for g in group_ids for _ in elements]
    # the slab of each type (for LJ across slabs): groups never straddle slabs
    type_slab = [0] * len(type_elements)
    for t, s in zip(types, slabs.tolist(), strict=True):
        type_slab[t - 1] = s
    return _Types(types, type_elements, type_group, type_slab, group_ids)


def _style_instances(
    model, t: _Types, single: bool, interlayer: bool
) -> tuple[list[tuple[str, str, str | None]], dict[int, list[tuple[int, int, str]]]]:
    """``(pair_style, coeff args, map)`` for each ``pair_coeff * *`` style instance (map None for
    a per-pair style, whose ``(ti, tj, args)`` lines are in the second value by instance)."""

    def element_map(style, group=None) -> str:
        # types without atoms are mapped too: LAMMPS wants every type pair covered
        known = set(style.known_elements)
        return " ".join(
            e if e in known and (group is None or t.type_group[k] == group) else "NULL"
            for k, e in enumerate(t.type_elements)
        )

    instances: list[tuple[str, str, str | None]] = []
    pair_lines: dict[int, list[tuple[int, int, str]]] = {}  # instance -> (ti, tj, args)
    for style in model.intra_styles:
        if not style.map_elements:
            instances.append((style.pair_style, style.coeff_args(), ""))
            continue
        for g in [None] if single else t.group_ids:
            mapping = element_map(style, g)
            if set(mapping.split()) != {"NULL"}:
                instances.append((style.pair_style, style.coeff_args(), mapping))
    for style in model.interlayer_styles if interlayer else ():
        if style.pair_coeff_pairs is None:
            instances.append((style.pair_style, style.coeff_args(), element_map(style)))
            continue
        lines = []
        for ti in range(1, t.n + 1):
            for tj in range(ti, t.n + 1):
                key = "-".join(sorted((t.type_elements[ti - 1], t.type_elements[tj - 1])))
                if key in style.pair_coeff_pairs:
                    lines.append((ti, tj, style.pair_coeff_pairs[key]))
        pair_lines[len(instances)] = lines
        instances.append((style.pair_style, "", None))
    return instances, pair_lines


def _pair_commands(
    t: _Types,
    instances: list[tuple[str, str, str | None]],
    pair_lines: dict[int, list[tuple[int, int, str]]],
    lj_table,
    cutoff: float,
) -> list[str]:
    """The ``pair_style`` and ``pair_coeff`` commands: LJ alone, one style, or a hybrid/overlay
    of every instance (and the LJ across the slabs), every type pair declared."""
    commands: list[str] = []

    def lj_coeffs(substyle: str) -> list[str]:
        out = []
        for ti, tj in t.cross_pairs():
            p: LJPair = lj_table[pair_key(t.type_elements[ti - 1], t.type_elements[tj - 1])]
            out.append(
                f"pair_coeff {ti} {tj} {substyle}{p.epsilon_ev:.17g} {p.sigma_angstrom:.17g}"
            )
        return out

    slab = t.type_slab
    if not instances:  # LJ only: plain lj/cut, zero within each slab
        commands.append(f"pair_style lj/cut {cutoff:.17g}")
        for ti in range(1, t.n + 1):
            for tj in range(ti, t.n + 1):
                if slab[ti - 1] == slab[tj - 1] or not (slab[ti - 1] and slab[tj - 1]):
                    commands.append(f"pair_coeff {ti} {tj} 0.0 1.0")
        commands += lj_coeffs("")
        commands.append("pair_modify shift yes")
        return commands
    if len(instances) == 1 and lj_table is None and instances[0][2] is not None:
        style, args, mapping = instances[0]
        commands.append(f"pair_style {style}")
        commands.append(" ".join(f"pair_coeff * * {args} {mapping}".split()))
        return commands
    names = [s.split()[0] for s, _, _ in instances]
    substyles = [s for s, _, _ in instances] + ([f"lj/cut {cutoff:.17g}"] if lj_table else [])
    commands.append("pair_style hybrid/overlay " + " ".join(substyles))
    seen: dict[str, int] = {}
    covered = set()
    for k, ((_style, args, mapping), name) in enumerate(zip(instances, names, strict=True)):
        seen[name] = seen.get(name, 0) + 1
        index = f" {seen[name]}" if names.count(name) > 1 else ""
        if mapping is None:  # per type pair
            for ti, tj, pair_args in pair_lines[k]:
                commands.append(f"pair_coeff {ti} {tj} {name}{index} {pair_args}")
                covered.add((ti, tj))
            continue
        commands.append(" ".join(f"pair_coeff * * {name}{index} {args} {mapping}".split()))
        on = [i + 1 for i, e in enumerate(mapping.split()) if e != "NULL"] if mapping else []
        covered |= {(ti, tj) for ti in on for tj in on if ti <= tj}
    if lj_table is not None:
        commands += lj_coeffs("lj/cut ")
        commands.append("pair_modify pair lj/cut shift yes")
        covered |= set(t.cross_pairs())
    # type pairs no sub-style covers (e.g. different layers with coupling none) interact
    # through nothing; LAMMPS wants them declared
    commands += [
        f"pair_coeff {ti} {tj} none"
        for ti in range(1, t.n + 1)
        for tj in range(ti, t.n + 1)
        if (ti, tj) not in covered
    ]
    return commands
