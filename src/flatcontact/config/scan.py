"""The ``scan`` section: the ISPES grid, the thicknesses, the per-point relaxation, the executor.

The names the section accepts (optimisers, warm-start orders) are data here, the same tuples
the scan core checks (:mod:`flatcontact.ispes.relax`, :mod:`flatcontact.ispes.order`; a test
keeps them equal), so the settings import no physics.
"""

from __future__ import annotations

import re
from typing import Any, Literal

from pydantic import Field, field_validator, model_validator

from flatcontact.config.messages import show
from flatcontact.config.section import Section, positive_pair
from flatcontact.foundation import limits
from flatcontact.foundation.numbers import physical

#: Optimisers a scan point may use (:data:`flatcontact.ispes.relax.OPTIMIZERS`): the built-in
#: L-BFGS rescaled (``LBFGS-scaled``) or with ASE's steps (``LBFGS``), ASE's others, and
#: ``lammps-cg`` (LAMMPS's own minimiser, LAMMPS models only).
OPTIMIZERS: tuple[str, ...] = (
    "LBFGS-scaled",
    "LBFGS",
    "FIRE",
    "FIRE2",
    "BFGS",
    "BFGSLineSearch",
    "lammps-cg",
)
#: The default optimiser (:class:`flatcontact.ispes.relax.RelaxSettings`' default).
DEFAULT_OPTIMIZER = "LBFGS-scaled"
#: Warm-start orders of the scan (:data:`flatcontact.ispes.order.PREFERENCES`).
PREFERENCES: tuple[str, ...] = ("columns", "planes", "cold")


#: Transports a Dask scheduler address may name (``tcp://host:8786``; bare ``host:8786`` is tcp).
DASK_SCHEMES = ("tcp", "tls", "ws", "wss", "ucx")
_HOST_PORT = re.compile(
    r"(?P<host>\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9](?:[A-Za-z0-9.-]*[A-Za-z0-9])?):(?P<port>\d{1,5})"
)


def parse_dask_address(address: str) -> tuple[str, str, int]:
    """(scheme, host, port) of a Dask scheduler address, or ValueError saying what is expected.

    The form is checked before anything connects (``garbage`` used to cost a 10 s
    timeout): ``[scheme://]host:port`` with a scheme of :data:`DASK_SCHEMES`, a host name or
    IP address (IPv6 in brackets) and a port 1..65535.
    """
    text = str(address).strip()
    scheme, sep, rest = text.partition("://")
    if not sep:
        scheme, rest = "tcp", text
    match = _HOST_PORT.fullmatch(rest)
    if match is not None and not match["host"].startswith("["):
        labels = match["host"].split(".")  # a host name: labels of 1..63 characters
        if len(match["host"]) > 253 or any(not 1 <= len(x) <= 63 for x in labels):
            match = None
    if scheme not in DASK_SCHEMES or match is None or not 1 <= int(match["port"]) <= 65535:
        raise ValueError(
            f"expected a Dask scheduler address [{'|'.join(DASK_SCHEMES)}://]host:port "
            f"(port 1..65535), e.g. tcp://10.0.0.5:8786, got {show(address)}"
        )
    return scheme, match["host"].strip("[]"), int(match["port"])


class PressureRange(Section):
    """n loads evenly spaced from lo_gpa to hi_gpa at the probe stacking."""

    lo_gpa: physical(-1e3, 1e3, "GPa") = Field(
        description="lowest target load (GPa; negative = tension)"
    )
    hi_gpa: physical(1e-6, 1e3, "GPa") = Field(description="highest target load (GPa, compressive)")
    n: int = Field(ge=2, description="number of thicknesses")

    @model_validator(mode="after")
    def _order(self) -> PressureRange:
        if not self.lo_gpa < self.hi_gpa:
            raise ValueError(f"expected lo_gpa < hi_gpa, got {self.lo_gpa} and {self.hi_gpa}")
        if self.n > limits.bound("thicknesses"):
            raise ValueError("n: " + limits.message("thicknesses", self.n, "thicknesses"))
        return self


