"""Atoms against the continuum: the run's laws through the modified Mindlin model.

For one load, from the measured records (:mod:`.records`) and the laws τ = k p + τ0,
σ = μ p + σ0 (the run's laws stage or a given laws.json):

- **(1) Hertz**: the model as the contact stage runs it, at the measured normal load, with
  Hertz pressure from R and E* (cylinder: :mod:`flatcontact.contact.line_contact`; sphere:
  :mod:`flatcontact.contact.mindlin`, the contact stage's own model);
- **(2) measured pressure**: the same pointwise laws fed the atoms' pressure profile of the
  pressed state (bins inside the measured contact), separating the friction-law assumption
  from the elasticity.

The pointwise model (the paper's construction) gives Q(Q_fs), where Q_fs is the load a fully
stuck contact would carry, proportional to u; the compliance of a finite periodic box is not
the half-space's, so u = Q_fs / K0 with K0 the atoms' initial stiffness (Q/u at the first
lateral step) — the one fitted number (``fitted_compliance``). The atoms' Q is counted from
the pressed state (Q − Q0; ``lateral_force_at_zero_displacement_n`` = Q0, nonzero where the
registry has no mirror symmetry along the sliding, as fcc(111) along [11-2]). For the cylinder the elastic
(generalised Cattaneo) model's stick zone at the atoms' Q/Q_sat is given too.

Compared: Q_peak, the peak mean shear stress (sphere Q_peak/(π a²), cylinder Q'_peak/(2a)),
c/a against Q/Q_peak, Q(u), and the local q/p against τ(p)/p and σ(p)/p. Ratios are
atoms / model.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from flatcontact.asperity.records import Binning, StepRecord
from flatcontact.contact import line_contact as lc

GPA = 1e9
ANGSTROM = 1e-10


@dataclass(frozen=True)
class Laws:
    """The interface's laws in the units of laws.json."""

    k_mpa_per_gpa: float
    tau0_mpa: float
    mu_mpa_per_gpa: float
    sigma0_mpa: float

    def point_laws(self) -> lc.PointLaws:
        return lc.PointLaws(
            k=self.k_mpa_per_gpa * 1e-3,
            tau0_pa=self.tau0_mpa * 1e6,
            mu=self.mu_mpa_per_gpa * 1e-3,
            sigma0_pa=self.sigma0_mpa * 1e6,
        )

    @classmethod
    def from_json(cls, doc: dict) -> Laws:
        return cls(
            float(doc["k_mpa_per_gpa"]),
            float(doc["tau0_mpa"]),
            float(doc["mu_mpa_per_gpa"]),
            float(doc["sigma0_mpa"]),
        )


def _sphere_pointwise(r_m, p_pa, a_m, laws: lc.PointLaws, q0_pa):
    """Axisymmetric pointwise model on a radial profile: q_fs = q0/√(1 − r²/a²), stick where
    q_fs < τ(p), σ(p) elsewhere; Q = 2π ∫ q r dr (numerical, cells of the grid r)."""
    rm = 0.5 * (r_m[1:] + r_m[:-1])
    pm = 0.5 * (p_pa[1:] + p_pa[:-1])
    # ∫ q0 a / √(a² − r²) r dr = q0 a [√(a² − r0²) − √(a² − r1²)]
    stick_cell = a_m * (
        np.sqrt(np.clip(a_m**2 - r_m[:-1] ** 2, 0, None))
        - np.sqrt(np.clip(a_m**2 - r_m[1:] ** 2, 0, None))
    )
    slip_cell = laws.sigma_pa(pm) * 0.5 * (r_m[1:] ** 2 - r_m[:-1] ** 2)
    kernel = 1.0 / np.sqrt(np.clip(1.0 - (rm / a_m) ** 2, 1e-300, None))
    q0 = np.atleast_1d(q0_pa)[:, None]
    stick = q0 * kernel[None, :] < laws.tau_pa(pm)[None, :]
    load = 2 * np.pi * np.where(stick, q0 * stick_cell[None, :], slip_cell[None, :]).sum(axis=1)
    edge = np.where(stick, rm[None, :], 0.0).max(axis=1)
    return load, edge


def _curve(geometry, profile_x_m, profile_p_pa, a_m, laws, axis_m):
    """Q (N) against Q_fs (N) of the pointwise model on a profile, and the stick edge (m)."""
    top = 1.5 * float(np.max(laws.tau_pa(profile_p_pa)))
    if geometry == "cylinder":
        prof = lc.Profile(profile_x_m, profile_p_pa, a_m)
        qfs = np.linspace(0.0, top * np.pi * a_m, 3001)
        curve = lc.pointwise_response(prof, laws, qfs)
        return qfs * axis_m, curve.lateral_n_per_m * axis_m, curve.stick_half_width_m
    q0 = np.linspace(0.0, top, 3001)
    load, edge = _sphere_pointwise(profile_x_m, profile_p_pa, a_m, laws, q0)
    return 2 * np.pi * a_m**2 * q0, load, edge  # Q_fs = 2π a² q0 (full-stick integral)


