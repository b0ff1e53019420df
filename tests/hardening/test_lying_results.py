"""``friction.nc`` and ``contact.nc`` that lie: the pipeline reads them back through the
checked reader (:mod:`flatcontact.stages.result_files`).

A results file changed after its stage is recomputed (the stage record keeps its SHA-256,
:mod:`flatcontact.foundation.rundir`); these tests make the record lie too (the digest of the damaged
file written into ``stage.json``), so the file reaches the reader: it is refused in one
``error:`` line naming the file and the defect, never used. An honest rerun still reads the
same numbers as the first run.
"""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest
import xarray as xr
from tests.hardening.helpers import TOY_YAML, refused, run_cli, tree

from flatcontact.config import build_config
from flatcontact.foundation.errors import InputError
from flatcontact.foundation.fileio import file_sha256
from flatcontact.stages.result_files import CONTACT, FRICTION, open_result


@pytest.fixture(scope="module")
def toy_run(finished_toy):
    return finished_toy


def _edit(path, change):
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        ds = ds.load()
    ds = change(ds)
    path.unlink()
    ds.to_netcdf(path, engine="h5netcdf")


def _set(name, value):
    def change(ds):
        ds[name] = ds[name].copy(data=np.full(ds[name].shape, value))
        return ds

    return change


def _attr(name, value):
    def change(ds):
        ds.attrs[name] = value
        return ds

    return change


def _rename_index(ds, index, values):
    return ds.assign_coords({index: values})


#: (stage folder, file, change, words of the defect)
CASES = {
    "friction-tau-inf": ("03-analyze", "friction.nc", _set("tau_mpa", np.inf), "tau_mpa"),
    "friction-tau-nan": ("03-analyze", "friction.nc", _set("tau_mpa", np.nan), "tau_mpa"),
    "friction-a1-text": ("03-analyze", "friction.nc", _attr("a1", "2.8 0"), "'a1'"),
    "friction-loads-repeated": (
        "03-analyze",
        "friction.nc",
        lambda ds: _rename_index(ds, "p_gpa", [0.0, 0.5, 0.5]),
        "repeats a load",
    ),
    "friction-loads-changed": (
        "03-analyze",
        "friction.nc",
        lambda ds: _rename_index(ds, "p_gpa", [0.0, 0.5, 2.0]),
        "settings ask for",
    ),
    "friction-variable-dropped": (
        "03-analyze",
        "friction.nc",
        lambda ds: ds.drop_vars("sigma_mss_mpa"),
        "'sigma_mss_mpa' missing",
    ),
    "contact-stiffness-nan": (
        "06-contact",
        "contact.nc",
        _set("initial_lateral_stiffness", np.nan),
        "initial_lateral_stiffness",
    ),
    "contact-param-text": (
        "06-contact",
        "contact.nc",
        _attr("param_tau0_mpa", "26.7"),
        "param_tau0",
    ),
    "contact-curve-inf": (
        "06-contact",
        "contact.nc",
        _set("lateral_force", -np.inf),
        "lateral_force",
    ),
}


def _lie(run, folder, name):
    """Write the damaged file's digest into the stage record, as if the stage had written it."""
    record = run / folder / "stage.json"
    data = json.loads(record.read_text())
    data["outputs"][name] = file_sha256(run / folder / name)
    record.write_text(json.dumps(data))


@pytest.mark.parametrize("case", sorted(CASES))
def test_a_lying_results_file_is_refused_naming_it(case, toy_run, tmp_path, capsys):
    conf, run = toy_run
    copy = tmp_path / "run"
    shutil.copytree(run, copy, symlinks=True)
    folder, name, change, words = CASES[case]
    _edit(copy / folder / name, change)
    _lie(copy, folder, name)
    before = tree(tmp_path)
    code, _, err = run_cli(["run", conf / "run.yaml", "--out", copy], capsys)
    line = refused(code, err, str(copy / folder / name), words)
    assert "remove" in line
    changed = {k for k, v in tree(tmp_path).items() if before.get(k) != v}
    # no stage folder changed: the damaged file was not used to write anything (the run's
    # own records, run.json, config.yaml, run.log, are rewritten by every run)
    assert not [k for k in changed if k.startswith("run/0")], changed


def test_an_honest_rerun_reads_the_same_results(toy_run, capsys):
    conf, run = toy_run
    from flatcontact.pipeline import Pipeline

    cfg = build_config(__import__("yaml").safe_load(TOY_YAML), source=str(conf / "run.yaml"))
    with Pipeline(cfg, run) as pipe:
        friction = pipe.analyze()
        contact = pipe.contact()
    with xr.open_dataset(run / "03-analyze" / "friction.nc", engine="h5netcdf") as raw:
        np.testing.assert_array_equal(friction["tau_mpa"].values, raw["tau_mpa"].values)
    assert sorted(contact["p0"].values.tolist()) == [0.5, 1.0]


def test_the_reader_refuses_plain_hdf5_and_huge_claims(tmp_path):
    import h5py

    plain = tmp_path / "friction.nc"
    with h5py.File(plain, "w") as f:
        f["x"] = np.arange(3)
    with pytest.raises(InputError, match=r"friction.nc: no 'p_gpa' dimension|not a readable"):
        open_result(plain, FRICTION)
    claims = tmp_path / "contact.nc"
    xr.Dataset(
        {"gross_sliding_stress": ("p0", np.zeros(2000))}, coords={"p0": np.arange(2000.0)}
    ).to_netcdf(claims, engine="h5netcdf")
    with pytest.raises(InputError, match="dimension 'p0' claims 2000 entries"):
        open_result(claims, CONTACT)
