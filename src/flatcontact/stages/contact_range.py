"""The contact stage's range: its adhesion regime and where concurrent slip stops.

- :func:`facts`: what the contact's range takes from the run (the pipeline reads it once):
  the gap between the facing atomic planes of ``interface.extxyz`` (z0 of the Tabor
  parameter), the build's structure record (``build.json`` ``recipe``: commensurate,
  twisted, approximant) and, at the lowest analysed load, the sliding path of
  ``friction.nc``: its barrier γ_us, its length b (the shift-lattice period along the
  sliding direction) and its largest force τ_max.
- :func:`adhesion_of`: :func:`flatcontact.contact.adhesion_regime.adhesion_regime` with the
  settings' names (``contact.p0_gpa``, ``contact.maugis_lambda``, ...).
- :func:`slip_of`: :func:`flatcontact.contact.slip_size.size_limits` at every p0, with the
  modified Mindlin Q_peak/πa² as the concurrent-slip strength.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from flatcontact.foundation import units

#: 1 meV/Å² in J/m².
MEV_PER_A2_TO_J_PER_M2 = 1e-3 * units.EV_PER_A2_TO_J_PER_M2


def interface_gap_angstrom(atoms) -> float | None:
    """The gap (Å) between the highest atom of slab 1 and the lowest of slab 2 (None if the
    slabs overlap in z or a slab is missing)."""
    slab = np.asarray(atoms.arrays["slab"])
    z = atoms.positions[:, 2]
    if not (np.any(slab == 1) and np.any(slab == 2)):
        return None
    gap = float(z[slab == 2].min() - z[slab == 1].max())
    return gap if gap > 0.0 else None


def path_facts(friction) -> dict:
    """γ_us (J/m²), b (Å) and τ_max (MPa) of the sliding path at the lowest load of
    ``friction`` (the opened ``friction.nc``); {} without a path.

    γ_us is the lowest minimum-energy-path barrier to the start's image one period along the
    sliding direction (``barrier_along_direction_mev_per_a2``: the way an interfacial
    dislocation goes), else the barrier of the reported path (max − min of its energy);
    b is the straight distance between the path's ends (one period along the direction)."""
    if "path_energy" not in friction:
        return {}
    i = int(np.argmin(friction["p_gpa"].values))
    e = np.asarray(friction["path_energy"].values[i], dtype=float)
    x = np.asarray(friction["path_x"].values[i], dtype=float)
    y = np.asarray(friction["path_y"].values[i], dtype=float)
    f = np.asarray(friction["path_force"].values[i], dtype=float)
    ok = np.isfinite(e) & np.isfinite(x) & np.isfinite(y)
    if ok.sum() < 3:
        return {}
    x, y = x[ok], y[ok]
    barrier, source = float(e[ok].max() - e[ok].min()), "the sliding path's barrier"
    if "barrier_along_direction_mev_per_a2" in friction:
        mep = float(friction["barrier_along_direction_mev_per_a2"].values[i])
        if math.isfinite(mep) and mep > 0.0:
            barrier, source = mep, "the minimum-energy-path barrier along the sliding direction"
    return {
        "p_gpa": float(friction["p_gpa"].values[i]),
        "unstable_stacking_j_per_m2": barrier * MEV_PER_A2_TO_J_PER_M2,
        "unstable_stacking_source": source,
        "burgers_angstrom": float(np.hypot(x[-1] - x[0], y[-1] - y[0])),
        "tau_max_mpa": float(np.nanmax(np.abs(f))),
    }


def facts(interface_path: Path, build_json: Path, friction) -> dict:
    """The run's facts for the contact's range (see the module)."""
    from flatcontact.structures.interface_io import read_interface

    recipe = None
    if build_json.is_file():
        recipe = json.loads(build_json.read_text()).get("recipe")
    return {
        "gap_angstrom": interface_gap_angstrom(read_interface(interface_path)),
        "recipe": recipe,
        "path": path_facts(friction) if friction is not None else {},
    }


def adhesion_of(settings, inputs, params, p0_gpa=None, p0_name: str = "contact.p0_gpa"):
    """The adhesion regime of the run (:mod:`flatcontact.contact.adhesion_regime`): z0 from
    ``contact.equilibrium_separation_angstrom`` or the built interface's gap; at
    ``contact.p0_gpa`` or at the peak pressures ``p0_gpa`` (named ``p0_name``)."""
    from flatcontact.contact.adhesion_regime import adhesion_regime

    c = settings.contact
    z0, source = None, ""
    gap = (inputs.interface or {}).get("gap_angstrom")
    if c.equilibrium_separation_angstrom is not None:
        z0, source = c.equilibrium_separation_angstrom, "contact.equilibrium_separation_angstrom"
    elif gap:
        z0, source = gap, "gap between the facing atomic planes of the built interface"
    return adhesion_regime(
        c.p0_gpa if p0_gpa is None else p0_gpa,
        params,
        equilibrium_separation_m=None if z0 is None else z0 * 1e-10,
        z0_source=source,
        maugis_lambda=c.maugis_lambda,
        use_hertz=c.contact_radius == "hertz",
        p0_name=p0_name,
    )