def _side(geometry, x_m, p_pa, a_m, laws, axis_m, u_m, k0_n_per_m, q_ratio):
    """Peak, Q(u) and c/a at the atoms' Q/Q_peak of the pointwise model on one profile."""
    qfs, q, edge = _curve(geometry, x_m, p_pa, a_m, laws, axis_m)
    i_peak = int(np.argmax(q))
    peak = float(q[i_peak])
    q_of_u = np.interp(k0_n_per_m * np.asarray(u_m), qfs, q)
    rising = slice(0, i_peak + 1)
    # on the rising branch only: c/a at the same Q/Q_peak as the atoms' (None past their peak)
    c_over_a = [
        None if f is None else float(np.interp(f * peak, q[rising], edge[rising] / a_m))
        for f in q_ratio
    ]
    area = 2 * a_m * axis_m if geometry == "cylinder" else np.pi * a_m**2
    return {
        "half_width_angstrom": a_m / ANGSTROM,
        "peak_lateral_force_n": peak,
        "peak_shear_stress_mpa": peak / area / 1e6,
        "lateral_force_n": q_of_u.tolist(),
        "stick_ratio_at_atoms_q": c_over_a,
    }


def profiles(
    records: list[StepRecord], binning_: Binning, radius_angstrom: float, contact_modulus_gpa: float
) -> dict[str, tuple[np.ndarray, np.ndarray, float]]:
    """The two pressure profiles of the comparison, (x (m) on 0..a, p (Pa), a (m)):
    ``hertz`` at the measured normal load (R, E*) and ``measured_pressure`` (the pressed
    state's binned pressure inside the atoms' contact)."""
    geometry = binning_.geometry
    axis_m = binning_.axis_length_angstrom * ANGSTROM
    normal_n = float(records[0].normal_force_n)
    a_atoms = records[0].contact_half_width_angstrom * ANGSTROM
    e_star = contact_modulus_gpa * GPA
    R = radius_angstrom * ANGSTROM
    if geometry == "cylinder":
        a_h = float(lc.line_half_width(normal_n / axis_m, R, e_star))
        p0_h = float(lc.line_peak_pressure(normal_n / axis_m, a_h))
        hertz = lc.hertz_profile(a_h, p0_h)
        hx, hp = hertz.x_m, hertz.p_pa
    else:
        a_h = (3 * normal_n * R / (4 * e_star)) ** (1 / 3)
        p0_h = 3 * normal_n / (2 * np.pi * a_h**2)
        hx = a_h * np.sin(np.linspace(0, np.pi / 2, 2001))
        hp = p0_h * np.sqrt(np.clip(1 - (hx / a_h) ** 2, 0, None))
    centres = binning_.centres_angstrom * ANGSTROM
    p_meas = np.asarray(records[0].pressure_gpa) * GPA
    if geometry == "cylinder":
        prof = lc.measured_profile(centres, np.nan_to_num(p_meas), a_atoms)
        mx, mp = prof.x_m, prof.p_pa
    else:
        mx = np.linspace(0.0, a_atoms, 401)
        mp = np.interp(mx, centres, np.nan_to_num(p_meas))
        mp[-1] = 0.0
    return {"hertz": (hx, hp, a_h), "measured_pressure": (mx, mp, a_atoms)}


