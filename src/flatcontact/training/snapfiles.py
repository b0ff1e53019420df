"""SNAP hyper-parameters and the LAMMPS ``.snapcoeff`` / ``.snapparam`` files.

A linear SNAP (Thompson et al., J. Comput. Phys. 285, 316 (2015)) gives atom i of
element t the energy ``E_i = beta_t0 + sum_k beta_tk B_k^i``; the quadratic form
adds ``1/2 sum_{k<=l} beta_tkl B_k^i B_l^i`` (LAMMPS orders the quadratic
coefficients row-wise over ``k <= l``, the same as ``compute snap`` with
``quadraticflag 1``). The neighbour cutoff between elements a and b is
``rcutfac * (R_a + R_b)``; ``w_a`` is the element weight in the density.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from flatcontact.foundation.errors import InputError, require
from flatcontact.foundation.fileio import write_text_atomic


def n_bispectrum(twojmax: int) -> int:
    """Number of bispectrum components B_k for ``twojmax`` (LAMMPS chemflag 0)."""
    n = 0
    for j1 in range(twojmax + 1):
        for j2 in range(j1 + 1):
            for j in range(j1 - j2, min(twojmax, j1 + j2) + 1, 2):
                if j >= j1:
                    n += 1
    return n


@dataclass(frozen=True)
class SnapHyper:
    """Descriptor hyper-parameters shared by ``compute snap`` and ``pair_style snap``.

    Attributes
    ----------
    twojmax : int
        Band limit 2J (6 -> 30 components, 8 -> 55).
    rcutfac : float
        Cutoff scale; the cutoff between a and b is ``rcutfac * (R_a + R_b)`` (Å).
    radii, weights : dict
        Per-element radius ``R`` and density weight ``w``.
    rfac0, rmin0 : float
        Angular mapping parameters (LAMMPS defaults 0.99363, 0).
    quadratic : bool
        Quadratic SNAP (``quadraticflag 1``).
    """

    twojmax: int = 6
    rcutfac: float = 5.0
    radii: dict = field(default_factory=lambda: {"Si": 0.5, "O": 0.5})
    weights: dict = field(default_factory=lambda: {"Si": 1.0, "O": 0.8})
    rfac0: float = 0.99363
    rmin0: float = 0.0
    quadratic: bool = False

    def __post_init__(self):
        require(
            self.twojmax in (2, 4, 6, 8, 10), f"twojmax={self.twojmax}: expected 2, 4, 6, 8 or 10"
        )
        require(self.rcutfac > 0, f"rcutfac={self.rcutfac}: expected > 0")
        require(
            set(self.radii) == set(self.weights),
            f"radii {sorted(self.radii)} and weights {sorted(self.weights)} must name the same elements",
        )

    @property
    def n_linear(self) -> int:
        """Number of bispectrum components per element."""
        return n_bispectrum(self.twojmax)

    @property
    def n_descriptor(self) -> int:
        """Descriptor columns per element (linear + quadratic products if enabled)."""
        n = self.n_linear
        return n + (n * (n + 1) // 2 if self.quadratic else 0)

    def cutoff(self, a: str, b: str) -> float:
        """Neighbour cutoff between elements ``a`` and ``b`` (Å)."""
        return self.rcutfac * (self.radii[a] + self.radii[b])

    def max_cutoff(self) -> float:
        """Largest pair cutoff (Å)."""
        return 2.0 * self.rcutfac * max(self.radii.values())

    def as_dict(self) -> dict:
        """JSON-ready form."""
        return {
            "twojmax": self.twojmax,
            "rcutfac": self.rcutfac,
            "radii": dict(self.radii),
            "weights": dict(self.weights),
            "rfac0": self.rfac0,
            "rmin0": self.rmin0,
            "quadratic": self.quadratic,
        }

    def compute_args(self, elements: list[str]) -> str:
        """Argument string of ``compute snap`` for the given type order."""
        radii = " ".join(repr(float(self.radii[e])) for e in elements)
        weights = " ".join(repr(float(self.weights[e])) for e in elements)
        return (
            f"{self.rcutfac!r} {self.rfac0!r} {self.twojmax} {radii} {weights} "
            f"rmin0 {self.rmin0!r} bzeroflag 1 quadraticflag {int(self.quadratic)} switchflag 1"
        )


@dataclass(frozen=True)
class SnapCoefficients:
    """Coefficients per element: ``beta[e]`` has ``1 + n_descriptor`` entries (beta_0 first)."""

    elements: tuple[str, ...]
    hyper: SnapHyper
    beta: dict


def write_snap_files(
    prefix: str | Path, coeffs: SnapCoefficients, header: str = ""
) -> tuple[Path, Path]:
    """Write ``<prefix>.snapcoeff`` and ``<prefix>.snapparam`` atomically; return their paths."""
    prefix = Path(prefix)
    h = coeffs.hyper
    ncol = 1 + h.n_descriptor
    comment = "".join(f"# {line}\n" for line in header.splitlines())
    lines = [comment, f"{len(coeffs.elements)} {ncol}"]
    for el in coeffs.elements:
        beta = np.asarray(coeffs.beta[el], dtype=float)
        require(beta.shape == (ncol,), f"coefficients of {el}: expected {ncol}, got {beta.shape}")
        lines.append(f"{el} {h.radii[el]!r} {h.weights[el]!r}")
        lines += [f"{b:.17g}" for b in beta]
    coeff_path = prefix.with_name(prefix.name + ".snapcoeff")
    param_path = prefix.with_name(prefix.name + ".snapparam")
    write_text_atomic(coeff_path, "\n".join(lines) + "\n")
    params = [
        comment.rstrip("\n"),
        f"rcutfac {h.rcutfac!r}",
        f"twojmax {h.twojmax}",
        f"rfac0 {h.rfac0!r}",
        f"rmin0 {h.rmin0!r}",
        "bzeroflag 1",
        f"quadraticflag {int(h.quadratic)}",
        "switchflag 1",
    ]
    write_text_atomic(param_path, "\n".join(p for p in params if p) + "\n")
    return coeff_path, param_path


def _strip(text: str) -> list[str]:
    return [ln.split("#", 1)[0].strip() for ln in text.splitlines() if ln.split("#", 1)[0].strip()]


def read_snapparam(path: str | Path) -> dict:
    """Parse a ``.snapparam`` file into a dict of keyword -> string value."""
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: SNAP parameter file not found")
    out = {}
    for line in _strip(path.read_text()):
        parts = line.split()
        require(len(parts) == 2, f"{path}: malformed line '{line}' (expected 'keyword value')")
        out[parts[0]] = parts[1]
    for key in ("rcutfac", "twojmax"):
        require(key in out, f"{path}: required keyword '{key}' missing")
    return out


def read_snapcoeff(path: str | Path, param_path: str | Path | None = None) -> SnapCoefficients:
    """Read a ``.snapcoeff`` (and its ``.snapparam``, by default beside it)."""
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: SNAP coefficient file not found")
    param_path = Path(param_path) if param_path else path.with_suffix(".snapparam")
    tokens = _strip(path.read_text())
    try:
        nel, ncol = (int(x) for x in tokens[0].split())
        elements, radii, weights, beta = [], {}, {}, {}
        pos = 1
        for _ in range(nel):
            el, r, w = tokens[pos].split()
            elements.append(el)
            radii[el], weights[el] = float(r), float(w)
            beta[el] = np.array([float(t) for t in tokens[pos + 1 : pos + 1 + ncol]])
            require(len(beta[el]) == ncol, f"{path}: element {el} has too few coefficients")
            pos += 1 + ncol
    except (ValueError, IndexError):
        raise InputError(f"{path}: malformed SNAP coefficient file") from None
    hyper = SnapHyper(radii=radii, weights=weights, twojmax=2, rcutfac=1.0)
    if param_path.is_file():
        p = read_snapparam(param_path)
        hyper = SnapHyper(
            twojmax=int(p["twojmax"]),
            rcutfac=float(p["rcutfac"]),
            radii=radii,
            weights=weights,
            rfac0=float(p.get("rfac0", 0.99363)),
            rmin0=float(p.get("rmin0", 0.0)),
            quadratic=bool(int(p.get("quadraticflag", 0))),
        )
        require(
            1 + hyper.n_descriptor == ncol,
            f"{path}: {ncol} coefficients per element, but {param_path.name} implies {1 + hyper.n_descriptor}",
        )
    return SnapCoefficients(tuple(elements), hyper, beta)
