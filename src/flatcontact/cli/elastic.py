"""``flatcontact elastic``: Cij and the contact moduli of a bulk crystal, the run's elastic
stage with a configuration (:func:`flatcontact.stages.elastic.elastic_stage`) or α-quartz with a
named potential (:func:`flatcontact.elastic.quartz_contact_moduli`)."""

from __future__ import annotations

import json
from pathlib import Path

import typer

from flatcontact.cli.app import app, check_out_dir, console
from flatcontact.cli.bulk_models import bulk_potential
from flatcontact.foundation.errors import InputError


@app.command("elastic")
def elastic_cmd(
    config: Path | None = typer.Argument(
        None,
        help="A run configuration: the elastic stage of that run (the bulk crystal of its "
        "structure with its potential), the same elastic.json as 'flatcontact run'.",
    ),
    potential: str = typer.Option(
        "sio2-snap",
        "--potential",
        help="Without CONFIG: alpha-quartz with vashishta | tersoff | \\[snap:]NAME | "
        "\\[snap:]path/X.snapcoeff | chgnet.",
    ),
    strain: float = typer.Option(0.005, "--strain", help="Finite strain amplitude (fraction)."),
    out: Path | None = typer.Option(
        None, "--out", help="With CONFIG: write elastic.json into this folder."
    ),
    json_out: bool = typer.Option(False, "--json", help="Print JSON."),
) -> None:
    """Cij (relaxed ions), Voigt-Reuss-Hill K, G, E, nu and the contact moduli E*, G*.

    With CONFIG this is the run's elastic stage (:func:`flatcontact.stages.elastic.elastic_stage`)
    for any material; without it, alpha-quartz with ``--potential``.
    """
    from flatcontact.config.elastic import ElasticConfig
    from flatcontact.elastic import quartz_contact_moduli
    from flatcontact.foundation.numbers import field_bounds

    try:  # the run's elastic.strain bounds
        strain = field_bounds(ElasticConfig.model_fields["strain"]).check(strain)
    except ValueError as exc:
        raise InputError(f"--strain: {exc}") from None
    if config is not None:
        res = _elastic_stage(config, strain, out)
    else:
        if out is not None:
            raise InputError(
                "--out: needs CONFIG (the run configuration whose elastic stage to run)"
            )
        res = quartz_contact_moduli(bulk_potential(potential, "--potential"), strain=strain)
    if json_out:
        print(json.dumps(res, indent=2))
        return
    crystal = res.get("crystal", {}).get("crystal", "alpha-quartz")
    model = res.get("potential", potential)
    lattice = ", ".join(
        f"{k.removesuffix('_angstrom')} = {res[k]:.4f} Å"
        for k in ("a_angstrom", "c_angstrom")
        if isinstance(res.get(k), float)
    )
    console.print(f"{crystal} with {model}" + (f": {lattice}" if lattice else ""))
    cij = res.get("cij_gpa") or _cij_of_tensor(res["tensor_gpa"])
    console.print("  " + "  ".join(f"{k} {v:.1f}" for k, v in cij.items()) + "  (GPa)")
    m = res["moduli_gpa"]
    console.print(
        f"  Hill: K {m['bulk_modulus']:.1f}  G {m['shear_modulus']:.1f}  E {m['youngs_modulus']:.1f} GPa  "
        f"nu {m['poisson_ratio']:.3f}"
    )
    console.print(
        f"  two identical bodies: E* {m['e_star']:.1f} GPa; G* {m['g_star_johnson']:.1f} GPa (Johnson, "
        f"q0 = 4G*u/(pi a)) = {m['g_star_paper']:.1f} GPa (paper, q0 = G*u/(pi a))"
    )


def _elastic_stage(config: Path, strain: float, out: Path | None) -> dict:
    """The run's elastic stage for ``config`` (strain from ``--strain``), writing ``--out``."""
    from flatcontact.cli.settings import resolve_config
    from flatcontact.stages.elastic import ElasticInputs, elastic_stage

    flags = {"elastic": {"enabled": True, "strain": strain}}
    settings = resolve_config(config, None, flags, {"elastic.strain": "--strain"})
    if out is not None:
        out = check_out_dir(out)
    return elastic_stage(settings, ElasticInputs(), out).to_json()


def _cij_of_tensor(tensor) -> dict[str, float]:
    """C11, C12, C13, C33, C44, C66 (GPa) of a 6x6 Voigt stiffness (Voigt order xx,yy,zz,yz,xz,xy)."""
    pick = {
        "C11": (0, 0),
        "C12": (0, 1),
        "C13": (0, 2),
        "C33": (2, 2),
        "C44": (3, 3),
        "C66": (5, 5),
    }
    return {name: float(tensor[i][j]) for name, (i, j) in pick.items()}
