"""CLI consistency: list flags, --version, typer's own errors, build's layers and file names,
``analyze --load-source``."""

import json

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from tests.cli.cli_helpers import one_error_line, run_cli

_run = run_cli
_one_error_line = one_error_line


# ---- empty items in comma lists ----------------------------------------------------------


@pytest.mark.parametrize("bad", ["1,,2", "1,", ",1", "1, ,2", ""])
@pytest.mark.parametrize(
    "argv, flag",
    [
        (["contact", "--p0-gpa"], "--p0-gpa"),
        (["analyze", "ispes.nc", "--p-gpa"], "--p-gpa"),
        (["scan", "--interface", "missing.extxyz", "--thickness-angstrom"], "--thickness-angstrom"),
    ],
)
def test_empty_list_item_is_one_line_before_work(tmp_path, monkeypatch, capsys, argv, flag, bad):
    monkeypatch.chdir(tmp_path)
    line = _one_error_line(*_run([*argv, bad], capsys)[::2])
    assert line.startswith(f"error: {flag} {bad!r}: empty item")
    assert list(tmp_path.iterdir()) == []


def test_list_flags_still_accept_every_documented_form(capsys):
    from flatcontact.cli.analyze import _split_arguments
    from flatcontact.cli.app import parse_floats

    assert parse_floats(["1,2", "3", " 4 , 5 ", "6 7"], "--x") == [1, 2, 3, 4, 5, 6, 7]
    path, p = _split_arguments(["my dir/ispes.nc", "2"], ["-0.5,1"])
    assert str(path) == "my dir/ispes.nc" and p == [-0.5, 1.0, 2.0]


_finite = st.floats(allow_nan=False, allow_infinity=False, width=32)


@given(st.lists(_finite, min_size=1, max_size=6), st.integers(0, 6))
def test_parse_floats_round_trip_and_refuses_any_empty_item(values, where):
    from flatcontact.cli.app import parse_floats
    from flatcontact.foundation.errors import InputError

    items = [repr(float(v)) for v in values]
    assert parse_floats([",".join(items)], "--x") == [float(v) for v in values]
    holed = items[:]
    holed.insert(min(where, len(items)), "")
    with pytest.raises(InputError, match=r"^--x .*empty item"):
        parse_floats([",".join(holed)], "--x")


# ---- --version ---------------------------------------------------------------------------


def test_version_option_and_subcommand_agree(capsys):
    from flatcontact import __version__

    code, out, err = _run(["--version"], capsys)
    assert code == 0 and out.strip() == __version__ and err == ""
    code, out2, _ = _run(["version"], capsys)
    assert code == 0 and out2 == out


# ---- typer's own usage errors are one line -----------------------------------------------


@pytest.mark.parametrize(
    "argv, words",
    [
        (["build", "--layers", "abc"], ["'--layers'", "flatcontact build --help"]),
        (["analyze"], ["Missing argument", "flatcontact analyze --help"]),
        (["contact", "--no-such-flag"], ["--no-such-flag", "flatcontact contact --help"]),
        (["scan", "--grid", "3"], ["'--grid'", "2 arguments"]),
        (["no-such-command"], ["no-such-command", "flatcontact --help"]),
    ],
)
def test_usage_errors_are_one_line(tmp_path, monkeypatch, capsys, argv, words):
    monkeypatch.chdir(tmp_path)
    line = _one_error_line(*_run(argv, capsys)[::2])
    assert all(w in line for w in words), line
    assert list(tmp_path.iterdir()) == []


def test_help_still_exits_zero(capsys):
    code, out, _ = _run(["build", "--help"], capsys)
    assert code == 0 and "--layers" in out


# ---- build: the minimum number of layers, the same for build and the run config -----------


