"""Contact mechanics of a Hertzian asperity with the ISPES laws: Hertz and adhesion, the
modified Mindlin lateral force and stiffness, the oscillation cycle, and the comparison with
and fit to measured stiffness.

Plain numbers in SI units (Pa, m, N) unless a name says otherwise; the parameters of one
contact are :class:`ContactParameters`, the modulus conventions (E*, G* = 4 G*_J) are stated
in :mod:`.moduli`.
"""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__,
    submod_attrs={
        "adhesion": [
            "dmt_contact_radius",
            "jkr_contact_radius",
            "maugis_dugdale_contact_radius",
            "maugis_parameter",
        ],
        "cycle": ["SteadyCycle", "cycles", "lockin_curve", "steady_cycle"],
        "experiment": ["collapse_stress", "compare_with_measurement", "fit_tau0"],
        "fit": ["FitResult", "fit_stiffness_curves"],
        "hertz": [
            "HertzContact",
            "hertz_contact_radius",
            "hertz_load",
            "hertz_pressure",
            "solve_hertz",
        ],
        "line_contact": [
            "PointLaws",
            "cattaneo_traction",
            "elastic_response",
            "pointwise_response",
        ],
        "measured": ["load_stiffness_csv"],
        "mindlin": ["LateralResponse", "initial_lateral_stiffness", "lateral_force", "peak_force"],
        "oscillation": ["StiffnessCurve", "lateral_stiffness", "stiffness_curve"],
        "parameters": ["ContactParameters"],
        "summary": ["ContactAnalysis", "analyse"],
    },
)
