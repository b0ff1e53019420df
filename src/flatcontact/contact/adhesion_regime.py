"""Which adhesive contact model applies, and the contact the modified Mindlin model then sees.

Conventions (SI; w the work of adhesion, K = 4E*/3, loads compressive positive)
-------------------------------------------------------------------------------
- Tabor parameter (Tabor 1977; Johnson & Greenwood 1997, J. Colloid Interface Sci. 192, 326)

      μ_T = (R w² / (E*² z0³))^(1/3),

  z0 the equilibrium separation of the interface (the gap between the two facing atomic
  planes of the built interface, or given).
- Maugis parameter of the Dugdale model matched to a Lennard-Jones law of the same w and
  z0 (peak tension σ_th = 1.03 w/z0; Johnson & Greenwood 1997):

      λ = 2 σ_th (R/(π w K²))^(1/3) = 2·1.03·(9/(16π))^(1/3) μ_T = 1.161 μ_T.

  A given λ (``contact.maugis_lambda``) is used as it is (μ_T = λ/1.161).
- Regime (Johnson & Greenwood's adhesion map, boundaries as drawn there): λ < 0.1 DMT,
  λ > 5 JKR, in between Maugis–Dugdale; the radius a at the applied load P (the Hertz
  load of the given p0, P = (2/3)π a_H² p0) from :mod:`flatcontact.contact.adhesion`.
  The regime is named "Hertz" (adhesion negligible) where that radius is within
  :data:`HERTZ_TOLERANCE` of the Hertz radius (the paper's own criterion for neglecting
  DMT); the numbers always use the model's radius, which tends to Hertz continuously.

The contact the modified Mindlin model sees
-------------------------------------------
The model needs a Hertzian pressure p(r) = p1 √(1 − r²/a²) inside the contact. Its peak
over the adhesive radius is p1 = 2E* a/(π R); that Hertzian part carries the load
P1 = 4E* a³/(3R) = P + P_adh (P_adh >= 0, the adhesive tension).

- DMT: the adhesive tension acts outside the contact (Derjaguin approximation): inside,
  the pressure is exactly Hertzian with peak p1, so the model at p1 is exact within DMT.
- JKR, Maugis–Dugdale: part of P_adh acts inside the contact (JKR: all of it,
  −p2/√(1 − r²/a²), singular at the edge; Maugis–Dugdale: P_adh less the cohesive zone's
  σ_D π (c² − a²) outside); the model at p1 leaves it out. The laws τ = k p + τ0,
  σ = μ p + σ0 then miss at most |k|·F_in of the stick force and |μ|·F_in of the slip
  force. The relative bound

      δ = max(|k| F_in / (τ0 π a² + k P1),  |μ| F_in / (σ0 π a² + μ P1))

  is reported; above :data:`REFUSE_FRACTION` no model of the tool applies and the stage
  refuses that p0 (one line).

The effective shear strength is then Q_peak(p1)/(π a²) over the adhesive area, and the
pull-off force of the regime's model is compared with the applied load.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from flatcontact.contact import adhesion
from flatcontact.contact.hertz import hertz_contact_radius, hertz_load
from flatcontact.contact.parameters import ContactParameters, check_positive
from flatcontact.foundation.errors import InputError

#: λ per μ_T for the Dugdale stress of a Lennard-Jones law, σ_th = 1.03 w/z0 (J&G 1997).
LAMBDA_PER_TABOR = 2.0 * 1.03 * (9.0 / (16.0 * np.pi)) ** (1.0 / 3.0)
#: Johnson & Greenwood's boundaries on λ: DMT below, JKR above.
DMT_BELOW, JKR_ABOVE = 0.1, 5.0
#: Below this |a/a_Hertz − 1| the regime is named Hertz (the paper neglects DMT under 5 %).
HERTZ_TOLERANCE = 0.05
#: Above this relative bound δ on the laws' forces the stage refuses the p0.
REFUSE_FRACTION = 0.25
#: z0 (m) assumed when neither the interface nor the configuration gives one: a typical
#: van der Waals equilibrium separation (the report says it was assumed).
ASSUMED_Z0_M = 0.3e-9

MODEL_NAMES = {"dmt": "DMT", "jkr": "JKR", "maugis-dugdale": "Maugis–Dugdale"}


def tabor_parameter(
    work_of_adhesion_j_per_m2: float,
    radius_m: float,
    contact_modulus_pa: float,
    equilibrium_separation_m: float,
) -> float:
    """μ_T = (R w²/(E*² z0³))^(1/3) (dimensionless)."""
    z0 = check_positive("equilibrium_separation_m", equilibrium_separation_m)
    return float(
        (radius_m * work_of_adhesion_j_per_m2**2 / (contact_modulus_pa**2 * z0**3)) ** (1.0 / 3.0)
    )


def adhesion_model(maugis_lambda: float) -> str:
    """'dmt' (λ < 0.1), 'jkr' (λ > 5) or 'maugis-dugdale' (Johnson & Greenwood's map)."""
    if maugis_lambda < DMT_BELOW:
        return "dmt"
    if maugis_lambda > JKR_ABOVE:
        return "jkr"
    return "maugis-dugdale"


@dataclass(frozen=True)
class AdhesiveContact:
    """The adhesive contact at one applied load (SI inside, unit-named in :meth:`record`).

    Attributes
    ----------
    p0_pa : the given peak Hertz pressure (it fixes the load P)
    load_n : applied load P = (2/3)π a_H² p0
    hertz_radius_m, radius_m : a_H and the radius of ``model`` at P
    model : 'hertz' (w = 0), 'dmt', 'jkr', 'maugis-dugdale'
    regime : the name shown: 'Hertz' where |a/a_H − 1| < HERTZ_TOLERANCE, else the model's
    contact_p0_pa : p1 = 2E* a/(πR), the peak of the Hertzian pressure over a
    pull_off_n : pull-off force of ``model`` (magnitude; 0 without adhesion)
    adhesive_tension_n : P1 − P, the adhesive tension the Hertzian part carries
    tension_inside_n : the part of it that acts inside the contact (0 for DMT; P1 − P for
        JKR; P1 − P minus the cohesive zone's σ_D π (c² − a²) for Maugis–Dugdale)
    law_bound : δ, the relative bound on the stick/slip forces the model leaves out
    """

    p0_pa: float
    load_n: float
    hertz_radius_m: float
    radius_m: float
    model: str
    regime: str
    contact_p0_pa: float
    pull_off_n: float
    adhesive_tension_n: float
    tension_inside_n: float
    law_bound: float

    @property
    def pull_off_per_load(self) -> float:
        """Pull-off force / applied load."""
        return self.pull_off_n / self.load_n

    def record(self) -> dict:
        """JSON-ready, unit-named."""
        d = asdict(self)
        return {
            "p0_gpa": d["p0_pa"] * 1e-9,
            "regime": self.regime,
            "model": self.model,
            "normal_load_un": self.load_n * 1e6,
            "hertz_contact_radius_nm": self.hertz_radius_m * 1e9,
            "contact_radius_nm": self.radius_m * 1e9,
            "radius_over_hertz": self.radius_m / self.hertz_radius_m,
            "contact_peak_pressure_gpa": self.contact_p0_pa * 1e-9,
            "pull_off_force_un": self.pull_off_n * 1e6,
            "pull_off_over_load": self.pull_off_per_load,
            "adhesive_tension_un": self.adhesive_tension_n * 1e6,
            "law_bound": self.law_bound,
        }


def dugdale_zone_force(
    radius_m: float,
    work_of_adhesion_j_per_m2: float,
    tip_radius_m: float,
    contact_modulus_pa: float,
    maugis_lambda: float,
) -> float:
    """F_out = σ_D π (c² − a²) (N): the adhesive tension of the Maugis–Dugdale cohesive zone
    a < r < c, outside the contact; σ_D = (λ/2)(π w K²/R)^(1/3), m = c/a from Maugis's
    equation at Ā = a (K/(π w R²))^(1/3). The rest of P1 − P acts inside the contact."""
    k = 4.0 * contact_modulus_pa / 3.0
    w, r = work_of_adhesion_j_per_m2, tip_radius_m
    abar = radius_m * (k / (np.pi * w * r * r)) ** (1.0 / 3.0)
    m = adhesion._md_m(abar, maugis_lambda)
    sigma_d = 0.5 * maugis_lambda * (np.pi * w * k * k / r) ** (1.0 / 3.0)
    return float(sigma_d * np.pi * radius_m**2 * (m * m - 1.0))


def _law_bound(params: ContactParameters, a: float, p1_load: float, tension: float) -> float:
    """δ of the module docstring (0 when no tension acts inside the contact)."""
    if tension <= 0.0:
        return 0.0
    area = np.pi * a * a
    out = 0.0
    for slope, offset in ((params.k, params.tau0_pa), (params.mu, params.sigma0_pa)):
        scale = offset * area + slope * p1_load
        if slope != 0.0:
            out = max(out, abs(slope) * tension / scale if scale > 0.0 else np.inf)
    return float(out)


def adhesive_contact(
    p0_pa: float,
    params: ContactParameters,
    maugis_lambda: float | None,
    use_hertz: bool = False,
) -> AdhesiveContact:
    """The contact at the Hertz load of ``p0_pa`` under the regime of ``maugis_lambda``
    (None or w = 0: Hertz); ``use_hertz``: the adhesive radius is reported, the model is
    evaluated at p0 (the paper's Hertz contact)."""
    r, e, w = params.radius_m, params.contact_modulus_pa, params.work_of_adhesion_j_per_m2
    a_h = float(hertz_contact_radius(p0_pa, r, e))
    load = float(hertz_load(p0_pa, a_h))
    if w == 0.0 or maugis_lambda is None:
        return AdhesiveContact(p0_pa, load, a_h, a_h, "hertz", "Hertz", p0_pa, 0.0, 0.0, 0.0, 0.0)
    model = adhesion_model(maugis_lambda)
    if model == "dmt":
        a = float(adhesion.dmt_contact_radius(load, w, r, e))
        pull_off = float(adhesion.dmt_pull_off_force(w, r))
    elif model == "jkr":
        a = float(adhesion.jkr_contact_radius(load, w, r, e))
        pull_off = float(adhesion.jkr_pull_off_force(w, r))
    else:
        a = float(adhesion.maugis_dugdale_contact_radius(load, w, r, e, maugis_lambda))
        pull_off = float(adhesion.maugis_dugdale_pull_off_force(w, r, maugis_lambda))
    p1_load = 4.0 * e * a**3 / (3.0 * r)
    tension = max(p1_load - load, 0.0)
    inside = 0.0 if model == "dmt" else tension
    if model == "maugis-dugdale":
        inside = max(tension - dugdale_zone_force(a, w, r, e, maugis_lambda), 0.0)
    regime = "Hertz" if abs(a / a_h - 1.0) < HERTZ_TOLERANCE else MODEL_NAMES[model]
    return AdhesiveContact(
        p0_pa=float(p0_pa),
        load_n=load,
        hertz_radius_m=a_h,
        radius_m=a,
        model=model,
        regime=regime,
        contact_p0_pa=float(p0_pa) if use_hertz else 2.0 * e * a / (np.pi * r),
        pull_off_n=pull_off,
        adhesive_tension_n=tension,
        tension_inside_n=inside,
        law_bound=0.0 if use_hertz else _law_bound(params, a, p1_load, inside),
    )


@dataclass(frozen=True)
class AdhesionRegime:
    """The regime of one run: its Tabor and Maugis parameters and the contact at every p0.

    ``z0_source`` says where z0 came from ('given λ' when ``contact.maugis_lambda`` set λ).
    """

    tabor: float | None
    maugis_lambda: float | None
    z0_m: float | None
    z0_source: str
    contacts: tuple[AdhesiveContact, ...]
    use_hertz: bool = False

    @property
    def contact_p0_pa(self) -> np.ndarray:
        """p1 per p0 (Pa): the peak pressure the modified Mindlin model is evaluated at."""
        return np.array([c.contact_p0_pa for c in self.contacts])

    @property
    def adhesive(self) -> bool:
        """Whether the model is evaluated at the adhesive radius at some p0."""
        return any(c.contact_p0_pa != c.p0_pa for c in self.contacts)

    def refused(self) -> list[AdhesiveContact]:
        """The contacts whose law bound δ exceeds :data:`REFUSE_FRACTION`."""
        return [c for c in self.contacts if c.law_bound > REFUSE_FRACTION]

    def sentence(self) -> str:
        """One line naming the regime (the console line and the report box)."""
        if self.maugis_lambda is None:
            return "adhesion: none (w = 0): Hertz contact, pull-off 0"
        names = list(dict.fromkeys(c.regime for c in self.contacts))
        ratios = [c.radius_m / c.hertz_radius_m for c in self.contacts]
        pulls = [c.pull_off_per_load for c in self.contacts]
        tabor = f"Tabor μ_T = {self.tabor:.3g}, λ = {self.maugis_lambda:.3g}"
        z0 = (
            f" (z0 = {self.z0_m * 1e10:.3g} Å, {self.z0_source})"
            if self.z0_m
            else (f" ({self.z0_source})")
        )
        used = (
            "yet the Hertz radius is used (contact.contact_radius: hertz)"
            if self.use_hertz
            else "the adhesive radius is used in Q_peak/πa² and in the modified Mindlin model"
        )
        bound = max(c.law_bound for c in self.contacts)
        left_out = (
            f" (the adhesive tension inside the contact, left out of τ(p) and σ(p), changes "
            f"their forces by up to {100 * bound:.2g} %)"
            if bound > 0.01 and not self.use_hertz
            else ""
        )
        return (
            f"adhesion regime {' / '.join(names)}: {tabor}{z0}; contact radius "
            f"{min(ratios):.3g}–{max(ratios):.3g} × Hertz, pull-off force "
            f"{min(pulls):.3g}–{max(pulls):.3g} × the load over the p0 range; {used}{left_out}"
        )

    def to_json(self) -> dict:
        """``summary.json["adhesion_regime"]``."""
        return {
            "tabor_parameter": self.tabor,
            "maugis_lambda": self.maugis_lambda,
            "equilibrium_separation_angstrom": None if self.z0_m is None else self.z0_m * 1e10,
            "equilibrium_separation_source": self.z0_source,
            "contact_radius": "hertz" if self.use_hertz else "adhesive",
            "conventions": {
                "lambda_per_tabor": LAMBDA_PER_TABOR,
                "dmt_below_lambda": DMT_BELOW,
                "jkr_above_lambda": JKR_ABOVE,
                "hertz_tolerance": HERTZ_TOLERANCE,
                "refuse_law_bound_above": REFUSE_FRACTION,
                "contact_peak_pressure": "p1 = 2 E* a/(pi R), the Hertzian part over the "
                "adhesive radius; the modified Mindlin model is evaluated at p1",
            },
            "sentence": self.sentence(),
            "results": [c.record() for c in self.contacts],
        }


def adhesion_regime(
    p0_gpa,
    params: ContactParameters,
    *,
    equilibrium_separation_m: float | None = None,
    z0_source: str = "",
    maugis_lambda: float | None = None,
    use_hertz: bool = False,
    p0_name: str = "p0_gpa",
) -> AdhesionRegime:
    """The adhesion regime of ``params`` at every p0 (GPa).

    λ is ``maugis_lambda`` if given, else LAMBDA_PER_TABOR·μ_T from z0; with w = 0 the
    contact is Hertz. Raises InputError naming ``p0_name`` where the bound δ exceeds
    :data:`REFUSE_FRACTION` (no model of the tool applies), unless ``use_hertz``.
    """
    w = params.work_of_adhesion_j_per_m2
    p0s = [float(p) for p in p0_gpa]
    tabor = lam = None
    z0 = equilibrium_separation_m
    if w > 0.0:
        if maugis_lambda is not None:
            lam = float(maugis_lambda)
            tabor = lam / LAMBDA_PER_TABOR
            z0_source = "given λ (contact.maugis_lambda)"
        else:
            if z0 is None:
                z0 = ASSUMED_Z0_M
                z0_source = (
                    "not known: assumed, a typical van der Waals separation; give "
                    "contact.equilibrium_separation_angstrom"
                )
            tabor = tabor_parameter(w, params.radius_m, params.contact_modulus_pa, z0)
            lam = LAMBDA_PER_TABOR * tabor
    contacts = tuple(adhesive_contact(p * 1e9, params, lam, use_hertz) for p in p0s)
    regime = AdhesionRegime(tabor, lam, z0, z0_source, contacts, use_hertz)
    bad = [] if use_hertz else regime.refused()
    if bad:
        c = bad[0]
        raise InputError(
            f"{p0_name} = {c.p0_pa * 1e-9:g} GPa: no contact model of the tool applies: the "
            f"{MODEL_NAMES[c.model]} contact (λ = {lam:.3g}) carries an adhesive tension of "
            f"{c.adhesive_tension_n * 1e6:.3g} µN inside a = {c.radius_m * 1e9:.3g} nm, which "
            f"changes the laws' forces by up to {100 * c.law_bound:.3g} % (> "
            f"{100 * REFUSE_FRACTION:g} %); raise p0 or set contact.contact_radius: hertz"
        )
    return regime
