"""Mountain-pass (minimum-energy-path) barriers on the periodic graph of minima and saddles.

On a 2-D landscape every minimum-energy path between minima passes through index-1
saddles. Steepest descent from each saddle along ± its unstable eigenvector ends in
two minima (with the lattice offsets of the two ends): the saddle is an edge between
them. Adding the edges in order of energy to a union-find that carries, per node, its
integer lattice offset from the component's root, a closed loop with a non-zero net
offset is a lattice translation reachable from the start; the translations reachable
below a level form a sub-lattice of Z² (kept in Hermite normal form). The first level
at which the start's component has a non-zero sub-lattice is the lowest barrier to an
equivalent minimum, and its shortest vector the lowest-barrier direction
(:mod:`.stackings`). Used by :func:`.stackings.analyze_stackings`.

``found`` entries are ``(s, xy, value, eigenvalues, kind)`` as from
:func:`.stackings.stationary_points`.
"""

from __future__ import annotations

import math

import numpy as np

from flatcontact.analysis.periodic import PeriodicSurface


def _scale(surface: PeriodicSurface) -> float:
    return float(np.min(np.linalg.norm(surface.lattice, axis=0)))


def angle_deg(v: np.ndarray) -> float:
    """Angle of ``v`` from x in degrees, in [0, 360), rounded to 1e-9."""
    a = math.degrees(math.atan2(float(v[1]), float(v[0]))) % 360.0
    return 0.0 if abs(a - 360.0) < 1e-9 else round(a, 9)


def descend(surface: PeriodicSurface, x: np.ndarray, iterations: int = 4000) -> np.ndarray:
    """Steepest descent (vectorised over rows of ``x``), Newton once the Hessian is positive."""
    x = np.array(x, float)
    scale = _scale(surface)
    c = np.abs(surface.coefficients)
    kk, ll = np.meshgrid(surface.k, surface.l, indexing="ij")
    g = 2 * np.pi * np.stack([kk, ll], -1) @ surface.inverse  # Cartesian reciprocal vectors
    lip = float(np.sum(c * np.sum(g**2, -1))) or 1.0  # bound on the Hessian's norm
    spread = max(float(np.ptp(surface.values)), 1e-300)
    for _ in range(iterations):
        sv = surface.evaluate(x)
        grad, hess = sv.gradient, sv.hessian
        done = np.linalg.norm(grad, axis=-1) * scale <= 1e-11 * spread
        if np.all(done):
            break
        lam = np.linalg.eigvalsh(hess)
        step = grad / lip
        pd = lam[:, 0] > 0
        if np.any(pd):
            newton = np.linalg.solve(hess[pd], grad[pd][..., None])[..., 0]
            n = np.linalg.norm(newton, axis=-1, keepdims=True)
            newton = np.where(
                n > 0.02 * scale, newton * 0.02 * scale / np.maximum(n, 1e-300), newton
            )
            step[pd] = newton
        step[done] = 0.0
        x = x - step
    return x


