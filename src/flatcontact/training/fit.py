"""Weighted, regularised least-squares SNAP fits and the hyper-parameter search.

Loss (per fit, training frames only)::

    L(beta) = sum_frames g_c^2 [ w_E^2 (E/N - a_E.beta/N)^2
                                 + sum_rows (F - A_F beta)^2
                                 + w_S^2 sum_voigt (S - A_S beta)^2 ]
              + lambda |D beta|^2

with energies in eV/atom, forces in eV/Å, stresses in eV/Å³, group weights
``g_c`` per ``config_type`` and ``D`` the column norms of the weighted design
matrix (ridge on standardised columns). Per-element reference energies e_t
are first fitted to the energies by composition (``E ≈ sum_t n_t e_t``) and
subtracted; they return as the constant coefficients beta_t0. The minimiser
is computed from one SVD per row weighting, so all ridge strengths are cheap.

Hyper-parameters (2J, rcutfac, element weights, w_E, w_S, lambda) are chosen
by the validation-split score ``rmse_E/10 meV + rmse_F/200 meV/Å +
rmse_S/0.5 GPa`` (each normalised by its target; rows weighted by the same
group weights as the loss, so the score measures what the fit is asked to
get right), preferring the cheaper 2J when its score is within 5 % of the best.
"""

from __future__ import annotations

import itertools
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from ase import Atoms

from flatcontact.foundation.errors import require
from flatcontact.foundation.units import EV_PER_A3_TO_GPA
from flatcontact.training.dataset import labels
from flatcontact.training.descriptors import DesignBlock, SnapDescriptors
from flatcontact.training.snapfiles import SnapCoefficients, SnapHyper

#: Targets that normalise the selection score (meV/atom, meV/Å, GPa).
TARGET_ENERGY_MEV = 10.0
TARGET_FORCE_MEV = 200.0
TARGET_STRESS_GPA = 0.5


@dataclass(frozen=True)
class FitSettings:
    """Row weights and ridge strength of one fit."""

    energy_weight: float = 30.0
    stress_weight: float = 300.0
    ridge: float = 1e-7
    group_weights: dict = field(default_factory=dict)

    def as_dict(self) -> dict:
        return {
            "energy_weight_per_eV_per_atom": self.energy_weight,
            "force_weight_per_eV_per_A": 1.0,
            "stress_weight_per_eV_per_A3": self.stress_weight,
            "ridge": self.ridge,
            "group_weights": dict(self.group_weights),
        }


def split_indices(
    config_types: Sequence[str], seed: int, fractions=(0.7, 0.15, 0.15)
) -> dict[str, np.ndarray]:
    """Stratified random split (per ``config_type``) into train/validation/test indices."""
    require(abs(sum(fractions) - 1.0) < 1e-9, f"split fractions {fractions} must sum to 1")
    rng = np.random.default_rng(seed)
    types = np.asarray(config_types)
    parts = {"train": [], "validation": [], "test": []}
    for ct in sorted(set(types.tolist())):
        idx = rng.permutation(np.flatnonzero(types == ct))
        n = len(idx)
        n_val = round(fractions[1] * n)
        n_test = round(fractions[2] * n)
        if n >= 3:
            n_val, n_test = max(n_val, 1), max(n_test, 1)
        parts["validation"] += idx[:n_val].tolist()
        parts["test"] += idx[n_val : n_val + n_test].tolist()
        parts["train"] += idx[n_val + n_test :].tolist()
    return {k: np.array(sorted(v), dtype=int) for k, v in parts.items()}


@dataclass
class DesignSet:
    """Stacked design rows and labels of a set of frames."""

    a_energy: np.ndarray  # (M, ncol) per atom
    y_energy: np.ndarray  # (M,) per atom, eV/atom
    a_force: np.ndarray  # (3 sum N, ncol)
    y_force: np.ndarray
    a_stress: np.ndarray  # (6 M_s, ncol)
    y_stress: np.ndarray
    frame_of_force: np.ndarray  # frame index (within the set) of each force row
    frame_of_stress: np.ndarray
    config_type: np.ndarray  # (M,)
    counts: np.ndarray  # (M, n_elements)


