"""The scan settings as one validated record (CLI flags and a simple YAML of the same names).

A YAML file may hold these keys at the top level or under ``scan:``::

    scan:
      interface: interface.extxyz
      potential: snap:sio2-snap      # or vashishta, tersoff, path/to/X.snapcoeff, spec.json
      grid: [12, 12]
      p_range_gpa: [-0.5, 5.0, 8]    # or thickness: [10.8, 11.0, 11.2]
      fmax_ev_per_a: 0.005
      optimizer: LBFGS
      workers: 2                     # local processes; or dask_address / jobqueue
      out: ispes

Flags given on the command line override the file. Unknown keys are refused.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Literal

import yaml
from pydantic import BaseModel, ConfigDict, ValidationError

from flatcontact.errors import InputError


class ScanConfig(BaseModel):
    """Everything ``flatcontact scan`` needs (units in the names)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    interface: str = "interface.extxyz"
    potential: str = "vashishta"
    #: a full-system ASE calculator "module:callable" instead of ``potential``
    calculator: str | None = None
    grid: tuple[int, int] = (12, 12)
    thickness: tuple[float, ...] | None = None
    p_range_gpa: tuple[float, float, int] | None = None
    fmax_ev_per_a: float = 0.005
    optimizer: str = "LBFGS"
    max_steps: int = 2000
    order: Literal["columns", "planes", "cold"] = "columns"
    executor: Literal["serial", "processes", "dask"] = "processes"
    workers: int | None = None
    dask_address: str | None = None
    jobqueue: dict[str, Any] | None = None
    out: str = "ispes"


def _one_line(exc: ValidationError, source: str) -> InputError:
    first = exc.errors()[0]
    where = ".".join(str(p) for p in first.get("loc", ()))
    return InputError(f"{source}: {where}: {first.get('msg', 'invalid')}")


def load_config(path: str | Path | None, overrides: dict[str, Any]) -> ScanConfig:
    """Read a YAML config (optional) and apply non-None ``overrides`` (the CLI flags)."""
    data: dict[str, Any] = {}
    source = "scan settings"
    if path is not None:
        path = Path(path)
        source = str(path)
        if not path.is_file():
            raise InputError(f"{path}: no such config file")
        try:
            loaded = yaml.safe_load(path.read_text()) or {}
        except yaml.YAMLError as exc:
            raise InputError(f"{path}: not valid YAML ({exc.__class__.__name__})") from None
        if not isinstance(loaded, dict):
            raise InputError(f"{path}: expected a mapping of scan settings")
        data = dict(loaded.get("scan", loaded))
    data.update({k: v for k, v in overrides.items() if v is not None})
    try:
        return ScanConfig(**data)
    except ValidationError as exc:
        raise _one_line(exc, source) from None