def _egcd(a: int, b: int) -> tuple[int, int, int]:
    if b == 0:
        return (abs(a), 1 if a >= 0 else -1, 0)
    g, x, y = _egcd(b, a % b)
    return g, y, x - (a // b) * y


def _hnf(gens: list[tuple[int, int]]) -> tuple:
    """Basis ``(pivot or None, g2)`` of the integer sub-lattice spanned by ``gens``."""
    pivot = None
    g2 = 0
    for v in gens:
        v = (int(v[0]), int(v[1]))
        if v[0] == 0:
            g2 = math.gcd(g2, abs(v[1]))
            continue
        if pivot is None:
            pivot = v
            continue
        g, x, y = _egcd(pivot[0], v[0])
        new = (x * pivot[0] + y * v[0], x * pivot[1] + y * v[1])
        other = (v[0] // g) * pivot[1] - (pivot[0] // g) * v[1]
        pivot = new
        g2 = math.gcd(g2, abs(other))
    if pivot is not None and pivot[0] < 0:
        pivot = (-pivot[0], -pivot[1])
    if pivot is not None and g2:
        pivot = (pivot[0], pivot[1] % g2)
    return (pivot, g2)


def member(basis: tuple, m: np.ndarray) -> bool:
    pivot, g2 = basis
    m0, m1 = int(m[0]), int(m[1])
    if m0 == 0 and m1 == 0:
        return True
    if pivot is None:
        return m0 == 0 and g2 != 0 and m1 % g2 == 0
    if m0 % pivot[0]:
        return False
    r = m1 - (m0 // pivot[0]) * pivot[1]
    return r == 0 if g2 == 0 else r % g2 == 0


def shortest_vector(basis: tuple, lattice: np.ndarray) -> np.ndarray | None:
    pivot, g2 = basis
    vecs = []
    if pivot is not None:
        vecs.append(np.array(pivot, float))
    if g2:
        vecs.append(np.array([0.0, g2]))
    if not vecs:
        return None
    best = None
    rng = range(-6, 7)
    for c1 in rng:
        for c2 in rng if len(vecs) > 1 else [0]:
            m = c1 * vecs[0] + (c2 * vecs[1] if len(vecs) > 1 else 0)
            if not np.any(m):
                continue
            v = lattice @ m
            key = (round(float(np.linalg.norm(v)), 9), angle_deg(v))
            if best is None or key < best[0]:
                best = (key, v)
    return None if best is None else best[1]


def barrier_graph(surface: PeriodicSurface, found: list[tuple], start: int, classes: list[int]):
    """Mountain-pass barriers of the start minimum to its lattice images (module step 4).

    Symmetry-equivalent saddles open together, at the lowest energy of their class
    (a round-off or pinning splitting of equivalent saddles does not pick a direction).
    """
    minima = [i for i, f in enumerate(found) if f[4] == "minimum"]
    saddles = [i for i, f in enumerate(found) if f[4] == "saddle"]
    scale = _scale(surface)
    edges = []
    if saddles:
        starts = []
        for i in saddles:
            hess = surface.evaluate(found[i][1]).hessian
            _, vec = np.linalg.eigh(hess)
            v = vec[:, 0]
            for sign in (1.0, -1.0):
                starts.append(found[i][1] + sign * 1e-3 * scale * v)
        ends = descend(surface, np.array(starts))
        for k, i in enumerate(saddles):
            sides = []
            for x in ends[2 * k : 2 * k + 2]:
                s = surface.fractional(x)
                match = None
                for j in minima:
                    ds = s - found[j][0]
                    off = np.round(ds)
                    if np.linalg.norm(surface.cartesian(ds - off)) < 1e-4 * scale:
                        match = (j, off.astype(int))
                        break
                sides.append(match)
            if None not in sides:
                (ja, ta), (jb, tb) = sides
                level = min(f[2] for f, c in zip(found, classes, strict=True) if c == classes[i])
                edges.append((level, ja, jb, tb - ta, i))
    edges.sort(key=lambda e: (e[0], e[4]))
    parent = {j: j for j in minima}
    offset = {j: np.zeros(2, int) for j in minima}
    gens: dict[int, list] = {j: [] for j in minima}

    def find(j: int) -> tuple[int, np.ndarray]:
        total = np.zeros(2, int)
        while parent[j] != j:
            total = total + offset[j]
            j = parent[j]
        return j, total

    history = []
    first = None
    for k, (energy, ja, jb, t, si) in enumerate(edges):
        ra, oa = find(ja)
        rb, ob = find(jb)
        # image(ja, 0) = image(ra, oa); image(jb, t) = image(rb, t + ob)
        if ra != rb:
            parent[rb] = ra
            offset[rb] = oa - t - ob
            gens[ra] = gens[ra] + gens.pop(rb)
        else:
            cycle = t + ob - oa
            if np.any(cycle):
                gens[ra].append(tuple(int(c) for c in cycle))
        if k + 1 < len(edges) and edges[k + 1][0] == energy:
            continue  # the rest of this class opens at the same level
        root, _ = find(start)
        basis = _hnf(gens[root])
        if basis != (None, 0) and (not history or history[-1][1] != basis):
            history.append((energy, basis))
            if first is None:
                first = (energy, basis, si)
    return first, tuple(history)
