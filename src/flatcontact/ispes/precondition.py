"""A fixed initial inverse Hessian for every point of a scan: the reference interface's own.

The scan's L-BFGS starts each point with H0 = I/α (ASE) or γ I (Nocedal & Wright eq. 7.20)
and spends most of its force calls learning the curvature of the stiff Si-O (or C-C, Cu-Cu)
bonds beside the soft interface, anew at every point. Every point of a scan is the same
interface, slab 2 shifted laterally and in z, so the curvature of the reference interface
is a good model of every point's: preconditioned L-BFGS (Nocedal & Wright, *Numerical
Optimization*, §7.2, any fixed symmetric positive definite H0 in Algorithm 7.4) with
H0 = (the reference's Hessian)⁻¹ takes a near-Newton step from the first one on, and the
stored pairs correct it where the point's curvature differs.

The Hessian
-----------
K_ij = -∂F_i/∂x_j of the relaxed coordinates (those the relaxation mode's projector keeps:
every component of the free atoms in ``full``, their z in ``normal``) by central differences
of the forces, step ``FD_STEP_ANGSTROM``, symmetrised: 2 force calls per relaxed coordinate,
once per scan, in its driver (:func:`finite_difference_hessian`, 144 calls on the 36-atom
quartz cell with 24 free atoms). Its eigenvalues are floored at ``FLOOR_FRACTION`` of the
largest (:func:`inverse_hessian_root`): the softest interface modes (0.13 eV/Å² against 94
on sio2-snap quartz) would otherwise ask for steps the next point's curvature does not
support, and a floor also makes a reference that is not an exact minimum positive definite. The removed coordinates get I/α (they are
projected out of every step anyway).

What the relaxation needs is L = H0^{1/2} (symmetric): :func:`flatcontact.ispes.lbfgs.lbfgs_relax`
runs the iteration in u = L⁻¹ x, where H0 is the identity (``preconditioner``).

Measured (``python -m benchmarks precondition``; ``docs/performance.md``, "The reference interface's
Hessian as H0"): 6 × 6 × 8 quartz grid, fmax 0.005 eV/Å, sio2-snap 15.4 force calls per
point with γ-scaling (``LBFGS-scaled``) → 3.15; Vashishta 12.6 → 2.6; every point converged.

Where it is not used as it is
-----------------------------
In mode ``full`` a soft in-slab mode (a plane of a slab sliding on the next: Cu(111) with one
atom per plane) gets the floored curvature, so the preconditioned steps along it are long and
can carry a plane over a barrier the plain iteration never approaches, to a point that passes
``fmax`` on another branch (the notebook's Cu EMT example, unguarded: a column whose energy
jumped by 0.010 eV between two thicknesses). A point whose relaxed planes slid against each
other (:func:`slips_inside_slab`) is therefore relaxed again from the same start with the
optimizer's own H0 (:func:`flatcontact.ispes.relax._relax_built_in`); both relaxations'
force calls count. Where the plain iteration slides the plane too, the scan's
``in_slab_slip`` gate reports it as before.

Determinism
-----------
The Hessian is a function of the reference, the calculator and the mode: its force calls
run on a calculator started afresh (:func:`flatcontact.ispes.relax.point_evaluator`), in a
fixed order, so any process computes the same K. Its root L is not quite: ``numpy.linalg.eigh``
and the product after it may round differently with another number of BLAS threads (the
scan's driver runs with the default, its local workers with one:
:func:`flatcontact.ispes.executors.one_blas_thread_in_workers`). A scan therefore computes L
once, in its driver (:mod:`flatcontact.ispes.shared_hessian`), and every process that relaxes
its points uses those bits (:class:`SharedRoot`, :func:`shared_root`, :func:`keep_root`): the
same numbers with the serial executor, local processes or Dask, and no Hessian per worker.
Outside a scan (a single :func:`flatcontact.ispes.relax.relax_point`) L is computed once per
process and calculator (:func:`cached_root`). It is never stored with the points nor sent
with each task (an n × n matrix per task).
"""

from __future__ import annotations

import dataclasses
import hashlib
import weakref
from collections.abc import Callable

import numpy as np

#: central-difference step of the Hessian (Å): the truncation error O(h²·F''') and the
#: round-off O(ε·|F|/h) both far below a force tolerance of 1e-3 eV/Å on quartz
FD_STEP_ANGSTROM = 2e-3
#: eigenvalues of the reference Hessian below this fraction of the largest are raised to it
#: (``python -m benchmarks precondition`` measures 0.001 … 0.05 on quartz)
FLOOR_FRACTION = 0.01
#: no preconditioner on cells with more relaxed coordinates than this: the Hessian costs two
#: force calls per coordinate once, and each step two dense n × n products
#: (≈ 2 n² flops: 2 µs at n = 108, ≈ 1 ms at n = 1,000, beside a force call of ≈ 3 ms)
MAX_COORDINATES = 1000


