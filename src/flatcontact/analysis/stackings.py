"""Named stackings of a constant-pressure landscape and its minimum-energy-path barrier.

For any 2-D lattice, from the exact periodic interpolant (:mod:`.periodic`):

1. **Stationary points.** Every zero of the gradient in the cell, by Newton's
   method (analytic gradient and Hessian) from the discrete minima of ``|∇e|²``
   on a grid three times finer than the data; classified by the Hessian's
   eigenvalues as ``minimum`` (both > 0), ``saddle`` (opposite signs) or
   ``maximum`` (both < 0). On the torus #minima − #saddles + #maxima = 0 (Morse);
   ``euler_ok`` says whether the set found satisfies it.
2. **Symmetry.** The landscape's own space-group operations ``T(r) = R r + t``:
   ``R`` runs over the point operations of the lattice
   (:func:`.symmetry.lattice_point_operations`; 11 for hexagonal, 7 square,
   3 rectangular, 1 oblique) and ``t`` over the translations that map the global
   minimum onto a minimum (any symmetry operation must); ``T`` is kept when the
   relative L2 deviation ``‖e∘T − e‖/‖e − ē‖`` (on a grid twice finer than the
   data, exact for the band-limited interpolant) is below ``tolerance`` (2 %, as
   :func:`.symmetry.symmetry_report`). Glides are included. Stationary points
   mapped onto each other (modulo the lattice) by kept operations form one
   **class** (symmetry-equivalent stackings; equal energies up to the deviation).
3. **Names.** Hexagonal lattice with one maximum per cell: the maximum is ``AA``;
   the stationary points at the two three-fold sites ``AA + (a + b)/3`` and
   ``AA + 2(a + b)/3`` (``a``, ``b`` the primitive vectors taken 60° apart, ``a``
   the cell's first vector) are ``AB`` and ``BA``; those at the three two-fold
   sites (half lattice vectors from AA) are ``SP`` (``SP1``..``SP3`` by energy if
   they are not one class). A name is given only to a point of the expected kind
   (AB/BA minima, SP saddles) at the site; positions are matched within
   ``SITE_TOLERANCE`` × the lattice constant. Every other class is named by kind
   and energy rank, ``min1``, ``saddle1``, ``max1``, ... (lowest first). This is
   the bilayer convention of graphene/h-BN derived from the lattice alone, not
   from any material. With ``site_names=False`` every point gets the kind-and-rank
   name: the landscape of a twisted or coincidence cell on its shift lattice
   (``shift_lattice_index`` > 1, :mod:`flatcontact.ispes.shift_lattice`) is hexagonal
   with one maximum too, but its minima are no AB or BA stacking (no atom of one
   slab sits over a hollow of the other across the cell); they are the lowest-energy
   registry of the cell, ``min1``.
4. **Minimum-energy-path barrier.** Index-1 saddles connect minima (steepest
   descent from each saddle along ± its unstable direction, then Newton). On
   this periodic graph (minima, with the lattice offsets of the saddles' ends)
   the lowest barrier to reach an *equivalent* minimum (a lattice translation
   of the start) is the mountain pass ``min over paths of max saddle energy −
   e(start)``; the translations reachable at that barrier form a sub-lattice,
   whose shortest vector is the **lowest-barrier direction** (equal lengths:
   the smallest angle from x in [0°, 360°)). The barrier for any other lattice
   translation (e.g. along a requested pulling direction) is reported the same
   way. The MEP passes through the saddles, so the barrier is exact to the
   interpolant (the string method of :func:`.path.minimum_energy_path` agrees,
   tested).

Energies per area in the surface's units (eV/Å² in the analysis), positions in Å.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from flatcontact.analysis.barrier_graph import angle_deg, barrier_graph, member, shortest_vector
from flatcontact.analysis.operation_deviation import coefficient_image_difference
from flatcontact.analysis.periodic import PeriodicSurface, lattice_vectors, rectangular_supercell
from flatcontact.analysis.symmetry import lattice_point_operations

#: Operations whose relative L2 deviation is below this are kept (as the symmetry report).
SYMMETRY_TOLERANCE = 0.02
#: Stationary points within this fraction of the lattice constant of a named site get its name.
SITE_TOLERANCE = 0.02
KINDS = ("minimum", "saddle", "maximum")
_PREFIX = {"minimum": "min", "saddle": "saddle", "maximum": "max"}


@dataclass(frozen=True)
class StationaryPoint:
    """A zero of the gradient, reduced into the cell."""

    name: str
    kind: str  #: "minimum", "saddle" or "maximum"
    xy_angstrom: np.ndarray
    fractional: np.ndarray  #: in [0, 1)²
    energy: float  #: surface units (eV/Å² in the analysis)
    hessian_eigenvalues: np.ndarray
    symmetry_class: int  #: index of its class of symmetry-equivalent points


@dataclass(frozen=True)
class SpaceOperation:
    """A kept symmetry operation ``T(r) = R r + t`` of the landscape."""

    matrix: np.ndarray  #: Cartesian 2×2 (R)
    translation_angstrom: np.ndarray  #: t
    deviation: float  #: relative L2 deviation ‖e∘T − e‖/‖e − ē‖

    def __call__(self, xy: np.ndarray) -> np.ndarray:
        return np.asarray(xy, float) @ self.matrix.T + self.translation_angstrom


@dataclass(frozen=True)
class Stackings:
    """Stationary points, their classes and names, kept operations and the MEP barrier."""

    lattice: str  #: "hexagonal", "square", "rectangular", "centred rectangular" or "oblique"
    points: tuple[StationaryPoint, ...]
    operations: tuple[SpaceOperation, ...]  #: kept, identity excluded
    euler_ok: bool
    start_index: int  #: the point the barriers are measured from (the global minimum)
    barrier: float  #: lowest barrier to an equivalent minimum (surface units); NaN if none
    barrier_vector_angstrom: np.ndarray | None  #: shortest translation at that barrier
    barrier_saddle_index: int | None  #: the saddle that sets it
    _inverse: np.ndarray = field(default_factory=lambda: np.eye(2), repr=False, compare=False)
    _basis_history: tuple = field(default=(), repr=False, compare=False)

    @property
    def barrier_direction_deg(self) -> float:
        """Angle from x of :attr:`barrier_vector_angstrom` (degrees in [0, 360)); NaN if none."""
        v = self.barrier_vector_angstrom
        return float("nan") if v is None else angle_deg(v)

    def energies(self) -> dict[str, float]:
        """Energy per named class (first member's name for hexagonal sites, class name else)."""
        out: dict[str, float] = {}
        for p in self.points:
            out.setdefault(p.name, p.energy)
        return out

    def kinds(self) -> dict[str, str]:
        """Kind per name."""
        out: dict[str, str] = {}
        for p in self.points:
            out.setdefault(p.name, p.kind)
        return out

    def minima(self) -> list[StationaryPoint]:
        """The minima, lowest first."""
        return sorted((p for p in self.points if p.kind == "minimum"), key=lambda p: p.energy)

    def equivalent_minima(self, index: int) -> list[int]:
        """Indices of the minima in the symmetry class of point ``index``."""
        c = self.points[index].symmetry_class
        return [i for i, p in enumerate(self.points) if p.symmetry_class == c]

    def name_at(self, xy_angstrom=(0.0, 0.0)) -> str:
        """Name of the stationary point at ``xy_angstrom`` modulo the lattice (within
        ``SITE_TOLERANCE`` × the shortest lattice vector), ``''`` if none is there.

        At the origin (the zero shift) this names the reference stacking by geometry: for a
        3-D crystal continued across the cut it is the perfect crystal, whatever its energy.
        """
        lattice = np.linalg.inv(self._inverse)
        tol = SITE_TOLERANCE * float(np.min(np.linalg.norm(lattice, axis=0)))
        for p in self.points:
            ds = self._inverse @ (np.asarray(p.xy_angstrom, float) - np.asarray(xy_angstrom, float))
            ds -= np.round(ds)
            if np.linalg.norm(lattice @ ds) < tol:
                return p.name
        return ""

    def barrier_for(self, vector_angstrom: np.ndarray) -> float:
        """Lowest barrier (surface units) to the start's image translated by a lattice vector."""
        if not self._basis_history:
            return float("nan")
        m = np.rint(self._inverse @ np.asarray(vector_angstrom, float)).astype(int)
        e0 = self.points[self.start_index].energy
        for energy, basis in self._basis_history:
            if member(basis, m):
                return float(energy - e0)
        return float("nan")

    def to_json(self, scale: float = 1.0) -> dict:
        """JSON-ready: per name kind, energy (× ``scale``), position and multiplicity."""
        out: dict[str, dict] = {}
        for p in self.points:
            entry = out.setdefault(
                p.name,
                {
                    "kind": p.kind,
                    "energy": p.energy * scale,
                    "x_angstrom": float(p.xy_angstrom[0]),
                    "y_angstrom": float(p.xy_angstrom[1]),
                    "multiplicity": 0,
                },
            )
            entry["multiplicity"] += 1
        return out


def lattice_kind(a1: np.ndarray, a2: np.ndarray) -> str:
    """The 2-D Bravais lattice of ``a1``, ``a2`` from the number of its point operations."""
    n = len(lattice_point_operations(a1, a2)) + 1
    if n == 12:
        return "hexagonal"
    if n == 8:
        return "square"
    if n == 4:
        sc = rectangular_supercell(a1, a2)
        area = abs(float(np.linalg.det(np.column_stack([a1[:2], a2[:2]]))))
        if (
            sc is not None
            and abs(abs(float(np.linalg.det(np.column_stack(sc)))) - area) < 1e-6 * area
        ):
            return "rectangular"
        return "centred rectangular"
    return "oblique"


# ---------------------------------------------------------------------------- stationary points


def _scale(surface: PeriodicSurface) -> float:
    return float(np.min(np.linalg.norm(surface.lattice, axis=0)))


def _reduce(surface: PeriodicSurface, xy: np.ndarray) -> np.ndarray:
    s = surface.fractional(xy)
    s = s - np.floor(s)
    s[np.abs(s - 1.0) < 1e-12] = 0.0
    return s


def _same_site(surface: PeriodicSurface, s1: np.ndarray, s2: np.ndarray, tol: float) -> bool:
    ds = np.asarray(s1) - np.asarray(s2)
    ds -= np.round(ds)
    return bool(np.linalg.norm(surface.cartesian(ds)) < tol)


def stationary_points(surface: PeriodicSurface, refine: int = 2) -> list[tuple]:
    """All inequivalent stationary points ``(s, xy, value, eigenvalues, kind)`` in the cell.

    Newton's method on ``∇e = 0`` (steps capped at 0.05 × the shortest lattice
    vector), vectorised, from the points of a grid ``refine`` times finer than the
    data where ``|∇e|²`` is a local minimum among its 8 neighbours; if the points
    found break the Morse relation (#min − #saddle + #max = 0 on the torus), from
    *every* point of that grid (each non-degenerate stationary point has a Newton
    basin wider than the grid spacing of a band-limited surface). Converged points
    (``|∇e|·a ≤ 1e-9 × range``) are reduced into the cell and deduplicated
    (1e-6 × a); points with a Hessian eigenvalue below ``1e-8`` of the largest
    magnitude (degenerate) are dropped.
    """
    n_a, n_b = surface.values.shape
    f_a, f_b = max(1, refine) * max(n_a, 4), max(1, refine) * max(n_b, 4)
    sa, sb = np.meshgrid(np.arange(f_a) / f_a, np.arange(f_b) / f_b, indexing="ij")
    x = surface.cartesian(np.stack([sa, sb], -1))
    sv = surface.evaluate(x)
    hmax = float(np.max(np.abs(np.linalg.eigvalsh(sv.hessian)))) or 1.0
    g2 = np.sum(sv.gradient**2, -1)
    is_min = np.ones(g2.shape, bool)
    for da in (-1, 0, 1):
        for db in (-1, 0, 1):
            if da or db:
                is_min &= g2 <= np.roll(np.roll(g2, da, 0), db, 1)
    found = _newton_points(surface, x[is_min], hmax)
    if not _euler_ok(found):
        found = _newton_points(surface, x.reshape(-1, 2), hmax)
    return found


def _euler_ok(found: list[tuple]) -> bool:
    counts = {k: sum(f[4] == k for f in found) for k in KINDS}
    return counts["minimum"] - counts["saddle"] + counts["maximum"] == 0


def _newton_points(surface: PeriodicSurface, x: np.ndarray, hmax: float) -> list[tuple]:
    """Newton from every row of ``x``; the distinct non-degenerate stationary points reached."""
    x = np.array(x, float)
    scale = _scale(surface)
    spread = max(float(np.ptp(surface.values)), 1e-300)
    cap = 0.05 * scale
    active = np.ones(len(x), bool)
    for _ in range(80):
        idx = np.flatnonzero(active)
        if idx.size == 0:
            break
        sv = surface.evaluate(x[idx])
        good = np.abs(np.linalg.det(sv.hessian)) > 1e-300
        step = np.zeros((idx.size, 2))
        step[good] = np.linalg.solve(sv.hessian[good], sv.gradient[good][..., None])[..., 0]
        norm = np.linalg.norm(step, axis=-1, keepdims=True)
        step = np.where(norm > cap, step * cap / np.maximum(norm, 1e-300), step)
        x[idx] -= step
        active[idx[(np.linalg.norm(step, axis=-1) < 1e-13 * scale) | ~good]] = False
    sv = surface.evaluate(x)
    converged = np.linalg.norm(sv.gradient, axis=-1) * scale <= 1e-9 * spread
    # deduplicate modulo the lattice: round the reduced fractional coordinates
    frac = surface.fractional(x[converged])
    frac = np.round(frac - np.floor(frac), 6) % 1.0
    _, first = np.unique(frac, axis=0, return_index=True)
    found: list[tuple] = []
    for xi in x[converged][np.sort(first)]:
        s = _reduce(surface, xi)
        if any(_same_site(surface, s, f[0], 1e-6 * scale) for f in found):
            continue
        v = surface.evaluate(surface.cartesian(s))
        lam = np.linalg.eigvalsh(v.hessian)
        if np.min(np.abs(lam)) < 1e-8 * hmax:
            continue
        kind = "minimum" if lam[0] > 0 else ("maximum" if lam[1] < 0 else "saddle")
        found.append((s, surface.cartesian(s), float(v.value), lam, kind))
    found.sort(key=lambda f: (KINDS.index(f[4]), f[2], round(f[0][0], 9), round(f[0][1], 9)))
    return found


# ---------------------------------------------------------------------------- symmetry


def kept_operations(
    surface: PeriodicSurface, minima_xy: list[np.ndarray], tolerance: float = SYMMETRY_TOLERANCE
) -> list[SpaceOperation]:
    """The landscape's kept space-group operations (module docstring, step 2), identity excluded.

    ``minima_xy[0]`` must be the global minimum; every operation maps it onto one of
    ``minima_xy`` (modulo the lattice), which gives the candidate translations. The
    deviation is exact from the Fourier coefficients (Parseval): ``e∘T`` has the
    coefficient ``c_g e^{2πi g·s_t}`` at the index ``Mᵀ g`` (``R L = L M``, ``s_t`` the
    fractional ``t``). Only frequencies whose image is in the interpolant's index set are
    compared (:func:`flatcontact.analysis.operation_deviation.coefficient_image_difference`,
    as the broken-symmetry gate): on an N×N grid of a hexagonal cell C3 sends the edge and
    Nyquist frequencies outside the set, and counting them as a mismatch read a three-fold
    symmetric sampled landscape as broken (Cu(111) 6×6: 2 % from C3). The deviation is
    relative to the norm of all non-constant coefficients.
    """
    c = surface.coefficients
    kk, ll = np.meshgrid(surface.k, surface.l, indexing="ij")
    mean = (kk == 0) & (ll == 0)
    norm2 = float(np.sum(np.abs(c[~mean]) ** 2))
    if norm2 <= 0:
        return []
    x0 = np.asarray(minima_xy[0], float)
    ops = []
    for r, m in lattice_point_operations(surface.a1, surface.a2):
        best = None
        for y in minima_xy:
            t = np.asarray(y, float) - r @ x0
            diff = coefficient_image_difference(surface, m, surface.fractional(t))
            dev = float(np.sqrt(float(np.sum(np.abs(diff[~mean]) ** 2)) / norm2))
            if best is None or dev < best[1]:
                best = (t, dev)
        if best is not None and best[1] < tolerance:
            ops.append(SpaceOperation(r, best[0], best[1]))
    return ops


def _classes(surface: PeriodicSurface, found: list[tuple], ops: list[SpaceOperation]) -> list[int]:
    """Union of stationary points (same kind) mapped onto each other by the kept operations."""
    parent = list(range(len(found)))

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    tol = SITE_TOLERANCE * _scale(surface)
    for op in ops:
        for i, (_, xy, _, _, kind) in enumerate(found):
            s = _reduce(surface, op(xy))
            for j, (sj, _, _, _, kj) in enumerate(found):
                if kj == kind and _same_site(surface, s, sj, tol):
                    ri, rj = root(i), root(j)
                    if ri != rj:
                        parent[max(ri, rj)] = min(ri, rj)
                    break
    roots = [root(i) for i in range(len(found))]
    order = {r: k for k, r in enumerate(dict.fromkeys(roots))}
    return [order[r] for r in roots]


# ---------------------------------------------------------------------------- names


def _names(
    surface: PeriodicSurface,
    found: list[tuple],
    classes: list[int],
    lattice: str,
    site_names: bool = True,
):
    names: list[str | None] = [None] * len(found)
    maxima = [i for i, f in enumerate(found) if f[4] == "maximum"]
    if site_names and lattice == "hexagonal" and len(maxima) == 1:
        a = surface.a1
        b = surface.a2 if float(np.dot(surface.a1, surface.a2)) > 0 else surface.a1 + surface.a2
        aa = found[maxima[0]][1]
        tol = SITE_TOLERANCE * _scale(surface)
        names[maxima[0]] = "AA"
        sites = {"AB": aa + (a + b) / 3, "BA": aa + 2 * (a + b) / 3}
        for name, site in sites.items():
            s_site = _reduce(surface, site)
            for i, f in enumerate(found):
                if (
                    names[i] is None
                    and f[4] == "minimum"
                    and _same_site(surface, f[0], s_site, tol)
                ):
                    names[i] = name
        sp = []
        for half in (a / 2, b / 2, (b - a) / 2):
            s_site = _reduce(surface, aa + half)
            for i, f in enumerate(found):
                if names[i] is None and f[4] == "saddle" and _same_site(surface, f[0], s_site, tol):
                    sp.append(i)
        if sp:
            if len({classes[i] for i in sp}) == 1:
                for i in sp:
                    names[i] = "SP"
            else:
                for k, i in enumerate(sorted(sp, key=lambda i: found[i][2]), start=1):
                    names[i] = f"SP{k}"
    # generic: by kind and energy rank of the class
    rank: dict[int, str] = {}
    counters = dict.fromkeys(KINDS, 0)
    for i in sorted(range(len(found)), key=lambda i: (KINDS.index(found[i][4]), found[i][2])):
        if names[i] is not None:
            continue
        c = classes[i]
        if c not in rank:
            counters[found[i][4]] += 1
            rank[c] = f"{_PREFIX[found[i][4]]}{counters[found[i][4]]}"
        names[i] = rank[c]
    return names


# ---------------------------------------------------------------------------- entry point


def analyze_stackings(
    surface: PeriodicSurface, tolerance: float = SYMMETRY_TOLERANCE, site_names: bool = True
) -> Stackings:
    """Stationary points, symmetry classes, names and MEP barrier of ``surface`` (module doc).

    ``site_names``: name the hexagonal sites AA, AB, BA, SP (module doc, step 3); ``False``
    (a twisted or coincidence cell's shift-lattice landscape): kind and rank only."""
    found = stationary_points(surface)
    minima = [i for i, f in enumerate(found) if f[4] == "minimum"]
    if not minima:  # cannot happen for a periodic function; keep the interface total
        xy, val = surface.global_minimum()
        s = _reduce(surface, xy)
        lam = np.linalg.eigvalsh(surface.evaluate(xy).hessian)
        found.insert(0, (s, surface.cartesian(s), float(val), lam, "minimum"))
        minima = [0]
    ops = kept_operations(surface, [found[i][1] for i in minima], tolerance)
    classes = _classes(surface, found, ops)
    lattice = lattice_kind(surface.a1, surface.a2)
    names = _names(surface, found, classes, lattice, site_names)
    start = minima[0]
    euler_ok = _euler_ok(found)
    first, history = barrier_graph(surface, found, start, classes)
    points = tuple(
        StationaryPoint(names[i], f[4], f[1], f[0], f[2], f[3], classes[i])
        for i, f in enumerate(found)
    )
    if first is None:
        barrier, vec, saddle = float("nan"), None, None
    else:
        barrier = float(first[0] - found[start][2])
        vec = shortest_vector(first[1], surface.lattice)
        saddle = first[2]
    return Stackings(
        lattice=lattice,
        points=points,
        operations=tuple(ops),
        euler_ok=euler_ok,
        start_index=start,
        barrier=barrier,
        barrier_vector_angstrom=vec,
        barrier_saddle_index=saddle,
        _inverse=surface.inverse,
        _basis_history=history,
    )


def lattice_vector_along(
    a1: np.ndarray, a2: np.ndarray, direction_deg: float, max_index: int = 8
) -> np.ndarray | None:
    """Shortest lattice vector parallel to (and along) ``direction_deg``, or None (index <= 8)."""
    th = np.deg2rad(direction_deg)
    d = np.array([np.cos(th), np.sin(th)])
    vecs = lattice_vectors(a1, a2, max_index)
    norms = np.linalg.norm(vecs, axis=1)
    ok = (norms > 0) & (np.abs(vecs @ d - norms) <= 1e-9 * np.maximum(norms, 1.0))
    if not np.any(ok):
        return None
    return vecs[ok][np.argmin(norms[ok])]
