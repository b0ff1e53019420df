"""The one place where a run configuration becomes an interaction model (calculators).

Until :class:`flatcontact.potentials.InteractionModel` is the config's one ``potential``
type, a run has either ``potential`` (a :class:`~flatcontact.potentials.PotentialSpec`) or a
whole-interface ASE ``calculator``; every branch on that choice lives here, so the stages,
the pipeline and the CLI never test ``cfg.calculator``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from flatcontact.errors import InputError
from flatcontact.stages._common import file_sha256


def label(cfg) -> str:
    """Human-readable name of the run's interaction model."""
    if cfg.calculator is not None:
        return f"ASE calculator {cfg.calculator.target}"
    return cfg.potential.label


def fingerprint(cfg) -> dict:
    """The model's part of a stage fingerprint: its settings and its files by content."""
    if cfg.calculator is not None:
        return {"calculator": cfg.section("calculator")}
    # by content: retraining a bundled SNAP or editing a coefficient file reruns the scan
    files = {Path(f).name: file_sha256(f) for f in cfg.potential.resolved.files}
    return {"potential": cfg.section("potential"), "files_sha256": files}


def factory(cfg) -> Any:
    """The picklable calculator factory of the scan workers (checked now, not in a worker)."""
    from flatcontact.ispes.calculators import CalculatorFactory, PotentialFactory

    if cfg.calculator is not None:
        return CalculatorFactory.from_target(cfg.calculator.target, **cfg.calculator.kwargs)
    return PotentialFactory.from_spec(cfg.potential)


def check_atoms(cfg, atoms) -> None:
    """One-line InputError when the model has no parameters for an element of ``atoms``."""
    if cfg.calculator is None:
        from flatcontact.potentials import check_elements

        check_elements(cfg.potential, atoms)


def builder_model(cfg) -> Any:
    """What the interface builders relax with (a PotentialSpec)."""
    return cfg.potential


def toy_kwargs(cfg) -> dict:
    """Keyword arguments of the toy interface (the calculator's, which sets its LJ)."""
    return dict(cfg.calculator.kwargs) if cfg.calculator is not None else {}


def elastic_potential(cfg) -> str:
    """The name :func:`flatcontact.elastic.quartz_contact_moduli` takes for this model."""
    intra = cfg.potential.intra
    if cfg.calculator is None and (intra == "vashishta" or intra.startswith("snap:")):
        return intra.removeprefix("snap:")
    raise InputError(
        "elastic.enabled: self-consistent moduli need potential.intra vashishta or snap:<name>, "
        f"got {intra if cfg.calculator is None else 'calculator ' + cfg.calculator.target}"
    )


def same_model(cfg, built: Any) -> bool:
    """Whether an interface's recorded PotentialSpec is the run's model."""
    return cfg.calculator is None and built == cfg.potential


def same_intra(cfg, intra: str) -> bool:
    """Whether an interface's recorded intra-slab name is the run's (older recipes)."""
    return cfg.calculator is None and intra == cfg.potential.intra


def lj(cfg) -> Any:
    """The cross-interface LJ of the model, or ``None`` (an ASE calculator)."""
    return cfg.potential.lj if cfg.calculator is None else None


def intra(cfg) -> str | None:
    """The intra-slab model's name, or ``None`` (an ASE calculator)."""
    return cfg.potential.intra if cfg.calculator is None else None


def check(cfg) -> None:
    """Checks of the model that need imports, before any work."""
    if cfg.calculator is not None:
        factory(cfg)
    if cfg.elastic.enabled:
        elastic_potential(cfg)
