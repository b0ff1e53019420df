"""Per-p0 results of the contact model: the JSON summary and ``contact.nc``.

:func:`analyse` evaluates everything the CLI reports for a list of p0; the result
converts to the unit-named JSON records (:meth:`ContactAnalysis.records`) and to
an xarray Dataset (:meth:`ContactAnalysis.to_dataset`) written atomically as
``contact.nc`` (h5netcdf) with a ``units`` attribute on every variable.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import xarray as xr

from flatcontact import __version__
from flatcontact.contact import adhesion, mindlin
from flatcontact.contact.oscillation import StiffnessCurve, stiffness_curve
from flatcontact.contact.parameters import ContactParameters
from flatcontact.foundation import units

#: Points of each Q(u) curve, on u in [0, 1.5·u_fs].
N_DISPLACEMENT = 301


@dataclass(frozen=True)
class ContactAnalysis:
    """Model results for several p0 (SI inside; unit-named views for output)."""

    params: ContactParameters
    p0_gpa: tuple[float, ...]
    maugis_lambda: float | None
    knee_fraction: float
    curves: tuple[StiffnessCurve, ...]
    peaks: mindlin.PeakForce
    displacement_m: np.ndarray  # (n_p0, N_DISPLACEMENT)
    response: mindlin.LateralResponse  # arrays (n_p0, N_DISPLACEMENT)
    #: the peak pressure the model is evaluated at per p0 (the Hertzian part over the
    #: adhesive radius, :mod:`.adhesion_regime`); None: p0 itself (Hertz)
    contact_p0_gpa: tuple[float, ...] | None = None

    @property
    def p0_pa(self) -> np.ndarray:
        """The given peak Hertz pressures (Pa): they fix the loads."""
        return np.asarray(self.p0_gpa) * units.GPA_TO_PA

    @property
    def contact_p0_pa(self) -> np.ndarray:
        """The peak pressures (Pa) the modified Mindlin model is evaluated at."""
        if self.contact_p0_gpa is None:
            return self.p0_pa
        return np.asarray(self.contact_p0_gpa) * units.GPA_TO_PA

    def records(self) -> list[dict[str, Any]]:
        """One JSON-ready dict per p0 (keys carry their units)."""
        pr = self.params
        p0 = self.p0_pa
        pc = self.contact_p0_pa
        a_h = mindlin.contact_radius(p0, pr)
        a = mindlin.contact_radius(pc, pr)  # the adhesive radius where pc != p0
        area = np.pi * a**2
        load = 2.0 / 3.0 * np.pi * a_h**2 * p0  # the applied load
        w = pr.work_of_adhesion_j_per_m2
        out = []
        for i, c in enumerate(self.curves):
            rec: dict[str, Any] = {
                "p0_gpa": self.p0_gpa[i],
                "contact_radius_nm": float(a[i] / units.NM_TO_M),
                "hertz_contact_radius_nm": float(a_h[i] / units.NM_TO_M),
                "contact_peak_pressure_gpa": float(pc[i] / units.GPA_TO_PA),
                "normal_load_un": float(load[i] * units.N_TO_UN),
                "mean_pressure_gpa": float(2.0 / 3.0 * pc[i] / units.GPA_TO_PA),
                "hertz_approach_nm": float(a_h[i] ** 2 / pr.radius_m / units.NM_TO_M),
            }
            if w > 0.0:
                for model, key in (("dmt", "dmt"), ("jkr", "jkr")):
                    am = float(
                        adhesion.contact_radius_at_p0(
                            model, p0[i], pr.radius_m, pr.contact_modulus_pa, w
                        )
                    )
                    rec[f"contact_radius_{key}_nm"] = am / units.NM_TO_M
                    rec[f"contact_radius_change_{key}_percent"] = 100.0 * (am / a_h[i] - 1.0)
                # pull-off (magnitude, load control): 2πwR (DMT), 1.5πwR (JKR)
                rec["pull_off_force_dmt_un"] = float(
                    adhesion.dmt_pull_off_force(w, pr.radius_m) * units.N_TO_UN
                )
                rec["pull_off_force_jkr_un"] = float(
                    adhesion.jkr_pull_off_force(w, pr.radius_m) * units.N_TO_UN
                )
                if self.maugis_lambda is not None:
                    am = float(
                        adhesion.contact_radius_at_p0(
                            "maugis-dugdale",
                            p0[i],
                            pr.radius_m,
                            pr.contact_modulus_pa,
                            w,
                            self.maugis_lambda,
                        )
                    )
                    rec["contact_radius_maugis_dugdale_nm"] = am / units.NM_TO_M
                    rec["contact_radius_change_maugis_dugdale_percent"] = 100.0 * (
                        am / a_h[i] - 1.0
                    )
                    rec["pull_off_force_maugis_dugdale_un"] = float(
                        adhesion.maugis_dugdale_pull_off_force(w, pr.radius_m, self.maugis_lambda)
                        * units.N_TO_UN
                    )
            pk = self.peaks
            rec.update(
                {
                    "peak_lateral_force_un": float(pk.force_n[i] * units.N_TO_UN),
                    "displacement_at_peak_nm": float(pk.displacement_m[i] / units.NM_TO_M),
                    "stick_radius_at_peak_nm": float(pk.stick_radius_m[i] / units.NM_TO_M),
                    "stick_inner_radius_at_peak_nm": float(
                        pk.stick_inner_radius_m[i] / units.NM_TO_M
                    ),
                    "saturated_lateral_force_un": float(pk.saturated_force_n[i] * units.N_TO_UN),
                    "full_slip_displacement_nm": float(
                        pk.full_slip_displacement_m[i] / units.NM_TO_M
                    ),
                    "overshoot": bool(pk.overshoot[i]),
                    "effective_shear_strength_mpa": float(
                        pk.force_n[i] / area[i] / units.MPA_TO_PA
                    ),
                    "effective_shear_strength_rms_mpa": float(
                        pk.force_n[i] / (np.sqrt(2.0) * area[i]) / units.MPA_TO_PA
                    ),
                    "gross_sliding_stress_mpa": float(
                        pk.saturated_force_n[i] / area[i] / units.MPA_TO_PA
                    ),
                    "uniform_shear_strength_mpa": float(
                        (pr.k * 2.0 / 3.0 * pc[i] + pr.tau0_pa) / units.MPA_TO_PA
                    ),
                    "initial_lateral_stiffness_n_per_m": c.initial_stiffness_n_per_m,
                    "knee_fraction": c.knee_fraction,
                    "knee_stress_amplitude_mpa": c.knee_stress_amplitude_pa / units.MPA_TO_PA,
                    "knee_stress_rms_mpa": c.knee_stress_rms_pa / units.MPA_TO_PA,
                }
            )
            out.append(rec)
        return out

    def to_dataset(self):
        """The Q(u) and stiffness curves as an xarray Dataset (units in attributes)."""
        n_amp = max(c.q_max_n.size for c in self.curves)

        def pad(arrs):
            m = np.full((len(arrs), n_amp), np.nan)
            for i, x in enumerate(arrs):
                m[i, : x.size] = x
            return m

        cv = self.curves
        r = self.response
        dims_u = ("p0", "displacement_index")
        dims_k = ("p0", "amplitude_index")
        ds = xr.Dataset(
            {
                "displacement": (dims_u, self.displacement_m / units.NM_TO_M, {"units": "nm"}),
                "lateral_force": (dims_u, r.lateral_force_n * units.N_TO_UN, {"units": "uN"}),
                "stick_force": (dims_u, r.stick_force_n * units.N_TO_UN, {"units": "uN"}),
                "slip_force": (dims_u, r.slip_force_n * units.N_TO_UN, {"units": "uN"}),
                "stick_radius": (dims_u, r.stick_radius_m / units.NM_TO_M, {"units": "nm"}),
                "force_amplitude": (
                    dims_k,
                    pad([c.q_max_n * units.N_TO_UN for c in cv]),
                    {"units": "uN"},
                ),
                "mean_displacement": (
                    dims_k,
                    pad([c.mean_displacement_m / units.NM_TO_M for c in cv]),
                    {"units": "nm", "long_name": "<u>, rms over a quarter cycle"},
                ),
                "lateral_stiffness": (
                    dims_k,
                    pad([c.stiffness_n_per_m for c in cv]),
                    {"units": "N/m", "long_name": "d<Q>/d<u>"},
                ),
                "stress_amplitude": (
                    dims_k,
                    pad([c.stress_amplitude_pa / units.MPA_TO_PA for c in cv]),
                    {"units": "MPa", "long_name": "Q_max/(pi a^2)"},
                ),
                "stress_rms": (
                    dims_k,
                    pad([c.stress_rms_pa / units.MPA_TO_PA for c in cv]),
                    {"units": "MPa", "long_name": "<Q>/(pi a^2)"},
                ),
            },
            coords={
                "p0": (
                    "p0",
                    np.asarray(self.p0_gpa),
                    {"units": "GPa", "long_name": "peak Hertz pressure"},
                )
            },
        )
        for key in self.records()[0]:
            vals = [rec.get(key) for rec in self.records()]
            if key == "p0_gpa" or any(v is None for v in vals):
                continue
            name, unit = _split_unit(key)
            ds[name] = (
                "p0",
                np.asarray(vals, dtype=float if not isinstance(vals[0], bool) else bool),
                {"units": unit},
            )
        ds.attrs.update({f"param_{k}": v for k, v in self.params.as_dict().items()})
        ds.attrs["model"] = "modified Mindlin (Dong et al.), q0 = G* u/(pi a)"
        ds.attrs["flatcontact_version"] = __version__
        return ds


_SUFFIXES = {
    "_nm": "nm",
    "_un": "uN",
    "_gpa": "GPa",
    "_mpa": "MPa",
    "_n_per_m": "N/m",
    "_percent": "%",
}


def _split_unit(key: str) -> tuple[str, str]:
    for suf, unit in _SUFFIXES.items():
        if key.endswith(suf):
            return key[: -len(suf)], unit
    return key, "1"


def analyse(
    p0_gpa: Any,
    params: ContactParameters,
    *,
    maugis_lambda: float | None = None,
    knee_fraction: float = 0.5,
    p0_name: str = "p0_gpa",
    contact_p0_gpa: Any = None,
) -> ContactAnalysis:
    """Evaluate Q(u), the peak, the stiffness curve and adhesion radii for each p0 (GPa).

    ``contact_p0_gpa`` (one per p0): the peak pressure of the Hertzian part over the
    adhesive radius (:func:`flatcontact.contact.adhesion_regime.adhesion_regime`) at which
    the model is evaluated; the p0 then only fix the applied loads. None: Hertz.

    Raises
    ------
    InputError
        Before any work, if a p0 is not > 0 or puts τ <= 0 or σ < 0 somewhere in the
        contact (k or μ < 0); the message names ``p0_name`` and the limit.
    """
    p0_list = tuple(params.check_p0_gpa(p0_gpa, p0_name))
    contact = None
    if contact_p0_gpa is not None:
        name = f"{p0_name} (as p1, the adhesive contact's Hertzian peak pressure)"
        contact = tuple(params.check_p0_gpa(contact_p0_gpa, name))
    p0 = np.asarray(contact or p0_list) * units.GPA_TO_PA
    peaks = mindlin.peak_force(p0, params)
    u = np.linspace(0.0, 1.5, N_DISPLACEMENT)[None, :] * peaks.full_slip_displacement_m[:, None]
    resp = mindlin.lateral_force(u, p0[:, None], params)
    curves = tuple(stiffness_curve(float(x), params, knee_fraction=knee_fraction) for x in p0)
    return ContactAnalysis(
        params=params,
        p0_gpa=p0_list,
        maugis_lambda=maugis_lambda,
        knee_fraction=knee_fraction,
        curves=curves,
        peaks=peaks,
        displacement_m=u,
        response=resp,
        contact_p0_gpa=contact,
    )
