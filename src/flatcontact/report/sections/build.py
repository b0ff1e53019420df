"""The report's section on the build stage: what the interface is, how it relaxes, Fig. 1.

What the interface is comes from the build stage's record (``build.json``: the recipe's
slabs, layers, twist and coincidence match) and from ``interface.extxyz`` (which layers the
scan holds); how the free layers relax is ``scan.relax_mode``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from ase import Atoms

from flatcontact.foundation.layout import BUILD_FIGURE, png
from flatcontact.report.format import fmt
from flatcontact.report.html import Figure, Section

#: How the free atoms of each grid point relax, by ``scan.relax_mode``.
RELAX_MODE_TEXT = {
    "full": "relax in all three directions at every grid point (scan.relax_mode = full)",
    "normal": "relax along z only at every grid point, their lateral positions held with "
    "their layer's shift (scan.relax_mode = normal, the generalized-stacking-fault convention)",
    "rigid-layers": "move along z at every grid point, each layer as a rigid body "
    "(scan.relax_mode = rigid-layers)",
    "rigid": "do not relax (scan.relax_mode = rigid)",
}
#: Why τ of a commensurate cell is an upper bound.
COMMENSURATE_WARNING = (
    "The scan's cell is commensurate: the two surfaces are locked in registry over the whole "
    "cell, so every atom climbs the same barrier at the same time. An incommensurate or "
    "misaligned contact of the same materials (another twist, an unstrained lattice "
    "mismatch) averages the registry out and slides far more easily (structural lubricity): "
    "τ and σ here overstate those of an incommensurate contact."
)


def approximant_note(build: dict) -> str | None:
    """The note on an approximant cell (``build.json``'s ``recipe.match``: a twist, or a
    coincidence cell of more than one primitive cell of slab 1), which replaces
    :data:`COMMENSURATE_WARNING`: its atoms are not in one registry, and its τ is the interior
    corrugation of the locked cell (docs/incommensurate.md). None for a 1×1 or untwisted cell."""
    rec = build.get("recipe")
    match = rec.get("match") if isinstance(rec, dict) else None
    if not isinstance(match, dict) or match.get("kind") not in ("twist", "coincidence"):
        return None
    supercell = match.get("slab1_supercell")
    if supercell is None:
        return None
    cells = round(abs(float(np.linalg.det(np.asarray(supercell, dtype=float)))))
    if cells <= 1:
        return None
    what = "commensurate twist" if match["kind"] == "twist" else "coincidence cell"
    return (
        f"The scan's cell is a {what} of {cells} primitive cells of slab 1 per layer: its atoms "
        f"sit in {cells} different registries, so most of the registry dependence cancels "
        "inside the cell, and τ and σ here are the interior corrugation of an infinite contact "
        "locked at this angle and strain (scanned on one period of its shift lattice, finer than "
        "the cell). The incommensurate contact is the limit of larger cells (`flatcontact study "
        "approximants`); the rim, edges and defects of a real finite contact are in no periodic "
        "cell (docs/incommensurate.md)."
    )


#: A commensurate lock that strains a slab by more than this (largest principal strain, %)
#: is stated in the report: the strained lattice is not the material's.
LOCK_STRAIN_NOTE_PERCENT = 0.5


def lock_statement(build: dict) -> str | None:
    """The note on a coincidence lock that strains a slab by more than
    :data:`LOCK_STRAIN_NOTE_PERCENT` (``build.json``'s ``recipe.match``), or None."""
    rec = build.get("recipe")
    match = rec.get("match") if isinstance(rec, dict) else None
    if not isinstance(match, dict) or match.get("kind") != "coincidence":
        return None
    parts = []
    for i in (1, 2):
        strains = [float(v) for v in match.get(f"slab{i}_strain_percent") or []]
        if strains and max(abs(v) for v in strains) > LOCK_STRAIN_NOTE_PERCENT:
            values = sorted({round(v, 3) for v in strains}, key=abs, reverse=True)
            material = (rec.get(f"slab{i}") or {}).get("material")
            parts.append(
                f"{' and '.join(f'{v:+.3g}' for v in values)} % on slab {i}"
                + (f" ({material})" if material else "")
            )
    if not parts:
        return None
    return (
        f"Commensurate lock, strain {'; '.join(parts)}: the lattices are strained to coincide "
        f"in a cell of {match.get('n_atoms', '?')} atoms, so the contact is neither "
        "incommensurate nor made of the unstrained materials. The incommensurate contact is "
        "the limit of `flatcontact study approximants` (docs/incommensurate.md)."
    )


def interface_material(atoms: Atoms) -> str:
    """The material of the run's interface (``info['material']`` of ``interface.extxyz``;
    its formula when the file names none)."""
    return str(atoms.info.get("material") or atoms.get_chemical_formula(mode="hill"))


def plural(n: int, word: str) -> str:
    """``1 layer``, ``2 layers``."""
    return f"{n} {word}{'' if n == 1 else 's'}"


def _ordinals(numbers: list[int]) -> str:
    return ", ".join(str(n) for n in numbers[:-1]) + (
        f" and {numbers[-1]}" if len(numbers) > 1 else str(numbers[-1])
    )


def held_layers(atoms: Atoms) -> dict[int, tuple[list[int], list[int]]]:
    """Per slab (1, 2): its layers counted from its outer face (1 = outermost), split into
    held and free (``arrays['layer']``, ``arrays['held']``; default held: surfaces 1 and 4)."""
    slab = np.asarray(atoms.arrays["slab"], int)
    if "held" in atoms.arrays:
        held = np.asarray(atoms.arrays["held"], bool)
    else:
        held = np.isin(np.asarray(atoms.arrays["surface"], int), (1, 4))
    layer = (
        np.asarray(atoms.arrays["layer"], int)
        if "layer" in atoms.arrays
        else np.asarray(atoms.arrays["surface"], int)
    )
    out = {}
    for s in (1, 2):
        ids = sorted(set(layer[slab == s]), reverse=(s == 2))  # outer face first
        h = [i + 1 for i, lid in enumerate(ids) if held[(layer == lid) & (slab == s)].all()]
        f = [i + 1 for i in range(len(ids)) if i + 1 not in h]
        out[s] = (h, f)
    return out


def relaxation_text(atoms: Atoms, relax_mode: str) -> str:
    """Which layers of each slab the scan holds and which relax, and how (``relax_mode``)."""
    parts = []
    any_free = False
    for s, (held, free) in held_layers(atoms).items():
        n = len(held) + len(free)
        if not free:
            parts.append(
                f"slab {s}: {plural(n, 'layer')}, all held (rigid)"
                if n > 1
                else f"slab {s}: 1 layer, held (rigid)"
            )
            continue
        any_free = True
        parts.append(
            f"slab {s}: {plural(n, 'layer')}, {'layer' if len(held) == 1 else 'layers'} "
            f"{_ordinals(held)} from the outer face held, {'layer' if len(free) == 1 else 'layers'} "
            f"{_ordinals(free)} free"
        )
    text = "Layers during the scan: " + "; ".join(parts) + ". "
    if not any_free:
        return text + (
            "Every atom is held: the layers move as rigid bodies at the imposed shift and gap, "
            "nothing relaxes."
        )
    if relax_mode == "rigid":
        return text + "The free layers " + RELAX_MODE_TEXT["rigid"] + "."
    return (
        text
        + "Held layers move as rigid bodies; the free layers "
        + RELAX_MODE_TEXT.get(relax_mode, f"relax (scan.relax_mode = {relax_mode})")
        + "."
    )


def structure_paragraphs(build: dict) -> list[str]:
    """What the interface is, from ``build.json``'s recipe record: slabs and layers per slab,
    slab 2's operation, the twist angle, and the strain and coincidence cell of a locked
    hetero pair. Empty without a recipe record (the paper's quartz builder)."""
    rec = build.get("recipe")
    if not isinstance(rec, dict):
        layers = build.get("layers")
        return [f"Each slab has {plural(int(layers), 'layer')}."] if layers else []
    s1, s2 = rec.get("slab1") or {}, rec.get("slab2") or {}
    out = [
        f"Slab 1: {s1.get('material', '?')}, {plural(int(s1.get('layers', 0)), 'layer')}; "
        f"slab 2: {s2.get('material', '?')}, {plural(int(s2.get('layers', 0)), 'layer')}"
        + (f" ({rec['slab2_operation']})" if rec.get("slab2_operation") else "")
        + (
            f". Interface spacing {fmt(rec['interface_spacing_angstrom'])} Å between "
            f"{rec.get('spacing_measured_between', 'the facing planes')}."
            if rec.get("interface_spacing_angstrom") is not None
            else "."
        )
    ]
    if rec.get("twist_angle_deg") is not None:
        out.append(
            f"Twisted bilayer: slab 2 is rotated by θ = {rec['twist_angle_deg']:.4f}° against "
            "slab 1 (commensurate twist cell)."
        )
    match = rec.get("match") or {}
    if match.get("kind") == "coincidence":
        strains = [
            f"slab {i} {', '.join(f'{v:+.3g}' for v in match.get(f'slab{i}_strain_percent', []))} %"
            for i in (1, 2)
            if any(abs(v) > 1e-9 for v in match.get(f"slab{i}_strain_percent", []))
        ]
        rot = [
            f"slab {i} rotated {match[f'slab{i}_rotation_deg']:.3g}°"
            for i in (1, 2)
            if abs(match.get(f"slab{i}_rotation_deg", 0.0)) > 1e-9
        ]
        out.append(
            "Hetero pair locked in a coincidence cell: supercell "
            f"{match.get('slab1_supercell')} of slab 1 on {match.get('slab2_supercell')} of "
            f"slab 2, {match.get('n_atoms', '?')} atoms; principal strains put on the "
            "slabs to make them commensurate: "
            + ("; ".join(strains) if strains else "none")
            + (f"; {'; '.join(rot)}" if rot else "")
            + "."
        )
    return out


#: A slab kept at the file's lattice (``structure.lattice: file``) strained by more than this
#: (largest in-plane principal strain against the model's own lattice, %) gets a note box.
FILE_LATTICE_NOTE_PERCENT = 0.1


def _pct(values) -> str:
    return ", ".join(f"{float(v):+.3g}" for v in values)


def lattice_paragraph(build: dict) -> str | None:
    """Which lattice the slabs are cut at (``build.json["lattice"]``): the model's own or the
    file's, and per slab the file's lattice against the model's (% per lattice vector, the
    in-plane strain) and the lateral stress the model puts on the bulk at the file's lattice.
    None for a build without the record (a prepared file or slab, the toy)."""
    lat = build.get("lattice")
    if not isinstance(lat, dict) or not lat.get("slabs"):
        return None
    used = lat.get("source")
    parts = []
    for name, rec in lat["slabs"].items():
        if "not_computed" in rec:
            parts.append(
                f"{name.replace('slab', 'slab ')} ({rec.get('material', '?')}): the model cannot "
                f"compute this material alone ({rec['not_computed']}), so it is kept at the "
                "file's lattice, unchecked"
            )
            continue
        pot = "/".join(f"{v:.4f}" for v in rec["potential_lengths_angstrom"])
        fil = "/".join(f"{v:.4f}" for v in rec["file_lengths_angstrom"])
        parts.append(
            f"{name.replace('slab', 'slab ')} ({rec.get('material', '?')}): the model's lattice "
            f"{pot} Å, the file's {fil} Å ({_pct(rec['file_vs_potential_percent'])} % per "
            f"lattice vector; in-plane {_pct(rec['in_plane_mismatch_percent'])} %); at the "
            f"file's lattice the model's bulk carries a lateral stress of "
            f"{rec['lateral_stress_gpa_at_file_lattice']:.3g} GPa (negative: compressed)"
        )
    head = (
        "Lattice: the slabs are cut at the interaction model's own equilibrium lattice "
        "(structure.lattice = potential; the bulk, or a sheet's in-plane cell, relaxed with "
        "the run's model). "
        if used == "potential"
        else "Lattice: the slabs are kept at the structure file's lattice (structure.lattice = "
        f"file; refused above {lat.get('max_file_mismatch_percent', '?')} % in-plane). "
    )
    match = (build.get("recipe") or {}).get("match") or {}
    against = [
        f"slab {i} {_pct(match[f'slab{i}_strain_vs_potential_percent'])} %"
        for i in (1, 2)
        if f"slab{i}_strain_vs_potential_percent" in match
    ]
    tail = (
        f" In the coincidence cell, strain against each slab's own model lattice: {'; '.join(against)}."
        if against
        else ""
    )
    return head + "; ".join(parts) + "." + tail


def file_lattice_note(build: dict) -> str | None:
    """The note on slabs kept at the file's lattice and strained against the model's by more
    than :data:`FILE_LATTICE_NOTE_PERCENT`, or None."""
    lat = build.get("lattice")
    if not isinstance(lat, dict) or lat.get("source") != "file":
        return None
    strained = [
        (name, rec)
        for name, rec in (lat.get("slabs") or {}).items()
        if max(abs(v) for v in rec["in_plane_mismatch_percent"]) > FILE_LATTICE_NOTE_PERCENT
    ]
    if not strained:
        return None
    what = "; ".join(
        f"{n.replace('slab', 'slab ')} {_pct(r['in_plane_mismatch_percent'])} % in-plane, "
        f"lateral stress {r['lateral_stress_gpa_at_file_lattice']:.3g} GPa"
        for n, r in strained
    )
    return (
        f"Not the model's lattice: {what}. The slabs are kept at the structure file's lattice "
        "(structure.lattice = file), so every energy, τ and σ here is that of a strained "
        "crystal under this lateral stress, not of the model's own (structure.lattice: "
        "potential cuts them at the model's equilibrium)."
    )


def interface_section(
    cfg, build: dict, folder: Path, atoms: Atoms | None = None, paper: bool = False
) -> Section:
    """Section 1: what the interface is (``build``: the build stage's ``build.json``,
    :func:`structure_paragraphs`), its atoms, thickness and relaxation, which layers the
    scan holds and how the others relax (``atoms``: ``interface.extxyz``;
    ``cfg.scan.relax_mode``), the lock's strain when above :data:`LOCK_STRAIN_NOTE_PERCENT`
    (:func:`lock_statement`) and the warning that a commensurate lock overstates τ, or for an
    approximant cell what its τ is (:func:`approximant_note`; neither for the paper's quartz,
    ``paper``) and Fig. 1 from ``folder``."""
    rel = build.get("interface_relaxation") or {}
    checks = build.get("interface_verification") or {}
    verified = bool(checks) and all(v.get("dense") for v in checks.values())
    lattice = lattice_paragraph(build)
    paragraphs = [
        *structure_paragraphs(build),
        *([lattice] if lattice else []),
        f"{build.get('n_atoms', '?')} atoms; reference thickness z = {fmt(build.get('thickness_angstrom'))} Å"
        + (
            f"; interface relaxation {'converged' if rel.get('converged') else 'NOT converged'}"
            f" in {rel.get('steps', '?')} steps to "
            f"{getattr(cfg.structure, 'fmax_ev_per_angstrom', float('nan')):g} eV/Å"
            if rel
            else ""
        )
        + (
            "; the dense surface verified on both slabs after the interface relaxation"
            if verified
            else ""
        )
        + ".",
    ]
    if atoms is not None:
        paragraphs.append(relaxation_text(atoms, getattr(cfg.scan, "relax_mode", "full")))
    return Section(
        "1. Interface",
        paragraphs=paragraphs,
        notes=[
            n
            for n in (
                file_lattice_note(build),
                *(
                    ()
                    if paper
                    else (lock_statement(build), approximant_note(build) or COMMENSURATE_WARNING)
                ),
            )
            if n
        ],
        figures=[
            Figure(
                folder / png(BUILD_FIGURE),
                "Fig. 1 style: side view and the top view of the inner face.",
            )
        ],
    )