def assemble(
    frames: Sequence[Atoms], blocks: Sequence[DesignBlock], elements: Sequence[str]
) -> DesignSet:
    """Stack the design blocks and labels of ``frames``."""
    ae, ye, af, yf, as_, ys, ff, fs, counts = [], [], [], [], [], [], [], [], []
    for k, (atoms, blk) in enumerate(zip(frames, blocks, strict=True)):
        e, f, s = labels(atoms)
        n = len(atoms)
        ae.append(blk.energy / n)
        ye.append(e / n)
        af.append(blk.forces)
        yf.append(f.ravel())
        ff.append(np.full(3 * n, k))
        if s is not None:
            as_.append(blk.stress)
            ys.append(s)
            fs.append(np.full(6, k))
        sym = np.array(atoms.get_chemical_symbols())
        counts.append([(sym == el).sum() for el in elements])
    ncol = len(blocks[0].energy)
    return DesignSet(
        a_energy=np.array(ae),
        y_energy=np.array(ye),
        a_force=np.vstack(af),
        y_force=np.concatenate(yf),
        a_stress=np.vstack(as_) if as_ else np.zeros((0, ncol)),
        y_stress=np.concatenate(ys) if ys else np.zeros(0),
        frame_of_force=np.concatenate(ff),
        frame_of_stress=np.concatenate(fs) if fs else np.zeros(0, dtype=int),
        config_type=np.array([a.info.get("config_type", "default") for a in frames]),
        counts=np.array(counts, dtype=float),
    )


def subset(ds: DesignSet, idx: np.ndarray) -> DesignSet:
    """The rows of the frames ``idx`` (renumbered 0..len(idx)-1)."""
    idx = np.asarray(idx, dtype=int)
    remap = -np.ones(len(ds.y_energy), dtype=int)
    remap[idx] = np.arange(len(idx))
    mf = remap[ds.frame_of_force] >= 0
    ms = remap[ds.frame_of_stress] >= 0
    return DesignSet(
        a_energy=ds.a_energy[idx],
        y_energy=ds.y_energy[idx],
        a_force=ds.a_force[mf],
        y_force=ds.y_force[mf],
        a_stress=ds.a_stress[ms],
        y_stress=ds.y_stress[ms],
        frame_of_force=remap[ds.frame_of_force[mf]],
        frame_of_stress=remap[ds.frame_of_stress[ms]],
        config_type=ds.config_type[idx],
        counts=ds.counts[idx],
    )


def reference_energies(ds: DesignSet) -> np.ndarray:
    """Per-element reference energies e_t from ``E ≈ sum_t n_t e_t`` (minimum-norm least squares)."""
    n_atoms = ds.counts.sum(axis=1)
    sol, *_ = np.linalg.lstsq(ds.counts, ds.y_energy * n_atoms, rcond=None)
    return sol


def _const_columns(n_elements: int, ncol: int) -> np.ndarray:
    k = ncol // n_elements
    return np.arange(n_elements) * k


class WeightedSystem:
    """SVD of the weighted, column-standardised training system for fast ridge solves."""

    def __init__(self, ds: DesignSet, settings: FitSettings, e_ref: np.ndarray):
        gw = np.array([settings.group_weights.get(c, 1.0) for c in ds.config_type])
        y_e = ds.y_energy - ds.counts @ e_ref / ds.counts.sum(axis=1)
        rows = [
            ds.a_energy * (settings.energy_weight * gw)[:, None],
            ds.a_force * gw[ds.frame_of_force][:, None],
            ds.a_stress * (settings.stress_weight * gw[ds.frame_of_stress])[:, None],
        ]
        rhs = [
            y_e * settings.energy_weight * gw,
            ds.y_force * gw[ds.frame_of_force],
            ds.y_stress * settings.stress_weight * gw[ds.frame_of_stress],
        ]
        a = np.vstack(rows)
        y = np.concatenate(rhs)
        self.scale = np.linalg.norm(a, axis=0)
        self.scale[self.scale == 0] = 1.0
        u, self.s, self.vt = np.linalg.svd(a / self.scale, full_matrices=False)
        self.uty = u.T @ y

    def solve(self, ridge: float) -> np.ndarray:
        """Coefficients (original column units) for ridge strength ``ridge``."""
        gamma = self.vt.T @ (self.s / (self.s**2 + ridge) * self.uty)
        return gamma / self.scale


def predict(ds: DesignSet, beta: np.ndarray) -> dict:
    """Predicted per-atom energies, forces and stresses of a design set."""
    return {
        "energy": ds.a_energy @ beta,
        "forces": ds.a_force @ beta,
        "stress": ds.a_stress @ beta,
    }


