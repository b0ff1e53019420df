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
3. direction p = -H g by the two-loop recursion with H0 = I/α (ASE: α fixed; with
   ``scaled=True``, not ASE's, H0 = γ I from the newest pair, γ = s·y/y·y, Nocedal & Wright
   eq. 7.20, once a pair of positive curvature is stored: "Initial Hessian scaling" below);
4. step dr = p, scaled by ``maxstep``/max_i |p_i| if the longest atomic step exceeds
   ``maxstep`` (Å), times ``damping``; x ← x + P(dr).

The recursion as triangular products
------------------------------------
The first loop (i = k-1 … 0) a_i = ρ_i s_i·(g - Σ_{j>i} a_j y_j) is the upper triangular
system R a = S g with R = triu(S Yᵀ), R_ij = s_i·y_j for j ≥ i (R_ii = 1/ρ_i); the second
loop (i = 0 … k-1) c_i = a_i - ρ_i y_i·(z0 + Σ_{j<i} c_j s_j), z0 = (g - Yᵀa)/α, is the lower
triangular system Rᵀ c = a/ρ - Y z0; then H g = z0 + Sᵀc (the compact form of Byrd,
Nocedal & Schnabel, Math. Prog. 63, 129 (1994), eq. 3.1, with the same R). The memory keeps
R⁻¹ up to date at O(k²) per pair (a new pair appends a column, the dropped oldest pair
removes the first row and column: both keep it triangular, :meth:`TwoLoopMemory._store`),
so each system is one k×k matrix-vector product where a general LU solve cost O(k³)
(≈ 0.2 ms per step at k = 100, on any cell). Only the sums are associated differently from
the loops (round-off: ``tests/ispes/test_lbfgs.py`` compares with the loops to 1e-12).

Two passes per step
-------------------
On a large cell the cost is reading the 2k stored vectors of length n from memory: at 4,704
Cu atoms (k = 21, 4.7 MB) callgrind's cache simulation puts 65 % of the scan's misses of a
1 MiB cache in these reads, 8.8 MB per call, where LAMMPS's own call misses 3.1 MB
(``docs/performance.md``, "Fourth round"). The memory keeps S Yᵀ and Y Yᵀ (k×k), so
Y z0 = (Y g - (Y Yᵀ) a)/α needs no pass, and H g = g/α + Yᵀ(-a/α) + Sᵀc is one pass. The new
pair's products with the stored ones need none either (:meth:`TwoLoopMemory.push`):
S y = S g - S g_prev and Y y = Y g - Y g_prev from the saved products of the last step, and
Y s = t Y (H g_prev) because the step is s = t P(H g_prev) for the orthogonal projector P
whose range holds every stored vector (t the step's scale). The pairs live interleaved in
one block (s_j, y_j adjacent), with the two gradient rows in front: S g and Y g are one
matrix-vector product over the slots in use, the new pair's s·y and y·y one over its two
rows, and -H g = -(g/α + Yᵀ(-a/α) + Sᵀc) one product over the gradient row and the slots
(no separate pass for g/α, the sum or the sign). Two passes over the stored vectors per
step, where the loops took six, equal to the loops to round-off
(``tests/ispes/test_lbfgs.py``); fewer cannot do, as S g needs the new gradient and the
step needs S g.

Initial Hessian scaling (``scaled=True``)
-----------------------------------------
ASE keeps H0 = I/α with α = 70 eV/Å² at every step. The textbook L-BFGS (Nocedal & Wright,
Algorithm 7.5 with eq. 7.20; Liu & Nocedal, Math. Prog. 45, 503 (1989)) rescales it at every
step to γ_k I, γ_k = s_{k-1}·y_{k-1}/y_{k-1}·y_{k-1}, the inverse curvature measured along the
last step (kept at 1/α until a pair with s·y > 0 and y·y > 0 arrives; the first step is
ASE's). The recursion is unchanged, H0 enters only as the scalar it multiplies. On
the 6 × 6 × 8 quartz SNAP + LJ grid of ``benchmarks/bench_scanspeed.py`` (fmax 0.005 eV/Å,
warm-start tree ``columns``) it took 17.8 force calls per point against ASE's 21.8
(``docs/performance.md``, "Fewer force calls per point"), every point within the same
max-norm tolerance. The scan uses it by default (optimiser ``LBFGS-scaled``,
:data:`flatcontact.ispes.relax.BUILT_IN_LBFGS`); ``LBFGS`` keeps ASE's iterates. (It waited
for the ``degenerate_minima`` gate to stop counting a tie-rule choice between degenerate
sites of equal τ as a move: :mod:`flatcontact.analysis.gates`.)

A fixed initial inverse Hessian (``preconditioner``)
---------------------------------------------------
Any fixed symmetric positive definite H0 may stand in Algorithm 7.4 (Nocedal & Wright,
§7.2). With H0 = L L (L symmetric, commuting with P) the iteration is run in u = L⁻¹ x,
where H0 is the identity: the memory keeps s_u = L⁻¹ s (the last step in u, kept: no
inverse is ever formed) and y_u = L y, the gradient row holds L g, and the direction -H_u g_u
becomes the atoms' step L(-H_u g_u), capped at ``maxstep`` in x as before. The two passes
and the memory are unchanged; a step adds two dense n × n products (L g, L d). The scan
takes the reference interface's Hessian (``RelaxSettings.precondition``,
:mod:`flatcontact.ispes.precondition`); with the
identity L = I/√α the iterates are ASE's to round-off (``tests/ispes/test_lbfgs_precondition.py``).

