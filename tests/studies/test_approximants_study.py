"""``flatcontact study approximants``: the plan, the scaling fit, the files, the refusals,
and (slow) τ of twisted bilayer graphene falling with the cell size."""

from __future__ import annotations

import csv
import io
import itertools
import json
import math

import numpy as np
import pytest
from matplotlib.figure import Figure
from tests.cli.cli_helpers import one_error_line, run_cli

from flatcontact.config.load import build_config
from flatcontact.foundation.errors import InputError
from flatcontact.plots.approximants import figure_approximants
from flatcontact.studies.approximants import RESOLVED_FACTOR, plan, run_approximants
from flatcontact.studies.output import (
    APPROXIMANTS_COLUMNS,
    approximants_csv_text,
    write_approximants,
)
from flatcontact.studies.scaling import fit_offset_power_law, fit_power_law, fit_scaling

TBG = {
    "structure": {"kind": "sheets", "sheet": "graphene", "layers": 1},
    "potential": {"preset": "graphene-rebo-kc"},
    "scan": {
        "grid": [6, 6],
        "p_range_gpa": {"lo_gpa": 0.0, "hi_gpa": 2.0, "n": 4},
        "relax_mode": "rigid-layers",
        "executor": "serial",
    },
    "analysis": {"p_gpa": [0.0, 0.5, 1.0, 1.5], "direction_deg": "auto"},
    "elastic": {"enabled": True},
    "approximants": {"max_cells": 3},
}


# ------------------------------------------------------------------ scaling fits
def test_the_power_law_recovers_a_known_exponent_and_prefactor():
    n = np.array([28.0, 76.0, 148.0, 244.0])
    y = 40.0 * n**-1.5
    fit = fit_power_law(n, y)
    assert fit["exponent"] == pytest.approx(1.5, rel=1e-9)
    assert fit["prefactor"] == pytest.approx(40.0, rel=1e-9)
    assert fit["exponent_half_width"] < 1e-6


def test_the_offset_power_law_recovers_exponent_and_limit_within_its_interval():
    rng = np.random.default_rng(7)
    n = np.array([28.0, 52.0, 76.0, 148.0, 244.0, 364.0, 508.0])
    truth = {"limit": 0.8, "prefactor": 300.0, "exponent": 1.2}
    y = truth["limit"] + truth["prefactor"] * n ** -truth["exponent"]
    y = y * (1 + 0.002 * rng.standard_normal(n.size))
    fit = fit_offset_power_law(n, y)
    for key in ("limit", "exponent"):
        assert abs(fit[key] - truth[key]) < fit[f"{key}_half_width"], (key, fit)
    assert fit["exponent_half_width"] < 0.1
    # the power law without the limit is biased on these data: its exponent is lower
    assert fit_power_law(n, y)["exponent"] < truth["exponent"] - 0.1


def test_too_few_cells_or_a_non_positive_value_is_refused_with_its_reason():
    fits = fit_scaling([28, 76], [1.0, 0.1])
    assert "needs at least 3" in fits["power_law"]["refused"]
    assert "at least 4" in fits["offset_power_law"]["refused"]
    assert "not positive" in fit_power_law([28, 76, 148], [1.0, -0.1, 0.01])["refused"]
    assert (
        "at least 4" in fit_scaling([28, 76, 148], [1.0, 0.1, 0.01])["offset_power_law"]["refused"]
    )


def test_a_power_law_through_values_that_go_up_and_down_is_refused_with_its_numbers():
    """τ0 of twisted h-BN (ILP, rigid layers, measured with this study over 28, 76, 148
    atoms) rises then falls: no c·N^−α does that. The fit is refused, keeping the least-squares
    exponent (checked against scipy's linregress); the same points in falling order are fitted."""
    from scipy import stats

    n = np.array([28.0, 76.0, 148.0])
    up_down = np.array([0.00618, 0.0204, 0.00149])
    reg = stats.linregress(np.log(n), np.log(up_down))
    fit = fit_power_law(n, up_down)
    assert "go up and down" in fit["refused"] and "prefactor" not in fit
    assert fit["exponent"] == pytest.approx(-reg.slope, rel=1e-9)
    assert fit["exponent_half_width"] == pytest.approx(stats.t.ppf(0.975, 1) * reg.stderr)
    falling = np.sort(up_down)[::-1]
    kept = fit_power_law(n, falling)
    assert "refused" not in kept
    assert kept["exponent"] == pytest.approx(-stats.linregress(np.log(n), np.log(falling)).slope)
    # the order is by atom count, not by the order the cells are given in
    assert "refused" not in fit_power_law(n[::-1], falling[::-1])


