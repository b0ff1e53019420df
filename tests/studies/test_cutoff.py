"""The cutoff of the cross-interface coupling as a refined setting, where the coupling has one.

``coupling: lj`` refines ``potential.lj.cutoff_angstrom``; ``coupling: interlayer`` refines
the cutoff argument of each tapered interlayer style (KC, ILP, coul/shield). The ladder's
models are checked against a plain LAMMPS input written here, and the taper against its
defining property: the interlayer energy vanishes beyond the cutoff and not inside it.
"""

from __future__ import annotations

import numpy as np
import pytest
from ase import Atoms
from tests.potentials.plain_lammps import lammps_energy

from flatcontact.config.load import build_config
from flatcontact.foundation.errors import InputError
from flatcontact.potentials import make_calculator
from flatcontact.potentials.lammps_runtime import lammps_potential_file
from flatcontact.potentials.styles import style_cutoff_angstrom, with_cutoff
from flatcontact.stages.measured_on import model_fingerprint
from flatcontact.studies.variants import (
    applicable_settings,
    base_value,
    chosen_settings,
    interlayer_cutoffs,
    step,
    variant_config,
)

BILAYER = {
    "structure": {"kind": "sheets", "sheet": "graphene", "layers": 1, "stacking": "AB"},
    "scan": {
        "grid": [3, 3],
        "p_range_gpa": {"lo_gpa": 0.0, "hi_gpa": 1.0, "n": 3},
        "relax_mode": "rigid-layers",
        "executor": "serial",
    },
    "analysis": {"p_gpa": [0.0, 0.5]},
    "elastic": {"enabled": False},
    "contact": {"p0_gpa": [0.5]},
    "report": {"svg": False},
}


def bilayer(preset: str, **refine):
    data = {**BILAYER, "potential": {"preset": preset}, "refine": refine}
    if preset.startswith("hbn"):
        data["structure"] = {**data["structure"], "sheet": "hbn"}
    return build_config(data, None, "bilayer")


def interlayer_styles(cfg) -> list[str]:
    il = cfg.potential.interlayer
    return [s.pair_style for s in (il if isinstance(il, tuple) else (il,))]


def test_style_cutoff_is_read_and_replaced_keeping_the_taper_flag():
    assert style_cutoff_angstrom("kolmogorov/crespi/full 16.0 1") == 16.0
    assert style_cutoff_angstrom("ilp/graphene/hbn 14 0") == 14.0
    assert style_cutoff_angstrom("rebo") is None
    assert style_cutoff_angstrom("lj/cut 10") is None  # the LJ cutoff is potential.lj's
    assert with_cutoff("ilp/graphene/hbn 16.0 1", 20.0) == "ilp/graphene/hbn 20 1"
    with pytest.raises(InputError, match="rebo"):
        with_cutoff("rebo", 20.0)


@pytest.mark.parametrize(
    ("preset", "styles"),
    [
        ("graphene-rebo-kc", ["kolmogorov/crespi/full {} 1"]),
        ("graphene-rebo-ilp", ["ilp/graphene/hbn {} 1"]),
        ("hbn-tersoff-ilp", ["ilp/graphene/hbn {} 1", "coul/shield {} 1"]),
    ],
)
def test_the_interlayer_cutoff_ladder_lengthens_every_tapered_style(preset, styles):
    cfg = bilayer(preset)
    assert applicable_settings(cfg)["cutoff"] == ""
    assert interlayer_cutoffs(cfg) == [16.0] * len(styles)
    assert base_value(cfg, "cutoff") == 16.0
    prints = {model_fingerprint(cfg)}
    for level, rc in ((1, 20), (2, 24)):
        v = step(cfg, "cutoff", level)
        assert v.value == rc and v.label == f"interlayer cutoff {rc} Å"
        variant = variant_config(cfg, v.overrides, "test")
        assert interlayer_styles(variant) == [s.format(rc) for s in styles]
        # the rest of the model is the base's: intralayer style, charges, coupling
        assert variant.potential.intra == cfg.potential.intra
        assert variant.potential.charges == cfg.potential.charges
        assert variant.potential.coupling == "interlayer"
        prints.add(model_fingerprint(variant))
    assert len(prints) == 3  # each rung is another model to the run directory


def test_the_lj_ladder_is_unchanged_and_a_coupling_without_cutoff_is_skipped():
    toy_lj = build_config({}, None, "quick")  # the quartz default: SNAP + LJ across
    assert toy_lj.potential.coupling == "lj"
    v = step(toy_lj, "cutoff", 2)
    rc = toy_lj.potential.lj.cutoff_angstrom + 8.0
    assert v.overrides == {"potential": {"lj": {"cutoff_angstrom": rc}}}
    assert v.label == f"LJ cutoff {rc:g} Å"
    eam = build_config(
        {
            **BILAYER,
            "structure": {"kind": "fcc111", "element": "Cu", "layers": 3},
            "potential": {"preset": "cu-eam"},
        },
        None,
        "cu",
    )
    assert "has no cutoff setting" in applicable_settings(eam)["cutoff"]
    with pytest.raises(InputError, match=r"refine\.settings: 'cutoff' cannot be refined here"):
        chosen_settings(
            eam.model_copy(
                update={"refine": eam.refine.model_copy(update={"settings": ["cutoff"]})}
            )
        )


