"""One home for the paper's values and the literature constants flatcontact compares with.

Everything here is a published number, not a setting: the run configuration's defaults
(:class:`flatcontact.config.contact.ContactConfig`), the ``flatcontact contact`` flag defaults,
:class:`flatcontact.contact.parameters.ContactParameters` and the report's comparison
table all read it from here, so a corrected value changes every place at once.

Sources
-------
- The paper: Dong, Uluca, Cross and Sanvito, *Single-Contact Problem in Atomically Flat
  Interfaces: a Simulation Approach* (α-quartz (0001) dense interface, SNAP + TS-vdW LJ).
  Its load laws τ = k·P + τ0 and σ = μ·P + σ0 (fitted on P < 3 GPa), the tip radius and
  the DFT contact moduli of the contact model (G* in the paper's convention
  q0 = G*·u/(πa), i.e. 4 × Johnson's G*_J).
- Hamaker constant of α-quartz across vacuum from Lifshitz theory with measured dielectric
  spectra: Bergström, Adv. Colloid Interface Sci. 70, 125 (1997).
- Elastic constants of α-quartz at 25 °C and zero pressure, adiabatic, ultrasonic
  pulse superposition, experiment: McSkimin, Andreatch and Thurston, J. Appl. Phys. 36,
  1624 (1965), their adjusted set (c11 8.680, c12 0.704, c13 1.191, c14 −1.804, c33 10.575,
  c44 5.820, c66 3.988 × 10¹¹ dyn/cm²). The one set every comparison of a potential with
  experiment reads (:mod:`flatcontact.training.validate`,
  :mod:`flatcontact.training.ispes_check`, ``flatcontact validate-potential``).
- Lattice constants and density of α-quartz, experiment (Levien, Prewitt and Weidner,
  Am. Mineral. 65, 920 (1980)).
- The paper's oscillatory-shear experiment (its Sec. "Experimental support", Fig. 6): a
  diamond spherecone, R = 5 µm, at p0 = 1.77 GPa; the lateral stiffness collapses near
  26.7 MPa on 4-layer graphene over SiOx and near 145 MPa on bare 300 nm SiOx (mean shear
  stress: force amplitude over the Hertz area, read off the figure: "~").
- Isotropic moduli of the experiment's bodies, the nanoindentation standard pair: diamond
  E = 1141 GPa, ν = 0.07, fused silica E = 72 GPa, ν = 0.17 (Oliver and Pharr, J. Mater.
  Res. 7, 1564 (1992)); the 300 nm thermal oxide is taken as fused silica.
"""

from __future__ import annotations

from types import MappingProxyType

#: The paper's parameters: tip radius R (µm), DFT moduli E* and G* (GPa, G* in the paper's
#: convention), and the load laws k (MPa/GPa), τ0 (MPa), μ (MPa/GPa), σ0 (MPa).
PAPER = MappingProxyType(
    {
        "radius_um": 5.0,
        "contact_modulus_gpa": 52.5,
        "shear_modulus_gpa": 29.0,
        "k_mpa_per_gpa": 4.52,
        "tau0_mpa": 26.7,
        "mu_mpa_per_gpa": 0.21,
        "sigma0_mpa": 11.1,
    }
)
#: The four load-law coefficients of :data:`PAPER`.
PAPER_LAW_KEYS = ("k_mpa_per_gpa", "tau0_mpa", "mu_mpa_per_gpa", "sigma0_mpa")
#: The load range of the paper's linear fits (GPa).
PAPER_THRESHOLD_GPA = 3.0
#: p0 of the paper's measured stiffness (its Fig. 6, GPa).
PAPER_EXPERIMENT_P0_GPA = 1.77
#: Peak Hertz pressures used when none are given (GPa): the paper's Fig. 4 (1 GPa) and
#: experiment (1.77 GPa) loads, bracketed by a light and two heavier loads.
DEFAULT_P0_GPA: tuple[float, ...] = (0.5, 1.0, 1.77, 2.0, 3.0)

#: The experiment's measured collapse stresses (MPa, amplitude Q_max/(π a²), p0 =
#: :data:`PAPER_EXPERIMENT_P0_GPA`): graphene-passivated and bare SiOx (Fig. 6 text).
PAPER_EXPERIMENT_COLLAPSE_MPA = MappingProxyType(
    {"graphene-passivated SiOx": 26.7, "bare SiOx": 145.0}
)
#: Young's modulus (GPa) and Poisson ratio of diamond and fused silica (Oliver and Pharr 1992).
DIAMOND_ISOTROPIC = MappingProxyType({"youngs_modulus_gpa": 1141.0, "poisson_ratio": 0.07})
FUSED_SILICA_ISOTROPIC = MappingProxyType({"youngs_modulus_gpa": 72.0, "poisson_ratio": 0.17})

#: Non-retarded Hamaker constant of α-quartz across vacuum, Lifshitz theory (zJ; Bergström 1997).
QUARTZ_HAMAKER_ZJ = 88.0

#: Elastic constants of α-quartz, experiment (GPa, Voigt notation, 25 °C; McSkimin et al.
#: 1965); C14 in the IEEE-1949 axes of right-handed quartz (negative). Its sign depends on
#: the handedness and on which a-axis is +x: compare |C14| with a model's.
QUARTZ_CIJ_EXPERIMENT_GPA = MappingProxyType(
    {
        "C11": 86.80,
        "C12": 7.04,
        "C13": 11.91,
        "C14": -18.04,
        "C33": 105.75,
        "C44": 58.20,
        "C66": 39.88,
    }
)
#: Lattice constants of α-quartz, experiment (Å).
QUARTZ_LATTICE_EXPERIMENT_ANGSTROM = MappingProxyType({"a": 4.916, "c": 5.405})
#: Density of α-quartz, experiment (g/cm³).
QUARTZ_DENSITY_EXPERIMENT_G_CM3 = 2.648

#: The elements of the paper's material (α-quartz): the only one the default moduli are for.
PAPER_ELEMENTS = frozenset({"Si", "O"})


def is_paper_material(settings, elements=None) -> bool:
    """Whether the run's slabs are the paper's α-quartz, the material of the default E*, G*.

    ``quartz-dense`` always; ``toy-lj`` (a demonstration model, no material) takes the
    defaults too; another recipe only when its atoms (``elements``, known after reading the
    structure) are Si and O alone. ``settings`` is the run configuration (its
    ``structure.kind`` is read).
    """
    kind = settings.structure.kind
    if kind in ("quartz-dense", "toy-lj"):
        return True
    return elements is not None and set(elements) <= PAPER_ELEMENTS
