"""Per-step records of an asperity run, asperity.nc and the atoms' side of asperity.json.

One :class:`StepRecord` per relaxed state (:mod:`.binning` states the conventions); a load's
records are a :class:`LoadRecord`; :func:`dataset` stacks them into the xarray written as
``asperity.nc`` (dims ``load``, ``step``, ``bin``; units in the variable names). Forces in N
(per metre of cylinder as well, ``*_n_per_m``), lengths Å, tractions GPa.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from ase import Atoms

from flatcontact.asperity import binning
from flatcontact.asperity.driver import EV_PER_ANGSTROM_N, StepState


@dataclass(frozen=True)
class Binning:
    """How a run bins: edges (Å), the contact-force and slip thresholds, the geometry."""

    edges_angstrom: np.ndarray
    contact_force_ev_per_angstrom: float
    slip_threshold_angstrom: float
    geometry: str
    axis_length_angstrom: float

    @property
    def centres_angstrom(self) -> np.ndarray:
        return 0.5 * (self.edges_angstrom[1:] + self.edges_angstrom[:-1])


@dataclass(frozen=True)
class StepRecord:
    """One relaxed state, measured (see the module docstring)."""

    displacement_angstrom: float
    lateral_force_n: float
    normal_force_n: float
    contact_half_width_angstrom: float
    stick_half_width_angstrom: float
    pressure_gpa: np.ndarray
    shear_gpa: np.ndarray
    slip_angstrom: np.ndarray
    iterations: int
    converged: bool
    residual_ev_per_angstrom: float


def _flat_top(atoms: Atoms) -> np.ndarray:
    """The flat's top atomic plane, found in the *built* (ideal) geometry: pressed, a bonded or
    adhesive rim lifts some surface atoms by more than half a plane spacing."""
    slab = np.asarray(atoms.arrays["slab"])
    z = atoms.positions[:, 2]
    top = z[slab == 1].max()
    spacing = float(atoms.info["plane_spacing_angstrom"])
    return np.flatnonzero((slab == 1) & (z > top - 0.5 * spacing))


def measure_load(atoms: Atoms, states: list[StepState], binning_: Binning) -> list[StepRecord]:
    """The records of one load's states (state 0 = pressed: the reference of the slip)."""
    slab = np.asarray(atoms.arrays["slab"])
    block = np.asarray(atoms.arrays["block"])
    cell2 = atoms.cell.array[:2, :2]
    apex = np.asarray(atoms.info["apex"], float)
    pressed = states[0].positions
    top = _flat_top(atoms)
    tip_free = np.flatnonzero((slab == 2) & (block == 0))
    spacing = float(atoms.info["plane_spacing_angstrom"])
    pairs_flat, pairs_tip = binning.facing_pairs(
        pressed[top], pressed[tip_free], cell2, 2.5 * spacing + 2.0
    )
    flat_idx, tip_idx = top[pairs_flat], tip_free[pairs_tip]
    flat_free = np.flatnonzero((slab == 1) & (block == 0))
    areas = binning.bin_areas(
        binning_.edges_angstrom, binning_.geometry, binning_.axis_length_angstrom
    )
    out = []
    for st in states:
        coord = binning.contact_coordinate(
            st.positions[flat_free, :2], apex, cell2, binning_.geometry
        )
        force = st.cross_force[flat_free]
        p, q = binning.traction_profiles(coord, force, binning_.edges_angstrom, areas)
        a = binning.contact_half_width(coord, force[:, 2], binning_.contact_force_ev_per_angstrom)
        s = binning.slip(
            st.positions[flat_idx] - pressed[flat_idx], st.positions[tip_idx] - pressed[tip_idx]
        )
        pair_coord = binning.contact_coordinate(
            pressed[flat_idx, :2], apex, cell2, binning_.geometry
        )
        slip_bins = binning.binned_mean(pair_coord, s, binning_.edges_angstrom)
        c = binning.stick_half_width(
            binning_.edges_angstrom, slip_bins, a, binning_.slip_threshold_angstrom
        )
        out.append(
            StepRecord(
                st.displacement_angstrom,
                # the force on the tip is the flat's reaction: Q on the contact is its negative
                -float(st.tip_force[1]) * EV_PER_ANGSTROM_N,
                float(st.tip_force[2]) * EV_PER_ANGSTROM_N,
                a,
                c,
                p,
                q,
                slip_bins,
                st.iterations,
                st.converged,
                st.residual_ev_per_angstrom,
            )
        )
    return out


def dataset(loads_p0_gpa, records: list[list[StepRecord]], binning_: Binning, attrs: dict):
    """asperity.nc's dataset: dims (load, step, bin)."""
    import xarray as xr

    def stack(name):
        return np.array([[getattr(r, name) for r in recs] for recs in records])

    length_m = binning_.axis_length_angstrom * 1e-10
    data = {
        "displacement_angstrom": (("load", "step"), stack("displacement_angstrom")),
        "lateral_force_n": (("load", "step"), stack("lateral_force_n")),
        "normal_force_n": (("load", "step"), stack("normal_force_n")),
        "contact_half_width_angstrom": (("load", "step"), stack("contact_half_width_angstrom")),
        "stick_half_width_angstrom": (("load", "step"), stack("stick_half_width_angstrom")),
        "pressure_gpa": (("load", "step", "bin"), stack("pressure_gpa")),
        "shear_gpa": (("load", "step", "bin"), stack("shear_gpa")),
        "slip_angstrom": (("load", "step", "bin"), stack("slip_angstrom")),
        "iterations": (("load", "step"), stack("iterations")),
        "converged": (("load", "step"), stack("converged").astype("i1")),
        "residual_ev_per_angstrom": (("load", "step"), stack("residual_ev_per_angstrom")),
    }
    if binning_.geometry == "cylinder":
        data["lateral_force_n_per_m"] = (("load", "step"), stack("lateral_force_n") / length_m)
        data["normal_force_n_per_m"] = (("load", "step"), stack("normal_force_n") / length_m)
    return xr.Dataset(
        data,
        coords={
            "load": np.arange(len(records)),
            "target_p0_gpa": ("load", np.asarray(loads_p0_gpa, float)),
            "step": np.arange(len(records[0])),
            "bin_centre_angstrom": ("bin", binning_.centres_angstrom),
        },
        attrs=attrs,
    )


def ramp_dataset(ramps: list[dict]):
    """The lock-in ramp's variables of asperity.nc: per load and amplitude (dim ``amplitude``)
    the atoms' and the models' k′ (N/m, NaN where the model has no steady cycle), and the
    path (dim ``ramp_step``): the tip's displacement (Å) and Q (N, from the pressed state)."""
    import xarray as xr

    def col(key):
        return np.array(
            [[np.nan if r.get(key) is None else r[key] for r in rp["amplitudes"]] for rp in ramps],
            dtype=float,
        )

    dims = ("load", "amplitude")
    data = {
        f"ramp_{key}": (dims, col(key))
        for key in (
            "displacement_amplitude_angstrom",
            "force_amplitude_n",
            "atoms_lockin_n_per_m",
            "atoms_loss_tangent",
            "model_hertz_lockin_n_per_m",
            "model_measured_pressure_lockin_n_per_m",
        )
    }
    data["ramp_displacement_angstrom"] = (
        ("load", "ramp_step"),
        np.array([rp["displacement_angstrom"] for rp in ramps]),
    )
    data["ramp_lateral_force_n"] = (
        ("load", "ramp_step"),
        np.array([rp["lateral_force_n"] for rp in ramps]),
    )
    return xr.Dataset(data, coords={"load": np.arange(len(ramps))})