# ------------------------------------------------------------------ plan and files
def test_the_plan_of_twisted_bilayer_graphene_keeps_the_base_grid_per_period():
    cells = plan(build_config(TBG))
    assert [c["label"] for c in cells] == ["twist-1-2", "twist-2-3", "twist-3-4"]
    assert [c["n_atoms"] for c in cells] == [28, 76, 148]
    for c, big in zip(cells, (7, 19, 37), strict=True):
        assert c["shift_lattice_index"] == big * big
        assert math.gcd(c["grid"][0], c["shift_lattice_index"]) == 1
        assert c["grid"] == [6, 6]
        assert c["config"]["structure"]["twist"] == c["structure_override"]["twist"]
        assert c["config"]["scan"]["symmetry"]["enabled"] == "auto"  # reduced like any cell
    assert cells[0]["twist_deg"] == pytest.approx(21.786789, abs=1e-5)


@pytest.mark.parametrize(
    ("mode", "enabled"),
    [("rigid-layers", "auto"), ("normal", "auto"), ("normal", True), ("full", "auto")],
)
def test_the_plan_keeps_the_configured_symmetry_in_every_mode(mode, enabled):
    """No special case for relaxed cells: the scan's verification is relative to each cell's
    own landscape (:func:`flatcontact.ispes.reduction.energy_tolerances`), so a relaxed cell
    that breaks its group is computed in full by the scan itself."""
    cfg = {**TBG, "scan": {**TBG["scan"], "relax_mode": mode, "symmetry": {"enabled": enabled}}}
    cells = plan(build_config(cfg))
    assert all(c["shift_lattice_index"] > 1 for c in cells)
    for c in cells:
        assert c["config"]["scan"]["symmetry"]["enabled"] == enabled


def _fake_doc() -> dict:
    cells = []
    for i, (n, tau, barrier) in enumerate(((28, 1.4, 0.05), (76, 0.2, 0.004), (148, 0.03, 3e-4))):
        cells.append(
            {
                "label": f"twist-{i + 1}-{i + 2}",
                "n_atoms": n,
                "twist_deg": 21.8 - 6 * i,
                "angle_error_deg": 0.0,
                "strain_percent_slab1": 0.0,
                "strain_percent_slab2": 0.0,
                "shift_lattice_index": 49,
                "grid": [6, 6],
                "tau0_mpa": tau,
                "k_mpa_per_gpa": 0.02,
                "sigma0_mpa": tau / 3,
                "mu_mpa_per_gpa": 0.006,
                "barrier_mev_per_a2": barrier,
                "noise_mev_per_a2": 1e-8,
                "relax_noise_mev_per_a2": math.nan,
                "floor_mev_per_a2": 1e-8,
                "relax_noise": None,
                "resolved": True,
                "force_calls": 144,
                "wall_s": 20.0,
                "gates": {"fired": ["negative_slope"] if i == 2 else []},
            }
        )
    cells.append({**cells[0], "label": "twist-4-5", "n_atoms": 244, "error": "refused"})
    ok = cells[:3]
    n = [c["n_atoms"] for c in ok]
    return {
        "study": "approximants",
        "relax_mode": "rigid-layers",
        "cells": cells,
        "scaling": {
            "tau0_mpa": fit_scaling(n, [c["tau0_mpa"] for c in ok]),
            "barrier_mev_per_a2": fit_scaling(n, [c["barrier_mev_per_a2"] for c in ok]),
        },
    }


def test_the_csv_has_one_row_per_cell_with_the_documented_columns(tmp_path):
    doc = _fake_doc()
    rows = list(csv.DictReader(io.StringIO(approximants_csv_text(doc))))
    assert tuple(rows[0]) == APPROXIMANTS_COLUMNS
    for required in (
        "label",
        "atoms",
        "twist_deg",
        "strain_percent_slab1",
        "strain_percent_slab2",
        "tau0_mpa",
        "k_mpa_per_gpa",
        "sigma0_mpa",
        "mu_mpa_per_gpa",
        "barrier_mev_per_a2",
        "force_calls",
        "wall_s",
    ):
        assert required in APPROXIMANTS_COLUMNS
    assert [r["atoms"] for r in rows] == ["28", "76", "148", "244"]
    assert float(rows[1]["tau0_mpa"]) == 0.2
    assert rows[2]["gates"] == "negative_slope"
    assert rows[3]["error"] == "refused" and rows[3]["tau0_mpa"] == ""
    files = write_approximants(doc, tmp_path, "flatcontact study approximants x.yaml")
    assert {f.name for f in files} == {"study.json", "approximants.csv", "approximants.png"}
    assert json.loads((tmp_path / "study.json").read_text())["provenance"]["command"]