def rmse_report(ds: DesignSet, beta: np.ndarray, group_weights: dict | None = None) -> dict:
    """RMSEs overall and per config_type: energy meV/atom, force meV/Å, stress GPa.

    With ``group_weights`` the overall RMSEs are weighted means over rows (weight
    ``g_c^2`` per row, as in the loss); per-group values are always unweighted.
    """
    pred = predict(ds, beta)
    gw = np.array([(group_weights or {}).get(c, 1.0) for c in ds.config_type]) ** 2

    def rm(x, w=None):
        if not len(x):
            return float("nan")
        return float(np.sqrt(np.average(x**2, weights=w)))

    de = (pred["energy"] - ds.y_energy) * 1e3
    df = (pred["forces"] - ds.y_force) * 1e3
    ds_ = (pred["stress"] - ds.y_stress) * EV_PER_A3_TO_GPA
    weighted = group_weights is not None
    out = {
        "n_frames": len(ds.y_energy),
        "n_atoms": int(ds.counts.sum()),
        "group_weighted": weighted,
        "energy_rmse_mev_per_atom": rm(de, gw if weighted else None),
        "force_rmse_mev_per_angstrom": rm(df, gw[ds.frame_of_force] if weighted else None),
        "stress_rmse_gpa": rm(ds_, gw[ds.frame_of_stress] if weighted and len(ds_) else None),
        "by_config_type": {},
    }
    for ct in sorted(set(ds.config_type.tolist())):
        fe = ds.config_type == ct
        ff = fe[ds.frame_of_force]
        fs = fe[ds.frame_of_stress]
        out["by_config_type"][ct] = {
            "n_frames": int(fe.sum()),
            "energy_rmse_mev_per_atom": rm(de[fe]),
            "force_rmse_mev_per_angstrom": rm(df[ff]),
            "stress_rmse_gpa": rm(ds_[fs]),
        }
    return out


def score(report: dict) -> float:
    """Validation score: RMSEs normalised by the targets, summed."""
    s = report["stress_rmse_gpa"]
    return (
        report["energy_rmse_mev_per_atom"] / TARGET_ENERGY_MEV
        + report["force_rmse_mev_per_angstrom"] / TARGET_FORCE_MEV
        + (0.0 if np.isnan(s) else s / TARGET_STRESS_GPA)
    )


@dataclass
class FitResult:
    """The chosen fit, its hyper-parameters, errors and the search table."""

    coefficients: SnapCoefficients
    settings: FitSettings
    split: dict
    errors: dict  # train / validation / test rmse reports
    search: list  # one dict per (hyper, settings) tried
    timings: dict
    predictions: dict  # per split: labels and predictions for parity plots


def compute_blocks(
    frames: Sequence[Atoms], hyper: SnapHyper, elements: Sequence[str]
) -> list[DesignBlock]:
    """Design blocks of every frame (one LAMMPS instance)."""
    desc = SnapDescriptors(hyper, list(elements))
    return [desc(a) for a in frames]


def fit_snap(
    frames: Sequence[Atoms],
    elements: Sequence[str],
    hypers: Sequence[SnapHyper],
    settings_grid: Sequence[FitSettings],
    ridges: Sequence[float] = (1e-9, 1e-7, 1e-5, 1e-3),
    seed: int = 0,
    split: dict | None = None,
    progress: Callable[[str], None] | None = None,
) -> FitResult:
    """Fit linear (or quadratic) SNAPs over a hyper-parameter grid; keep the best on validation.

    Parameters
    ----------
    frames
        Labelled frames (see :mod:`.dataset`); ``info["config_type"]`` groups them.
    elements
        Element order of the potential (LAMMPS types).
    hypers, settings_grid, ridges
        Descriptor hyper-parameters, row weightings and ridge strengths to try.
    seed
        Seed of the train/validation/test split (when ``split`` is not given).
    """
    require(
        len(frames) >= 3, f"{len(frames)} frames: need at least 3 to split train/validation/test"
    )
    say = progress or (lambda msg: None)
    split = split or split_indices([a.info.get("config_type", "default") for a in frames], seed)
    require(
        len(split["train"]) > 0 and len(split["validation"]) > 0,
        "empty training or validation split",
    )
    search, best = [], None
    timings = {"descriptors_s": 0.0, "solve_s": 0.0}
    twoj_cost = {h.twojmax for h in hypers}
    for hyper in hypers:
        t0 = time.perf_counter()
        blocks = compute_blocks(frames, hyper, elements)
        timings["descriptors_s"] += time.perf_counter() - t0
        ds = assemble(frames, blocks, elements)
        train, val = subset(ds, split["train"]), subset(ds, split["validation"])
        e_ref = reference_energies(train)
        t0 = time.perf_counter()
        for settings in settings_grid:
            system = WeightedSystem(train, settings, e_ref)
            for ridge in ridges:
                beta = system.solve(ridge)
                beta[_const_columns(len(elements), len(beta))] += e_ref
                rep = rmse_report(val, beta, settings.group_weights)
                sc = score(rep)
                row = {
                    "hyper": hyper.as_dict(),
                    "settings": {**settings.as_dict(), "ridge": ridge},
                    "validation": {k: v for k, v in rep.items() if k != "by_config_type"},
                    "score": sc,
                }
                search.append(row)
                cand = (
                    sc,
                    hyper,
                    FitSettings(
                        settings.energy_weight,
                        settings.stress_weight,
                        ridge,
                        settings.group_weights,
                    ),
                    beta,
                    ds,
                )
                if best is None or sc < best[0]:
                    best = cand
        timings["solve_s"] += time.perf_counter() - t0
        say(
            f"2J={hyper.twojmax} rcutfac={hyper.rcutfac} w={hyper.weights}: best score so far "
            f"{best[0]:.3f}"
        )
    # prefer the cheaper 2J when within 5 % of the best score
    if len(twoj_cost) > 1:
        cheapest = min(twoj_cost)
        cheap_rows = [r for r in search if r["hyper"]["twojmax"] == cheapest]
        cheap_best = min(cheap_rows, key=lambda r: r["score"])
        if best[1].twojmax != cheapest and cheap_best["score"] <= 1.05 * best[0]:
            say(
                f"choosing 2J={cheapest} (score {cheap_best['score']:.3f} within 5 % of {best[0]:.3f})"
            )
            return _refit(frames, elements, cheap_best, split, search, timings, settings_grid)
    sc, hyper, settings, beta, ds = best
    return _result(ds, elements, hyper, settings, beta, split, search, timings)


