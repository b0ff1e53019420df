"""flatcontact: the onset of sliding of a Hertzian asperity with an atomically flat crystalline contact.

The pipeline::

    crystal -> two-slab interface -> ISPES scan U(x, y, z), p(x, y, z)
      -> constant-pressure ISPES -> sliding path -> tau, sigma_MSS, shear stiffness per load
      -> load laws tau = k p + tau0, sigma = mu p + sigma0
      -> modified Mindlin contact (Hertz + adhesion) -> Q(u), lateral stiffness

The public API, one name per job, for a notebook or a script::

    from flatcontact import make_interface, scan_interface, analyze_ispes, contact_from_laws
    ispes = scan_interface(interface, calculator, grid=(6, 6), p_range_gpa=(-1, 3, 6))

    from flatcontact import load_config, Pipeline

    cfg = load_config("my-interface.yaml")      # or load_config(preset_name="quick")
    Pipeline(cfg, "my-run").run()               # the whole study, resumable

    from flatcontact import read_interface, run_scan, open_ispes, analyze_ispes, fit_load_laws
    from flatcontact import ContactParameters, solve_hertz, InputError

Every name is loaded on first use (SPEC 1 lazy loading, :mod:`lazy_loader`), so ``import
flatcontact`` is cheap and the command line can set its thread variables before numpy loads.
Each sub-package exports what it owns the same way (``flatcontact.contact.lateral_force``,
``flatcontact.ispes.GridSpec``, ...): see ``__all__`` of each and docs/architecture.md.
"""

import lazy_loader

#: Public name -> the sub-package (or top-level module) that owns it.
_EXPORTS: dict[str, list[str]] = {
    "config": ["RunConfig", "build_config", "load_config", "preset", "to_yaml"],
    "foundation.errors": ["InputError"],
    "pipeline": ["Pipeline", "StageEvent"],
    "potentials": [
        "InteractionModel",
        "LammpsStyle",
        "LJSpec",
        "bulk_calculator",
        "calculator_factory",
        "make_calculator",
    ],
    "structures": ["build_interface", "make_interface", "read_interface", "write_interface"],
    "ispes": ["GridSpec", "RelaxSettings", "open_ispes", "run_scan", "write_ispes"],
    "analysis": ["AnalysisOptions", "analyze_ispes", "constant_pressure", "fit_load_laws"],
    "contact": [
        "ContactParameters",
        "lateral_force",
        "lateral_stiffness",
        "solve_hertz",
        "steady_cycle",
    ],
    "elastic": ["elastic_tensor", "isotropic_moduli"],
    "notebook": ["contact_from_laws", "scan_interface"],
}

_lazy_getattr, _lazy_dir, _lazy_all = lazy_loader.attach(
    __name__,
    submodules=[
        "analysis",
        "config",
        "contact",
        "elastic",
        "ispes",
        "notebook",
        "pipeline",
        "plots",
        "potentials",
        "report",
        "stages",
        "structures",
        "training",
    ],
    submod_attrs=_EXPORTS,
)
__all__ = ["__version__", *sorted(name for names in _EXPORTS.values() for name in names)]


def _version() -> str:
    """The installed distribution's version (importlib.metadata: ~40 ms, so read on first use,
    not while the command line starts: :mod:`flatcontact.__main__`)."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("flatcontact")
    except PackageNotFoundError:  # running from a source tree without installation
        return "0.0.0+unknown"


def __getattr__(name: str):
    if name == "__version__":
        globals()["__version__"] = found = _version()
        return found
    return _lazy_getattr(name)


def __dir__() -> list[str]:
    return ["__version__", *_lazy_dir()]