class SymmetryConfig(Section):
    """Irreducible registries: one relaxation per orbit of the interface's shift-space group."""

    enabled: bool | Literal["auto"] = Field(
        "auto",
        description="relax one registry per orbit of the interface's shift-space group and fill "
        "the grid by symmetry; auto: on unless relax_mode is full (a full relaxation can break "
        "the symmetry at unstable registries, which a few verified points may miss); false: "
        "relax every grid point",
    )
    verify_points: int = Field(
        2, ge=0, le=64, description="mapped points also relaxed and compared with their registry"
    )
    tolerance_angstrom: physical(1e-6, 0.1, "Å") = Field(
        1e-3, description="structural tolerance of the group (Å per atom)"
    )
    energy_tolerance_mev_per_a2: physical(1e-9, 10.0, "meV/Å²") = Field(
        1e-2,
        description="largest accepted energy difference of a verified point (meV/Å²; two full "
        "scans of Cu(111) at fmax 0.005 eV/Å differ by up to 9e-4); above it "
        "the relaxation breaks the symmetry and every point is computed. On a flat landscape "
        "the smaller energy_tolerance_fraction of its range at the point's thickness applies "
        "(never below the energy's round-off)",
    )
    energy_tolerance_fraction: physical(1e-6, 1.0, "") = Field(
        0.05,
        # left out of the dumped config while default, so existing run fingerprints are unchanged
        exclude_if=lambda value: value == 0.05,
        description="largest accepted energy difference of a verified point as a fraction of "
        "the range (max - min) of the computed energies at its thickness, when smaller than "
        "energy_tolerance_mev_per_a2 (half the broken_symmetry gate's 10 %: a twist cell's "
        "whole corrugation can be below 0.01 meV/Å²)",
    )
    stress_tolerance_gpa: physical(1e-9, 10.0, "GPa") = Field(
        0.5,
        description="largest accepted normal-load difference of a verified point (GPa; the "
        "reaction load is only as precise as fmax/area: two full scans of the 8-atom Cu(111) "
        "cell differ by up to 0.19 GPa)",
    )