def test_min_layers_leaves_one_inner_layer_between_fixed_and_sliding_faces():
    """The reason for MIN_LAYERS: with the faces tagged as the scan uses them (outer face fixed,
    inner face sliding), a slab of MIN_LAYERS units has exactly one untagged (inner, fully
    relaxed) unit; with one unit fewer the two face layers would touch and the interface
    cannot even be tagged."""
    from flatcontact.foundation.errors import InputError
    from flatcontact.structures.assemble import make_interface
    from flatcontact.structures.build import SYMMETRIC_CUT
    from flatcontact.structures.dense import QUARTZ_ATOMS_PER_LAYER
    from flatcontact.structures.interface_contract import fixed_mask
    from flatcontact.structures.quartz_layers import DENSE_FACE_LAYERS, MIN_LAYERS
    from flatcontact.structures.slab import quartz_0001_slab

    assert MIN_LAYERS == 2 * DENSE_FACE_LAYERS + 1 == 5
    face = DENSE_FACE_LAYERS * QUARTZ_ATOMS_PER_LAYER
    with pytest.raises(InputError, match="face_atoms"):
        make_interface(
            quartz_0001_slab(layers=MIN_LAYERS - 1, cut=SYMMETRIC_CUT), 3.0, face_atoms=face
        )
    for layers, inner_units in ((MIN_LAYERS, 1), (6, 2)):
        slab = quartz_0001_slab(layers=layers, cut=SYMMETRIC_CUT)
        atoms = make_interface(slab, 3.0, face_atoms=face)
        surface, which = atoms.arrays["surface"], atoms.arrays["slab"]
        for s in (1, 2):
            inner = np.count_nonzero((surface == 0) & (which == s))
            assert inner == inner_units * QUARTZ_ATOMS_PER_LAYER, (layers, s)
        assert np.count_nonzero(fixed_mask(atoms)) == 2 * face


def test_build_and_config_refuse_the_same_layer_counts(tmp_path, monkeypatch, capsys):
    from pydantic import ValidationError

    from flatcontact.structures.quartz_layers import MIN_LAYERS, check_layers
    from flatcontact.structures.recipe import QuartzDenseRecipe

    monkeypatch.chdir(tmp_path)
    for layers in (MIN_LAYERS - 1, 1, 0, -3):
        line = _one_error_line(*_run(["build", "--layers", str(layers)], capsys)[::2])
        assert line.startswith(f"error: --layers={layers}: expected an integer >= {MIN_LAYERS}")
        with pytest.raises(ValidationError, match=f"needs >= {MIN_LAYERS}"):
            QuartzDenseRecipe(layers=layers)
    line = _one_error_line(*_run(["build", "--layers", "4", "--regenerate-dense"], capsys)[::2])
    assert "--layers=4" in line
    assert list(tmp_path.iterdir()) == []
    assert check_layers(MIN_LAYERS) == QuartzDenseRecipe(layers=MIN_LAYERS).layers == MIN_LAYERS


def test_build_writes_the_run_build_stage_names(tmp_path, capsys):
    """`flatcontact build` writes what the run's 01-build/ holds: interface.extxyz, build.json,
    fig1_interface.png (+ .svg); build.json's thickness is the written interface's."""
    from flatcontact.structures.interface_contract import thickness
    from flatcontact.structures.interface_io import read_interface

    out = tmp_path / "b"
    code, stdout, err = _run(["build", "--potential", "vashishta", "--out", str(out)], capsys)
    assert code == 0, err
    assert sorted(p.name for p in out.iterdir()) == [
        "build.json",
        "fig1_interface.png",
        "fig1_interface.svg",
        "interface.extxyz",
    ]
    report = json.loads((out / "build.json").read_text())
    assert report["thickness_angstrom"] == pytest.approx(
        thickness(read_interface(out / "interface.extxyz")), abs=1e-6
    )
    assert report["layers"] == 6 and report["interface_verification"]["slab2"]["dense"]
    assert "build.json" in stdout and "fig1_interface.png" in stdout
    code, _, _ = _run(
        ["build", "--potential", "vashishta", "--out", str(tmp_path / "c"), "--no-svg"], capsys
    )
    assert code == 0 and not (tmp_path / "c" / "fig1_interface.svg").exists()


