"""What a measured uncertainty belongs to: the fingerprints of a run's structure and model.

A convergence or model study (:mod:`flatcontact.studies`) records, in the ``uncertainty``
block it writes, ``measured_on = {structure_sha256, model_sha256}`` of the configuration it
measured. :func:`check_measured_on` refuses, in one line, a run whose structure recipe or
interaction model differs: the numbers say nothing about another interface or potential.

* ``structure_sha256``: SHA-256 of the structure recipe as the build stage fingerprints it
  (files by name and content, :func:`flatcontact.foundation.rundir.portable`); the layer count is part
  of it, so a block measured at 9 layers does not apply at 12.
* ``model_sha256``: SHA-256 of :meth:`flatcontact.potentials.model.InteractionModel.fingerprint`
  (the model's canonical data, its files by name and SHA-256).

Scan and analysis settings are not in either: a block measured at the study's base settings
is the (lower-bound) uncertainty of a run at those or coarser settings of the same interface.
"""

from __future__ import annotations

from flatcontact.config import RunConfig, recipe_files
from flatcontact.foundation.errors import InputError
from flatcontact.foundation.fileio import file_sha256
from flatcontact.foundation.rundir import fingerprint, portable
from flatcontact.stages import _calculator


def structure_fingerprint(cfg: RunConfig) -> str:
    """SHA-256 of the structure recipe (files by name and content)."""
    inputs = {"structure": portable(cfg.structure_section(), "file")}
    for dotted, path in recipe_files(cfg.structure):
        inputs[f"{dotted}_sha256"] = file_sha256(path)
    return fingerprint(inputs)


def model_fingerprint(cfg: RunConfig) -> str:
    """SHA-256 of the interaction model (canonical data, files by name and content)."""
    return fingerprint(_calculator.fingerprint(cfg))


def measured_on(cfg: RunConfig) -> dict[str, str]:
    """``{"structure_sha256", "model_sha256"}`` of ``cfg`` (the study's ``measured_on``)."""
    return {"structure_sha256": structure_fingerprint(cfg), "model_sha256": model_fingerprint(cfg)}


def check_measured_on(cfg: RunConfig, source: str = "config") -> None:
    """Refuse a run whose ``uncertainty.measured_on`` names another structure or model.

    A block without ``measured_on`` (written by hand) is the user's statement and is used.

    Raises
    ------
    InputError
        One line naming the field, what differs and what to do.
    """
    recorded = cfg.uncertainty.measured_on
    if not recorded:
        return
    mine = measured_on(cfg)
    for key, what in (("structure_sha256", "structure"), ("model_sha256", "potential")):
        if key in recorded and recorded[key] != mine[key]:
            raise InputError(
                f"{source}: uncertainty.measured_on.{key}: the block was measured on another "
                f"{what} ({recorded[key][:12]}, this run's is {mine[key][:12]}); run "
                f"'flatcontact study' on this configuration or remove the uncertainty block"
            )
