"""What a convergence study will cost, extrapolated from its base run, before the variants run.

``flatcontact study convergence CONFIG --estimate`` runs (or reuses) the base, the run every
setting shares, and prints per variant of every ladder: the points of its scan (lateral grid
points × thicknesses), the irreducible points it computes, its force calls and its time, so a
user knows whether the study fits the machine before spending it. The study itself prints
the same table after its base round and stores it in ``study.json`` (``estimate``) beside
what was spent.

Extrapolation from the base (``b``) to a variant (``v``), the rules stated per setting:

* points = ``grid_x · grid_y · thicknesses``; the thicknesses are the base scan's own list
  (the requested ones plus those the probe column added to reach P = 0, at the requested
  spacing), and a thickness step samples the same z range at the refined spacing,
  ``T_v = 1 + (T_b − 1)(R_v − 1)/(R_b − 1)`` (R: requested thicknesses). The probe may add
  a few more or fewer thicknesses for another grid or spacing: on the toy the points came out
  within 10 % (tests/studies/test_estimate.py). A refined spacing ``h_v = h_b (R_b − 1)/(R_v
  − 1)`` (``h_b`` the base's mean spacing) below the scan's minimum spacing
  (:data:`flatcontact.ispes.thicknesses.MIN_THICKNESS_SPACING_ANGSTROM`) is widened as the
  scan's merge widens it, to the first multiple of ``h_v`` at or above the minimum, and
  ``T_v = 1 + range_b / h_v`` (Ni(111), Foiles EAM, n 4 → 6: 15 estimated, 16 scanned; the
  rule without the merge said 29);
* computed points (the irreducible registries the scan relaxes) scale with the points:
  ``C_v = C_b · points_v / points_b`` (the interface's symmetry fraction is kept);
* force calls = the base's force calls per computed point × ``C_v``. For ``fmax`` and
  ``cutoff`` steps this is a lower bound (a tighter tolerance takes more optimiser steps;
  nothing relaxes in ``rigid``/``rigid-layers`` scans, where it is exact);
* scan seconds = the base's scan seconds per force call × force calls, times
  ``layers_v / layers_b`` for a layers step (cost per call ∝ atoms for the short-ranged
  potentials used here), and for a cutoff step times the measured ratio of one force call
  with the variant's model to one with the base's, on the base's unrelaxed interface
  (:func:`cutoff_call_ratios`; a longer cutoff multiplies the pairs a call sums: a
  bilayer-graphene KC rung 16 → 66 Å took 333 s where the per-call-constant rule said
  about 47 s; one call on its 4-atom cell, timed on a loaded machine: 0.5 ms at 16 Å,
  16 ms at 66 Å); build, analyze and laws take the base's seconds (a layers or cutoff
  variant rebuilds: the base's build seconds are counted for it, others share the base's).

Wall time: each round runs its variants side by side on ``workers`` processes, so a round
takes ``max(Σ seconds / workers, max seconds)``; the total assumes every setting uses all
``max_steps`` steps (an upper bound: a converged setting stops).
"""

from __future__ import annotations

import math
from pathlib import Path

from flatcontact.config.run import RunConfig
from flatcontact.foundation.errors import InputError
from flatcontact.foundation.layout import SCAN_JSON, STAGES
from flatcontact.foundation.result_json import read_result_json
from flatcontact.foundation.rundir import RECORD_NAME, RunDirectory
from flatcontact.ispes.thicknesses import MIN_THICKNESS_SPACING_ANGSTROM
from flatcontact.studies.approximant_cost import duration, time_force_call
from flatcontact.studies.variants import Variant, base_value, shares_build

#: The stages a variant runs (the study's runner stops after laws).
STUDY_STAGES = ("build", "scan", "analyze", "laws")


