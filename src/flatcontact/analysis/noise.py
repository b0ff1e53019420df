"""Noise of the constant-pressure ISPES caused by an error in the load ``p(z)``.

At a fixed load ``P`` each column is read at ``z*`` with ``p(z*) = P``. If the
load used carries an error ``δp``, the thickness moves by
``δz = δp / |dp/dz|`` and, expanding ``U`` about the true ``z*``
(``dU/dz = -P A``, ``d²U/dz² = -A dp/dz``), the energy per area moves by

.. math::

    δẽ = -P\\,δz + \\tfrac12 |dp/dz|\\,δz^2
         \\;\\Rightarrow\\;
    ε_{\\rm int}(P) = \\frac{|P|\\,δp}{|dp/dz|} + \\frac{δp^2}{2|dp/dz|}

for the internal form ``ẽ = U(z*)/A``, and only by the second-order term
``ε_H = δp²/(2|dp/dz|)`` for the enthalpy form ``h = min_z [U/A + P z]``
(stationary in ``z``). Random errors of size ``ε`` at lateral grid points a
spacing ``Δ`` apart put slopes of order ``ε/Δ`` into the interpolated landscape:
the *force-noise scale* reported with ``τ`` and ``σ`` (MPa).

``δp`` is estimated from the data (rms over the branch nodes of the grid):

- load source ``"stress"``: the stress–energy mismatch ``p - (-(1/A) dU/dz)``;
  the relaxation error of ``p`` is first order in the residual forces, that of
  ``U`` second order, so the mismatch measures the error of the stored stress;
- load source ``"energy"``: the difference between ``-(1/A) dU/dz`` of the cubic
  spline and of the quintic interpolating spline of the same energies (the
  interpolation error of the derivative plus its sensitivity to energy noise);
  NaN with fewer than 6 thickness points.

``|dp/dz|`` is the median over the columns at ``z*(P)``.

Barriers in σ_MSS lower than ``BARRIER_NOISE_FACTOR · ε(P)`` are not counted
(:func:`flatcontact.analysis.friction.friction_along_path`): two independent
errors of size ε at a minimum and a maximum make a spurious dip of about
``√2 ε``; a factor 2 removes those and keeps every barrier the data resolve.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from flatcontact.foundation import units

#: Barriers below this multiple of the energy noise ε(P) do not count in σ_MSS.
BARRIER_NOISE_FACTOR = 2.0
#: Warn when the force-noise scale exceeds this fraction of τ, or ε of the largest barrier.
NOISE_WARN_FRACTION = 0.1


@dataclass(frozen=True)
class LoadNoise:
    """Per-load noise estimate of the constant-pressure ISPES (see the module docstring)."""

    load_source: str
    form: str
    delta_p_gpa: float  #: rms error estimate of the load used (GPa)
    stress_energy_mismatch_rms_gpa: float  #: rms of p + (1/A)dU/dz on the branch nodes (GPa)
    grid_spacing_angstrom: float  #: lateral grid spacing Δ (Å)
    p_gpa: np.ndarray  #: loads (GPa)
    slope_gpa_per_angstrom: np.ndarray  #: median |dp/dz| at z*(P) (GPa/Å)
    energy_noise_mev_per_a2: np.ndarray  #: ε(P) (meV/Å²)
    force_noise_mpa: np.ndarray  #: ε(P)/Δ (MPa)

    @property
    def barrier_threshold_ev_per_a2(self) -> np.ndarray:
        """Smallest barrier counted in σ_MSS per load (eV/Å²); 0 where ε is unknown."""
        eps = self.energy_noise_mev_per_a2 / units.EV_PER_A2_TO_MEV_PER_A2
        return np.where(np.isfinite(eps), BARRIER_NOISE_FACTOR * eps, 0.0)

    def to_json(self) -> dict:
        """Plain numbers for ``analyze.json`` / ``friction.nc`` attributes."""

        def num(v: float) -> float | None:
            return float(v) if np.isfinite(v) else None

        return {
            "load_source": self.load_source,
            "energy_form": self.form,
            "delta_p_gpa": num(self.delta_p_gpa),
            "stress_energy_mismatch_rms_gpa": num(self.stress_energy_mismatch_rms_gpa),
            "grid_spacing_angstrom": self.grid_spacing_angstrom,
            "barrier_noise_factor": BARRIER_NOISE_FACTOR,
            "per_pressure": [
                {
                    "p_gpa": float(p),
                    "slope_gpa_per_angstrom": num(s),
                    "energy_noise_mev_per_a2": num(e),
                    "force_noise_mpa": num(f),
                }
                for p, s, e, f in zip(
                    self.p_gpa,
                    self.slope_gpa_per_angstrom,
                    self.energy_noise_mev_per_a2,
                    self.force_noise_mpa,
                    strict=True,
                )
            ],
        }


def energy_noise_gpa_angstrom(
    p_gpa: np.ndarray, delta_p_gpa: float, slope_gpa_per_angstrom: np.ndarray, form: str
) -> np.ndarray:
    """ε(P) in GPa·Å (= energy per area) for the ``"internal"`` or ``"enthalpy"`` form."""
    p = np.abs(np.asarray(p_gpa, float))
    s = np.abs(np.asarray(slope_gpa_per_angstrom, float))
    second = 0.5 * delta_p_gpa**2 / s
    return second + (p * delta_p_gpa / s if form == "internal" else 0.0)


def load_noise(
    p_gpa: np.ndarray,
    delta_p_gpa: float,
    mismatch_rms_gpa: float,
    slope_gpa_per_angstrom: np.ndarray,
    grid_spacing_angstrom: float,
    form: str,
    load_source: str,
) -> LoadNoise:
    """Assemble :class:`LoadNoise` from ``δp``, ``|dp/dz|`` at ``z*`` and the grid spacing."""
    eps = energy_noise_gpa_angstrom(p_gpa, delta_p_gpa, slope_gpa_per_angstrom, form)
    # GPa·Å -> eV/Å²: 1 GPa = 1/EV_PER_A3_TO_GPA eV/Å³
    eps_ev_per_a2 = eps / units.EV_PER_A3_TO_GPA
    return LoadNoise(
        load_source=load_source,
        form=form,
        delta_p_gpa=float(delta_p_gpa),
        stress_energy_mismatch_rms_gpa=float(mismatch_rms_gpa),
        grid_spacing_angstrom=float(grid_spacing_angstrom),
        p_gpa=np.asarray(p_gpa, float),
        slope_gpa_per_angstrom=np.abs(np.asarray(slope_gpa_per_angstrom, float)),
        energy_noise_mev_per_a2=eps_ev_per_a2 * units.EV_PER_A2_TO_MEV_PER_A2,
        force_noise_mpa=eps_ev_per_a2 / grid_spacing_angstrom * units.EV_PER_A3_TO_MPA,
    )
