"""``flatcontact asperity CONFIG --out DIR``: the asperity in atoms against the modified Mindlin
model of the interface's laws (:func:`flatcontact.stages.asperity.asperity_stage`)."""

from __future__ import annotations

import json
from pathlib import Path

import typer

from flatcontact.cli.app import app, check_out_dir, console
from flatcontact.foundation.errors import InputError


@app.command("asperity")
def asperity_cmd(
    config: Path = typer.Argument(..., help="A run configuration with an asperity: section."),
    out: Path = typer.Option(..., "--out", help="Folder of asperity.nc/.json, figures, state/."),
    run_dir: Path | None = typer.Option(
        None,
        "--run",
        help="A finished run directory of CONFIG: its laws (04-laws/laws.json) and E* "
        "(05-elastic/elastic.json).",
    ),
    laws: Path | None = typer.Option(None, "--laws", help="A laws.json (overrides --run's)."),
    json_out: bool = typer.Option(False, "--json", help="Print asperity.json."),
    radii: str | None = typer.Option(
        None,
        "--radii",
        help="Comma-separated radii in Å (overrides asperity.radius_angstrom): one asperity "
        "per radius in OUT/R<r>, every (radius, load) a job on the scan's executor.",
    ),
) -> None:
    """Press a tip of slab 2's crystal on a flat of slab 1's, slide it quasi-statically in
    LAMMPS, and compare Q_peak, c/a, Q(u) and q/p with the model (docs/asperity.md).

    Rerunning into the same --out resumes from the last relaxed step.
    """
    from flatcontact.cli.settings import resolve_config
    from flatcontact.foundation.layout import ELASTIC_JSON, LAWS_JSON, STAGES
    from flatcontact.stages.asperity import (
        AsperityInputs,
        asperity_stage,
        radius_settings,
        run_asperity_radii,
    )

    settings = resolve_config(config, None, {"asperity": {"enabled": True}}, {})
    values = None
    if radii is not None:  # refused before anything is written
        values = _radii(radii)
        for r in values:
            radius_settings(settings, r)
    out = check_out_dir(out)
    laws_doc, e_star = None, None
    if run_dir is not None:
        laws_path = run_dir / f"{STAGES['laws']:02d}-laws" / LAWS_JSON
        elastic_path = run_dir / f"{STAGES['elastic']:02d}-elastic" / ELASTIC_JSON
        if not laws_path.is_file():
            raise InputError(f"--run: {laws_path} is not a file (run the laws stage first)")
        laws_doc = json.loads(laws_path.read_text())
        if elastic_path.is_file():
            e_star = float(json.loads(elastic_path.read_text())["contact_modulus_gpa"])
    if laws is not None:
        if not laws.is_file():
            raise InputError(f"--laws: {laws} is not a file")
        laws_doc = json.loads(laws.read_text())
    inputs = AsperityInputs(laws=laws_doc, contact_modulus_gpa=e_star)

    def tell(line: str) -> None:
        console.print(line)

    if values is not None:
        results = run_asperity_radii(settings, inputs, out, values, progress=tell)
        for result in results:
            _print(result.to_json(), json_out)
        return
    _print(asperity_stage(settings, inputs, out, progress=tell).to_json(), json_out)


def _radii(text: str) -> list[float]:
    """``--radii 200,400``: distinct finite numbers (Å)."""
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise InputError(f"--radii: {text!r}: expected comma-separated radii in Å") from None
    if not values or len(set(values)) != len(values):
        raise InputError(f"--radii: {text!r}: expected distinct comma-separated radii in Å")
    return values


def _print(doc: dict, json_out: bool) -> None:
    """asperity.json (``--json``) or its summary lines."""
    if json_out:
        print(json.dumps(doc, indent=1))
        return
    console.print(
        f"{doc['geometry']} R = {doc['radius_angstrom']:g} Å, {doc['n_atoms']:,} atoms, "
        f"{doc['wall_seconds']:.0f} s"
    )
    for row in doc["peak_shear_stress_mpa"]:
        console.print(
            f"  p0 {row['target_p0_gpa']:g} GPa: Q_peak/area atoms {row['atoms']:.1f} MPa, "
            f"model (Hertz) {row['model_hertz']:.1f}, model (measured p) "
            f"{row['model_measured_pressure']:.1f}"
        )
    for p0, ramp in zip(doc["target_p0_gpa"], doc.get("ramp") or [], strict=False):
        for r in ramp["amplitudes"]:
            model = r.get("model_hertz_lockin_n_per_m")
            console.print(
                f"  p0 {p0:g} GPa, U {r['displacement_amplitude_angstrom']:.3g} Å: lock-in k' "
                f"atoms {r['atoms_lockin_n_per_m']:.4g} N/m, model (Hertz) "
                + ("-" if model is None else f"{model:.4g}")
            )
    console.print(doc["verdict"])
    for w in doc["warnings"]:
        console.print(f"warning: {w}")
