"""Where concurrent slip stops: the critical contact size of the modified Mindlin numbers.

The modified Mindlin model assumes concurrent slip: every point of the interface reaches
its local strength τ(p) and gives way with its neighbours. Two size limits (SI units;
G* the paper's shear modulus, q0 = G*·u/(π a), stuck-contact stiffness 2 G* a):

Commensurate interfaces: dislocation-assisted slip (Hurtado & Kim, Proc. R. Soc. A 455,
3363 and 3385 (1999); Sharp, Pastewka, Lignères & Robbins, PRB 96, 155436 (2017))
-------------------------------------------------------------------------------------
A stuck contact of radius a under a tangential force Q is an external circular crack in
shear: its edge traction is Q/(2π a²)/√(1 − r²/a²). Once the energy released per unit
area of edge advance reaches the unstable stacking energy γ_us of the interface (the
barrier of the γ-surface along the sliding path), an interfacial dislocation loop
nucleates at the edge and sweeps the contact by one Burgers vector (Rice's criterion,
G = γ_us, in the energy-release form). With the stuck-contact compliance 1/(2 G* a) the
strain energy is U = Q²/(4 G* a), and averaged over the edge (area 2π a da)

    G = (dU/da)|_Q / (2π a) = Q²/(8π G* a³) = π τ̄² a / (8 G*),   τ̄ = Q/(π a²),

so the mean shear stress at which a dislocation nucleates is

    τ_dis(a) = √(8 G* γ_us / (π a)),

falling as a^(−1/2) (Hurtado & Kim's single-dislocation-assisted regime). Concurrent
slip holds while it lies above the concurrent-slip strength τ_c (here the modified
Mindlin Q_peak/πa² of the p0); the critical radius is

    a_c = 8 G* γ_us / (π τ_c²).

For a sinusoidal γ-surface of period b (the Burgers vector, the shift-lattice period along
the sliding direction) and peak τ_max, γ_us = τ_max b/π; the shape factor
π γ_us/(τ_max b) of the run's own path is reported. Assumptions: an isotropic elastic
stuck contact (the paper's G*), the edge at zero pressure (γ_us at the lowest load), one
loop nucleated on the interface plane, no lattice friction for its glide (the
multiple-dislocation regime of Hurtado & Kim's Part II, where the stress levels at the
interface's Peierls stress, is not estimated: τ_dis is an upper estimate there). The
estimate is an order of magnitude near a_c, where a_c is a few dislocation core widths
ζ = G* b/(2π τ_max) (reported as a_c/ζ).

Incommensurate and approximant interfaces: the elastic bound of superlubricity
(Sharp, Pastewka & Robbins, PRB 93, 121402 (2016))
------------------------------------------------------------------------------
A contact slides as a rigid body (superlubric, its friction stress falling with size) while
its elastic displacement under the interfacial stress stays below the period: a patch of
size ℓ has stiffness ~ 2 G* ℓ, so the stress τ_p displaces it by ~ π ℓ τ_p/(2 G*); it
reaches b/2 (locking into local registry becomes possible) at

    a_el = G* b / (π τ_p),

with τ_p the run's concurrent-slip strength of the cell. Beyond a_el elasticity lets the
interface pin locally and the friction stress stops falling with size: the concurrent
number of the approximant is then only a lower bound (no size-limited estimate is made).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from flatcontact.contact.parameters import check_positive

FloatArray = NDArray[np.float64]

#: The structure kinds (:func:`structure_regime`) and their size limit.
COMMENSURATE, TWISTED, APPROXIMANT = "commensurate", "twisted", "approximant"


def dislocation_strength(
    contact_radius_m: ArrayLike, shear_modulus_pa: float, unstable_stacking_j_per_m2: float
) -> FloatArray:
    """τ_dis(a) = √(8 G* γ_us/(π a)) (Pa): the mean shear stress at which an interfacial
    dislocation nucleates at the edge of a stuck contact of radius a (paper's G*)."""
    a = np.asarray(contact_radius_m, dtype=float)
    return np.sqrt(8.0 * shear_modulus_pa * unstable_stacking_j_per_m2 / (np.pi * a))


def critical_radius(
    concurrent_strength_pa: ArrayLike, shear_modulus_pa: float, unstable_stacking_j_per_m2: float
) -> FloatArray:
    """a_c = 8 G* γ_us/(π τ_c²) (m): above it τ_dis(a) < τ_c (commensurate interfaces)."""
    tau = np.asarray(concurrent_strength_pa, dtype=float)
    return 8.0 * shear_modulus_pa * unstable_stacking_j_per_m2 / (np.pi * tau**2)


def elastic_bound(
    concurrent_strength_pa: ArrayLike, shear_modulus_pa: float, burgers_m: float
) -> FloatArray:
    """a_el = G* b/(π τ_p) (m): the size above which an incommensurate contact no longer
    slides as a rigid body (Sharp, Pastewka & Robbins 2016)."""
    tau = np.asarray(concurrent_strength_pa, dtype=float)
    return shear_modulus_pa * burgers_m / (np.pi * tau)


def core_width(tau_max_pa: float, shear_modulus_pa: float, burgers_m: float) -> float:
    """ζ = G* b/(2π τ_max) (m), the Peierls–Nabarro half-width of a sinusoidal interface."""
    return shear_modulus_pa * burgers_m / (2.0 * np.pi * tau_max_pa)


def structure_regime(recipe: dict | None) -> tuple[str, str]:
    """(kind, why) of the interface from the build's ``recipe`` record (``build.json``).

    - ``twist_angle_deg`` present: twisted (a commensurate approximant of a twist);
    - ``match.kind`` 'coincidence' with a slab rotated or a supercell of more than one
      primitive cell: an approximant of an incommensurate interface;
    - otherwise (identity match, a strained 1×1 lock, no match record: the paper's quartz
      or a finished file): commensurate.
    """
    recipe = recipe or {}
    if recipe.get("twist_angle_deg") is not None:
        return TWISTED, f"twisted by {float(recipe['twist_angle_deg']):.4g}° (build.json)"
    match = recipe.get("match") or {}
    if match.get("kind") == "coincidence":
        dets = [
            abs(round(float(np.linalg.det(np.asarray(match[k], dtype=float)))))
            for k in ("slab1_supercell", "slab2_supercell")
            if k in match
        ]
        rotated = any(abs(float(match.get(f"slab{i}_rotation_deg", 0.0))) > 1e-3 for i in (1, 2))
        if rotated or any(d > 1 for d in dets):
            return APPROXIMANT, (
                f"coincidence cell of {'×'.join(str(d) for d in dets)} primitive cells"
                + (", rotated" if rotated else "")
                + " (build.json): an approximant of an incommensurate interface"
            )
        return COMMENSURATE, "a strained 1×1 coincidence: a commensurate lock (build.json)"
    if match.get("kind") == "identity":
        return COMMENSURATE, "both slabs on the same primitive cell (build.json)"
    return COMMENSURATE, "no coincidence or twist recorded: taken as commensurate"


@dataclass(frozen=True)
class SlipInterface:
    """What the size limit takes from the run: structure kind, γ_us, b, τ_max (SI)."""

    kind: str
    why: str
    unstable_stacking_j_per_m2: float | None
    burgers_m: float | None
    tau_max_pa: float | None = None
    source: str = ""

    def __post_init__(self) -> None:
        if self.unstable_stacking_j_per_m2 is not None:
            check_positive("unstable_stacking_j_per_m2", self.unstable_stacking_j_per_m2)
        if self.burgers_m is not None:
            check_positive("burgers_m", self.burgers_m)


@dataclass(frozen=True)
class SlipSize:
    """The size limit at one p0 (SI; ``record`` is unit-named)."""

    p0_gpa: float
    contact_radius_m: float
    concurrent_strength_pa: float
    critical_radius_m: float
    size_limited_strength_pa: float | None  # None: not estimated (incommensurate)
    exceeded: bool

    def record(self) -> dict:
        s = self.size_limited_strength_pa
        return {
            "p0_gpa": self.p0_gpa,
            "contact_radius_nm": self.contact_radius_m * 1e9,
            "critical_radius_nm": self.critical_radius_m * 1e9,
            "exceeded": self.exceeded,
            "concurrent_strength_mpa": self.concurrent_strength_pa * 1e-6,
            "size_limited_strength_mpa": None if s is None else s * 1e-6,
        }


def size_limits(
    interface: SlipInterface,
    p0_gpa: ArrayLike,
    contact_radius_m: ArrayLike,
    concurrent_strength_pa: ArrayLike,
    shear_modulus_pa: float,
) -> tuple[SlipSize, ...] | None:
    """Per p0: the contact radius against the critical size of ``interface``; None when the
    run lacks γ_us (commensurate) or b (incommensurate)."""
    p0 = np.atleast_1d(np.asarray(p0_gpa, dtype=float))
    a = np.atleast_1d(np.asarray(contact_radius_m, dtype=float))
    tau = np.atleast_1d(np.asarray(concurrent_strength_pa, dtype=float))
    if interface.kind == COMMENSURATE:
        if interface.unstable_stacking_j_per_m2 is None:
            return None
        crit = critical_radius(tau, shear_modulus_pa, interface.unstable_stacking_j_per_m2)
        tdis = dislocation_strength(a, shear_modulus_pa, interface.unstable_stacking_j_per_m2)
        limited = np.minimum(tau, tdis)
    else:
        if interface.burgers_m is None:
            return None
        crit = elastic_bound(tau, shear_modulus_pa, interface.burgers_m)
        limited = [None] * p0.size
    return tuple(
        SlipSize(
            float(p0[i]),
            float(a[i]),
            float(tau[i]),
            float(crit[i]),
            None if limited[i] is None else float(limited[i]),
            bool(a[i] > crit[i]),
        )
        for i in range(p0.size)
    )


def slip_sentences(doc: dict | None) -> list[str]:
    """One sentence per p0 whose contact radius exceeds the critical size (the report box
    and the console) of ``summary.json["slip_size"]``."""
    if not doc:
        return []
    out = []
    commensurate = doc["structure"] == "commensurate"
    for r in doc["results"]:
        if not r["exceeded"]:
            continue
        if commensurate:
            out.append(
                f"p0 = {r['p0_gpa']:g} GPa: the contact radius a = {r['contact_radius_nm']:.4g} nm "
                f"exceeds the critical radius of concurrent slip a_c = "
                f"{r['critical_radius_nm']:.3g} nm of this commensurate interface, so it slides "
                f"by dislocation-assisted slip at about {r['size_limited_strength_mpa']:.4g} MPa, "
                f"not the concurrent-slip {r['concurrent_strength_mpa']:.4g} MPa "
                f"(reported: {r['reported']})."
            )
        else:
            out.append(
                f"p0 = {r['p0_gpa']:g} GPa: the contact radius a = {r['contact_radius_nm']:.4g} nm "
                f"exceeds the elastic bound of superlubricity a_el = "
                f"{r['critical_radius_nm']:.3g} nm of this {doc['structure']} cell, so the "
                f"concurrent-slip {r['concurrent_strength_mpa']:.4g} MPa is only a lower bound "
                "(no size-limited estimate)."
            )
    return out
