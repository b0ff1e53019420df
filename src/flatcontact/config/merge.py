"""How a configuration file's keys are laid over a preset (and flags over a file).

Nested mappings merge key by key; anything else is replaced. Three sections start afresh
instead: a ``structure`` of another ``kind``, a ``potential`` that defines a whole model
(:func:`replaces_model`), and one of ``scan.p_range_gpa`` / ``scan.thickness_angstrom``
given in place of the other.
"""

from __future__ import annotations

import copy
from typing import Any

from flatcontact.potentials.presets import PRESETS


def merge_config(base: dict, over: dict) -> dict:
    """``over`` laid over ``base`` (nested mappings merged, everything else replaced).

    Top-level sections that start afresh instead of merging: a ``structure`` of another
    ``kind`` (none of the old recipe's fields apply) and a ``potential`` that defines a whole
    model (:func:`replaces_model`: a preset, a calculator, a coupling, LAMMPS styles).
    """
    out = copy.deepcopy(base)
    for key, value in over.items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            old = out[key]
            if key == "structure" and value.get("kind", old.get("kind")) != old.get("kind"):
                out[key] = {}
            elif key == "potential" and "preset" in old and replaces_model(value):
                out[key] = {}
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