The memory
----------
ASE's 100 pairs on cells up to 1,000 atoms; beyond, :func:`memory_for` keeps m·n ≤ 300,000
coordinates (at least 20 pairs), so the algebra stays near a tenth of a cheap force call;
the measurements behind it are in its docstring and ``docs/performance.md``.
"""

from __future__ import annotations

import dataclasses
import inspect
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
    """The L-BFGS memory (s, y, ρ) in a ring buffer, and H·g by two triangular products.

    The long vectors live in one preallocated (2 + 2·memory, n) array ``block``: two rows
    for the caller's gradients (:attr:`gradients`), then the pairs interleaved, s of slot j
    in row 2 + 2j and y in the row after it (ring order), so the slots in use are one
    contiguous matrix and, with the gradient, so is the combination H g. Beside them, in
    chronological order, the memory keeps the k×k products S Yᵀ (s_i·y_j), Y Yᵀ (y_i·y_j)
    and the inverse R⁻¹ of R = triu(S Yᵀ) (module docstring, "The recursion as triangular
    products"), and from the last direction d = H g the k-vectors S g, Y g and Y d. A step of
    :func:`lbfgs_relax` (:meth:`push_stored`) then reads the stored vectors twice, in two
    matrix-vector products (module docstring, "Two passes per step").

    Parameters
    ----------
    n
        Length of the flattened coordinate vector.
    memory
        Number of (s, y) pairs kept (the oldest is dropped beyond it).
    alpha
        Initial inverse Hessian H0 = I/α (α in eV/Å²).
    scaled
        If true, H0 = γ I with γ = s·y/y·y of the newest pair of positive curvature (module
        docstring, "Initial Hessian scaling"); else I/α throughout (ASE).
    """

    def __init__(
        self,
        n: int,
        memory: int = ASE_MEMORY,
        alpha: float = ASE_ALPHA_EV_PER_A2,
        scaled: bool = False,
    ):
        if memory < 1:
            raise ValueError(f"memory: expected at least one stored pair, got {memory}")
        self.memory = m = int(memory)
        self.h0 = 1.0 / float(alpha)
        self.scaled = bool(scaled)
        self.block = np.zeros((2 + 2 * m, n))
        #: two rows the caller may keep g and g_prev in: H g then takes no pass of its own
        #: (two views made once: :meth:`_gradient_row` knows them by identity)
        self.gradients = (self.block[0], self.block[1])
        self.s = self.block[2::2]  # views: s of slot j is s[j], y of slot j is y[j]
        self.y = self.block[3::2]
        # chronological (oldest first), the top-left size × size block in use
        self.rho = np.zeros(m)
        self.sy = np.zeros((m, m))  # sy[i, j] = s_i · y_j
        self.yy = np.zeros((m, m))  # yy[i, j] = y_i · y_j
        self.r_inv = np.zeros((m, m))  # R⁻¹, R = triu(sy) (diagonal included)
        self.count = 0  # pairs stored so far (all time)
        # s_i·g, y_i·g and y_i·d (chronological) of the last direction d = H g; None before it
        self._last: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
        self._weights = np.zeros(2 + 2 * m)
        self._order = (-1, np.zeros(0, dtype=np.intp))  # (count, _slots(count)) of the last call

    @property
    def size(self) -> int:
        """Pairs currently held."""
        return min(self.count, self.memory)

    def _slots(self, count: int | None = None) -> np.ndarray:
        """Slots of the pairs held when ``count`` pairs were stored, oldest first."""
        count = self.count if count is None else count
        if self._order[0] == count:  # asked two or three times per step: kept (read-only)
            return self._order[1]
        k = min(count, self.memory)
        order = np.arange(count - k, count) % self.memory
        order.flags.writeable = False
        self._order = (count, order)
        return order

    def _pairs(self, used: int) -> np.ndarray:
        """The rows of the first ``used`` slots, s and y interleaved: one (2·used, n) matrix."""
        return self.block[2 : 2 + 2 * used]

    def next_pair(self) -> tuple[np.ndarray, np.ndarray]:
        """Views (s, y) of the slot the next pair goes to, for :meth:`push_stored` (the
        caller writes the pair there: no copy). The slot may hold the oldest pair still."""
        slot = self.count % self.memory
        return self.s[slot], self.y[slot]

    def _own_products(self) -> tuple[float, float]:
        """s·y and y·y of the pair in :meth:`next_pair`'s slot: one product of its two
        adjacent rows with y."""
        slot = self.count % self.memory
        rows = self.block[2 + 2 * slot : 4 + 2 * slot]
        sy, yy = rows @ rows[1]
        return float(sy), float(yy)

    def _store(self, ys: np.ndarray, sy: np.ndarray, yy: np.ndarray, own_sy: float, own_yy: float):
        """Append the pair just written to :meth:`next_pair` to the chronological k×k products
        given, for the k pairs held before it (oldest first), ys[i] = y_i·s, sy[i] = s_i·y and
        yy[i] = y_i·y, and s·y, y·y. A full memory drops its oldest pair first: the trailing
        block of a triangular matrix's inverse is the inverse of its trailing block, so R⁻¹
        keeps its lower-right part; the new column of R⁻¹ is -R⁻¹ (S y)/(s·y) (block inverse
        of [[R, S y], [0, s·y]])."""
        k = self.size
        if k == self.memory:
            for mat in (self.sy, self.yy, self.r_inv):
                mat[:-1, :-1] = mat[1:, 1:]
            self.rho[:-1] = self.rho[1:]
            ys, sy, yy = ys[1:], sy[1:], yy[1:]
            k -= 1
        self.sy[k, :k] = ys
        self.sy[:k, k] = sy
        self.sy[k, k] = own_sy
        self.yy[k, :k] = yy
        self.yy[:k, k] = yy
        self.yy[k, k] = own_yy
        self.rho[k] = 1.0 / own_sy
        self.r_inv[k, :k] = 0.0
        self.r_inv[:k, k] = self.r_inv[:k, :k] @ sy * (-1.0 / own_sy)
        self.r_inv[k, k] = 1.0 / own_sy
        self.count += 1
        self._last = None
        if self.scaled and own_sy > 0.0 and own_yy > 0.0:  # H0 = γ I, eq. 7.20
            self.h0 = own_sy / own_yy

    def add(self, s: np.ndarray, y: np.ndarray) -> None:
        """Store the pair (s, y) with ρ = 1/(y·s), as ASE does (no curvature test).

        Every product is computed afresh (a pass over the stored vectors); :meth:`push` is
        the step's cheaper path.
        """
        s_new, y_new = self.next_pair()
        s_new[...] = s
        y_new[...] = y
        self._add_stored()

    def _add_stored(self) -> None:
        """:meth:`add` for the pair already written to :meth:`next_pair`. Over a full memory
        the products with the slot it overwrote belong to the oldest pair, which is dropped."""
        s, y = self.next_pair()
        k = self.size
        order = self._slots()
        with_s = self._pairs(k) @ s  # s_j·s, y_j·s interleaved
        with_y = self._pairs(k) @ y
        self._store(
            with_s[1::2][order], with_y[0::2][order], with_y[1::2][order], *self._own_products()
        )

    def push(self, s: np.ndarray, y: np.ndarray, g: np.ndarray, step: float) -> np.ndarray:
        """Store the pair (s, y) and return H·g, as ``add(s, y)`` then
        ``inverse_hessian_times(g)``, reading the stored vectors twice (:meth:`push_stored`
        after copying the pair into its slot)."""
        s_new, y_new = self.next_pair()
        s_new[...] = s
        y_new[...] = y
        return self.push_stored(g, step)

    def push_stored(
        self, g: np.ndarray, step: float, out: np.ndarray | None = None, factor: float = 1.0
    ) -> np.ndarray:
        """Store the pair already written to :meth:`next_pair` and return ``factor``·H·g.

        Valid for the L-BFGS step only: the last call returned d = H g_prev (times its
        factor), y = g - g_prev, and s = ``step``·P(d) for an orthogonal projector P whose
        range holds every stored vector and g (so y_i·s = ``step`` (Y d)_i). The products
        with the new pair then follow from the saved k-vectors: S y = S g - S g_prev,
        Y y = Y g - Y g_prev, Y s = step·Y d; S g and Y g over the slots in use (the new
        pair's included: s·g and y·g come with them, a slot being overwritten gives a
        product that is dropped with its pair) are one pass over the stored vectors, and
        the new pair's s·y, y·y the only other long products. Without a previous direction
        it falls back to the products computed afresh (:meth:`add`). ``out``: where the
        result goes (length n), else a new array.
        """
        if self._last is None:
            self._add_stored()
            return self.inverse_hessian_times(g, out, factor)
        k = self.size
        sg_prev, yg_prev, yd_prev = self._last
        used = min(self.count + 1, self.memory)  # slots in use with the new pair
        products = self._pairs(used) @ g  # s_j·g, y_j·g interleaved, slot order
        sg_slot, yg_slot = products[0::2], products[1::2]
        old = self._slots()  # the k pairs held before (their slots; one may now hold the new)
        self._store(
            step * yd_prev[:k],
            sg_slot[old] - sg_prev[:k],
            yg_slot[old] - yg_prev[:k],
            *self._own_products(),
        )
        order = self._slots()
        return self._apply(g, sg_slot[order], yg_slot[order], out, factor)

    def inverse_hessian_times(
        self, g: np.ndarray, out: np.ndarray | None = None, factor: float = 1.0
    ) -> np.ndarray:
        """``factor``·H·g of the L-BFGS two-loop recursion (module docstring), in ``out`` or a
        new array."""
        order = self._slots()
        products = self._pairs(self.size) @ g
        return self._apply(g, products[0::2][order], products[1::2][order], out, factor)

    def _gradient_row(self, g: np.ndarray) -> int | None:
        """0 or 1 if ``g`` is that row of :attr:`gradients` (the same memory), else None.

        The views of :attr:`gradients` themselves (what :func:`lbfgs_relax` passes) are known
        by identity; any other array by its strides and data address (≈ 30 µs per step on a
        large cell inside a relaxation, where the interpreter's own data start cold).
        """
        for row in (0, 1):
            if g is self.gradients[row]:
                return row
        if g.ndim != 1 or g.strides != self.block.strides[1:] or len(g) != self.block.shape[1]:
            return None
        for row in (0, 1):
            if g.ctypes.data == self.block[row].ctypes.data:
                return row
        return None

    def _apply(
        self, g: np.ndarray, sg: np.ndarray, yg: np.ndarray, out: np.ndarray | None, factor: float
    ) -> np.ndarray:
        """``factor``·H·g from the chronological products sg[i] = s_i·g, yg[i] = y_i·g.

        The long vectors are used in place (ring order); only k-vectors and k×k matrices
        are chronological, so a wrapped memory on a large cell copies nothing of size n.
        H g = g/α + Yᵀ(-a/α) + Sᵀc is one matrix-vector product over the slots in use, and
        the gradient too when ``g`` is a row of :attr:`gradients` (else one more pass adds
        g/α). Saves S g, Y g and Y·(H g) for the next :meth:`push_stored`.
        """
        k = self.size
        if out is None:
            out = np.empty_like(g)
        if k == 0:
            self._last = (sg, yg, np.zeros(0))
            return np.multiply(g, factor * self.h0, out=out)
        r_inv = self.r_inv[:k, :k]
        # first loop: R a = S g
        a = r_inv @ sg
        # z0 = (g - Yᵀa)/α is never formed: Y z0 = (Y g - (Y Yᵀ) a)/α
        y_z0 = (yg - self.yy[:k, :k] @ a) * self.h0
        # second loop: Rᵀ c = diag(R) a - Y z0, i.e. c = R⁻ᵀ (a/ρ - Y z0)
        c = (a / self.rho[:k] - y_z0) @ r_inv
        # the second pass over the stored vectors: weights c on s, -a/α on y (times factor)
        order = self._slots()
        used = min(self.count, self.memory)
        weights = self._weights[: 2 + 2 * used]
        weights[:2] = 0.0
        weights[2 + 2 * order] = factor * c
        weights[3 + 2 * order] = -factor * self.h0 * a
        row = self._gradient_row(g)
        if row is not None:  # g/α in the same product
            weights[row] = factor * self.h0
            np.dot(weights, self.block[: 2 + 2 * used], out=out)
        else:
            np.dot(weights[2:], self._pairs(used), out=out)
            out += np.multiply(g, factor * self.h0)
        # Y (H g) = Y z0 + (Y Sᵀ) c, for the next pair's products y_i·s
        self._last = (sg, yg, y_z0 + c @ self.sy[:k, :k])
        return out


def largest_atomic_norm(vectors: np.ndarray, scratch: np.ndarray | None = None) -> float:
    """max_i |v_i| over atoms of an (n, 3) array (ASE's force and step norm).

    The squares in one vectorised pass, x² + y² + z² summed into the first column in two
    more (as ASE's ``(v**2).sum(axis=1)``), the square root of their maximum only (the root
    is monotonic and correctly rounded: the same number). ``einsum("ij,ij->i")`` did it
    without a temporary but loops over rows of three: ≈ 6× slower at 4,704 atoms.
    ``scratch``: an (n, 3) array for the squares (:func:`lbfgs_relax` reuses one: on a large
    cell a fresh array costs more than the arithmetic), else a new one.
    """
    if not len(vectors):
        return 0.0
    sq = np.multiply(vectors, vectors, out=scratch)
    norms = sq[:, 0]
    np.add(norms, sq[:, 1], out=norms)
    np.add(norms, sq[:, 2], out=norms)
    return float(np.sqrt(norms.max()))


def _checked_root(preconditioner: np.ndarray | None, n: int) -> np.ndarray | None:
    """``preconditioner`` as a float (n, n) array, or None."""
    if preconditioner is None:
        return None
    root = np.asarray(preconditioner, dtype=float)
    if root.shape != (n, n):
        raise ValueError(f"preconditioner: expected a ({n}, {n}) matrix, got {root.shape}")
    return root


def _projector_into(
    project: Callable, shape: tuple
) -> Callable[[np.ndarray, np.ndarray], np.ndarray]:
    """``into(v, out)``: P(v) written to ``out`` (any array of v's size, possibly v itself),
    returned as ``shape``; through ``project``'s ``out`` argument if it has one (no copy)."""
    if "out" in inspect.signature(project).parameters:
        return lambda v, out: project(v.reshape(shape), out=out.reshape(shape))

    def into(v: np.ndarray, out: np.ndarray) -> np.ndarray:
        view = out.reshape(shape)
        view[...] = project(v.reshape(shape))
        return view

    return into


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
    scaled: bool = False,
    preconditioner: np.ndarray | None = None,
) -> LbfgsOutcome:
    """Relax ``positions`` with ASE's L-BFGS iteration, one ``evaluate`` per step.

    The long vectors of a step (positions, gradients, the direction, the pair s, y) live in
    buffers allocated once: s and y are written straight into the memory's next slot
    (:meth:`TwoLoopMemory.next_pair`), the direction into a reused array, and the positions
    and gradients alternate between two arrays each.

    Parameters
    ----------
    evaluate
        ``evaluate(positions) -> (energy_ev, forces)``, positions and forces (n, 3) in Å
        and eV/Å; called exactly once per visited structure. The positions array is reused
        two steps later: ``evaluate`` must copy what it keeps. The forces it returns are
        read (never modified) before the next call only, so they may be the engine's own
        array (:meth:`~flatcontact.potentials.lammps_engine.LammpsEngine.compute` with
        ``copy=False``); the outcome keeps a copy of the last.
    positions
        Start (n, 3), Å; not modified.
    project
        The constraint projector P: (n, 3) -> (n, 3), linear, applied to the forces and to
        every step (held atoms get zero, constrained directions are removed); returns a
        new array, or, if it takes an ``out`` argument, writes every component of ``out``
        (the memory's gradient row for the forces, the step itself for the step: ``out``
        may be ``v``) and returns it.
    fmax
        Converged when the largest per-atom norm of P(F) is below ``fmax`` (eV/Å).
    max_steps
        Step cap (the outcome is then ``converged=False``).
    memory
        Stored (s, y) pairs; ``None``: :func:`memory_for` the number of coordinates (ASE's
        100 up to 1,000 atoms).
    alpha, maxstep, damping
        ASE's ``LBFGS`` parameters (defaults: ASE's).
    scaled
        Rescale H0 to γ I at every step (module docstring, "Initial Hessian scaling"); the
        default ``False`` takes ASE's steps.
    preconditioner
        L = H0^{1/2}, symmetric (3n, 3n), commuting with ``project`` (module docstring, "A
        fixed initial inverse Hessian"; :func:`flatcontact.ispes.precondition.inverse_hessian_root`):
        H0 = L L (Å²/eV) replaces I/α (``scaled`` rescales it by γ). None: I/α (ASE).

    Returns
    -------
    LbfgsOutcome
    """
    x = np.array(positions, dtype=float)
    shape = x.shape
    root = _checked_root(preconditioner, x.size)
    # the memory first: its gradient rows take -P(F) straight away (np.zeros: pages untouched
    # until used, nothing spent on a start that is already converged); H0 = I in u
    size = memory_for(x.size) if memory is None else memory
    history = TwoLoopMemory(x.size, size, alpha if root is None else 1.0, scaled)
    g, g_prev = history.gradients  # -H g then takes one product (TwoLoopMemory._apply)
    project_into = _projector_into(project, shape)
    g_x = None if root is None else np.empty(x.size)  # -P(F) before L (its norm: the test)

    def gradient(forces: np.ndarray, out: np.ndarray) -> np.ndarray:
        """-P(F) into the row ``out`` (times L if preconditioned); -P(F) as (n, 3)."""
        target = out if root is None else g_x
        np.negative(project_into(forces, target), out=target.reshape(shape))
        if root is not None:
            np.dot(root, target, out=out)
        return target.reshape(shape)

    energy, forces = evaluate(x)
    calls = 1
    steps = 0
    scratch = np.empty(shape)  # the squares of largest_atomic_norm
    converged = largest_atomic_norm(gradient(forces, g), scratch) < fmax
    if converged or max_steps < 1:
        return LbfgsOutcome(x, float(energy), np.array(forces), steps, calls, bool(converged))
    x_prev = np.empty_like(x)
    direction = np.empty(x.size)
    # the step in x: -H g itself (a view of the direction's buffer), or L·(-H g) in u
    dr = (direction if root is None else np.empty(x.size)).reshape(shape)
    scale = 1.0  # s = scale · P(H g_prev): the factor of the last step
    while not converged and steps < max_steps:
        if steps == 0:
            history.inverse_hessian_times(g, out=direction, factor=-1.0)
        else:
            s, y = history.next_pair()
            if root is None:
                np.subtract(x.ravel(), x_prev.ravel(), out=s)
            else:  # u - u_prev: the last step in u, kept in the direction's buffer
                s[...] = direction
            np.subtract(g, g_prev, out=y)
            history.push_stored(g, scale, out=direction, factor=-1.0)
        if root is not None:
            np.dot(root, direction, out=dr.reshape(-1))
        scale = -damping
        longest = largest_atomic_norm(dr, scratch)
        if longest >= maxstep:
            dr *= maxstep / longest
            scale *= maxstep / longest
        if damping != 1.0:
            dr *= damping
        if root is not None:  # the step in u, P(scale'·(-H g)), for the next pair's s
            direction *= -scale
            project_into(direction, direction)
        x, x_prev = x_prev, x
        np.add(x_prev, project_into(dr, dr), out=x)
        g, g_prev = g_prev, g
        steps += 1
        energy, forces = evaluate(x)
        calls += 1
        converged = largest_atomic_norm(gradient(forces, g), scratch) < fmax
    return LbfgsOutcome(x, float(energy), np.array(forces), steps, calls, bool(converged))