def base_measurements(base_dir: str | Path) -> dict:
    """What the finished base run measured: points, force calls and seconds per stage.

    Returns
    -------
    dict
        ``grid`` [nx, ny], ``thicknesses`` (the scan's own list, probe additions included),
        ``thickness_range_angstrom`` (its largest minus its smallest),
        ``points_total``, ``points_computed``, ``force_calls``, ``seconds`` (stage -> s).
    """
    root = Path(base_dir)
    folder = {s: root / f"{STAGES[s]:02d}-{s}" for s in STUDY_STAGES}
    seconds = {}
    for s in STUDY_STAGES:
        record = RunDirectory.read_record(folder[s]) or {}
        value = record.get("seconds")
        seconds[s] = float(value) if isinstance(value, int | float) and value >= 0 else 0.0
    record = RunDirectory.read_record(folder["scan"]) or {}
    inputs = (record.get("inputs") or {}).get("scan") or {}
    grid = inputs.get("grid")
    if not (isinstance(grid, list) and len(grid) == 2):
        raise InputError(f"{folder['scan'] / RECORD_NAME}: no scan grid; rerun the base")
    scan = read_result_json(folder["scan"] / SCAN_JSON, grid=grid)
    if "thickness_angstrom" not in scan:
        raise InputError(f"{folder['scan'] / SCAN_JSON}: no thickness_angstrom; rerun the base")
    return {
        "grid": [int(g) for g in inputs["grid"]],
        "thicknesses": len(scan["thickness_angstrom"]),
        "thickness_range_angstrom": float(
            max(scan["thickness_angstrom"]) - min(scan["thickness_angstrom"])
        ),
        "points_total": int(scan["points_total"]),
        "points_computed": int(scan.get("points_computed") or scan["points_total"]),
        "force_calls": int(scan["force_calls_total"]),
        "seconds": seconds,
    }


def _requested_thicknesses(cfg: RunConfig) -> int:
    scan = cfg.scan
    return scan.p_range_gpa.n if scan.p_range_gpa is not None else len(scan.thickness_angstrom)


def cutoff_call_ratios(cfg: RunConfig, ladder: dict[str, list[Variant]], configs: dict) -> dict:
    """Variant name -> (CPU s of one force call with its model) / (one with the base's), for
    the cutoff rungs of ``ladder`` (``configs``: variant name -> configuration dict), each
    timed on the base's interface built unrelaxed
    (:func:`flatcontact.studies.approximant_cost.time_force_call`)."""
    rungs = ladder.get("cutoff", [])
    if not rungs:
        return {}
    base_s = time_force_call(cfg.to_dict())["cpu_s"]
    return {v.name: time_force_call(configs[v.name])["cpu_s"] / max(base_s, 1e-9) for v in rungs}


def _variant_estimate(cfg: RunConfig, v: Variant, base: dict, call_ratio: float = 1.0) -> dict:
    grid = list(base["grid"])
    thick = base["thicknesses"]
    if v.setting == "grid":
        grid = [int(g) for g in v.overrides["scan"]["grid"]]
    elif v.setting == "thicknesses":
        requested = _requested_thicknesses(cfg)
        ratio = (requested - 1) / max(v.value - 1, 1)  # spacing of the rung / the base's
        span = base.get("thickness_range_angstrom")
        h = span / (thick - 1) * ratio if span and thick > 1 else None
        if (
            h is not None
            and cfg.scan.p_range_gpa is not None
            and h < MIN_THICKNESS_SPACING_ANGSTROM
        ):
            h *= math.ceil(MIN_THICKNESS_SPACING_ANGSTROM / h - 1e-9)  # the scan's merge
            thick = round(1 + span / h)
        else:
            thick = round(1 + (thick - 1) / ratio)
    points = grid[0] * grid[1] * thick
    computed = base["points_computed"] * points / base["points_total"]
    calls_per_point = base["force_calls"] / max(base["points_computed"], 1)
    calls = calls_per_point * computed
    per_call = base["seconds"]["scan"] / max(base["force_calls"], 1)
    scan_s = per_call * calls
    if v.setting == "layers":
        scan_s *= v.value / base_value(cfg, "layers")
    scan_s *= call_ratio
    build_s = 0.0 if shares_build(v.setting) else base["seconds"]["build"]
    seconds = build_s + scan_s + base["seconds"]["analyze"] + base["seconds"]["laws"]
    return {
        "name": v.name,
        "setting": v.setting,
        "level": v.level,
        "label": v.label,
        "grid": grid,
        "thicknesses": thick,
        "points": points,
        "points_computed": round(computed),
        "force_calls": round(calls),
        "seconds": seconds,
        "call_ratio": call_ratio,
        "lower_bound": v.setting in ("fmax", "cutoff")
        and cfg.scan.relax_mode not in ("rigid", "rigid-layers"),
    }


