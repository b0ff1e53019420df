"""How a configuration file's keys are laid over a preset (and flags over a file).

Nested mappings merge key by key; anything else is replaced. Three sections start afresh
instead: a ``structure`` of another ``kind``, a ``potential`` that defines a whole model
(:func:`replaces_model`), and one of ``scan.p_range_gpa`` / ``scan.thickness_angstrom``
given in place of the other.

A new intra-slab model laid over a ``potential`` (``intra: vashishta``, what ``--potential
vashishta`` gives) replaces the intra model and keeps the cross-interface coupling the
section states (:func:`kept_for_intra`), with two exceptions. An ASE calculator over the
whole interface has no coupling of its own to keep (its ``coupling: none`` only says that the
calculator sees both slabs): the new intra model starts afresh, with the coupling it would
have written alone (the preset's LJ), never with no interaction across the interface. A
preset's name goes with its intra model: what remains is the preset's coupling under the new
model's name.
"""

from __future__ import annotations

import copy
from typing import Any

from flatcontact.potentials.presets import PRESETS


def merge_config(base: dict, over: dict) -> dict:
    """``over`` laid over ``base`` (nested mappings merged, everything else replaced).

    Top-level sections that start afresh instead of merging: a ``structure`` of another
    ``kind`` (none of the old recipe's fields apply) and a ``potential`` that defines a whole
    model (:func:`replaces_model`: a preset, a calculator, a coupling, LAMMPS styles). A
    ``potential`` naming a new intra-slab model is laid over what :func:`kept_for_intra`
    keeps of the old one.
    """
    out = copy.deepcopy(base)
    for key, value in over.items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            old = out[key]
            if key == "structure" and value.get("kind", old.get("kind")) != old.get("kind"):
                out[key] = {}
            elif key == "potential" and "preset" in old and replaces_model(value):
                out[key] = {}
            elif key == "potential" and _new_intra(value):
                out[key] = kept_for_intra(old)
        if isinstance(value, dict) and isinstance(out.get(key), dict) and key != "kwargs":
            # an explicit pressure range or thickness list replaces the other
            if key == "scan":
                if "thickness_angstrom" in value:
                    out[key].pop("p_range_gpa", None)
                if "p_range_gpa" in value:
                    out[key].pop("thickness_angstrom", None)
            out[key] = merge_config(out[key], value)
        else:
            out[key] = copy.deepcopy(value)
    return out


def replaces_model(section: Any) -> bool:
    """Whether a ``potential`` section defines a whole model rather than editing the default.

    A preset (``preset:`` or a preset name as ``intra``), a calculator, a coupling or
    LAMMPS styles replace the default model; ``intra: vashishta`` or ``lj: {...}`` alone
    edit it (they keep the quartz default's Hamaker-calibrated LJ).
    """
    if not isinstance(section, dict):
        return False
    intra = section.get("intra")
    return (
        any(section.get(k) is not None for k in ("preset", "calculator", "coupling", "interlayer"))
        or (isinstance(intra, str) and intra.strip() in PRESETS)
        or (intra is not None and not isinstance(intra, str))
    )


def _new_intra(section: dict) -> bool:
    """Whether a ``potential`` section names an intra-slab model (not ``none``) and no calculator."""
    intra = section.get("intra")
    return intra is not None and intra != "none" and section.get("calculator") is None


def kept_for_intra(section: dict) -> dict:
    """What of the ``potential`` section ``section`` a new intra-slab model laid over it keeps.

    Its cross-interface coupling (``coupling``, ``lj``, ``interlayer``, ...): the new intra
    model replaces the old one only. An ASE calculator's section keeps nothing when the
    calculator covers the whole interface (its ``coupling: none`` is the calculator's, not a
    choice of no interaction across the interface: the new model takes the coupling it has
    alone) and its coupling when it is one per slab (``lj`` or ``none``, as the section
    states). A preset's section keeps the preset's fields without the preset's name, so the
    model is named by its new intra model, not by the preset it no longer is.
    """
    calculator = section.get("calculator")
    if calculator is not None:
        scope = calculator.get("scope", "interface") if isinstance(calculator, dict) else None
        if scope != "slab":
            return {}
        return {k: section[k] for k in ("coupling", "lj") if k in section}
    name = section.get("preset")
    if name is not None:
        return {**PRESETS.get(name, {}), **section, "preset": None}
    return section
