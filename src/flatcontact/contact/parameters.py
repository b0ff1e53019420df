"""Parameters of the continuum contact model, with the paper's defaults.

Values are stored in the units a person reads (``radius_um``, ``p0_gpa``,
``k_mpa_per_gpa`` ...) and validated on construction; the ``*_si`` properties
give the SI values (m, Pa, dimensionless) the physics functions take.

Moduli: ``contact_modulus_gpa`` is the Hertz E*, ``shear_modulus_gpa`` the paper's G*
(``q0 = G*·u/(π a)``, = 4 G*_J of Johnson); the conventions and the conversions are
:mod:`flatcontact.contact.moduli`.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import asdict, dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from flatcontact.foundation import units
from flatcontact.foundation.errors import require
from flatcontact.foundation.reference import PAPER as PAPER_DEFAULTS


def _finite(name: str, value: Any) -> float:
    require(
        isinstance(value, numbers.Real) and not isinstance(value, bool),
        f"{name} must be a number, got {value!r}",
    )
    require(math.isfinite(value), f"{name} must be finite, got {value!r}")
    return float(value)


def check_positive(name: str, value: Any) -> float:
    """Return ``value`` as float or raise InputError unless it is finite and > 0."""
    v = _finite(name, value)
    require(v > 0.0, f"{name} must be > 0, got {value!r}")
    return v


def check_non_negative(name: str, value: Any) -> float:
    """Return ``value`` as float or raise InputError unless it is finite and >= 0."""
    v = _finite(name, value)
    require(v >= 0.0, f"{name} must be >= 0, got {value!r}")
    return v


@dataclass(frozen=True)
class ContactParameters:
    """Sphere-on-flat contact with load-dependent interfacial shear laws.

    Parameters
    ----------
    radius_um : float
        Tip radius R (µm), > 0.
    contact_modulus_gpa : float
        Hertz contact modulus E* (GPa), ``1/E* = (1−ν1²)/E1 + (1−ν2²)/E2``, > 0.
    shear_modulus_gpa : float
        The paper's effective shear modulus G* (GPa) in ``q0 = G*·u/(π a)``
        (= 4× Johnson's G*_J), > 0.
    k_mpa_per_gpa, tau0_mpa : float
        Shear-strength law τ(p) = k·p + τ0 (k in MPa/GPa, τ0 in MPa). τ0 >= 0; k
        may be negative (a strength that falls with load), then τ0 > 0; k and τ0
        not both zero. τ must stay > 0 on the whole contact, which for k < 0
        bounds the peak pressure: p0 < τ0/|k| (:attr:`p0_limit_gpa`).
    mu_mpa_per_gpa, sigma0_mpa : float
        Slip-zone ("minimal-scale sliding") friction law σ(p) = μ·p + σ0. σ0 >= 0;
        μ may be negative, then σ0 > 0 and p0 <= σ0/|μ| (σ >= 0 on the contact).
    work_of_adhesion_j_per_m2 : float
        Work of adhesion w (J/m²) of the tip on the surface, for the DMT/JKR/Maugis–Dugdale
        radii, >= 0 (0: no adhesion correction). A contact input, measured or chosen; a run
        without one takes the scan's ideal work of separation W
        (:class:`flatcontact.ispes.work_of_separation.WorkOfSeparation`), a distinct quantity:
        W separates two perfect slabs at one stacking, w is what the contact feels.
    """

    radius_um: float = PAPER_DEFAULTS["radius_um"]
    contact_modulus_gpa: float = PAPER_DEFAULTS["contact_modulus_gpa"]
    shear_modulus_gpa: float = PAPER_DEFAULTS["shear_modulus_gpa"]
    k_mpa_per_gpa: float = PAPER_DEFAULTS["k_mpa_per_gpa"]
    tau0_mpa: float = PAPER_DEFAULTS["tau0_mpa"]
    mu_mpa_per_gpa: float = PAPER_DEFAULTS["mu_mpa_per_gpa"]
    sigma0_mpa: float = PAPER_DEFAULTS["sigma0_mpa"]
    work_of_adhesion_j_per_m2: float = 0.0

    def __post_init__(self) -> None:
        for name in ("radius_um", "contact_modulus_gpa", "shear_modulus_gpa"):
            object.__setattr__(self, name, check_positive(name, getattr(self, name)))
        for name in ("tau0_mpa", "sigma0_mpa", "work_of_adhesion_j_per_m2"):
            object.__setattr__(self, name, check_non_negative(name, getattr(self, name)))
        for name in ("k_mpa_per_gpa", "mu_mpa_per_gpa"):
            object.__setattr__(self, name, _finite(name, getattr(self, name)))
        require(
            self.k_mpa_per_gpa > 0.0 or self.tau0_mpa > 0.0,
            "k_mpa_per_gpa and tau0_mpa are both 0: the interface would have no shear "
            "strength and no stick zone; give k > 0 or tau0 > 0"
            if self.k_mpa_per_gpa == 0.0
            else f"k_mpa_per_gpa = {self.k_mpa_per_gpa:g} < 0 needs tau0_mpa > 0 (τ = k·p + τ0 "
            "must be > 0 on the whole contact, and τ = τ0 at its edge), got tau0_mpa = 0",
        )
        require(
            self.mu_mpa_per_gpa >= 0.0 or self.sigma0_mpa > 0.0,
            f"mu_mpa_per_gpa = {self.mu_mpa_per_gpa:g} < 0 needs sigma0_mpa > 0 (σ = μ·p + σ0 "
            "must be >= 0 on the whole contact), got sigma0_mpa = 0",
        )

    # --- SI views -------------------------------------------------------------
    @property
    def radius_m(self) -> float:
        """R in m."""
        return self.radius_um * units.UM_TO_M

    @property
    def contact_modulus_pa(self) -> float:
        """E* in Pa."""
        return self.contact_modulus_gpa * units.GPA_TO_PA

    @property
    def shear_modulus_pa(self) -> float:
        """The paper's G* in Pa."""
        return self.shear_modulus_gpa * units.GPA_TO_PA

    @property
    def k(self) -> float:
        """Pressure coefficient of the shear strength, dimensionless (MPa/GPa · 1e-3)."""
        return self.k_mpa_per_gpa * units.MPA_PER_GPA_TO_RATIO

    @property
    def tau0_pa(self) -> float:
        """τ0 in Pa."""
        return self.tau0_mpa * units.MPA_TO_PA

    @property
    def mu(self) -> float:
        """Pressure coefficient of the slip friction, dimensionless."""
        return self.mu_mpa_per_gpa * units.MPA_PER_GPA_TO_RATIO

    @property
    def sigma0_pa(self) -> float:
        """σ0 in Pa."""
        return self.sigma0_mpa * units.MPA_TO_PA

    # --- where the model is defined -----------------------------------------------
    @property
    def p0_limit_gpa(self) -> float:
        """The largest peak pressure (GPa, exclusive for τ) at which τ > 0 and σ >= 0 on the
        whole contact: min(τ0/|k| for k < 0, σ0/|μ| for μ < 0); inf when k, μ >= 0."""
        return min(_tau_limit_gpa(self), _sigma_limit_gpa(self))

    @property
    def annular_stick_p0_gpa(self) -> float:
        """p0 (GPa) above which the stick zone turns into a ring before full slip: τ0/(2|k|).

        With k < 0 the stick function k·p0·s² + τ0·s (s = √(1 − r²/a²)) is no longer
        increasing on [0, 1] once p0 > τ0/(2|k|): the centre then slips (q0 > τ(centre))
        while an annulus still sticks (:mod:`flatcontact.contact.mindlin`). inf for k >= 0.
        """
        return 0.5 * _tau_limit_gpa(self)

    def check_p0_gpa(self, p0_gpa: Any, name: str = "p0_gpa") -> list[float]:
        """Validate peak pressures (GPa) for these laws: finite, > 0, and τ > 0, σ >= 0 on the
        whole contact (k < 0: p0 < τ0/|k|; μ < 0: p0 <= σ0/|μ|). Returns them as floats.

        Raises
        ------
        InputError
            One line naming ``name``, the offending p0, the law and the limit.
        """
        values = check_p0_gpa(p0_gpa, name)
        for p0 in values:
            tau_c = self.k_mpa_per_gpa * p0 + self.tau0_mpa
            require(
                tau_c > 0.0,
                f"{name} = {p0:g} GPa: k_mpa_per_gpa = {self.k_mpa_per_gpa:g} makes τ(centre) = "
                f"k·p0 + τ0 = {tau_c:.4g} MPa <= 0; the model needs p0 < τ0/|k| = "
                f"{_tau_limit_gpa(self):.4g} GPa",
            )
            sigma_c = self.mu_mpa_per_gpa * p0 + self.sigma0_mpa
            require(
                sigma_c >= -_ROUND * (abs(self.mu_mpa_per_gpa) * p0 + self.sigma0_mpa),
                f"{name} = {p0:g} GPa: mu_mpa_per_gpa = {self.mu_mpa_per_gpa:g} makes σ(centre) = "
                f"μ·p0 + σ0 = {sigma_c:.4g} MPa < 0; the model needs p0 <= σ0/|μ| = "
                f"{_sigma_limit_gpa(self):.4g} GPa",
            )
        return values

    def check_p0_pa(self, p0_pa: ArrayLike, name: str = "p0") -> None:
        """:meth:`check_p0_gpa` for an array of peak pressures in Pa (the physics functions)."""
        p0 = np.asarray(p0_pa, dtype=float)
        tau_c = self.k * p0 + self.tau0_pa
        sigma_c = self.mu * p0 + self.sigma0_pa
        sigma_tol = _ROUND * (abs(self.mu) * np.abs(p0) + self.sigma0_pa)
        ok = np.isfinite(p0) & (p0 > 0.0) & (tau_c > 0.0) & (sigma_c >= -sigma_tol)
        if not bool(np.all(ok)):
            bad = float(p0.ravel()[np.argmin(ok.ravel())])
            self.check_p0_gpa(bad / units.GPA_TO_PA if math.isfinite(bad) else bad, name)

    def replace(self, **changes: float) -> ContactParameters:
        """A validated copy with some fields changed."""
        return replace(self, **changes)

    def as_dict(self) -> dict[str, float]:
        """Fields with their unit-bearing names (for JSON and netCDF attributes)."""
        return asdict(self)


#: σ(centre) = 0 is allowed; a σ(centre) below 0 by no more than this fraction of its
#: terms is round-off at the limit p0 = σ0/|μ| (the GPa and Pa forms round differently)
_ROUND = 1e-12


def _tau_limit_gpa(p: ContactParameters) -> float:
    """τ0/|k| (GPa) for k < 0, where τ(centre) = k·p0 + τ0 reaches 0; inf for k >= 0."""
    return p.tau0_mpa / -p.k_mpa_per_gpa if p.k_mpa_per_gpa < 0.0 else math.inf


def _sigma_limit_gpa(p: ContactParameters) -> float:
    """σ0/|μ| (GPa) for μ < 0, where σ(centre) = μ·p0 + σ0 reaches 0; inf for μ >= 0."""
    return p.sigma0_mpa / -p.mu_mpa_per_gpa if p.mu_mpa_per_gpa < 0.0 else math.inf


def check_p0_gpa(p0_gpa: Any, name: str = "p0_gpa") -> list[float]:
    """Validate one or several peak Hertz pressures (GPa) and return them as floats."""
    values = [p0_gpa] if isinstance(p0_gpa, numbers.Real) else list(p0_gpa)
    require(len(values) > 0, f"{name}: give at least one peak pressure")
    return [check_positive(name, v) for v in values]
