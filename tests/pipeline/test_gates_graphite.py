"""3 + 3 graphene sheets with ``full`` relaxation: the inner sheets slide inside their own
slab and the ISPES loses the hexagonal symmetry of the stack; the run stops before the
contact stage naming both (measured: 24 of 180 points slipped up to 0.38 Å; the rotations,
mirrors and slab-swapping axes of its order-12 shift-space group broken by 12.5-17.4 % of the
map's range, tolerance 10 %), and goes on, with the report's box, when told to."""

from __future__ import annotations

import json

import pytest

from flatcontact.config import build_config
from flatcontact.foundation.errors import InputError
from flatcontact.pipeline import Pipeline

G33 = {
    "structure": {"kind": "sheets", "sheet": "graphene", "layers": 3, "stacking": "ABA"},
    "potential": {"preset": "graphene-rebo-kc"},
    "scan": {
        "grid": [6, 6],
        "p_range_gpa": {"lo_gpa": -0.3, "hi_gpa": 2.0, "n": 4},
        "relax_mode": "full",
        "executor": "serial",
    },
    "analysis": {"p_gpa": [0.0, 0.5, 1.0, 1.5], "direction_deg": "auto"},
    "contact": {"p0_gpa": [0.5, 1.0], "contact_modulus_gpa": 30, "shear_modulus_gpa": 10},
    "report": {"svg": False},
}


@pytest.mark.slow
def test_three_plus_three_graphene_full_is_gated_then_overridden(tmp_path):
    root = tmp_path / "g33"
    with Pipeline(build_config(G33), root) as pipe, pytest.raises(InputError) as err:
        pipe.run()
    message = str(err.value)
    assert "\n" not in message
    assert message.startswith("in_slab_slip: planes inside a slab slid sideways")
    assert "broken_symmetry" in message and "relax_mode: normal" in message
    assert not (root / "06-contact" / "summary.json").exists()
    scan = json.loads((root / "02-scan" / "scan.json").read_text())
    assert scan["layer_slip"]["n_slipped_points"] > 0
    insist = {
        **G33,
        "contact": {
            **G33["contact"],
            # the broken relaxation also leaves inequivalent minima that trade places with load
            "accept_untrusted": ["in_slab_slip", "broken_symmetry", "degenerate_minima"],
        },
    }
    with Pipeline(build_config(insist), root) as pipe:
        report = pipe.run()
        assert pipe.results["scan"].action == "skipped"
    summary = json.loads((root / "06-contact" / "summary.json").read_text())
    overridden = summary["gates"]["overridden"]
    assert {"in_slab_slip", "broken_symmetry"} <= set(overridden)
    # the first refusal named every gate the user then had to accept
    assert all(f"{gate}:" in message for gate in overridden)
    page = report.read_text()
    assert page.index("Numbers not to be trusted") < page.index("<h2>Summary</h2>")