def compare_load(
    records: list[StepRecord],
    binning_: Binning,
    laws: Laws,
    radius_angstrom: float,
    contact_modulus_gpa: float,
) -> dict:
    """Atoms and the two continuum predictions of one load side by side (module docstring)."""
    geometry = binning_.geometry
    axis_m = binning_.axis_length_angstrom * ANGSTROM
    pl = laws.point_laws()
    u_m = np.array([r.displacement_angstrom for r in records]) * ANGSTROM
    # Q relative to the pressed state: a registry without the mirror y -> -y (fcc(111) along
    # [11-2]) leaves a lateral force Q0 on the held tip block at u = 0; the model starts at 0
    q_offset = float(records[0].lateral_force_n)
    q_n = np.array([r.lateral_force_n for r in records]) - q_offset
    normal_n = float(records[0].normal_force_n)
    a_atoms = records[0].contact_half_width_angstrom * ANGSTROM
    i_peak = int(np.argmax(q_n))
    q_peak = float(q_n[i_peak])
    k0 = float(q_n[1] / u_m[1]) if len(u_m) > 1 and u_m[1] > 0 else float("nan")
    ratio = np.clip(q_n / q_peak, 0.0, 1.0) if q_peak > 0 else np.zeros_like(q_n)
    # the atoms' rising branch: Q/Q_peak up to their peak, None after it
    rising = [float(f) if k <= i_peak else None for k, f in enumerate(ratio)]
    c_over_a = np.array(
        [
            r.stick_half_width_angstrom / r.contact_half_width_angstrom
            if r.contact_half_width_angstrom > 0
            else np.nan
            for r in records
        ]
    )
    area = 2 * a_atoms * axis_m if geometry == "cylinder" else np.pi * a_atoms**2
    atoms = {
        "normal_force_n": normal_n,
        "contact_half_width_angstrom": a_atoms / ANGSTROM,
        "peak_lateral_force_n": q_peak,
        "peak_displacement_angstrom": float(u_m[i_peak] / ANGSTROM),
        "lateral_force_at_zero_displacement_n": q_offset,
        # the largest Q at the last step: the slide never passed a peak, Q_peak is a lower bound
        "peak_reached": bool(i_peak < len(q_n) - 1),
        "peak_shear_stress_mpa": q_peak / area / 1e6 if area > 0 else None,
        "initial_stiffness_n_per_m": k0,
        "displacement_angstrom": (u_m / ANGSTROM).tolist(),
        "lateral_force_n": q_n.tolist(),
        "q_over_q_peak": ratio.tolist(),
        "stick_ratio": c_over_a.tolist(),
    }
    prof = profiles(records, binning_, radius_angstrom, contact_modulus_gpa)
    (hx, hp, a_h), (mx, mp, _) = prof["hertz"], prof["measured_pressure"]
    p0_h = float(hp[0])
    model_hertz = _side(geometry, hx, hp, a_h, pl, axis_m, u_m, k0, rising)
    model_hertz["peak_pressure_gpa"] = p0_h / GPA
    model_measured = _side(geometry, mx, mp, a_atoms, pl, axis_m, u_m, k0, rising)
    out = {
        "atoms": atoms,
        "model_hertz": model_hertz,
        "model_measured_pressure": model_measured,
        "fitted_compliance_m_per_n": 1.0 / k0 if k0 and np.isfinite(k0) else None,
        "ratios_atoms_over_model": {
            "peak_lateral_force_hertz": q_peak / model_hertz["peak_lateral_force_n"],
            "peak_lateral_force_measured_pressure": q_peak / model_measured["peak_lateral_force_n"],
            "contact_half_width_hertz": a_atoms / a_h,
        },
        "local_traction": local_traction(
            records, binning_, laws, [0, i_peak // 2, i_peak, len(records) - 1]
        ),
    }
    if geometry == "cylinder":
        sat = lc.sliding_force(lc.Profile(hx, hp, a_h), pl) * axis_m
        model_hertz["sliding_force_n"] = sat
        model_hertz["elastic_stick_ratio_at_atoms_q"] = [
            None
            if f is None
            else lc.elastic_response(
                lc.Profile(hx, hp, a_h), pl, f * sat / axis_m
            ).stick_half_width_m
            / a_h
            for f in rising
        ]
    return out


def local_traction(records: list[StepRecord], binning_: Binning, laws: Laws, steps) -> list[dict]:
    """Per bin inside the contact at the given steps: p, q, q/p and the laws τ(p), σ(p) (GPa)."""
    pl = laws.point_laws()
    out = []
    for k in sorted(set(int(s) for s in steps)):
        r = records[k]
        inside = np.abs(binning_.centres_angstrom) < r.contact_half_width_angstrom
        p = np.asarray(r.pressure_gpa)[inside]
        q = np.asarray(r.shear_gpa)[inside]
        with np.errstate(divide="ignore", invalid="ignore"):
            qp = np.where(p > 0, q / p, np.nan)
        out.append(
            {
                "step": k,
                "displacement_angstrom": r.displacement_angstrom,
                "bin_centre_angstrom": binning_.centres_angstrom[inside].tolist(),
                "pressure_gpa": p.tolist(),
                "shear_gpa": q.tolist(),
                "q_over_p": [None if not np.isfinite(v) else float(v) for v in qp],
                "tau_gpa": (pl.tau_pa(p * GPA) / GPA).tolist(),
                "sigma_gpa": (pl.sigma_pa(p * GPA) / GPA).tolist(),
            }
        )
    return out