def graphene_bilayer(d: float, shift=(1 / 3, 1 / 3)) -> Atoms:
    """Two graphene primitive cells at distance d (Å), the top one shifted by shift·(a1, a2)."""
    a = 2.46
    cell = np.array([[a, 0, 0], [a / 2, a * np.sqrt(3) / 2, 0], [0, 0, 60.0]])
    sites = np.array([[0, 0], [1 / 3, 1 / 3]])
    pos = [
        [*(frac @ cell[:2, :2]), z]
        for z, offset in ((10.0, 0.0), (10.0 + d, np.asarray(shift)))
        for frac in sites + offset
    ]
    atoms = Atoms("C4", positions=pos, cell=cell, pbc=(True, True, False))
    atoms.arrays["slab"] = np.array([1, 1, 2, 2])
    atoms.arrays["layer"] = np.array([1, 1, 2, 2])
    return atoms


def energy(cfg, atoms) -> float:
    a = atoms.copy()
    a.calc = make_calculator(cfg.potential, a)
    return a.get_potential_energy()


def test_each_rung_is_the_plain_lammps_model_and_the_taper_ends_at_its_cutoff():
    """The variant's model equals ``kolmogorov/crespi/full 20 1`` written by hand, and the
    interlayer energy E(d) − E(∞) is zero beyond each rung's cutoff and negative inside it."""
    cfg = bilayer("graphene-rebo-kc")
    v20 = variant_config(cfg, step(cfg, "cutoff", 1).overrides, "test")
    plain = [
        "pair_style hybrid/overlay rebo kolmogorov/crespi/full 20 1",
        f"pair_coeff * * rebo {lammps_potential_file('CH.rebo')} C C",
        f"pair_coeff * * kolmogorov/crespi/full {lammps_potential_file('CH_taper.KC')} C C",
    ]
    for d in (3.4, 6.0):
        atoms = graphene_bilayer(d)
        assert energy(v20, atoms) == pytest.approx(
            lammps_energy(atoms, [1, 1, 2, 2], plain, [1, 1, 2, 2]), abs=1e-8
        )
    far = energy(cfg, graphene_bilayer(40.0))
    assert energy(v20, graphene_bilayer(40.0)) == pytest.approx(far, abs=1e-12)
    # between the two cutoffs: the 16 Å model has no interlayer energy left, the 20 Å one has
    e16, e20 = (energy(c, graphene_bilayer(17.0)) - far for c in (cfg, v20))
    assert abs(e16) < 1e-12
    assert e20 < -1e-7
    # at the equilibrium distance the longer taper keeps more of the fitted potential:
    # binding and corrugation (AA − AB) both grow, by a few per cent, not by a factor
    b16, b20 = (energy(c, graphene_bilayer(3.4)) - far for c in (cfg, v20))
    assert b20 < b16 < 0
    assert 1.0 < b20 / b16 < 1.1
    c16, c20 = (
        energy(c, graphene_bilayer(3.4, (0, 0))) - energy(c, graphene_bilayer(3.4))
        for c in (cfg, v20)
    )
    assert 1.0 < c20 / c16 < 1.1


@pytest.mark.slow
def test_a_cutoff_study_of_the_kc_bilayer_rebuilds_with_the_longer_taper(tmp_path):
    """One cutoff step 16 -> 20 Å on the rigid KC bilayer (3x3): the rung is its own model
    (its build is not the base's), its run directory holds the 20 Å style, and the step moves
    τ and σ_MSS by a few per cent at most (the taper's weight at the interlayer distance
    changes by 2 %: 0.959 -> 0.981), so the setting converges at the 3 % default or says
    which load moved more."""
    from flatcontact.studies.convergence import run_convergence

    cfg = bilayer("graphene-rebo-kc", settings=["cutoff"], max_steps=1)
    doc = run_convergence(cfg, tmp_path)
    st = doc["settings"]["cutoff"]
    assert st["state"] in ("converged", "not converged") and st["steps"] == 1
    assert st["base_value"] == 16.0
    assert 0.0 < st["last_change"]["max_pct"] < 10.0
    by = {v["name"]: v for v in doc["variants"]}
    assert by["cutoff1"]["values"] == {"cutoff": 20.0}
    config = (tmp_path / "runs" / "cutoff1" / "config.yaml").read_text()
    assert "kolmogorov/crespi/full 20 1" in config
    base_build = (tmp_path / "runs" / "base" / "01-build" / "stage.json").read_text()
    rung_build = (tmp_path / "runs" / "cutoff1" / "01-build" / "stage.json").read_text()
    assert base_build != rung_build
