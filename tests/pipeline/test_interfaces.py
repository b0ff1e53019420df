"""The run configuration for any interface: recipes in ``structure:``, the scan's relaxation
mode, direction 'auto', the elastic stage on the slab material and the moduli rule."""

from __future__ import annotations

import pytest

from flatcontact.config import build_config, load_config
from flatcontact.foundation.errors import InputError
from flatcontact.stages.scan import grid_spec, relax_settings


def _build_structure_inputs(cfg, root):
    from flatcontact.pipeline import Pipeline

    pipe = Pipeline(cfg, root)
    captured = {}

    class Stop(Exception):
        pass

    def record(name, inputs, work):
        captured[name] = inputs
        raise Stop

    pipe._run = record
    with pytest.raises(Stop):
        pipe.build()
    return captured["build"]["structure"]


def test_default_structure_section_keeps_the_fingerprint_of_runs_before_recipes(tmp_path):
    """The build stage's structure inputs of the default run are the earlier flat section, plus
    ``lattice: potential`` since the slabs are cut at the model's own lattice (another
    structure); with ``lattice: file`` (what every recipe meant before) exactly the earlier one."""
    cfg = load_config()
    earlier = {
        "kind": "quartz-dense",
        "layers": 6,
        "source": cfg.structure.source,
        "file": None,
        "gap_angstrom": 3.0,
        "fmax_ev_per_angstrom": 0.01,
    }
    assert _build_structure_inputs(cfg, tmp_path / "run") == {**earlier, "lattice": "potential"}
    kept = cfg.model_copy(
        update={"structure": cfg.structure.model_copy(update={"lattice": "file"})}
    )
    assert _build_structure_inputs(kept, tmp_path / "kept") == earlier


@pytest.mark.parametrize("key", ["face_depth_angstrom: 2.0", "normal_axis: 2", "layers: 6"])
def test_a_key_the_recipe_lacks_is_refused_naming_it(tmp_path, key):
    slab = tmp_path / "slab.extxyz"
    from ase.build import fcc111

    fcc111("Cu", (1, 1, 3), vacuum=5.0, a=3.615).write(slab)
    path = tmp_path / "c.yaml"
    path.write_text(
        "structure: {kind: slab, file: slab.extxyz}\npotential: {preset: cu-eam}\n"
        "elastic: {enabled: false}\ncontact: {contact_modulus_gpa: 70, shear_modulus_gpa: 55}\n"
    )
    cfg = load_config(path)
    assert cfg.structure.kind == "slab" and cfg.structure.file == str(slab.resolve())
    path.write_text(path.read_text().replace("slab.extxyz}", f"slab.extxyz, {key}}}"))
    name = key.partition(":")[0]
    with pytest.raises(InputError, match=rf"c\.yaml: structure\.{name}: unknown field$"):
        load_config(path)


def test_another_kind_does_not_inherit_the_presets_quartz_keys():
    cfg = build_config(
        {"structure": {"kind": "fcc111", "element": "Cu"}, "elastic": {"enabled": True}}
    )
    assert cfg.structure.kind == "fcc111" and cfg.structure.layers == 6
    with pytest.raises(InputError, match=r"structure.elemnt"):
        build_config({"structure": {"kind": "fcc111", "element": "Cu", "elemnt": "Ni"}})


def test_recipe_files_are_relative_to_the_config_and_must_exist(tmp_path):
    path = tmp_path / "c.yaml"
    path.write_text("structure: {kind: crystal, bulk: missing.cif, miller: [1, 1, 1]}\n")
    with pytest.raises(InputError, match=r"structure.bulk: file .*missing.cif not found"):
        load_config(path)
    # a built-in sheet name stays a name
    path.write_text(
        "structure: {kind: sheets, sheet: graphene}\npotential: {preset: graphene-rebo-kc}\n"
        "elastic: {enabled: true}\n"
    )
    assert load_config(path).structure.sheet == "graphene"


def test_relax_mode_and_bracket_reach_the_scan_and_leave_the_default_dump_unchanged():
    default = build_config({})
    assert "relax_mode" not in default.section("scan")
    assert "bracket_all_stackings" not in default.section("scan")
    cfg = build_config({"scan": {"relax_mode": "normal", "bracket_all_stackings": False}})
    assert relax_settings(cfg.scan).mode == "normal"
    assert grid_spec(cfg.scan).bracket_all_stackings is False
    with pytest.raises(InputError, match=r"scan.relax_mode"):
        build_config({"scan": {"relax_mode": "sideways"}})


def test_direction_auto_and_angles():
    assert build_config({"analysis": {"direction_deg": "auto"}}).analysis.direction_deg == "auto"
    assert build_config({"analysis": {"direction_deg": 30}}).analysis.direction_deg == 30.0
    with pytest.raises(InputError, match=r"analysis.direction_deg"):
        build_config({"analysis": {"direction_deg": "north"}})


def test_elastic_stage_on_fcc_copper_gives_mishins_elastic_constants():
    """Mishin et al. (2001), Table: C11 = 169.9, C12 = 122.6, C44 = 76.2 GPa for this EAM."""
    from flatcontact.stages.elastic import ElasticInputs, elastic_stage

    cfg = build_config(
        {
            "structure": {"kind": "fcc111", "element": "Cu", "a_angstrom": 3.615},
            "potential": {"preset": "cu-eam"},
            "elastic": {"enabled": True},
        }
    )
    doc = elastic_stage(cfg, ElasticInputs(), None).to_json()
    c = doc["tensor_gpa"]
    assert c[0][0] == pytest.approx(169.9, rel=0.01)
    assert c[0][1] == pytest.approx(122.6, rel=0.01)
    assert c[3][3] == pytest.approx(76.2, rel=0.01)
    assert doc["crystal"]["crystal"] == "fcc Cu"
    # the contact moduli are the Hill-averaged isotropic ones, two identical bodies
    e, nu, g = (doc["moduli_gpa"][k] for k in ("youngs_modulus", "poisson_ratio", "shear_modulus"))
    assert doc["contact_modulus_gpa"] == pytest.approx(e / (2 * (1 - nu**2)))
    assert doc["shear_modulus_gpa"] == pytest.approx(4 * g / (2 * (2 - nu)))


def test_elastic_stage_refuses_a_hetero_interface_naming_the_fields():
    from flatcontact.stages.elastic import bulk_crystal

    cfg = build_config(
        {
            "structure": {"kind": "sheets", "sheet": "graphene", "slab2": {"sheet": "h-BN"}},
            "potential": {"preset": "graphene-hbn-ilp"},
            "elastic": {"enabled": True},
        }
    )
    with pytest.raises(InputError, match=r"elastic.enabled: structure.slab2") as exc:
        bulk_crystal(cfg.structure)
    assert "contact.contact_modulus_gpa" in str(exc.value)


def test_quartz_file_takes_the_paper_moduli_and_a_metal_file_does_not(tmp_path):
    from ase.build import fcc111

    from flatcontact.stages.contact import check_moduli_source

    slab = tmp_path / "cu.extxyz"
    fcc111("Cu", (1, 1, 3), vacuum=5.0, a=3.615).write(slab)
    cfg = build_config(
        {"structure": {"kind": "slab", "file": str(slab)}, "potential": {"preset": "cu-eam"}}
    )
    check_moduli_source(cfg, {"Si", "O"})  # the paper's material: defaults apply
    with pytest.raises(InputError, match=r"structure.kind=slab \(Cu\)"):
        check_moduli_source(cfg, {"Cu"})