# ---- analyze --load-source ---------------------------------------------------------------


@pytest.fixture(scope="module")
def grids(tmp_path_factory):
    """A noise-free synthetic grid and the same grid with 0.02 GPa of noise on the stress
    (thicknesses on the repulsive branch: p = 23 .. -1.5 GPa, the maximum tension is beyond)."""
    from flatcontact.analysis import synthetic as syn
    from flatcontact.ispes.contract import write_ispes

    a1, a2 = syn.hexagonal_cell()
    model = syn.SyntheticInterface(
        a1,
        a2,
        syn.three_cosine(a1, a2, (1.0, 0.9, 1.1)),
        corrugation_ev_per_a2=-2e-4,
        gap_modulation_angstrom=-0.02,
    )
    z = np.linspace(24.3, 25.3, 12)
    folder = tmp_path_factory.mktemp("grids")
    paths = {}
    for name, noise in (("clean", 0.0), ("noisy", 0.02)):
        paths[name] = folder / f"{name}.nc"
        write_ispes(model.grid(8, 8, z, stress_noise_gpa=noise, seed=3), paths[name])
    return paths


def _analyze(path, source, capsys, *extra):
    argv = ["analyze", str(path), "--p-gpa", "0.5,1,2", "--load-source", source, "--json"]
    code, out, err = _run([*argv, *extra], capsys)
    assert code == 0, err
    return json.loads(out)


@pytest.mark.parametrize("source", ["energy", "stress"])
def test_analyze_load_source_json(grids, capsys, source):
    data = _analyze(grids["clean"], source, capsys)
    assert data["load_source"] == source and data["noise"]["load_source"] == source
    assert [row["p_gpa"] for row in data["pressures"]] == [0.5, 1.0, 2.0]
    for row in data["pressures"]:
        assert row["tau_mpa"] > 0
        for key in ("energy_noise_mev_per_a2", "force_noise_mpa"):
            assert key in row and (row[key] is None or row[key] >= 0)


def test_analyze_load_sources_agree_without_noise_and_energy_ignores_stress_noise(grids, capsys):
    """Noise-free: both sources read the same closed-form model, so τ agrees. With 0.02 GPa
    of stress noise the stress source's δp sees it and the energy source's τ barely moves."""
    tau = {
        (g, s): [r["tau_mpa"] for r in _analyze(grids[g], s, capsys)["pressures"]]
        for g in ("clean", "noisy")
        for s in ("energy", "stress")
    }
    np.testing.assert_allclose(tau["clean", "energy"], tau["clean", "stress"], rtol=0.01)
    np.testing.assert_allclose(tau["noisy", "energy"], tau["clean", "energy"], rtol=0.01)
    noisy_stress = _analyze(grids["noisy"], "stress", capsys)["noise"]
    assert noisy_stress["delta_p_gpa"] == pytest.approx(0.02, rel=0.5)


@pytest.mark.parametrize("bad", ["Energy", "forces", ""])
def test_analyze_bad_load_source_is_one_line(grids, tmp_path, capsys, bad):
    out = tmp_path / "res"
    argv = ["analyze", str(grids["clean"]), "--p-gpa", "1", "--load-source", bad, "--out", str(out)]
    line = _one_error_line(*_run(argv, capsys)[::2])
    assert line == f"error: --load-source: expected 'energy' or 'stress', got \"{bad}\""
    assert not out.exists()


def test_build_layers_the_shipped_slab_cannot_reach_is_one_line(capsys):
    """`build --layers 7 --source shipped`: one line naming --layers and the reachable counts
    (the shipped 6-layer slab grows by whole α-quartz c-repeats of 3 layers), before any work."""
    line = _one_error_line(*_run(["build", "--layers", "7", "--source", "shipped"], capsys)[::2])
    assert line.startswith("error: --layers=7: the shipped dense slab has 6 O-Si-O layers")
    assert "expected 6, 9, 12, ..." in line
