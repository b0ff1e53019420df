"""The refinement ladder of each setting: config overrides of step 1, 2, ... over the base.

A step of setting ``s`` at level ``i`` is the base configuration with that one setting
refined ``i`` times (:class:`flatcontact.config.refine.RefineConfig`); level 0 is the base
itself, shared by every setting. :func:`applicable_settings` says which settings a recipe and
model have, and why the others are left out (reported in ``study.json``).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

from pydantic import ValidationError

from flatcontact.config.merge import merge_config
from flatcontact.config.refine import REFINABLE
from flatcontact.config.run import RunConfig
from flatcontact.foundation.errors import InputError
from flatcontact.potentials.styles import CUTOFF_FIRST_STYLES, style_cutoff_angstrom, with_cutoff

#: Recipe kinds whose ``layers`` field is a slab thickness a study may refine (``slab`` and
#: ``file`` read their layers from the structure file).
LAYERED_KINDS = ("quartz-dense", "sheets", "crystal", "fcc111", "toy-lj")
#: Layer step of the dense quartz slab with the shipped source (one bulk c-repeat, 3 layers).
QUARTZ_LAYER_STEP = 3


@dataclass(frozen=True)
class Variant:
    """One run of a study: its name, what it varies, the level, its x value and overrides."""

    name: str
    setting: str
    level: int
    value: float
    label: str
    overrides: dict


def applicable_settings(cfg: RunConfig) -> dict[str, str]:
    """Setting -> ``""`` if the study can refine it for ``cfg``, else why not."""
    out = dict.fromkeys(REFINABLE, "")
    if cfg.structure.kind not in LAYERED_KINDS:
        out["layers"] = f"structure.kind {cfg.structure.kind} has no layer count to refine"
    if cfg.scan.relax_mode == "rigid":
        out["fmax"] = "scan.relax_mode rigid relaxes nothing"
    if cfg.potential.calculator is not None or (
        cfg.potential.coupling != "lj" and not interlayer_cutoffs(cfg)
    ):
        out["cutoff"] = (
            f"the cross-interface coupling ({cfg.potential.coupling}) has no cutoff setting "
            "of its own (coupling: lj has potential.lj.cutoff_angstrom, coupling: interlayer "
            f"a cutoff argument of {', '.join(sorted(CUTOFF_FIRST_STYLES))})"
        )
    return out


def _interlayer_styles(cfg: RunConfig) -> list[dict]:
    """The ``potential.interlayer`` styles of ``cfg`` as plain data (one or a list)."""
    data = cfg.to_dict()["potential"].get("interlayer")
    if data is None:
        return []
    return [data] if isinstance(data, dict) else list(data)


def interlayer_cutoffs(cfg: RunConfig) -> list[float]:
    """The global cutoffs (Å) of the interlayer styles that take one (``coupling: interlayer``)."""
    if cfg.potential.coupling != "interlayer":
        return []
    cuts = (style_cutoff_angstrom(s["pair_style"]) for s in _interlayer_styles(cfg))
    return [c for c in cuts if c is not None]


def _cutoff_step(cfg: RunConfig, level: int) -> tuple[dict, float, str]:
    """Overrides, x value and label of the cross-interface cutoff refined ``level`` times.

    ``coupling: lj``: the LJ cutoff + level · step (the energy is shifted to zero there).
    ``coupling: interlayer``: every interlayer style with a cutoff argument (KC, ILP,
    coul/shield) gets its own cutoff + level · step, its taper flag kept: the taper takes the
    term smoothly to zero at the new cutoff, so every step is a continuous potential; the
    ladder only lengthens the cutoff from the model's own (the fitted 16 Å of the presets),
    it never cuts into the range the model was fitted with.
    """
    add = level * cfg.refine.cutoff_step_angstrom
    if cfg.potential.coupling == "lj":
        rc = cfg.potential.lj.cutoff_angstrom + add
        return {"potential": {"lj": {"cutoff_angstrom": rc}}}, rc, f"LJ cutoff {rc:g} Å"
    styles = []
    for s in _interlayer_styles(cfg):
        rc = style_cutoff_angstrom(s["pair_style"])
        styles.append(
            s if rc is None else {**s, "pair_style": with_cutoff(s["pair_style"], rc + add)}
        )
    rc = interlayer_cutoffs(cfg)[0] + add
    potential = cfg.to_dict()["potential"]  # whole: an interlayer entry replaces the model
    interlayer = styles[0] if isinstance(potential["interlayer"], dict) else styles
    return {"potential": {**potential, "interlayer": interlayer}}, rc, f"interlayer cutoff {rc:g} Å"


def chosen_settings(cfg: RunConfig) -> tuple[list[str], dict[str, str]]:
    """(settings to refine, {setting: why it is skipped}) from ``cfg.refine.settings``."""
    why = applicable_settings(cfg)
    asked = REFINABLE if cfg.refine.settings == "auto" else tuple(cfg.refine.settings)
    skipped = {s: why[s] for s in REFINABLE if s in asked and why[s]}
    if cfg.refine.settings != "auto" and skipped:
        s, reason = next(iter(skipped.items()))
        raise InputError(f"refine.settings: {s!r} cannot be refined here: {reason}")
    return [s for s in asked if not why[s]], skipped


def _midpoints(values: list[float]) -> list[float]:
    out = [values[0]]
    for a, b in itertools.pairwise(values):
        out += [(a + b) / 2, b]
    return out


def step(cfg: RunConfig, setting: str, level: int) -> Variant:
    """The variant of ``setting`` refined ``level`` times from ``cfg`` (level 0: the base)."""
    r, scan = cfg.refine, cfg.scan
    if level == 0:
        return Variant("base", "base", 0, math.nan, "base", {})
    if setting == "grid":
        grid = [math.ceil(g * r.grid_factor**level - 1e-9) for g in scan.grid]
        over, value, label = {"scan": {"grid": grid}}, float(grid[0]), f"grid {grid[0]}x{grid[1]}"
    elif setting == "thicknesses":
        if scan.p_range_gpa is not None:
            n = math.ceil(scan.p_range_gpa.n * r.thickness_factor**level - 1e-9)
            rng = {**cfg.section("scan")["p_range_gpa"], "n": n}
            over, value = {"scan": {"p_range_gpa": rng}}, float(n)
        else:
            values = list(scan.thickness_angstrom)
            for _ in range(level):
                values = _midpoints(values)
            over, value = {"scan": {"thickness_angstrom": values}}, float(len(values))
        label = f"{int(value)} thicknesses"
    elif setting == "layers":
        add = r.layers_step
        if cfg.structure.kind == "quartz-dense":
            add = QUARTZ_LAYER_STEP * math.ceil(add / QUARTZ_LAYER_STEP)
        layers = cfg.structure.layers + level * add
        over, value, label = {"structure": {"layers": layers}}, float(layers), f"{layers} layers"
    elif setting == "fmax":
        fmax = scan.fmax_ev_per_angstrom * r.fmax_factor**level
        over = {"scan": {"fmax_ev_per_angstrom": fmax}}
        value, label = fmax, f"fmax {fmax:.3g} eV/Å"
    elif setting == "cutoff":
        over, value, label = _cutoff_step(cfg, level)
    else:
        raise InputError(
            f"refine.settings: expected some of {', '.join(REFINABLE)}, got {setting!r}"
        )
    return Variant(f"{setting}{level}", setting, level, value, label, over)


def base_value(cfg: RunConfig, setting: str) -> float:
    """The x value of the base run for ``setting`` (the study's figures)."""
    scan = cfg.scan
    if setting == "grid":
        return float(scan.grid[0])
    if setting == "thicknesses":
        return float(scan.p_range_gpa.n if scan.p_range_gpa else len(scan.thickness_angstrom))
    if setting == "layers":
        return float(cfg.structure.layers)
    if setting == "fmax":
        return float(scan.fmax_ev_per_angstrom)
    if cfg.potential.coupling == "interlayer" and interlayer_cutoffs(cfg):
        return interlayer_cutoffs(cfg)[0]
    return float(cfg.potential.lj.cutoff_angstrom)


def without_foreign_uncertainty(cfg: RunConfig) -> RunConfig:
    """``cfg`` without its ``uncertainty`` block when that was measured on another structure or model.

    A variant of a study changes the structure (layers) or the model (cutoff, ``--models``) of a
    base that may carry a measured block (the ``paper`` preset's quartz numbers): the block does
    not apply to the variant, and the run would refuse it
    (:func:`flatcontact.stages.measured_on.check_measured_on`). The study measures the variant's
    τ and σ_MSS, which the block does not touch, so the variant runs without it. A block that
    applies (the variants of the scan settings) is kept, so their stage fingerprints are those
    of the base's own configuration.
    """
    from flatcontact.stages.measured_on import measured_on

    recorded = cfg.uncertainty.measured_on
    if not recorded:
        return cfg
    mine = measured_on(cfg)
    if all(recorded[k] == mine[k] for k in recorded if k in mine):
        return cfg
    data = cfg.to_dict()
    del data["uncertainty"]
    return RunConfig.model_validate(data)


def variant_config(cfg: RunConfig, overrides: dict, source: str) -> RunConfig:
    """``cfg`` with ``overrides`` laid over it, validated (one-line InputError naming ``source``).

    An ``uncertainty`` block measured on another structure or model than the variant's is
    dropped (:func:`without_foreign_uncertainty`).
    """
    from flatcontact.config.messages import one_line

    try:
        out = RunConfig.model_validate(merge_config(cfg.to_dict(), overrides))
    except ValidationError as exc:
        raise one_line(exc, source) from None
    return without_foreign_uncertainty(out)


def shares_build(setting: str) -> bool:
    """Does a step of ``setting`` leave the build stage's inputs (structure, model) as they are?"""
    return setting in ("grid", "thicknesses", "fmax")