def finite_difference_hessian(
    evaluate: Callable[[np.ndarray], tuple[float, np.ndarray]],
    positions: np.ndarray,
    coordinates: np.ndarray,
    step_angstrom: float = FD_STEP_ANGSTROM,
    between_columns: Callable[[], None] | None = None,
) -> np.ndarray:
    """K = -∂F/∂x over the flat indices ``coordinates`` (k,) of ``positions`` (n, 3), (k, k).

    Central differences, column j from the forces at x ± h e_j (2k calls of
    ``evaluate(positions) -> (energy_ev, forces)``, in the order of ``coordinates``),
    symmetrised (K + Kᵀ)/2. Exact to round-off for a quadratic energy.
    ``between_columns()``, if given, is called after each column (a scan's driver feeds its
    workers there: :meth:`flatcontact.ispes.executors.ProcessExecutor.serve`); it cannot
    change K.
    """
    coordinates = np.asarray(coordinates, dtype=np.intp)
    if step_angstrom <= 0:
        raise ValueError(f"step_angstrom: expected a positive step, got {step_angstrom}")
    x0 = np.array(positions, dtype=float)
    k = coordinates.size
    hessian = np.empty((k, k))
    work = x0.copy()
    flat = work.reshape(-1)
    for col, i in enumerate(coordinates):
        flat[i] = x0.flat[i] + step_angstrom
        plus = np.array(evaluate(work)[1], dtype=float).reshape(-1)[coordinates]
        flat[i] = x0.flat[i] - step_angstrom
        minus = np.array(evaluate(work)[1], dtype=float).reshape(-1)[coordinates]
        flat[i] = x0.flat[i]
        hessian[:, col] = (minus - plus) / (2.0 * step_angstrom)
        if between_columns is not None:
            between_columns()
    return 0.5 * (hessian + hessian.T)


def inverse_hessian_root(
    hessian: np.ndarray,
    coordinates: np.ndarray,
    n: int,
    alpha: float,
    floor_fraction: float | None = None,
) -> np.ndarray:
    """L = H0^{1/2} (n × n, symmetric) for H0 = K_floored⁻¹ on ``coordinates``, I/α elsewhere.

    K (``hessian``, k × k over the flat indices ``coordinates``) = V diag(λ) Vᵀ; each λ is
    raised to at least ``floor_fraction`` (default ``FLOOR_FRACTION``) · max λ (eV/Å²; a K
    with no positive eigenvalue is refused), and L = V diag(λ^{-1/2}) Vᵀ on those coordinates. L is block diagonal
    between them and the rest, so it commutes with a projector that keeps exactly them.
    """
    hessian = np.asarray(hessian, dtype=float)
    coordinates = np.asarray(coordinates, dtype=np.intp)
    if hessian.shape != (coordinates.size, coordinates.size):
        raise ValueError(
            f"hessian: expected ({coordinates.size}, {coordinates.size}) for the coordinates, "
            f"got {hessian.shape}"
        )
    root = np.zeros((n, n))
    root[np.diag_indices(n)] = 1.0 / np.sqrt(alpha)
    if coordinates.size == 0:
        return root
    lam, vec = np.linalg.eigh(hessian)
    if not np.isfinite(lam).all() or lam.max() <= 0.0:
        raise ValueError(
            f"hessian: expected a positive curvature, got eigenvalues {lam.min():.3g}…{lam.max():.3g}"
        )
    fraction = FLOOR_FRACTION if floor_fraction is None else floor_fraction
    lam = np.maximum(lam, fraction * lam.max())
    root[np.ix_(coordinates, coordinates)] = (vec / np.sqrt(lam)) @ vec.T
    return root


_CACHE: dict = {}
#: keys kept per calculator (a scan asks for one: its reference and mode)
KEYS_PER_CALCULATOR = 2


def cached_root(calc, key, compute: Callable[[], np.ndarray | None]) -> np.ndarray | None:
    """``compute()`` once per calculator ``calc`` and ``key`` in this process.

    Each entry holds a weak reference to its calculator and goes with it (a new calculator
    that reuses a freed one's ``id`` computes its own); a calculator keeps its last
    ``KEYS_PER_CALCULATOR`` keys, so the calculators of several threads in one process
    (Dask) do not evict each other's.
    """
    for stale in [k for k, (ref, _) in _CACHE.items() if ref() is None]:
        del _CACHE[stale]
    full_key = (id(calc), key)
    entry = _CACHE.get(full_key)
    if entry is None or entry[0]() is not calc:
        mine = [k for k in _CACHE if k[0] == id(calc)]
        while len(mine) >= KEYS_PER_CALCULATOR:
            del _CACHE[mine.pop(0)]
        entry = _CACHE[full_key] = (weakref.ref(calc), compute())
    return entry[1]


def root_key(reference, fixed: np.ndarray, mode: str) -> tuple:
    """The key of the reference's root in :func:`cached_root` (with the calculator): what it is a
    function of besides the calculator, the relaxation ``mode`` and the reference interface with
    its held atoms ``fixed``."""
    return (
        mode,
        reference.positions.tobytes(),
        reference.numbers.tobytes(),
        reference.cell.array.tobytes(),
        np.asarray(fixed).tobytes(),
    )


