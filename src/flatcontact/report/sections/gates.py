"""The box at the top of the report: which numbers are not to be trusted and why.

From ``summary.json["gates"]`` (:mod:`flatcontact.stages.gates`): every validity gate that
fired and was passed with ``contact.accept_untrusted``, and the notes (a negative slope used
as fitted). A run where nothing fired and nothing is noted has no such section.
"""

from __future__ import annotations

from flatcontact.report.html import Section

#: What each gate makes untrustworthy (the numbers downstream of it).
UNTRUSTED = {
    "in_slab_slip": "the ISPES, τ and σ_MSS at every load, the load laws and every contact result",
    "broken_symmetry": "the ISPES, τ and σ_MSS at the loads named, the load laws and every "
    "contact result",
    "load_fold": "τ and σ_MSS beyond the fold, the load laws and every contact result",
    "negative_slope": "the load laws (k or μ) and every contact result",
    "degenerate_minima": "τ at the loads named, the law τ = k·P + τ0 and every contact result",
}


#: The numbers each gate's finding reaches (the fitted laws' keys; ``w``: the scan's work of
#: separation, read from the same landscape).
REACHES = {
    "in_slab_slip": ("k_mpa_per_gpa", "tau0_mpa", "mu_mpa_per_gpa", "sigma0_mpa", "w"),
    "broken_symmetry": ("k_mpa_per_gpa", "tau0_mpa", "mu_mpa_per_gpa", "sigma0_mpa", "w"),
    "load_fold": ("k_mpa_per_gpa", "tau0_mpa", "mu_mpa_per_gpa", "sigma0_mpa"),
    "negative_slope": ("k_mpa_per_gpa", "tau0_mpa", "mu_mpa_per_gpa", "sigma0_mpa"),
    "degenerate_minima": ("k_mpa_per_gpa", "tau0_mpa"),
}
_NAMES = {
    "k_mpa_per_gpa": ("k", "MPa/GPa"),
    "tau0_mpa": ("τ0", "MPa"),
    "mu_mpa_per_gpa": ("μ", "MPa/GPa"),
    "sigma0_mpa": ("σ0", "MPa"),
}


def flowed_on(contact: dict, gates: list[str]) -> str | None:
    """One line: the untrusted numbers the contact stage took (values and where from) after
    ``gates`` were passed with ``contact.accept_untrusted``, and the results they reach;
    None when every number they reach was given in the configuration."""
    params = contact.get("parameters") or {}
    prov = contact.get("provenance") or {}
    keys = list(dict.fromkeys(k for g in gates for k in REACHES.get(g, REACHES["in_slab_slip"])))
    used = [
        f"{_NAMES[k][0]} = {params[k]:.4g} {_NAMES[k][1]}"
        for k in keys
        if k in _NAMES and prov.get(k) == "fitted laws" and k in params
    ]
    if "w" in keys and prov.get("work_of_adhesion_j_per_m2") == "scan work of separation":
        used.append(f"w = {params.get('work_of_adhesion_j_per_m2', float('nan')):.4g} J/m² (scan)")
    if not used:
        return None
    p0 = [r.get("p0_gpa") for r in contact.get("results") or [] if r.get("p0_gpa") is not None]
    where = ", ".join(f"{v:g}" for v in p0)
    line = (
        "Untrusted numbers that flowed on into the contact stage: "
        + ", ".join(used)
        + " (fitted laws)"
        + (f"; they enter every contact result (p0 = {where} GPa)" if where else "")
    )
    if prov.get("moduli") == "config":
        line += (
            f". E* = {params.get('contact_modulus_gpa', float('nan')):g} GPa and G* = "
            f"{params.get('shear_modulus_gpa', float('nan')):g} GPa are the configuration's "
            "(contact.contact_modulus_gpa, contact.shear_modulus_gpa), not computed with this "
            "run's model (elastic.enabled computes them)"
        )
    return line


def gates_section(contact: dict) -> Section | None:
    """The section of the gates recorded by the contact stage, or None if there is nothing
    to say."""
    gates = contact.get("gates") or {}
    fired = gates.get("fired") or []
    notes = gates.get("notes") or []
    if not fired and not notes:
        return None
    boxes = [
        f"Not to be trusted: {UNTRUSTED.get(f['gate'], 'the results')}. Gate {f['gate']} "
        f"fired and was passed with contact.accept_untrusted: {f['message']}"
        for f in fired
    ]
    flowed = flowed_on(contact, [f["gate"] for f in fired if f.get("overridden", True)])
    if fired and flowed is not None:
        boxes.append(flowed)
    boxes += [f"Note: {n}" for n in notes]
    paragraphs = []
    if fired:
        paragraphs.append(
            "The validity gates checked before the contact stage fired; the run went on "
            "because contact.accept_untrusted lists them. The figures and tables below are "
            "computed from these numbers."
        )
    return Section(
        "Numbers not to be trusted" if fired else "Notes on the laws", paragraphs, notes=boxes
    )