def contact_p0_gpa(regime) -> tuple[float, ...] | None:
    """The peak pressures (GPa) the modified Mindlin model is evaluated at; None: Hertz."""
    if not regime.adhesive:
        return None
    return tuple(float(p) / units.GPA_TO_PA for p in regime.contact_p0_pa)


def slip_interface(inputs):
    """The :class:`~flatcontact.contact.slip_size.SlipInterface` of the run (None without
    the run's facts, e.g. ``flatcontact contact`` alone)."""
    from flatcontact.contact.slip_size import SlipInterface, structure_regime

    run = inputs.interface
    if run is None:
        return None
    if run.get("structure"):
        kind, why = run["structure"], "given"
    else:
        kind, why = structure_regime(run.get("recipe"))
    path = run.get("path") or {}
    gus, b = path.get("unstable_stacking_j_per_m2"), path.get("burgers_angstrom")
    return SlipInterface(
        kind,
        why,
        gus if gus and gus > 0 else None,
        b * 1e-10 if b and b > 0 else None,
        path["tau_max_mpa"] * 1e6 if "tau_max_mpa" in path else None,
        path.get("source")
        or f"{path.get('unstable_stacking_source', 'the path')} and the path's period, "
        f"friction.nc at P = {path.get('p_gpa', 0.0):g} GPa",
    )


def slip_of(settings, interface, analysis) -> dict | None:
    """``summary.json["slip_size"]``: per p0 the contact radius against the critical size,
    the concurrent and the size-limited strength, and which one ``contact.slip_regime``
    reports (None without an interface or a path)."""
    from flatcontact.contact import mindlin
    from flatcontact.contact.slip_size import COMMENSURATE, core_width, size_limits

    if interface is None:
        return None
    params = analysis.params
    a = mindlin.contact_radius(analysis.contact_p0_pa, params)
    tau = analysis.peaks.force_n / (np.pi * a**2)
    rows = size_limits(interface, analysis.p0_gpa, a, tau, params.shear_modulus_pa)
    if rows is None:
        return None
    mode = settings.contact.slip_regime
    doc = {
        "structure": interface.kind,
        "why": interface.why,
        "slip_regime": mode,
        "source": interface.source,
        "shear_modulus_gpa": params.shear_modulus_gpa,
        "unstable_stacking_j_per_m2": interface.unstable_stacking_j_per_m2,
        "burgers_angstrom": None if interface.burgers_m is None else interface.burgers_m * 1e10,
        "estimate": "a_c = 8 G* gamma_us/(pi tau_c^2), tau_dis(a) = sqrt(8 G* gamma_us/(pi a))"
        if interface.kind == COMMENSURATE
        else "a_el = G* b/(pi tau_p); beyond it the concurrent number is a lower bound",
        "results": [],
    }
    t, b, g = interface.tau_max_pa, interface.burgers_m, interface.unstable_stacking_j_per_m2
    if t and b and g and np.isfinite(t):
        doc["shape_factor"] = float(np.pi * g / (t * b))
        doc["core_width_nm"] = core_width(t, params.shear_modulus_pa, b) * 1e9
    for row in rows:
        rec = row.record()
        limited = row.size_limited_strength_pa is not None
        use_limited = limited and (mode == "size-limited" or (mode == "auto" and row.exceeded))
        rec["reported"] = "size-limited" if use_limited else "concurrent"
        rec["reported_strength_mpa"] = (
            rec["size_limited_strength_mpa"] if use_limited else rec["concurrent_strength_mpa"]
        )
        doc["results"].append(rec)
    return doc


def foreign_moduli_note(settings, provenance: dict, params) -> str | None:
    """A sentence when the configured E*, G* are the paper's α-quartz values (52.5, 29 GPa,
    DFT and its SNAP) but the run's material or interaction model is another; else None."""
    from flatcontact.foundation.reference import PAPER, is_paper_material

    if provenance.get("moduli") != "config":
        return None
    paper = (PAPER["contact_modulus_gpa"], PAPER["shear_modulus_gpa"])
    if (params.contact_modulus_gpa, params.shear_modulus_gpa) != paper:
        return None
    label = getattr(getattr(settings, "potential", None), "label", "") or ""
    if not is_paper_material(settings):
        whose = f"this run's material is {settings.structure.kind}"
    elif "snap" not in label.lower() and settings.structure.kind != "toy-lj":
        whose = f"this run's interaction model is {label}"
    else:
        return None
    return (
        f"E* = {paper[0]:g} GPa and G* = {paper[1]:g} GPa are the paper's α-quartz moduli "
        f"(DFT, its SNAP); {whose}: they belong to another material or potential than the "
        "run's (set elastic.enabled: true for the run's own)"
    )


def log_lines(adhesion: dict | None, slip: dict | None, moduli_note: str | None) -> None:
    """The contact's range in the run's log (the ``flatcontact`` logger, INFO): the adhesion
    regime, the moduli note and one line per p0 past the critical size. The console lines are
    printed by the commands from ``summary.json`` (``flatcontact run``, ``flatcontact
    contact``)."""
    import logging

    from flatcontact.contact.slip_size import slip_sentences

    log = logging.getLogger("flatcontact.contact")
    if adhesion is not None:
        log.info("contact: %s", adhesion["sentence"])
    for line in ([moduli_note] if moduli_note else []) + slip_sentences(slip):
        log.info("contact: %s", line)
