"""The steady oscillation cycles as output: JSON rows and the loops as an xarray Dataset.

The physics is :mod:`flatcontact.contact.cycle`; this module only converts its
:class:`~flatcontact.contact.cycle.SteadyCycle` results to unit-named records
(``summary.json`` ``cycle`` rows, ``contact --cycle --json``) and to the ``cycle_*``
variables of ``contact.nc``. Units are in the key (``_un``, ``_nm``, ``_fj``, ``_mpa``,
``_n_per_m``) or in each variable's ``units`` attribute.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import xarray as xr

from flatcontact.contact import cycle
from flatcontact.contact.cycle import SteadyCycle
from flatcontact.contact.parameters import ContactParameters
from flatcontact.foundation import units


def cycle_records(cyc: Sequence[SteadyCycle]) -> list[dict[str, Any]]:
    """One JSON-ready row per (p0, amplitude), unit-named keys (``contact --cycle --json``)."""
    rows = []
    for c in cyc:
        area = np.pi * c.contact_radius_m**2
        for i, qa in enumerate(c.force_amplitude_n):
            rows.append(
                {
                    "p0_gpa": c.p0_pa / units.GPA_TO_PA,
                    "model": c.model,
                    "lateral_force_amplitude_un": float(qa * units.N_TO_UN),
                    "amplitude_fraction_of_gross_sliding": float(qa / c.gross_sliding_force_n),
                    "stress_amplitude_mpa": float(qa / area / units.MPA_TO_PA),
                    "stress_rms_mpa": float(qa / (np.sqrt(2.0) * area) / units.MPA_TO_PA),
                    "displacement_amplitude_nm": float(
                        c.displacement_amplitude_m[i] / units.NM_TO_M
                    ),
                    "dissipated_energy_per_cycle_fj": float(
                        c.dissipated_energy_j[i] * units.J_TO_FJ
                    ),
                    "lockin_stiffness_n_per_m": float(c.lockin_stiffness_n_per_m[i]),
                    "lockin_in_phase_nm": float(c.in_phase_displacement_m[i] / units.NM_TO_M),
                    "lockin_quadrature_nm": float(c.quadrature_displacement_m[i] / units.NM_TO_M),
                    "loss_tangent": float(c.loss_tangent[i]),
                    "secant_stiffness_n_per_m": float(c.secant_stiffness_n_per_m[i]),
                    "paper_stiffness_n_per_m": float(c.paper_stiffness_n_per_m[i]),
                    "initial_stiffness_n_per_m": float(c.initial_stiffness_n_per_m),
                    "gross_sliding_force_un": float(c.gross_sliding_force_n * units.N_TO_UN),
                }
            )
    return rows


def cycle_dataset(
    cyc: Sequence[SteadyCycle],
    params: ContactParameters,
    n_points: int = 201,
) -> xr.Dataset:
    """The loops and per-amplitude cycle results as an xarray Dataset (for ``contact.nc``).

    Dims ``p0`` (GPa, the same coordinate as :meth:`ContactAnalysis.to_dataset`),
    ``cycle_amplitude`` (index; amplitudes may differ per p0) and ``loop_point``. Variables
    carry a ``units`` attribute; names are prefixed ``cycle_`` so the Dataset merges with
    the contact Dataset (``xr.merge([analysis.to_dataset(), cycle_dataset(...)])``).
    """
    n_amp = max(c.force_amplitude_n.size for c in cyc)
    n_loop = 2 * n_points - 1
    shape2, shape3 = (len(cyc), n_amp), (len(cyc), n_amp, n_loop)
    lu, lq = np.full(shape3, np.nan), np.full(shape3, np.nan)
    per = {k: np.full(shape2, np.nan) for k in ("qa", "w", "k", "u1", "u2", "kp", "tan", "ua")}
    for i, c in enumerate(cyc):
        n = c.force_amplitude_n.size
        for j, lp in enumerate(
            cycle.loops(c.force_amplitude_n, c.p0_pa, params, c.model, n_points)
        ):
            lu[i, j] = lp.displacement_m / units.NM_TO_M
            lq[i, j] = lp.force_n * units.N_TO_UN
        per["qa"][i, :n] = c.force_amplitude_n * units.N_TO_UN
        per["w"][i, :n] = c.dissipated_energy_j * units.J_TO_FJ
        per["k"][i, :n] = c.lockin_stiffness_n_per_m
        per["u1"][i, :n] = c.in_phase_displacement_m / units.NM_TO_M
        per["u2"][i, :n] = c.quadrature_displacement_m / units.NM_TO_M
        per["kp"][i, :n] = c.paper_stiffness_n_per_m
        per["tan"][i, :n] = c.loss_tangent
        per["ua"][i, :n] = c.displacement_amplitude_m / units.NM_TO_M
    d2, d3 = ("p0", "cycle_amplitude"), ("p0", "cycle_amplitude", "loop_point")
    model = cyc[0].model
    ds = xr.Dataset(
        {
            "cycle_loop_displacement": (
                d3,
                lu,
                {"units": "nm", "long_name": "u on the steady loop"},
            ),
            "cycle_loop_force": (d3, lq, {"units": "uN", "long_name": "Q on the steady loop"}),
            "cycle_force_amplitude": (d2, per["qa"], {"units": "uN"}),
            "cycle_displacement_amplitude": (d2, per["ua"], {"units": "nm"}),
            "cycle_dissipated_energy": (d2, per["w"], {"units": "fJ", "long_name": "per cycle"}),
            "cycle_lockin_stiffness": (
                d2,
                per["k"],
                {"units": "N/m", "long_name": "Q_amp/u'_1 (first harmonic, in phase)"},
            ),
            "cycle_lockin_in_phase": (d2, per["u1"], {"units": "nm"}),
            "cycle_lockin_quadrature": (d2, per["u2"], {"units": "nm"}),
            "cycle_loss_tangent": (d2, per["tan"], {"units": "1"}),
            "cycle_paper_stiffness": (d2, per["kp"], {"units": "N/m", "long_name": "d<Q>/d<u>"}),
        },
        coords={
            "p0": ("p0", np.asarray([c.p0_pa / units.GPA_TO_PA for c in cyc]), {"units": "GPa"}),
        },
    )
    ds.attrs["cycle_model"] = model
    ds.attrs["cycle_conventions"] = (
        "Q(t) = Q_amp sin(theta); u_1 = u'_1 sin(theta) - u''_1 cos(theta); lock-in stiffness "
        "Q_amp/u'_1; W = pi Q_amp u''_1; "
        + (
            "modified Mindlin, q0 = G* u/(pi a), paper's G* = 4 G*_J"
            if model == "modified"
            else "Cattaneo-Mindlin/Mindlin-Deresiewicz, mu = k, G*_J = G*/4"
        )
    )
    return ds
