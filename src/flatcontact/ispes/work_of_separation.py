"""The ideal work of separation of an interface: two slabs apart against the zero-load contact.

W = [E(slab 1 alone) + E(slab 2 alone) − E(interface at zero load)] / A, in J/m²
(``EV_PER_A2_TO_J_PER_M2``), A = |a1 × a2| the cell area in Å².

- The interface at zero load is taken at the **perfect stacking** when the interface is a
  3-D crystal continued across the cut (its zero shift, named by geometry whatever its
  energy: a potential that favours the stacking fault would otherwise put W at the fault;
  :func:`flatcontact.structures.interface_contract.continues_crystal`), else at the
  **global minimum** (the lowest-energy lateral stacking of the scan's rigid single points);
  ``work_of_separation_stacking`` says which (:func:`work_shift`). It is taken at the
  thickness where the normal load p (GPa, > 0 pressed;
  :func:`flatcontact.ispes.relax.normal_stress_gpa`) vanishes: p = −(1/A) dU/dz, so that
  thickness is the minimum of the relaxed energy U(z) of the column. It is found by a
  safeguarded secant on p(z) (regula falsi with the Illinois modification) between two
  thicknesses that bracket p = 0, every point relaxed as a grid point
  (:func:`flatcontact.ispes.relax.relax_point`: held layers held, the scan's mode).
- The slabs alone: both in the same periodic cell, slab 2 lifted rigidly by a distance D
  beyond every interaction between them, relaxed with the same settings as a grid point
  (held layers held, the interface surfaces relax as the mode allows), so E(apart) =
  E(slab 1 alone) + E(slab 2 alone). D is the first of ``SEPARATIONS_ANGSTROM`` at which the
  rigid reference's energy no longer changes (E at z_ref + D and z_ref + 2D agree to
  ``APART_TOL_J_PER_M2`` per area). Computed with the interface's own calculator, the
  structure has the same atoms, types and layers as every grid point: a calculator built
  for one slab without the other need not accept it (a LAMMPS interlayer Coulomb
  sub-style with one layer has nothing to act on; a monolayer gives a box of zero height).

This is one cut: the surface energies of the two new surfaces plus the interface energy,
W = γ1 + γ2 − γ12 (Dupré); for a crystal cut across a plane of itself (coupling ``same``,
perfect stacking) it is 2γ. It depends on the interface and the relaxation settings only,
not on the thicknesses of a grid. The scan's probe, pulling a column apart with its inner
planes free, can open more than one gap; its pull-off work is kept as a diagnostic
(:mod:`flatcontact.ispes.separation`).
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
from ase import Atoms

from flatcontact.foundation.errors import InputError
from flatcontact.foundation.units import EV_PER_A2_TO_J_PER_M2
from flatcontact.ispes.contract import cell_area
from flatcontact.ispes.geometry import in_plane_vectors, place_slab2, thickness
from flatcontact.ispes.relax import PointTask, RelaxSettings, relax_point, start_afresh
from flatcontact.potentials.guarded import CalculatorFailure, failing_at
from flatcontact.structures.interface_contract import continues_crystal, recipe_record

#: first step (Å) away from the reference thickness when bracketing p = 0; doubled each time
FIRST_STEP_ANGSTROM = 0.05
#: the bracket search gives up this far (Å) from the reference thickness
MAX_REACH_ANGSTROM = 20.0
#: the zero-load thickness is located to this width (Å); U is stationary there, so the
#: energy error is of order ½ A k δz² (k the normal stiffness per area): negligible
XTOL_ANGSTROM = 1e-4
#: or until |p| is below this load (GPa)
PTOL_GPA = 1e-6
MAX_ITERATIONS = 60
#: distances (Å, added to the reference thickness) tried for the slabs apart
SEPARATIONS_ANGSTROM = (20.0, 40.0, 80.0, 160.0)
#: the slabs are apart when the rigid energy changes by less than this per area (J/m²)
APART_TOL_J_PER_M2 = 1e-6


#: ``work_of_separation_stacking``: where W is taken (:func:`work_shift`).
AT_PERFECT_STACKING = "perfect stacking (zero shift: slab 2 continues slab 1's crystal)"
AT_GLOBAL_MINIMUM = "global minimum (lowest rigid energy of the grid's stackings)"


def work_shift(reference: Atoms, lowest: tuple[float, float]) -> tuple[tuple[float, float], str]:
    """The lateral stacking W is taken at and its label: the zero shift of a continued 3-D
    crystal (the perfect stacking), else ``lowest`` (the grid's lowest rigid stacking)."""
    if continues_crystal(recipe_record(reference)):
        return (0.0, 0.0), AT_PERFECT_STACKING
    return (float(lowest[0]), float(lowest[1])), AT_GLOBAL_MINIMUM


@dataclasses.dataclass(frozen=True)
class WorkOfSeparation:
    """The ideal work of separation and the states it compares (energies in eV).

    W = [E(slabs apart) - E(interface at zero load)] / A of two perfect slabs at one stacking
    (``work_of_separation_j_per_m2``, J/m²). The contact stage takes it as its work of adhesion
    w (``contact.work_of_adhesion_j_per_m2``) when none is given: a distinct quantity (w is
    the tip's adhesion on the surface, measured or chosen), of which W is an estimate.
    """

    work_of_separation_j_per_m2: float
    #: distance (Å) added to the reference thickness for the slabs apart
    separation_angstrom: float
    #: lateral stacking (fractions of a1, a2) and thickness (Å) of the zero-load interface
    zero_load_shift: tuple[float, float]
    zero_load_thickness_angstrom: float
    #: the load left at that thickness (GPa), a measure of how well p = 0 was located
    zero_load_stress_gpa: float
    interface_energy_ev: float
    apart_energy_ev: float
    area_angstrom2: float
    #: every relaxation met the force tolerance
    converged: bool
    force_calls: int
    #: where W is taken (:func:`work_shift`)
    stacking: str = AT_GLOBAL_MINIMUM

    def record(self) -> dict[str, Any]:
        """Flat scalar entries for ``scan.json``'s ``adhesion`` and ``ispes.nc``'s attrs."""
        return {
            "work_of_separation_j_per_m2": self.work_of_separation_j_per_m2,
            "work_of_separation_shift_a": self.zero_load_shift[0],
            "work_of_separation_shift_b": self.zero_load_shift[1],
            "work_of_separation_thickness_angstrom": self.zero_load_thickness_angstrom,
            "work_of_separation_residual_stress_gpa": self.zero_load_stress_gpa,
            "work_of_separation_apart_angstrom": self.separation_angstrom,
            "work_of_separation_converged": self.converged,
            "work_of_separation_stacking": self.stacking,
        }


def ideal_work_of_separation(
    reference: Atoms,
    factory: Any,
    relax: RelaxSettings,
    shift: tuple[float, float],
    calc: Any = None,
) -> WorkOfSeparation:
    """W of ``reference`` at the lateral stacking ``shift`` (see the module docstring).

    Parameters
    ----------
    reference
        The reference interface (interface contract).
    factory
        The scan's calculator factory: ``factory(atoms)`` -> ASE calculator; called for the
        interface unless ``calc`` is given.
    relax
        The scan's relaxation settings (tolerance, optimiser, mode).
    shift
        The lowest-energy lateral stacking (fractions of a1, a2); replaced by the zero shift
        (the perfect stacking) for a continued 3-D crystal (:func:`work_shift`).
    calc
        A calculator already built for ``reference`` (the scan driver's), reused.
    """
    shift, stacking = work_shift(reference, shift)
    a1, a2 = in_plane_vectors(reference)
    area = cell_area(a1, a2)
    calc = factory(reference) if calc is None else calc
    with failing_at("ideal work of separation"):  # a user's calculator that fails: one line
        z_eq, e_int, p_eq, ok, calls = zero_load_interface(reference, calc, relax, shift)
        d, e_apart, converged, n = slabs_apart(reference, calc, relax, shift, area)
    w = (e_apart - e_int) / area * EV_PER_A2_TO_J_PER_M2
    return WorkOfSeparation(
        work_of_separation_j_per_m2=float(w),
        separation_angstrom=float(d),
        zero_load_shift=(float(shift[0]), float(shift[1])),
        zero_load_thickness_angstrom=float(z_eq),
        zero_load_stress_gpa=float(p_eq),
        interface_energy_ev=float(e_int),
        apart_energy_ev=float(e_apart),
        area_angstrom2=float(area),
        converged=bool(ok and converged),
        force_calls=int(calls + n),
        stacking=stacking,
    )


def slabs_apart(
    reference: Atoms, calc: Any, relax: RelaxSettings, shift: tuple[float, float], area: float
) -> tuple[float, float, bool, int]:
    """E(slab 1 alone) + E(slab 2 alone): the slabs relaxed a distance D apart.

    Returns
    -------
    separation_angstrom, energy_ev, converged, force_calls
    """
    a, b = float(shift[0]), float(shift[1])
    z_ref = thickness(reference)
    tol_ev = APART_TOL_J_PER_M2 / EV_PER_A2_TO_J_PER_M2 * area

    def rigid_energy(z: float) -> float:
        atoms = place_slab2(reference, a, b, z, spread_compression=False)
        start_afresh(calc)  # a function of z alone, whatever ran before
        atoms.calc = calc
        try:
            return float(atoms.get_potential_energy())
        finally:
            atoms.calc = None

    change = np.nan
    for d in SEPARATIONS_ANGSTROM:
        change = rigid_energy(z_ref + 2 * d) - rigid_energy(z_ref + d)
        if abs(change) < tol_ev:
            break
    else:
        raise InputError(
            f"work of separation: the slabs still interact {SEPARATIONS_ANGSTROM[-1]:.4g} Å "
            f"apart (the energy changes by {change / area * EV_PER_A2_TO_J_PER_M2:.3g} J/m² "
            "when the distance doubles); give contact.work_of_adhesion_j_per_m2"
        )
    r = relax_point(reference, calc, PointTask((0, 0, 0), a, b, z_ref + d), relax)
    return d, r.energy_ev, r.converged, r.force_calls + r.hessian_force_calls


def zero_load_interface(
    reference: Atoms, calc: Any, relax: RelaxSettings, shift: tuple[float, float]
) -> tuple[float, float, float, bool, int]:
    """The relaxed interface at ``shift`` where p(z) = 0.

    Starting at the reference thickness, steps of ``FIRST_STEP_ANGSTROM`` (doubled each
    time) go up while the interface is pressed (p > 0) or down while it is in tension,
    until p changes sign; the Illinois regula falsi then narrows the bracket to
    ``XTOL_ANGSTROM`` or |p| < ``PTOL_GPA``. Each point starts from the relaxed point
    nearest in z.

    Returns
    -------
    z_angstrom, energy_ev, normal_stress_gpa, converged, force_calls
        Of the evaluated point with the smallest |p|.
    """
    a, b = float(shift[0]), float(shift[1])
    done: dict[float, tuple[float, float, np.ndarray, bool]] = {}
    calls = 0

    def load(z: float) -> float:
        nonlocal calls
        start = min(done, key=lambda zz: abs(zz - z)) if done else None
        task = PointTask(
            (0, 0, 0),
            a,
            b,
            z,
            done[start][2] if start is not None else None,
            (a, b) if start is not None else None,
            start,
        )
        try:
            r = relax_point(reference, calc, task, relax)
        except CalculatorFailure:
            raise  # the user's calculator failed: not an overlap
        except InputError as exc:
            raise InputError(
                f"work of separation: the slabs overlap at z = {z:.4g} Å before the load "
                f"at shift ({a:.4g}, {b:.4g}) changes sign ({exc})"
            ) from None
        calls += r.force_calls + r.hessian_force_calls
        done[z] = (r.energy_ev, r.normal_stress_gpa, r.positions, r.converged)
        return r.normal_stress_gpa

    z0 = z_ref = thickness(reference)
    p0 = load(z0)
    direction = 1.0 if p0 > 0 else -1.0
    step = FIRST_STEP_ANGSTROM
    z1, p1 = z0, p0
    while p1 * p0 > 0 and abs(p1) >= PTOL_GPA:
        if step > MAX_REACH_ANGSTROM:
            raise InputError(
                f"work of separation: the load at shift ({a:.4g}, {b:.4g}) stays "
                f"{'compressive' if p0 > 0 else 'tensile'} from z = {z_ref:.4g} to {z1:.4g} Å "
                f"(p = {done[z_ref][1]:.3g} .. {p1:.3g} GPa); no zero-load thickness"
            )
        z0, p0 = z1, p1
        z1 = z0 + direction * step
        p1 = load(z1)
        step *= 2.0
    lo, hi = (z0, p0), (z1, p1)  # p changes sign between them
    for _ in range(MAX_ITERATIONS):
        (za, pa), (zb, pb) = lo, hi
        if abs(zb - za) < XTOL_ANGSTROM or min(abs(done[za][1]), abs(pb)) < PTOL_GPA:
            break
        z = zb - pb * (zb - za) / (pb - pa)
        p = load(z)
        if p * pb < 0:
            lo, hi = (zb, pb), (z, p)
        else:  # Illinois: the end kept again counts half
            lo, hi = (za, pa / 2.0), (z, p)
    z_best = min(done, key=lambda zz: abs(done[zz][1]))
    e, p, _, converged = done[z_best]
    return z_best, e, p, converged, calls
