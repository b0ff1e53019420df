"""The picklable calculator factory of an interaction model (scan workers, Dask)."""

from __future__ import annotations

import dataclasses
import json
from functools import cached_property


@dataclasses.dataclass(frozen=True)
class ModelFactory:
    """``factory(atoms)`` -> the model's ASE calculator; built from the model's JSON form.

    Attributes
    ----------
    model_json
        ``InteractionModel.model_dump_json()``; pickles as a string to any worker.
    """

    model_json: str

    @cached_property
    def model(self):
        from flatcontact.potentials.model import InteractionModel

        return InteractionModel.model_validate_json(self.model_json)

    def spec(self):
        """The :class:`~flatcontact.potentials.model.InteractionModel` (earlier name)."""
        return self.model

    def __call__(self, atoms):
        return self.model.interface_calculator(atoms)

    @cached_property
    def fingerprint(self) -> str:
        """JSON of :meth:`InteractionModel.fingerprint` (content-based, no absolute paths).

        Computed once per factory (it reads and hashes the model's files) and pickled with
        it, so a scan worker, which gets a fresh copy with every task, keys its calculator
        cache by the driver's fingerprint without validating the model again (that cost
        about 1 ms per grid point).
        """
        return json.dumps({"potential": self.model.fingerprint()}, sort_keys=True)

    @property
    def label(self) -> str:
        return self.model.label

    def __getstate__(self):
        return {"model_json": self.model_json, "fingerprint": self.fingerprint}

    def __setstate__(self, state):
        object.__setattr__(self, "model_json", state["model_json"])
        if "fingerprint" in state:
            self.__dict__["fingerprint"] = state["fingerprint"]
