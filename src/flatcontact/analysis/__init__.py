"""From an ISPES grid to friction: the constant-pressure ISPES, the sliding path, τ, σ_MSS and
the shear stiffness per load (:func:`analyze_ispes`), and the load laws τ = k·p + τ0,
σ = μ·p + σ0 (:func:`fit_load_laws`).
"""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__,
    submod_attrs={
        "analyze": ["AnalysisResult", "PressureAnalysis", "analyze_ispes"],
        "constant_pressure": ["ConstantPressureISPES", "constant_pressure"],
        "options": ["AnalysisOptions"],
        "friction": ["FrictionResult", "friction_along_path"],
        "laws": ["LinearLaw", "LoadLaws", "fit_linear_law", "fit_load_laws"],
    },
)