def _relaxed_doc() -> dict:
    """The fake study as a relaxed one: the first cell's relaxation floor is measured (with its
    cost), the second's is above its corrugation (unresolved, with the advice line), the third
    relaxes nothing (nan)."""
    from flatcontact.ispes.relax_noise import RelaxationNoise
    from flatcontact.studies.approximants import tolerance_advice

    doc = _fake_doc()
    for cell, relax in zip(doc["cells"][:2], (2.5e-7, 1e-3), strict=True):
        measured = RelaxationNoise(relax * 1e-3, 0.01, "normal", 12, 340, 0, 0.02)
        cell.update(
            relax_noise_mev_per_a2=relax,
            floor_mev_per_a2=max(relax, cell["noise_mev_per_a2"]),
            relax_noise=measured.to_json(),
            resolved=cell["barrier_mev_per_a2"] >= RESOLVED_FACTOR * relax,
            tolerance_advice=tolerance_advice(
                cell["barrier_mev_per_a2"], cell["noise_mev_per_a2"], measured
            ),
        )
    return {**doc, "relax_mode": "normal"}


def test_the_relaxation_floor_round_trips_through_the_csv_and_study_json(tmp_path):
    doc = _relaxed_doc()
    write_approximants(doc, tmp_path, "flatcontact study approximants x.yaml")
    rows = list(csv.DictReader(io.StringIO((tmp_path / "approximants.csv").read_text())))
    back = json.loads((tmp_path / "study.json").read_text())["cells"]
    for cell, row, stored in zip(doc["cells"][:3], rows, back, strict=False):
        for key in ("noise_mev_per_a2", "relax_noise_mev_per_a2", "floor_mev_per_a2"):
            assert float(row[key]) == pytest.approx(cell[key], nan_ok=True, rel=0), key
            assert float(stored[key]) == pytest.approx(cell[key], nan_ok=True, rel=0), key
        assert row["resolved"] == str(cell["resolved"])
        assert stored["relax_noise"] == cell["relax_noise"]
    assert [r["resolved"] for r in rows[:3]] == ["True", "False", "True"]
    assert back[0]["relax_noise"]["mev_per_a2"] == pytest.approx(2.5e-7, rel=1e-12)
    assert back[0]["relax_noise"]["force_calls"] == 340
    assert rows[3]["relax_noise_mev_per_a2"] == rows[3]["floor_mev_per_a2"] == ""


def test_the_advice_names_the_tolerance_that_could_resolve_a_relaxed_cell():
    """Corrugation bound B below 10x the relaxation floor X at fmax f (and above 10x the
    round-off): the floor ∝ fmax² reaches B/10 at f·sqrt(B/(10 X)); nothing to say when the
    cell is resolved, when the round-off alone hides it, or when nothing relaxes."""
    from flatcontact.ispes.relax_noise import RelaxationNoise
    from flatcontact.studies.approximants import tolerance_advice

    measured = RelaxationNoise(1e-7, 0.01, "normal", 12, 300, 0, 0.02)  # 1e-4 meV/Å²
    line = tolerance_advice(2e-4, 2e-8, measured)
    assert "scan.fmax_ev_per_angstrom <= ~0.0044 " in line  # 0.01·sqrt(2e-4/1e-3) = 0.00447
    # the H 0.3 % cell at fmax 0.0005: 0.000486 was printed as the tolerance it ran at
    at_05 = RelaxationNoise(8.4e-9, 0.0005, "rigid-layers", 12, 300, 0, 0.02)  # 8.4e-6 meV/Å²
    bound = 10 * 8.4e-6
    advice = tolerance_advice(bound * (0.000486 / 0.0005) ** 2, 2e-9, at_05)
    assert "<= ~0.00048 " in advice
    assert "relaxation floor 0.0001" in line and "\n" not in line
    assert tolerance_advice(2e-3, 2e-8, measured) == ""  # resolved: 2e-3 >= 10 x 1e-4
    assert tolerance_advice(1e-7, 2e-8, measured) == ""  # below 10x the round-off too
    assert tolerance_advice(2e-4, 2e-8, None) == ""