class ScanConfig(Section):
    """The ISPES grid (stage ``scan``)."""

    grid: tuple[int, int] = Field(
        (12, 12), description="lateral points along a1 and a2 over the primitive cell"
    )
    p_range_gpa: PressureRange | None = Field(
        None,
        description="choose the thicknesses z so that the loads at the probe stacking span "
        "lo_gpa..hi_gpa (n values); exclusive with thickness_angstrom",
    )
    thickness_angstrom: list[physical(0.1, 1e3, "Å")] | None = Field(
        None, description="explicit thicknesses z (Å, surface 1 to surface 4)"
    )
    fmax_ev_per_angstrom: physical(1e-6, 10.0, "eV/Å") = Field(
        0.005, description="force tolerance on the free atoms at each point (eV/Å)"
    )
    optimizer: str = Field(
        DEFAULT_OPTIMIZER,
        description="Optimiser of each point: " + ", ".join(OPTIMIZERS),
    )
    precondition: bool = Field(
        True,
        description="start the built-in L-BFGS of every point from the reference interface's "
        "inverse Hessian (computed once per process: 2 force calls per relaxed coordinate) "
        "where it applies: optimizers LBFGS-scaled and LBFGS, modes full and normal, at most "
        "1,000 relaxed coordinates; about 5x fewer force calls on quartz. In mode full a point "
        "where it slid a plane inside a slab is relaxed again without it (docs/performance.md)",
    )
    max_steps: int = Field(2000, ge=1, le=1_000_000, description="optimiser step cap per point")
    relax_mode: Literal["full", "normal", "rigid-layers", "rigid"] = Field(
        "full",
        # left out of the dumped config while default, so existing run fingerprints are unchanged
        exclude_if=lambda value: value == "full",
        description="relaxation of each point: full (free atoms in 3D, the paper's), normal "
        "(along z only: the generalized-stacking-fault convention), rigid-layers (each free "
        "layer a rigid body along z), rigid (none)",
    )
    bracket_all_stackings: bool = Field(
        True,
        exclude_if=lambda value: value is True,
        description="p_range_gpa: probe the extreme columns so that every stacking spans the "
        "loads (default); false: only the lowest-energy column decides the thicknesses",
    )
    order: str = Field(
        "columns",
        description="warm-start tree: columns (walk each column along z), planes, cold",
    )
    symmetry: SymmetryConfig = Field(
        default_factory=SymmetryConfig,
        description="irreducible registries (shift-space symmetry of the interface)",
    )
    executor: Literal["serial", "processes", "dask"] = Field(
        "processes", description="serial, local processes, or Dask"
    )
    workers: int | None = Field(None, ge=1, description="worker processes (default: one per core)")
    dask_address: str | None = Field(None, description="address of a running Dask scheduler")
    jobqueue: dict[str, Any] | None = Field(
        None,
        # left out of the dumped config while unset, so existing run fingerprints are unchanged
        exclude_if=lambda value: value is None,
        description="a dask-jobqueue cluster instead of local workers: {kind: slurm|pbs|sge|lsf|"
        "htcondor|oar|moab, jobs: N, ...keyword arguments of the cluster class}",
    )

    @field_validator("optimizer")
    @classmethod
    def _optimizer(cls, value: str) -> str:
        if value not in OPTIMIZERS:
            raise ValueError(f"expected one of {', '.join(OPTIMIZERS)}, got {show(value)}")
        return value

    @field_validator("order")
    @classmethod
    def _order(cls, value: str) -> str:
        if value not in PREFERENCES:
            raise ValueError(f"expected one of {', '.join(PREFERENCES)}, got {show(value)}")
        return value

    @field_validator("dask_address")
    @classmethod
    def _dask_address(cls, value: str | None) -> str | None:
        if value is not None:
            parse_dask_address(value)
        return value

    @field_validator("grid", mode="before")
    @classmethod
    def _grid(cls, value: Any) -> tuple[int, int]:
        return positive_pair(value, "grid")

    @model_validator(mode="after")
    def _one_of(self) -> ScanConfig:
        if (self.p_range_gpa is None) == (self.thickness_angstrom is None):
            raise ValueError("give exactly one of p_range_gpa and thickness_angstrom")
        if self.thickness_angstrom is not None:
            z = self.thickness_angstrom
            if not z or any(not v > 0 for v in z):
                raise ValueError(f"thickness_angstrom: expected positive values in Å, got {z}")
            if len(set(z)) != len(z):
                repeated = sorted({v for v in z if z.count(v) > 1})
                raise ValueError(
                    f"thickness_angstrom: expected distinct values in Å, {show(repeated)} repeated"
                )
        n_z = len(self.thickness_angstrom) if self.thickness_angstrom else self.p_range_gpa.n
        if n_z > limits.bound("thicknesses"):
            raise ValueError(
                "thickness_angstrom: " + limits.message("thicknesses", n_z, "thicknesses")
            )
        points = self.grid[0] * self.grid[1] * n_z
        if points > limits.bound("scan_points"):
            raise ValueError(
                "grid: "
                + limits.message(
                    "scan_points",
                    points,
                    f"{self.grid[0]}x{self.grid[1]} points x {n_z} thicknesses",
                )
            )
        if self.workers is not None and self.workers > limits.bound("workers"):
            raise ValueError(
                "workers: " + limits.message("workers", self.workers, "worker processes")
            )
        return self

    def executor_options(self) -> dict[str, Any]:
        """How the points are run (:func:`flatcontact.ispes.scan.run_scan`'s ``executor_options``)."""
        return {
            "kind": self.executor,
            "workers": self.workers,
            "dask_address": self.dask_address,
            "jobqueue": self.jobqueue,
        }
