"""The asperity in atoms: a cap of slab 2's crystal pressed and sheared on a flat of slab 1's,
relaxed quasi-statically in LAMMPS, against the modified Mindlin model from the same laws.

Modules: :mod:`.builder` (the atoms), :mod:`.driver` (LAMMPS: press, slide, resume),
:mod:`.binning` (tractions and slip along the contact), :mod:`.records` (asperity.nc,
asperity.json), :mod:`.compare` (atoms against the continuum). docs/asperity.md.
"""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__,
    submod_attrs={
        "builder": ["build_asperity", "plan_sizes"],
        "experiment": ["ExperimentSpec", "run_experiment"],
    },
)
