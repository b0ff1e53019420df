"""The names the report gives the analysis's stackings, for the lattice at hand.

The analysis (:mod:`flatcontact.analysis.stackings`) names the stationary points of a
hexagonal landscape with one maximum by the bilayer letters ``AA`` (the maximum), ``AB`` and
``BA`` (the two three-fold sites) and ``SP`` (the two-fold saddles), and every other point by
kind and energy rank (``min1``, ``saddle1``, ``max1``). Those keys stay in ``friction.csv``
and ``friction.nc``; the report shows the names of the interface's own family
(:func:`stacking_family`, from the build stage's record):

``gamma``
    A 3-D crystal continued across the cut (``fcc111``, or ``crystal`` with one material,
    slab 2 the continuation of slab 1: :func:`~flatcontact.structures.interface_contract.continues_crystal`):
    the ISPES is the generalized stacking-fault (γ) surface. Names come from the geometry,
    not from the energies: the stationary point at the zero shift (``zero_shift_stacking``
    of ``friction.csv``) is the **perfect stacking**, whatever its energy (a potential with
    γ_isf < 0 puts the fault below it); the other three-fold site the **intrinsic stacking
    fault**, the two-fold saddle the **unstable stacking fault** and the maximum the
    **on-top stacking**. Without the zero-shift key (a ``friction.csv`` written before it
    existed) the points keep their kind-and-rank names.
``antiparallel``
    A bilayer of one sheet with slab 2 rotated by 180° (h-BN, 2H TMDs): the lower three-fold
    minimum is **AA′** (each atom above the other species), the other three-fold sites
    **AB1′** and **AB2′** in order of energy.
``bilayer``
    A bilayer of one sheet otherwise (graphene): the analysis's letters AB, BA, SP, AA.
``analysis``
    The paper's α-quartz (and a build record without a recipe): the analysis's own keys.
``generic``
    Anything else (hetero pairs, twisted cells, files, a crystal flipped or rotated): minima,
    saddles and maxima by energy rank (``minimum 1``, ``saddle 1``, ``maximum 1``, lowest
    first).
"""

from __future__ import annotations

import re

from flatcontact.structures.interface_contract import continues_crystal

#: The analysis's hexagonal-site keys (:mod:`flatcontact.analysis.stackings`).
THREE_FOLD = ("AB", "BA")
_SP = re.compile(r"^SP(\d*)$")
_GENERIC = re.compile(r"^(min|saddle|max)(\d+)$")
_KIND_WORD = {"min": "minimum", "saddle": "saddle", "max": "maximum"}


def stacking_family(build: dict) -> str:
    """``gamma``, ``antiparallel``, ``bilayer``, ``analysis`` or ``generic`` (module docstring) from the
    build stage's ``build.json`` (its ``recipe`` record)."""
    recipe = build.get("recipe") or {}
    kind = recipe.get("kind")
    if kind is None or kind == "quartz-dense":
        return "analysis"
    slab1, slab2 = recipe.get("slab1") or {}, recipe.get("slab2") or {}
    one_material = slab1.get("material") == slab2.get("material")
    if not one_material or "twist_angle_deg" in recipe:
        return "generic"
    if kind in ("fcc111", "crystal"):
        return "gamma" if continues_crystal(recipe) else "generic"
    if kind == "sheets":
        operation = str(recipe.get("slab2_operation", ""))
        return "antiparallel" if "rotated 180°" in operation else "bilayer"
    return "generic"


def display_names(energies: dict[str, float], family: str, zero_shift: str = "") -> dict[str, str]:
    """The report's name of each analysis key of ``energies`` (key → energy at one load, any
    units) for ``family`` (:func:`stacking_family`); keys it does not rename keep their own.

    ``zero_shift``: the analysis key of the stationary point at the zero shift
    (``friction.csv`` ``zero_shift_stacking``), the perfect stacking of the ``gamma`` family.
    """
    names = {key: key for key in energies}
    if family in ("bilayer", "analysis"):
        return names
    three = sorted((k for k in THREE_FOLD if k in energies), key=lambda k: energies[k])
    sps = sorted((k for k in energies if _SP.match(k)), key=lambda k: energies[k])
    if family == "gamma" and zero_shift in energies:
        names[zero_shift] = "perfect stacking"
        for k in three:
            if k != zero_shift and zero_shift in THREE_FOLD:
                names[k] = "intrinsic stacking fault"
        for i, k in enumerate(sps, start=1):
            names[k] = "unstable stacking fault" + (f" {i}" if len(sps) > 1 else "")
        if "AA" in energies:
            names["AA"] = "on-top stacking"
        return names
    if family == "antiparallel" and three:
        rest = sorted([*three[1:], *(["AA"] if "AA" in energies else [])], key=energies.get)
        names[three[0]] = "AA′"
        for i, k in enumerate(rest, start=1):
            names[k] = f"AB{i}′"
        for i, k in enumerate(sps, start=1):
            names[k] = "saddle" + (f" {i}" if len(sps) > 1 else "")
        return names
    # generic (and gamma without its zero-shift key): every point by kind and energy rank,
    # the hexagonal letters included
    kinds: dict[str, list[str]] = {"min": [], "saddle": [], "max": []}
    for k in energies:
        m = _GENERIC.match(k)
        if m:
            kinds[m.group(1)].append(k)
        elif k in THREE_FOLD:
            kinds["min"].append(k)
        elif _SP.match(k):
            kinds["saddle"].append(k)
        elif k == "AA":
            kinds["max"].append(k)
    for prefix, keys in kinds.items():
        for i, k in enumerate(sorted(keys, key=energies.get), start=1):
            names[k] = f"{_KIND_WORD[prefix]} {i}"
    return names