def keep_root(calc, key, root: np.ndarray) -> None:
    """Make ``root`` the one :func:`cached_root` gives for ``calc`` and ``key`` (a root received
    from the scan's driver, :func:`shared_root`), replacing any other kept there."""
    entry = _CACHE.get((id(calc), key))
    if entry is None or entry[0]() is not calc or entry[1] is not root:
        _CACHE.pop((id(calc), key), None)
        cached_root(calc, key, lambda: root)


@dataclasses.dataclass(frozen=True)
class SharedRoot:
    """Where the processes of a scan find the root its driver computed (picklable, small).

    ``key``: SHA-256 of what the root is a function of (the model's fingerprint, the mode,
    the reference and its held atoms; names the file); ``sha256``: of the root's bytes
    (float64, C order), which every process checks before it uses them; ``size``: n (the root
    is n × n); ``path``: the hidden file in the scan's folder that local worker processes
    read, or None where the root reaches the processes otherwise (the driver's own: in
    memory; Dask workers: a worker plugin, :func:`receive_root`).
    """

    key: str
    sha256: str
    size: int
    path: str | None = None


def root_sha256(root: np.ndarray) -> str:
    """SHA-256 (hex) of ``root``'s float64 bytes in C order."""
    return hashlib.sha256(np.ascontiguousarray(root, dtype=float).tobytes()).hexdigest()


#: the roots this process received from scans' drivers, by their SHA-256 (the last
#: ``KEPT_RECEIVED``: a Dask worker may serve two scans at once)
_RECEIVED: dict[str, np.ndarray] = {}
KEPT_RECEIVED = 2


def receive_root(root: np.ndarray, sha256: str) -> np.ndarray:
    """Keep ``root`` as this process's root of digest ``sha256`` (checked; read-only from now
    on; the oldest of more than ``KEPT_RECEIVED`` goes) and return it."""
    root = np.ascontiguousarray(root, dtype=float)
    if root.ndim != 2 or root.shape[0] != root.shape[1] or root_sha256(root) != sha256:
        raise RuntimeError(
            f"the scan's reference Hessian: the root received ({root.shape}) is not the "
            f"driver's (SHA-256 {sha256[:12]}…)"
        )
    root.flags.writeable = False
    _RECEIVED.pop(sha256, None)
    _RECEIVED[sha256] = root
    while len(_RECEIVED) > KEPT_RECEIVED:
        del _RECEIVED[next(iter(_RECEIVED))]
    return root


def shared_root(shared: SharedRoot) -> np.ndarray:
    """The driver's root that ``shared`` names, in this process: received before
    (:func:`receive_root`), else read from ``shared.path`` and checked against its size and
    digest. A root that cannot be had so is an error, never computed here instead: the
    scan's points would then depend on the process that relaxed them."""
    root = _RECEIVED.get(shared.sha256)
    if root is not None:
        return root
    if shared.path is None:
        raise RuntimeError(
            "the scan's reference Hessian: this process received none from the driver "
            f"(SHA-256 {shared.sha256[:12]}…)"
        )
    try:
        root = np.load(shared.path, allow_pickle=False)
    except (OSError, ValueError) as exc:
        raise RuntimeError(
            f"the scan's reference Hessian: cannot read the driver's {shared.path} ({exc})"
        ) from None
    if root.shape != (shared.size, shared.size):
        raise RuntimeError(
            f"the scan's reference Hessian: {shared.path} holds a {root.shape} matrix, "
            f"expected ({shared.size}, {shared.size})"
        )
    return receive_root(root, shared.sha256)


def slips_inside_slab(reference, positions: np.ndarray, shift: tuple[float, float]) -> bool:
    """Whether a plane inside a slab of the relaxed ``positions`` at lateral ``shift`` slid
    against its neighbour by more than :data:`flatcontact.ispes.slip.SLIP_THRESHOLD_ANGSTROM`
    (:mod:`flatcontact.ispes.slip`'s definition; layers from ``arrays["layer"]``, found from
    the structure if the interface has none)."""
    from flatcontact.ispes import slip

    reference = _with_layers(reference)
    gaps = slip.in_slab_gaps(reference)
    moved = slip.layer_displacements(reference, positions, shift)
    return any(
        np.linalg.norm(moved[g.upper] - moved[g.lower]) > slip.SLIP_THRESHOLD_ANGSTROM for g in gaps
    )


#: the last references given layers by :func:`_with_layers` (a scan asks for one)
_LAYERED: dict[tuple, object] = {}


def _with_layers(reference):
    """``reference`` if it has ``arrays["layer"]``; else a copy with the layers found from the
    structure, found once per reference (the guard asks for them at every point)."""
    if "layer" in reference.arrays:
        return reference
    from flatcontact.structures.interface_contract import atoms_content

    key = atoms_content(reference, ("slab",))
    if key not in _LAYERED:
        from flatcontact.structures.layers import interface_layers

        layered = reference.copy()
        layered.arrays["layer"] = interface_layers(reference)
        if key is None:  # an object array: no key to keep it by
            return layered
        _LAYERED.clear()
        _LAYERED[key] = layered
    return _LAYERED[key]
