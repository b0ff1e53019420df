"""ISPES analysis on a 24×24×12 grid at 10 pressures: seconds per stage and evaluation counts.

The grid is the synthetic Morse model with a broken-symmetry three-cosine
pattern (closed-form, see :mod:`flatcontact.analysis.synthetic`). Prints the
time of each stage of :func:`flatcontact.analysis.analyze.analyze_ispes` for both
load sources (``energy``: p = -(1/A) dU/dz of the spline of U; ``stress``: the stored
normal_stress) and their ratio (best of ``REPEATS``), the number of interpolant
evaluations per path, and the same with the string-method MEP.
"""

from __future__ import annotations

import time
import warnings

import numpy as np

from flatcontact.analysis import synthetic as syn
from flatcontact.analysis.analyze import LOAD_SOURCES, analyze_ispes
from flatcontact.analysis.diagnostics import AnalysisWarning
from flatcontact.analysis.options import AnalysisOptions
from flatcontact.analysis.periodic import PeriodicSurface

P_GPA = np.linspace(0.0, 4.5, 10)
#: Timings are the best of this many runs (the machine is shared).
REPEATS = 3


class _Counting(PeriodicSurface):
    calls = 0

    def evaluate(self, xy):  # count points evaluated with derivatives
        _Counting.calls += int(np.asarray(xy).size // 2)
        return super().evaluate(xy)


def _print_run(label: str, total: float, res) -> None:
    print(f"24x24x12 grid, {P_GPA.size} pressures ({label}): total {total:.2f} s")
    for stage, seconds in res.timings_s.items():
        print(f"  {stage:<18s} {seconds:7.3f} s  ({100 * seconds / total:4.1f} %)")
    steps = [len(pa.path.t_angstrom) for pa in res.pressures]
    jumps = [len(pa.path.jumps) for pa in res.pressures]
    print(f"  path samples per load: {min(steps)}..{max(steps)}; jumps: {jumps}")


def main() -> None:
    a1, a2 = syn.hexagonal_cell()
    model = syn.SyntheticInterface(
        a1,
        a2,
        syn.three_cosine(a1, a2, (1.0, 0.8, 1.15)),
        depth_modulation=0.3,
        gap_modulation_angstrom=-0.05,
        corrugation_ev_per_a2=-2e-4,
    )
    ds = model.grid(24, 24, np.linspace(24.3, 26.5, 12))
    totals, stage = {}, {}
    for load_source in LOAD_SOURCES:
        best = None
        for _ in range(REPEATS):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", AnalysisWarning)
                clock = time.perf_counter()
                res = analyze_ispes(
                    ds, P_GPA, AnalysisOptions(load_source=load_source, with_symmetry=True)
                )
                total = time.perf_counter() - clock
            if best is None or total < best[0]:
                best = (total, res)
        total, res = best
        totals[load_source] = total
        stage[load_source] = res.timings_s["constant_pressure"]
        _print_run(f"{load_source} load, best of {REPEATS}", total, res)
        taus = ", ".join(f"{pa.friction.tau_mpa:.1f}" for pa in res.pressures)
        print(f"  tau (MPa): {taus}")
    print(
        f"load source energy/stress time ratio: {totals['energy'] / totals['stress']:.3f} "
        f"({totals['energy']:.3f} s / {totals['stress']:.3f} s); the only stage the source "
        f"changes, constant_pressure: {stage['energy'] / stage['stress']:.3f} "
        f"({stage['energy'] * 1e3:.1f} ms / {stage['stress'] * 1e3:.1f} ms)"
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", AnalysisWarning)
        clock = time.perf_counter()
        res = analyze_ispes(ds, P_GPA, AnalysisOptions(with_mep=True, with_symmetry=True))
        total = time.perf_counter() - clock
    _print_run(f"{res.load_source} load, with MEP", total, res)
    print(f"  MEP iterations per load: {[pa.mep.iterations for pa in res.pressures]}")

    # evaluation count of one path tracking on the same surface
    from flatcontact.analysis.path import zero_perpendicular_force_path

    surf = res.pressures[0].surface
    counting = _Counting(surf.values, surf.a1, surf.a2)
    _Counting.calls = 0
    clock = time.perf_counter()
    path = zero_perpendicular_force_path(counting, 90.0)
    seconds = time.perf_counter() - clock
    print(
        f"one path: {len(path.t_angstrom)} samples, {_Counting.calls} interpolant evaluations "
        f"({_Counting.calls / len(path.t_angstrom):.1f} per sample), {seconds * 1e3:.0f} ms"
    )
