"""L-BFGS for one grid point: ASE's ``LBFGS``, step for step, driving the energy directly.

The scan relaxes thousands of small cells, each in 5-30 force calls. ASE's optimiser loop
asks the calculator for forces three to four times per step (log, convergence check, step),
copies the Atoms for the calculator's change check, applies every constraint object and
runs the L-BFGS two-loop recursion as 4k numpy calls on k memory pairs: on the 36-atom
quartz cell that was 1.1 ms per force call beside LAMMPS's 2.8 ms. This module does the
same iteration with one evaluation per step and the recursion as a handful of array
operations, so the steps are ASE's to round-off (``tests/ispes/test_lbfgs.py`` compares
trajectories with ``ase.optimize.LBFGS``).

The iteration (ASE 3.23-3.29 ``LBFGS`` with ``use_line_search=False``; Nocedal, Math.
Comp. 35, 773 (1980); Nocedal & Wright, *Numerical Optimization*, Algorithm 7.4)
------------------------------------------------------------------------------------
With generalised forces f = P(F) (``project``: held atoms and constrained directions
zeroed; see :mod:`flatcontact.ispes.relax`) and gradient g = -f:

1. converged when max_i |f_i| < fmax (largest per-atom force norm);
2. from the second step on, store s = x - x_prev, y = g - g_prev, ρ = 1/(y·s) (the oldest
   pair dropped beyond ``memory`` pairs; no curvature test, as in ASE);
3. direction p = -H g by the two-loop recursion with H0 = I/α;
4. step dr = p, scaled by ``maxstep``/max_i |p_i| if the longest atomic step exceeds
   ``maxstep`` (Å), times ``damping``; x ← x + P(dr).

The recursion as triangular solves
----------------------------------
The first loop (i = k-1 … 0) a_i = ρ_i s_i·(g - Σ_{j>i} a_j y_j) is the unit upper
triangular system (I + diag(ρ) U) a = ρ ∘ (S g), U_ij = s_i·y_j for j > i; the second loop
(i = 0 … k-1) c_i = a_i - ρ_i y_i·(z0 + Σ_{j<i} c_j s_j), z0 = (g - Yᵀa)/α, is the unit lower
triangular system (I + diag(ρ) L) c = a - ρ ∘ (Y z0), L_ij = y_i·s_j for j < i; then
H g = z0 + Sᵀc. Back and forward substitution perform the loops' own operations in the
loops' order; only the sums inside each dot product are associated differently (round-off).

Four matrix-vector products per step
------------------------------------
On a large cell the cost is reading the 2k stored vectors of length n (memory bandwidth:
≈ 0.5 ms per 100×14,112 matrix on one core; a matrix product with a few right-hand sides
is no cheaper in OpenBLAS, which packs the matrix). The memory keeps S Yᵀ and Y Yᵀ (k×k),
so Y z0 = (Y g - (Y Yᵀ) a)/α needs no pass, and H g = g/α + Yᵀ(-a/α) + Sᵀc is one pass over
S and Y. The new pair's products with the stored ones need none either (:meth:`TwoLoopMemory.push`):
S y = S g - S g_prev and Y y = Y g - Y g_prev from the saved products of the last step, and
Y s = t Y (H g_prev) because the step is s = t P(H g_prev) for the orthogonal projector P
whose range holds every stored vector (t the step's scale). A step is then S g, Y g and the
combination: four matrix-vector products where the loops took six (the two loops' four and
two for the new pair), equal to the loops to round-off (``tests/ispes/test_lbfgs.py``).

The memory
----------
ASE's 100 pairs on cells up to 1,000 atoms; beyond, :func:`memory_for` keeps m·n ≤ 300,000
coordinates (at least 20 pairs), so the algebra stays near a tenth of a cheap force call;
the measurements behind it are in its docstring and ``docs/performance.md``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import numpy as np

#: ASE's LBFGS defaults (memory pairs, initial curvature α in eV/Å², largest atomic step Å)
ASE_MEMORY = 100
ASE_ALPHA_EV_PER_A2 = 70.0
ASE_MAXSTEP_A = 0.2
#: the memory rule (:func:`memory_for`): stored coordinates m·n kept at or below this budget…
PAIR_BUDGET_COORDS = 300_000
#: …but never fewer pairs than this
MIN_LARGE_CELL_MEMORY = 20


def memory_for(n_coords: int) -> int:
    """L-BFGS memory for ``n_coords`` coordinates: ASE's 100 pairs up to 3,000 coordinates
    (1,000 atoms), then ``PAIR_BUDGET_COORDS // n_coords``, never below 20.

    Measured (``benchmarks/optimiser_cost.py``, ``docs/performance.md``): a step's algebra
    reads the 2m stored vectors of length n twice (four matrix-vector products, ≈ 2 ns
    per stored coordinate and pair on one core), while an EAM force call costs ≈ 0.25 µs per
    coordinate; so 100 pairs cost ≈ 0.8 of a Cu EAM call on any cell larger than the cache,
    and the tenth of a call takes m ≈ 12-20. Fewer pairs need more calls on the Cu(111)
    stacking fault (116 calls at m = 100, 130 at 50, 132 at 20, 143-147 at 15-5) and on REBO+KC
    graphene (19 calls for m ≥ 10, 23 at 5); at 4,704 Cu atoms CPU per point was lowest at
    m = 20. Small cells (every preset and example below 1,000 atoms) keep ASE's memory and
    their iterates.
    """
    if n_coords < 1:
        raise ValueError(f"n_coords: expected a positive number of coordinates, got {n_coords}")
    return int(min(ASE_MEMORY, max(MIN_LARGE_CELL_MEMORY, PAIR_BUDGET_COORDS // n_coords)))


@dataclasses.dataclass
class LbfgsOutcome:
    """Where a relaxation ended (energies in eV, forces in eV/Å, positions in Å).

    ``forces`` are the raw forces of the last evaluation (no projection); ``steps`` counts
    optimiser steps, ``force_calls`` evaluations (steps + 1: one per visited structure).
    """

    positions: np.ndarray
    energy_ev: float
    forces: np.ndarray
    steps: int
    force_calls: int
    converged: bool


class TwoLoopMemory:
    """The L-BFGS memory (s, y, ρ) in a ring buffer, and H·g by two triangular solves.

    The long vectors live in two preallocated (memory, n) arrays S and Y; beside them the
    memory keeps the k×k products S Yᵀ (s_i·y_j) and Y Yᵀ (y_i·y_j), and from the last
    direction d = H g the k-vectors S g, Y g and Y d. A step of :func:`lbfgs_relax` (:meth:`push`)
    then reads S and Y twice, in four matrix-vector products (module docstring, "Four
    matrix-vector products per step").

    Parameters
    ----------
    n
        Length of the flattened coordinate vector.
    memory
        Number of (s, y) pairs kept (the oldest is dropped beyond it).
    alpha
        Initial inverse Hessian H0 = I/α (α in eV/Å²).
    """

    def __init__(self, n: int, memory: int = ASE_MEMORY, alpha: float = ASE_ALPHA_EV_PER_A2):
        if memory < 1:
            raise ValueError(f"memory: expected at least one stored pair, got {memory}")
        self.memory = int(memory)
        self.h0 = 1.0 / float(alpha)
        self.s = np.zeros((self.memory, n))
        self.y = np.zeros((self.memory, n))
        self.rho = np.zeros(self.memory)
        self.sy = np.zeros((self.memory, self.memory))  # sy[i, j] = s_i · y_j (slots)
        self.yy = np.zeros((self.memory, self.memory))  # yy[i, j] = y_i · y_j (slots)
        self.count = 0  # pairs stored so far (all time)
        # s_i·g, y_i·g and y_i·d (slots) of the last direction d = H g; None before the first
        self._last: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
        self._tmp = np.empty(n)

    @property
    def size(self) -> int:
        """Pairs currently held."""
        return min(self.count, self.memory)

    def _slots(self) -> np.ndarray:
        """Slots of the held pairs, oldest first."""
        k = self.size
        return (np.arange(self.count - k, self.count)) % self.memory

    def _store(
        self, s: np.ndarray, y: np.ndarray, ys: np.ndarray, sy: np.ndarray, yy: np.ndarray
    ) -> int:
        """Write the pair into its slot given, for the k pairs held before it (slot order),
        ys[i] = y_i·s, sy[i] = s_i·y and yy[i] = y_i·y; returns the slot."""
        k = self.size
        slot = self.count % self.memory
        # a slot being overwritten gets its row and column replaced below
        self.sy[slot, :k] = ys
        self.sy[:k, slot] = sy
        self.yy[slot, :k] = yy
        self.yy[:k, slot] = yy
        self.s[slot] = s
        self.y[slot] = y
        own = np.dot(y, s)
        self.rho[slot] = 1.0 / own
        self.sy[slot, slot] = own
        self.yy[slot, slot] = np.dot(y, y)
        self.count += 1
        self._last = None
        return slot

    def add(self, s: np.ndarray, y: np.ndarray) -> None:
        """Store the pair (s, y) with ρ = 1/(y·s), as ASE does (no curvature test).

        Every product is computed afresh (three matrix-vector products); :meth:`push` is the
        step's cheaper path.
        """
        k = self.size
        self._store(s, y, self.y[:k] @ s, self.s[:k] @ y, self.y[:k] @ y)

    def push(self, s: np.ndarray, y: np.ndarray, g: np.ndarray, step: float) -> np.ndarray:
        """Store the pair (s, y) and return H·g, as ``add(s, y)`` then
        ``inverse_hessian_times(g)``, reading the stored vectors twice.

        Valid for the L-BFGS step only: the last call returned d = H g_prev, y = g - g_prev,
        and s = ``step``·P(d) for an orthogonal projector P whose range holds every stored
        vector and g (so y_i·s = ``step`` (Y d)_i). The products with the new pair then follow
        from the saved k-vectors: S y = S g - S g_prev, Y y = Y g - Y g_prev, Y s = step·Y d;
        the new pair's own products s·y, y·y, s·g, y·g are direct dot products.
        Without a previous direction it falls back to :meth:`add`.
        """
        if self._last is None:
            self.add(s, y)
            return self.inverse_hessian_times(g)
        k = self.size
        sg_prev, yg_prev, yd_prev = self._last
        sg = np.zeros(self.memory)
        yg = np.zeros(self.memory)
        sg[:k] = self.s[:k] @ g
        yg[:k] = self.y[:k] @ g
        slot = self._store(s, y, step * yd_prev[:k], sg[:k] - sg_prev[:k], yg[:k] - yg_prev[:k])
        sg[slot] = np.dot(s, g)
        yg[slot] = np.dot(y, g)
        return self._apply(g, sg, yg)

    def inverse_hessian_times(self, g: np.ndarray) -> np.ndarray:
        """H·g of the L-BFGS two-loop recursion (module docstring), a new array."""
        k = self.size
        sg = np.zeros(self.memory)
        yg = np.zeros(self.memory)
        sg[:k] = self.s[:k] @ g
        yg[:k] = self.y[:k] @ g
        return self._apply(g, sg, yg)

    def _apply(self, g: np.ndarray, sg: np.ndarray, yg: np.ndarray) -> np.ndarray:
        """H·g from the products sg[i] = s_i·g, yg[i] = y_i·g (slot order, length ``memory``).

        The long vectors are used in place (slot order); only the k-vectors and the k×k
        matrices are put in chronological order, so a wrapped memory on a large cell copies
        nothing of size n. Saves S g, Y g and Y·(H g) for the next :meth:`push`.
        """
        k = self.size
        if k == 0:
            self._last = (sg, yg, np.zeros(self.memory))
            return self.h0 * g
        order = self._slots()  # chronological position -> slot
        rho = self.rho[order]
        idx = np.ix_(order, order)
        a_mat = self.sy[idx]  # a_mat[i, j] = s_i · y_j, oldest first
        eye = np.eye(k)
        # first loop: (I + diag(rho) U) a = rho * (S g), U_ij = s_i·y_j for j > i
        upper = eye + rho[:, None] * np.triu(a_mat, 1)
        a = unit_upper_solve(upper, rho * sg[order])
        # z0 = (g - Yᵀa)/α is never formed: Y z0 = (Y g - (Y Yᵀ) a)/α
        yy_a = self.yy[idx] @ a
        y_z0 = (yg[order] - yy_a) * self.h0
        # second loop: (I + diag(rho) L) c = a - rho * (Y z0), L_ij = y_i·s_j = a_mat[j, i], j < i;
        # in reversed order (index k-1-i) that lower system is upper triangular
        lower = eye + rho[:, None] * np.tril(a_mat.T, -1)
        c = unit_upper_solve(lower[::-1, ::-1], (a - rho * y_z0)[::-1])[::-1]
        # H g = z0 + Sᵀc = g/α + Yᵀ(-a/α) + Sᵀc: the second pass over the stored vectors
        weights = np.zeros((2, self.memory))
        weights[0, order] = c
        weights[1, order] = -self.h0 * a
        out = np.dot(weights[0, :k], self.s[:k])
        out += np.dot(weights[1, :k], self.y[:k], out=self._tmp)
        out += self.h0 * g
        # Y (H g) = Y z0 + (Y Sᵀ) c, for the next pair's products y_i·s
        yd = np.zeros(self.memory)
        yd[order] = y_z0 + a_mat.T @ c
        self._last = (sg, yg, yd)
        return out


def unit_upper_solve(m: np.ndarray, b: np.ndarray) -> np.ndarray:
    """x with m x = b for a unit upper triangular ``m``: back substitution.

    ``numpy.linalg.solve`` (LAPACK ``gesv``): partial pivoting finds nothing below the unit
    diagonal to swap and the elimination multipliers are exact zeros, so the LU factors are
    (I, m) exactly and the solve is back substitution with divisions by 1.
    """
    return np.linalg.solve(m, b)


def largest_atomic_norm(vectors: np.ndarray) -> float:
    """max_i |v_i| over atoms of an (n, 3) array (ASE's force and step norm)."""
    if not len(vectors):
        return 0.0
    return float(np.sqrt(np.add.reduce(vectors * vectors, axis=1)).max())


def lbfgs_relax(
    evaluate: Callable[[np.ndarray], tuple[float, np.ndarray]],
    positions: np.ndarray,
    project: Callable[[np.ndarray], np.ndarray],
    fmax: float,
    max_steps: int,
    memory: int | None = None,
    alpha: float = ASE_ALPHA_EV_PER_A2,
    maxstep: float = ASE_MAXSTEP_A,
    damping: float = 1.0,
) -> LbfgsOutcome:
    """Relax ``positions`` with ASE's L-BFGS iteration, one ``evaluate`` per step.

    Parameters
    ----------
    evaluate
        ``evaluate(positions) -> (energy_ev, forces)``, positions and forces (n, 3) in Å
        and eV/Å; called exactly once per visited structure.
    positions
        Start (n, 3), Å; not modified.
    project
        The constraint projector P: (n, 3) -> (n, 3), linear, applied to the forces and to
        every step (held atoms get zero, constrained directions are removed).
    fmax
        Converged when the largest per-atom norm of P(F) is below ``fmax`` (eV/Å).
    max_steps
        Step cap (the outcome is then ``converged=False``).
    memory
        Stored (s, y) pairs; ``None``: :func:`memory_for` the number of coordinates (ASE's
        100 up to 1,000 atoms).
    alpha, maxstep, damping
        ASE's ``LBFGS`` parameters (defaults: ASE's).

    Returns
    -------
    LbfgsOutcome
    """
    x = np.array(positions, dtype=float)
    shape = x.shape
    energy, forces = evaluate(x)
    calls = 1
    f = project(forces)
    steps = 0
    converged = largest_atomic_norm(f) < fmax
    history = TwoLoopMemory(x.size, memory_for(x.size) if memory is None else memory, alpha)
    x_prev = g_prev = None
    scale = 1.0  # s = scale · P(H g_prev): the factor of the last step
    while not converged and steps < max_steps:
        g = -f.ravel()
        if x_prev is None:
            direction = history.inverse_hessian_times(g)
        else:
            direction = history.push(x.ravel() - x_prev, g - g_prev, g, scale)
        dr = -direction.reshape(shape)
        scale = -damping
        longest = largest_atomic_norm(dr)
        if longest >= maxstep:
            dr *= maxstep / longest
            scale *= maxstep / longest
        dr *= damping
        x_prev, g_prev = x.ravel().copy(), g
        x = x + project(dr)
        steps += 1
        energy, forces = evaluate(x)
        calls += 1
        f = project(forces)
        converged = largest_atomic_norm(f) < fmax
    return LbfgsOutcome(x, float(energy), forces, steps, calls, bool(converged))