def estimate_convergence(
    cfg: RunConfig,
    ladder: dict[str, list[Variant]],
    base: dict,
    workers: int,
    call_ratios: dict[str, float] | None = None,
) -> dict:
    """The cost of every rung of ``ladder`` extrapolated from the measured ``base``.

    Parameters
    ----------
    cfg
        The study's base configuration.
    ladder
        Setting -> its variants, level 1 … ``max_steps`` (:func:`flatcontact.studies.
        variants.step`).
    base
        :func:`base_measurements` of the finished base run.
    workers
        Variants run side by side (the study's executor).
    call_ratios
        Variant name -> cost of its force call over the base's (:func:`cutoff_call_ratios`);
        1 for a variant not named.

    Returns
    -------
    dict
        ``base`` (as measured), ``variants`` (one estimate each), ``force_calls_study``
        (every rung once, the base once), ``force_calls_from_scratch`` (each setting's
        ladder with its own base), ``serial_seconds`` (every run one after another) and
        ``wall_seconds`` (rounds of ``workers`` side by side, every setting using all its
        steps: an upper bound). Seconds are the base's wall seconds scaled: they carry the
        machine's load while the base ran.
    """
    ratios = call_ratios or {}
    variants = [
        _variant_estimate(cfg, v, base, ratios.get(v.name, 1.0))
        for steps in ladder.values()
        for v in steps
    ]
    base_seconds = sum(base["seconds"].values())
    calls = base["force_calls"] + sum(v["force_calls"] for v in variants)
    scratch = calls + base["force_calls"] * max(len(ladder) - 1, 0)
    wall = base_seconds
    levels = max((len(s) for s in ladder.values()), default=0)
    for level in range(1, levels + 1):
        round_s = [v["seconds"] for v in variants if v["level"] == level]
        if round_s:
            wall += max(sum(round_s) / max(workers, 1), max(round_s))
    return {
        "base": base,
        "variants": variants,
        "force_calls_study": calls,
        "force_calls_from_scratch": scratch,
        "serial_seconds": base_seconds + sum(v["seconds"] for v in variants),
        "wall_seconds": wall,
        "workers": workers,
    }


def estimate_lines(est: dict) -> list[str]:
    """The estimate as console lines: one per variant, then the totals."""
    b = est["base"]
    lines = [
        f"estimate from the base ({b['grid'][0]}x{b['grid'][1]}, {b['thicknesses']} thicknesses: "
        f"{b['points_total']} points, {b['points_computed']} computed, {b['force_calls']} force "
        f"calls, {sum(b['seconds'].values()):.0f} s):"
    ]
    for v in est["variants"]:
        bound = " (lower bound)" if v["lower_bound"] else ""
        scanned = f"; ~{v['thicknesses']} scanned" if v["setting"] == "thicknesses" else ""
        if v.get("call_ratio", 1.0) != 1.0:
            scanned += f"; a force call ~{v['call_ratio']:.3g}x the base's"
        lines.append(
            f"  {v['name']} ({v['label']}{scanned}): {v['points']} points, ~{v['points_computed']} "
            f"computed, ~{v['force_calls']} force calls{bound}, ~{duration(v['seconds'])}"
        )
    lines.append(
        f"  all {len(est['variants'])} variants: ~{est['force_calls_study']} force calls "
        f"(each setting from scratch: ~{est['force_calls_from_scratch']}), "
        f"~{duration(est['serial_seconds'])} one after another, ~{duration(est['wall_seconds'])} on "
        f"{est['workers']} worker(s) if no setting converges early"
    )
    return lines
