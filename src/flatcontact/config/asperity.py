"""The ``asperity`` section: the asperity in atoms against the modified Mindlin model.

Off by default (the default run is unchanged). docs/asperity.md.
"""

from __future__ import annotations

import itertools
from typing import Literal

from pydantic import Field, field_validator

from flatcontact.config.section import Section
from flatcontact.foundation.numbers import physical

#: Largest ``asperity.mpi_ranks`` (flatcontact.asperity.ranks checks against it too).
MAX_MPI_RANKS = 256


class AsperityConfig(Section):
    """A cap of slab 2's crystal pressed and slid on a flat of slab 1's (``flatcontact asperity``)."""

    enabled: bool = Field(False, description="run the asperity in atoms (stage asperity)")
    geometry: Literal["cylinder", "sphere"] = Field(
        "cylinder",
        description="cylinder (line contact, periodic along its axis a1: quasi-2D, cheap) or "
        "sphere (the paper's geometry)",
    )
    tip: Literal["slab2", "slab1"] = Field(
        "slab2",
        description="the crystal cut to the cap: slab2 (on a flat of slab 1) or slab1 (the "
        "interface turned upside down: on a flat of slab 2)",
    )
    radius_angstrom: physical(5.0, 1e5, "Å") = Field(300.0, description="tip radius R")
    p0_gpa: list[physical(1e-3, 100.0, "GPa")] = Field(
        [1.0], description="target loads as Hertz peak pressures p0 (from R and E*)"
    )
    contact_modulus_gpa: physical(1.0, 2000.0, "GPa") | None = Field(
        None,
        description="E* for the sizes and the Hertz model; default: the run's elastic stage "
        "(elastic.json), else contact.contact_modulus_gpa",
    )
    step_angstrom: physical(1e-3, 2.0, "Å") = Field(
        0.05, description="lateral displacement of the tip's rigid block per step"
    )
    steps: int = Field(40, ge=1, le=10000, description="lateral steps per load")
    fmax_ev_per_angstrom: physical(1e-6, 1.0, "eV/Å") = Field(
        1e-3, description="relaxation tolerance: largest force component"
    )
    max_iterations: int = Field(20000, ge=10, description="FIRE iterations per relaxation")
    depth_factor: physical(0.5, 50.0) = Field(
        2.0, description="depth of each body in Hertz half-widths a"
    )
    lateral_factor: physical(1.0, 50.0) = Field(
        4.0, description="lateral period in contact widths 2a"
    )
    axis_repeats: int = Field(2, ge=1, le=1000, description="cylinder: cells along its axis")
    rigid_angstrom: physical(1.0, 100.0, "Å") = Field(
        6.0, description="thickness of each rigid block (at least the potential's cutoff)"
    )
    repeats: tuple[int, int] | None = Field(
        None, description="override: primitive cells along a1, a2 (else from R, load, E*)"
    )
    layers: int | None = Field(
        None, ge=3, le=2000, description="override: atomic planes of the flat (tip: + rigid)"
    )
    gap_angstrom: physical(0.5, 20.0, "Å") | None = Field(
        None, description="initial gap at the apex (default: the structure's spacing)"
    )
    bin_width_angstrom: physical(0.1, 100.0, "Å") = Field(
        2.0, description="width of the traction and slip bins along the contact"
    )
    contact_force_ev_per_angstrom: physical(1e-6, 10.0, "eV/Å") = Field(
        0.005, description="an atom pushed down by more than this is in force contact"
    )
    slip_threshold_angstrom: physical(1e-4, 10.0, "Å") = Field(
        0.1, description="a pair of facing atoms slipped less than this sticks"
    )
    mpi_ranks: int = Field(
        1,
        ge=1,
        le=MAX_MPI_RANKS,
        description="MPI ranks LAMMPS relaxes each step on (mpiexec of the mpich wheel; "
        "1: in this process). Same protocol and resume points; states equal to the 1-rank "
        "run's within the minimiser's tolerance. docs/asperity.md",
    )
    ramp_amplitudes_angstrom: list[physical(1e-3, 10.0, "Å")] | None = Field(
        None,
        description="lock-in cycles at these lateral amplitudes of the tip's block, increasing "
        "(the stiffness against amplitude of the paper's Fig. 6); steps of step_angstrom; "
        "default: none",
    )
    laws_file: str | None = Field(
        None, description="laws.json to compare with (default: the run's laws stage)"
    )

    @field_validator("ramp_amplitudes_angstrom")
    @classmethod
    def _ramp(cls, value):
        if value is not None and (not value or any(b <= a for a, b in itertools.pairwise(value))):
            raise ValueError(f"expected strictly increasing amplitudes in Å, got {value}")
        return value
