"""Studies that would silently do the wrong thing: a refinement of nothing or of one setting
twice is one line before any run; a long interlayer cutoff (a KC cutoff ladder) gets the
neighbour capacity it needs; the estimate of a cutoff rung carries its costlier force call."""

from __future__ import annotations

import pytest
from tests.hardening.helpers import refused, run_cli
from tests.studies.toy import toy_data, write_yaml

from flatcontact.config.load import build_config
from flatcontact.config.merge import merge_config


@pytest.mark.parametrize(
    ("settings", "names"),
    [([], ["refine.settings", "refines nothing"]), (["grid", "grid"], ["grid given twice"])],
)
def test_a_refinement_of_nothing_or_twice_the_same_is_one_line(tmp_path, capsys, settings, names):
    conf = write_yaml(tmp_path / "toy.yaml", toy_data(refine={"settings": settings}))
    code, _, err = run_cli(["config", "--check", conf], capsys)
    refused(code, err, *names)
    out = tmp_path / "study"
    code, _, err = run_cli(["study", "convergence", conf, "--out", out], capsys)
    refused(code, err, *names)
    assert not out.exists()


def _kc_bilayer(cutoff_angstrom: float):
    """(configuration, unrelaxed 4-atom AB bilayer) with REBO + KC at ``cutoff_angstrom``."""
    from flatcontact.structures.construct import build_interface

    data = {
        "structure": {"kind": "sheets", "sheet": "graphene", "layers": 1, "stacking": "AB"},
        "potential": {
            "intra": [{"pair_style": "rebo", "pair_coeff": ["CH.rebo"], "elements": ["C"]}],
            "intra_scope": "layer",
            "coupling": "interlayer",
            "interlayer": {
                "pair_style": f"kolmogorov/crespi/full {cutoff_angstrom:g} 1",
                "pair_coeff": ["CH_taper.KC"],
                "elements": ["C"],
            },
        },
        "scan": {"grid": [3, 3], "relax_mode": "rigid-layers"},
        "contact": {"contact_modulus_gpa": 30.0, "shear_modulus_gpa": 5.0},
    }
    cfg = build_config(data, None, "kc")
    atoms, _ = build_interface(cfg.structure)
    return cfg, atoms


def _energy_ev(cutoff_angstrom: float) -> float:
    from flatcontact.potentials.engines import make_calculator
    from flatcontact.stages import _calculator

    cfg, atoms = _kc_bilayer(cutoff_angstrom)
    atoms.calc = make_calculator(_calculator.model(cfg), atoms)
    try:
        return float(atoms.get_potential_energy())
    finally:
        atoms.calc.close()


@pytest.mark.slow
def test_a_long_kc_cutoff_computes_and_its_tail_converges():
    """96 Å (16 + 2 rungs of 40 Å): 'Neighbor list overflow' before (the capacity was sized
    for 16 Å). The KC attraction falls as r^-6, so the energy beyond a cutoff r_c summed over
    a sheet falls as r_c^-4: the move from 56 to 96 Å is (56^-4 - 96^-4)/(16^-4 - 56^-4) =
    0.6 % of the move from 16 to 56 Å for a sharp cutoff; the taper smooths it, so allow 10 %."""
    e16, e56, e96 = (_energy_ev(rc) for rc in (16.0, 56.0, 96.0))
    assert e96 < e56 < e16  # more attraction with every rung
    assert abs(e96 - e56) < 0.1 * abs(e56 - e16)


def test_the_neighbour_capacity_covers_the_longest_interlayer_cutoff():
    from flatcontact.potentials.lammps_setup import compile_setup, neighbour_capacity
    from flatcontact.stages import _calculator

    for rc in (16.0, 96.0):
        cfg, atoms = _kc_bilayer(rc)
        setup = compile_setup(_calculator.model(cfg), atoms)
        lines = [c for c in setup.commands if c.startswith("neigh_modify one")]
        assert len(lines) == 1
        one = int(lines[0].split()[2])
        assert one >= neighbour_capacity(rc) and one >= 20000


def test_a_cutoff_rungs_estimate_carries_its_costlier_force_call():
    """The per-call cost is measured, not assumed equal to the base's: 16 → 46 Å sums
    (47/17)^2 ≈ 8 times the interlayer pairs of a sheet."""
    from flatcontact.studies.estimate import cutoff_call_ratios, estimate_convergence
    from flatcontact.studies.variants import step

    cfg, _ = _kc_bilayer(16.0)
    cfg = build_config(
        merge_config(
            cfg.to_dict(),
            {"refine": {"settings": ["cutoff"], "max_steps": 1, "cutoff_step_angstrom": 30.0}},
        ),
        None,
        "kc",
    )
    rung = step(cfg, "cutoff", 1)
    config = build_config(merge_config(cfg.to_dict(), rung.overrides), None, "kc").to_dict()
    ratios = cutoff_call_ratios(cfg, {"cutoff": [rung]}, {rung.name: config})
    assert ratios[rung.name] > 2.0
    base = {
        "grid": [3, 3],
        "thicknesses": 4,
        "thickness_range_angstrom": 1.0,
        "points_total": 36,
        "points_computed": 12,
        "force_calls": 12,
        "seconds": {"build": 1.0, "scan": 10.0, "analyze": 1.0, "laws": 1.0},
    }
    est = estimate_convergence(cfg, {"cutoff": [rung]}, base, 1, ratios)
    (v,) = est["variants"]
    assert v["seconds"] == pytest.approx(1.0 + 10.0 * ratios[rung.name] + 2.0)