def _refit(frames, elements, row, split, search, timings, settings_grid):
    h = row["hyper"]
    hyper = SnapHyper(
        twojmax=h["twojmax"],
        rcutfac=h["rcutfac"],
        radii=h["radii"],
        weights=h["weights"],
        rfac0=h["rfac0"],
        rmin0=h["rmin0"],
        quadratic=h["quadratic"],
    )
    s = row["settings"]
    settings = FitSettings(
        s["energy_weight_per_eV_per_atom"],
        s["stress_weight_per_eV_per_A3"],
        s["ridge"],
        s["group_weights"],
    )
    ds = assemble(frames, compute_blocks(frames, hyper, elements), elements)
    train = subset(ds, split["train"])
    e_ref = reference_energies(train)
    beta = WeightedSystem(train, settings, e_ref).solve(settings.ridge)
    beta[_const_columns(len(elements), len(beta))] += e_ref
    return _result(ds, elements, hyper, settings, beta, split, search, timings)


def _result(ds, elements, hyper, settings, beta, split, search, timings) -> FitResult:
    desc_beta = {
        e: beta[t * (1 + hyper.n_descriptor) : (t + 1) * (1 + hyper.n_descriptor)].copy()
        for t, e in enumerate(elements)
    }
    errors, predictions = {}, {}
    for name, idx in split.items():
        if len(idx) == 0:
            continue
        sub = subset(ds, idx)
        errors[name] = rmse_report(sub, beta)
        pred = predict(sub, beta)
        predictions[name] = {
            "energy_ref": sub.y_energy,
            "energy_pred": pred["energy"],
            "force_ref": sub.y_force,
            "force_pred": pred["forces"],
            "stress_ref": sub.y_stress,
            "stress_pred": pred["stress"],
        }
    return FitResult(
        coefficients=SnapCoefficients(tuple(elements), hyper, desc_beta),
        settings=settings,
        split={k: v.tolist() for k, v in split.items()},
        errors=errors,
        search=search,
        timings=timings,
        predictions=predictions,
    )


def default_hypers(elements: Sequence[str], quadratic: bool | None = None) -> list[SnapHyper]:
    """The default search grid: rcutfac in (4.5, 5.0) x O weight in (0.6, 1.0) x descriptor.

    Descriptors: linear 2J = 6 and 8 and quadratic 2J = 6 (``quadratic=None``, the
    default), or only the quadratic (True) or only the linear ones (False).
    """
    kinds = {
        None: [(6, False), (8, False), (6, True)],
        True: [(6, True)],
        False: [(6, False), (8, False)],
    }
    out = []
    for (twoj, quad), rc, wo in itertools.product(kinds[quadratic], (4.5, 5.0), (0.6, 1.0)):
        radii = dict.fromkeys(elements, 0.5)
        weights = {e: (wo if e == "O" else 1.0) for e in elements}
        out.append(
            SnapHyper(twojmax=twoj, rcutfac=rc, radii=radii, weights=weights, quadratic=quad)
        )
    return out


def default_settings(group_weights: dict | None = None) -> list[FitSettings]:
    """The default row-weight grid: w_E in (30, 100) x w_S in (300, 1000)."""
    gw = dict(group_weights or {})
    return [
        FitSettings(energy_weight=we, stress_weight=ws, group_weights=gw)
        for we, ws in itertools.product((30.0, 100.0), (300.0, 1000.0))
    ]