def test_the_figure_states_the_fit_or_why_there_is_none():
    doc = _fake_doc()
    fig = figure_approximants(doc)
    assert isinstance(fig, Figure)
    texts = [t.get_text() for ax in fig.axes for t in ax.texts]
    assert any("α = " in t for t in texts)
    assert any("y∞ + c·N^−α: not fitted" in t for t in texts)


# ------------------------------------------------------------------ refusals
def test_a_bad_section_is_refused_in_one_line(tmp_path, capsys):
    with pytest.raises(InputError, match=r"approximants\.max_cells"):
        build_config({**TBG, "approximants": {"max_cells": 0}})
    cfg = tmp_path / "bad.yaml"
    cfg.write_text(
        "structure: {kind: sheets, sheet: graphene}\nelastic: {enabled: true}\n"
        "approximants: {strain_percent: [1, 3]}\n"
    )
    line = one_error_line(*run_cli(["study", "approximants", str(cfg), "--list"], capsys)[::2])
    assert "approximants.strain_percent" in line


def test_a_structure_without_a_second_slab_is_refused_before_any_work(tmp_path, capsys):
    cfg = tmp_path / "toy.yaml"
    cfg.write_text("structure: {kind: quartz-dense}\n")
    line = one_error_line(*run_cli(["study", "approximants", str(cfg), "--list"], capsys)[::2])
    assert "structure.kind" in line
    assert not (tmp_path / "flatcontact-study").exists()


def test_list_prints_the_cells_and_runs_nothing(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    cfg = tmp_path / "tbg.yaml"
    cfg.write_text(json.dumps(TBG))
    code, out, _ = run_cli(["study", "approximants", str(cfg), "--list"], capsys)
    assert code in (0, None)
    assert "twist-3-4: 148 atoms" in out and "shift lattice index 1369" in out
    assert not (tmp_path / "flatcontact-study").exists()


# ------------------------------------------------------------------ physics (slow)
@pytest.mark.slow
def test_tau_of_twisted_bilayer_graphene_falls_with_the_cell_size(tmp_path):
    """Rigid-layers REBO + KC over the (1, 2), (2, 3), (3, 4) cells (28, 76, 148 atoms): the
    corrugation falls by orders of magnitude per cell, so the cells whose corrugation is
    resolved above the energy noise floor have strictly falling τ0 and corrugation, the
    first two are resolved, and a cell that is not resolved has a noise floor (its
    corrugation's upper bound, times the resolution factor) below the resolved corrugation of
    the cell before it. τ0 of (1, 2) is far below the AB bilayer's ≈ 226 MPa (docs/studies.md)
    and no gate fires on it. Measured: 1.40 MPa, 9.5e-5 MPa, (3, 4) not resolved (~5 min)."""
    doc = run_approximants(build_config(TBG), tmp_path)
    cells = doc["cells"]
    assert not doc["failed"], doc["failed"]
    assert cells[0]["resolved"] and cells[1]["resolved"], cells
    resolved = [c for c in cells if c["resolved"]]
    taus = [c["tau0_mpa"] for c in resolved]
    barriers = [c["barrier_mev_per_a2"] for c in resolved]
    assert all(a > b > 0 for a, b in itertools.pairwise(taus)), taus
    assert all(a > b > 0 for a, b in itertools.pairwise(barriers)), barriers
    for before, cell in itertools.pairwise(cells):
        if not cell["resolved"]:
            assert before["resolved"]
            bound = RESOLVED_FACTOR * cell["noise_mev_per_a2"]
            assert bound < before["barrier_mev_per_a2"], (before, cell)
    assert cells[0]["tau0_mpa"] < 226.0 / 50
    # the first cell is clean; the (2, 3) landscape is only ~20x its noise floor, so gates
    # on its minima and slopes may fire (measured: degenerate_minima, negative_slope)
    assert cells[0]["gates"]["fired"] == [], cells[0]["gates"]


def test_a_cell_whose_gates_fired_leaves_the_fit_and_is_named():
    """A number the tool distrusts does not flow silently into the scaling fit: a resolved cell
    whose laws are gated (degenerate_minima) leaves the τ0 fit but not the corrugation fit (that
    gate distrusts the laws, not the landscape); broken_symmetry distrusts both; an accepted gate
    (contact.accept_untrusted) counts as not fired; the console line names what was left out."""
    from flatcontact.cli.study import _scaling_line
    from flatcontact.studies.approximants import scaling_block

    def cell(label, n, tau0, fired=()):
        return {
            "label": label,
            "n_atoms": n,
            "tau0_mpa": tau0,
            "barrier_mev_per_a2": tau0 / 100,
            "resolved": True,
            "gates": {"fired": list(fired)},
        }

    cells = [
        cell("a", 28, 1.0),
        cell("b", 76, 0.3),
        cell("c", 148, 0.1, ["degenerate_minima"]),
        cell("d", 244, 0.05, ["broken_symmetry"]),
    ]
    doc = scaling_block(cells, set())
    assert doc["tau0_mpa"]["cells"] == ["a", "b"]
    assert doc["tau0_mpa"]["gated"] == {"c": ["degenerate_minima"], "d": ["broken_symmetry"]}
    assert "refused" in doc["tau0_mpa"]["power_law"]  # 2 cells left: no fit
    assert doc["barrier_mev_per_a2"]["cells"] == ["a", "b", "c"]
    assert doc["barrier_mev_per_a2"]["gated"] == {"d": ["broken_symmetry"]}
    assert "refused" not in doc["barrier_mev_per_a2"]["power_law"]
    line = _scaling_line("tau0", doc["tau0_mpa"])
    assert "left out (gates fired): c (degenerate_minima), d (broken_symmetry)" in line
    accepted = scaling_block(cells, {"degenerate_minima", "broken_symmetry"})
    assert accepted["tau0_mpa"]["cells"] == ["a", "b", "c", "d"]
    assert not accepted["tau0_mpa"]["gated"]


# ------------------------------------------------------------------ contact moduli
#: Twisted h-BN as a new user writes it: no moduli source (no contact.*_modulus_gpa, no
#: elastic stage), the study's loads.
HBN = {
    **TBG,
    "structure": {"kind": "sheets", "sheet": "h-BN", "layers": 1},
    "potential": {"preset": "hbn-tersoff-ilp"},
    "elastic": {"enabled": False},
    "approximants": {"max_cells": 2},
}
EXPERIMENT = {"experiment": {"compare": "passivated-tip", "p0_gpa": 1.77}}


def test_without_the_experiment_comparison_no_moduli_are_needed(tmp_path):
    """The study runs build and scan only: a configuration without contact moduli plans, and
    each cell's own pipeline (its preflight: build unrelaxed, model set up) accepts it."""
    from flatcontact.config.run import RunConfig
    from flatcontact.pipeline import Pipeline

    cells = plan(build_config(HBN))
    assert [c["label"] for c in cells] == ["twist-1-2", "twist-2-3"]
    with Pipeline(RunConfig.model_validate(cells[0]["config"]), tmp_path / "cell"):
        pass


def test_the_experiment_comparison_without_moduli_is_refused_before_any_work(tmp_path, capsys):
    """With contact.experiment.compare each cell's laws go through the contact model: without
    E*, G* it would take the quartz defaults. Refused in one line naming both fields, before a
    cell is built; elastic.enabled does not count (the study runs no elastic stage); both
    moduli given are accepted."""
    for extra in ({}, {"elastic": {"enabled": True}}):
        with pytest.raises(InputError) as info:
            plan(build_config({**HBN, **extra, "contact": EXPERIMENT}))
        text = str(info.value)
        assert "\n" not in text
        assert text.startswith("contact.contact_modulus_gpa/shear_modulus_gpa:")
        assert "contact.experiment.compare" in text and "structure.kind=sheets" in text
    given = {**EXPERIMENT, "contact_modulus_gpa": 30.0, "shear_modulus_gpa": 20.0}
    assert len(plan(build_config({**HBN, "contact": given}))) == 2
    cfg = tmp_path / "hbn.yaml"
    cfg.write_text(json.dumps({**HBN, "contact": EXPERIMENT}))
    line = one_error_line(
        *run_cli(["study", "approximants", str(cfg), "--out", str(tmp_path / "s")], capsys)[::2]
    )
    assert "contact.experiment.compare" in line
    assert not (tmp_path / "s").exists()


def test_a_cut_off_coulomb_term_across_the_interface_is_stated(tmp_path, capsys):
    """The h-BN ILP preset carries coul/shield cut off at 16 A across the interface, whose
    registry dependence (not the ILP's) is the whole corrugation of rigid twisted h-BN from
    the second cell on (docs/incommensurate.md): the study says so, naming the style; REBO +
    KC graphene has no such term and gets no caveat."""
    from flatcontact.studies.approximants import model_caveats

    assert model_caveats(build_config(TBG)) == []
    # graphene on h-BN: the same coul/shield style, but the graphene sheet has no charge
    gr_hbn = {
        **HBN,
        "structure": {"kind": "sheets", "sheet": "graphene", "slab2": {"sheet": "h-BN"}},
        "potential": {"preset": "graphene-hbn-ilp"},
    }
    assert model_caveats(build_config(gr_hbn)) == []
    (caveat,) = model_caveats(build_config(HBN))
    assert caveat.startswith("potential.interlayer 'coul/shield 16.0 1': a Coulomb term cut off")
    assert "16 A" in caveat
    cfg = tmp_path / "hbn.yaml"
    cfg.write_text(json.dumps(HBN))
    code, out, _ = run_cli(["study", "approximants", str(cfg), "--list"], capsys)
    assert code in (0, None)
    assert "caveat: potential.interlayer 'coul/shield 16.0 1'" in out


def _lateral_range_mev_per_a2(cell_config: dict, interlayer: list, charges: dict | None):
    """Max − min of the energy per supercell area of a rigid cell over a 4 × 4 grid on one
    shift-lattice period at the reference thickness, with ``interlayer`` across (Tersoff in
    each sheet): slab 2 placed rigidly, one energy per shift."""
    from flatcontact.config.run import RunConfig
    from flatcontact.ispes.shift_lattice import shift_lattice_of
    from flatcontact.potentials.engines import make_calculator
    from flatcontact.structures.construct import build_interface
    from flatcontact.structures.interface_contract import in_plane_vectors, thickness
    from flatcontact.structures.placement import place_slab2

    data = dict(cell_config)
    data["potential"] = {
        "intra": [{"pair_style": "tersoff", "pair_coeff": ["BNC.tersoff"], "elements": ["B", "N"]}],
        "intra_scope": "layer",
        "coupling": "interlayer",
        "interlayer": interlayer,
        **({"charges": charges} if charges else {}),
    }
    cfg = RunConfig.model_validate(data)
    ref, _ = build_interface(cfg.structure)
    basis = shift_lattice_of(ref, 1e-3).basis
    a1, a2 = in_plane_vectors(ref)
    area = abs(a1[0] * a2[1] - a1[1] * a2[0])
    calc = make_calculator(cfg.potential, ref)
    energies = []
    for i, j in itertools.product(range(4), range(4)):
        s = i / 4 * basis[0] + j / 4 * basis[1]
        atoms = place_slab2(ref, float(s[0]), float(s[1]), thickness(ref), spread_compression=False)
        atoms.calc = calc
        energies.append(atoms.get_potential_energy())
    return 1e3 * (max(energies) - min(energies)) / area


def test_the_twisted_hbn_corrugation_beyond_the_first_cell_is_the_coulomb_cutoff():
    """The measurement behind the caveat (docs/incommensurate.md), on the rigid (2, 3) cell
    (76 atoms): the ILP alone has a lateral range > 1000x below the shielded Coulomb term at
    the preset's 16 A cutoff, and the Coulomb term's range falls > 10x when its cutoff goes to
    48 A (the infinite sum's is ~e^(-|G| d), nothing): the cutoff, not the ILP, the B/N
    sublattice or the Tersoff round-off, sets the corrugation. Measured 4.8e-9, 2.5e-5,
    1.7e-7 meV/A^2 on a 6 x 6 grid."""
    cell = plan(build_config(HBN))[1]
    assert cell["label"] == "twist-2-3"
    ilp = [
        {
            "pair_style": "ilp/graphene/hbn 16.0 1",
            "pair_coeff": ["BNCH.ILP"],
            "elements": ["B", "N"],
        }
    ]
    pairs = {"B-B": "0.70", "B-N": "0.69498201415576216335", "N-N": "0.69"}
    charges = {"B": 0.42, "N": -0.42}

    def coul(cut):
        return [{"pair_style": f"coul/shield {cut} 1", "pair_coeff_pairs": pairs}]

    ilp_only = _lateral_range_mev_per_a2(cell["config"], ilp, None)
    coul_16 = _lateral_range_mev_per_a2(cell["config"], coul(16.0), charges)
    coul_48 = _lateral_range_mev_per_a2(cell["config"], coul(48.0), charges)
    assert coul_16 > 1000 * ilp_only, (coul_16, ilp_only)
    assert coul_48 < coul_16 / 10, (coul_48, coul_16)
