"""The coupling across the interface: its kinds and the Lennard-Jones settings of ``lj``.

- :data:`Coupling`: ``lj`` (Lennard-Jones from Tkatchenko–Scheffler C6), ``same`` (the intra
  potential acts across the interface too), ``interlayer`` (a registry-dependent interlayer
  potential between all layers) or ``none``;
- :class:`LJSpec`: the ``lj`` settings; the pair parameters themselves come from
  :mod:`flatcontact.potentials.lj`.
"""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from flatcontact.foundation.errors import InputError
from flatcontact.foundation.numbers import physical
from flatcontact.potentials.lj import hamaker_c6_scale, lj_table, pair_key
from flatcontact.potentials.styles import check_element

#: How the two slabs interact across the interface.
Coupling = Literal["lj", "same", "interlayer", "none"]


class LJSpec(BaseModel):
    """Cross-interface Lennard-Jones from vdW-DFT C6 (see :mod:`flatcontact.potentials.lj`).

    Attributes
    ----------
    c6_source
        ``"ts"``: Tkatchenko–Scheffler free-atom C6/α with the TS combination rule (optionally
        Hirshfeld-scaled by ``volume_ratio``); ``"user"``: every pair's C6 must be in ``c6_ev_a6``.
    c6_ev_a6
        Effective C6 per element pair, e.g. ``{"O-Si": 30.1}`` (eV·Å⁶); overrides TS values.
    r0_angstrom
        vdW radius R0 per element (Å), overriding the TS free-atom radius.
    volume_ratio
        Hirshfeld volume ratio V_eff/V_free per element (TS 2009 Eqs. 7–9).
    c6_scale
        One factor on every C6 after the above (σ unchanged, so only the well depths scale).
    hamaker_zj
        Instead of ``c6_scale``: the Hamaker constant (zJ = 1e-21 J) the LJ must reproduce by
        pairwise summation, A = π² Σ C6_AB ρ_A ρ_B; the factor on every C6 follows from it
        (:func:`flatcontact.potentials.lj.hamaker_c6_scale`). Lifshitz theory gives ≈ 88 zJ
        for α-quartz across vacuum (Bergström 1997), where free-atom TS C6 give ≈ 410 zJ.
    number_density_per_nm3
        Bulk number density per element (nm⁻³) for ``hamaker_zj``; α-quartz:
        ``{Si: 26.52, O: 53.04}`` (:data:`flatcontact.potentials.lj.ALPHA_QUARTZ_NUMBER_DENSITY_PER_NM3`).
    cutoff_angstrom
        LJ cutoff r_c (Å); the energy is shifted to zero at r_c.
    """

    model_config = ConfigDict(frozen=True, extra="forbid", allow_inf_nan=False)

    c6_source: Literal["ts", "user"] = "ts"
    c6_ev_a6: dict[str, float] = Field(default_factory=dict)
    r0_angstrom: dict[str, float] = Field(default_factory=dict)
    volume_ratio: dict[str, float] = Field(default_factory=dict)
    c6_scale: physical(1e-3, 1e3) = 1.0
    hamaker_zj: physical(1.0, 1e4, "zJ") | None = None
    number_density_per_nm3: dict[str, float] = Field(default_factory=dict)
    #: 1..50 Å: below an atom's size the shift is the potential; beyond, a neighbour list
    #: of every LAMMPS worker grows as rc³ with nothing left to converge (10 Å: 0.1 % of U)
    cutoff_angstrom: physical(1.0, 50.0, "Å") = Field(
        10.0, description="cutoff of the cross-interface Lennard-Jones (Å)"
    )

    @field_validator("c6_ev_a6")
    @classmethod
    def _pairs(cls, value: dict[str, float]) -> dict[str, float]:
        out = {}
        for key, c6 in value.items():
            parts = key.split("-")
            if len(parts) != 2 or not all(parts):
                raise ValueError(f"c6_ev_a6 key '{key}': expected an element pair like 'O-Si'")
            for symbol in parts:
                check_element(symbol, f"c6_ev_a6 key '{key}'")
            if not c6 > 0:
                raise ValueError(f"c6_ev_a6['{key}']={c6}: expected > 0 eV·Å⁶")
            out["-".join(sorted(parts))] = float(c6)
        return dict(sorted(out.items()))

    @model_validator(mode="after")
    def _hamaker_needs_densities(self) -> LJSpec:
        if self.hamaker_zj is not None:
            if self.c6_scale != 1.0:
                raise ValueError("give either c6_scale or hamaker_zj, not both")
            if not self.number_density_per_nm3:
                raise ValueError(
                    "hamaker_zj needs number_density_per_nm3 (bulk number density per element, "
                    "nm⁻³; α-quartz: {Si: 26.52, O: 53.04})"
                )
        return self

    def effective_c6_scale(self, elements) -> float:
        """The factor applied to every C6: ``c6_scale``, or the one that gives ``hamaker_zj``."""
        if self.hamaker_zj is None:
            return self.c6_scale
        missing = sorted(str(e) for e in set(elements) - set(self.number_density_per_nm3))
        if missing:
            raise InputError(
                f"lj.number_density_per_nm3 lacks the elements {missing} needed for hamaker_zj "
                "(give your material's densities and Hamaker constant, or set lj.hamaker_zj: null "
                "for free-atom C6)"
            )
        species = sorted(self.number_density_per_nm3)
        base = lj_table(
            species,
            species,
            c6_ev_a6=self.c6_ev_a6,
            r0_angstrom=self.r0_angstrom,
            volume_ratio=self.volume_ratio,
        )
        return hamaker_c6_scale(base, self.number_density_per_nm3, self.hamaker_zj)

    @field_validator("r0_angstrom", "volume_ratio", "number_density_per_nm3")
    @classmethod
    def _positive(cls, value: dict[str, float]) -> dict[str, float]:
        for key, v in value.items():
            check_element(key, f"key '{key}'")
            if not v > 0:
                raise ValueError(f"value for '{key}' must be > 0, got {v}")
        return dict(sorted(value.items()))

    def __hash__(self) -> int:
        return hash(self.model_dump_json())

    def table(self, symbols_1, symbols_2):
        """LJ parameters for all element pairs across the interface (dict keyed 'A-B')."""
        if self.c6_source == "user":
            missing = sorted(
                {pair_key(a, b) for a in set(symbols_1) for b in set(symbols_2)}
                - set(self.c6_ev_a6)
            )
            if missing:
                raise InputError(f"lj.c6_source='user' but c6_ev_a6 lacks the pairs {missing}")
        return lj_table(
            symbols_1,
            symbols_2,
            c6_ev_a6=self.c6_ev_a6,
            r0_angstrom=self.r0_angstrom,
            volume_ratio=self.volume_ratio,
            c6_scale=self.effective_c6_scale(set(symbols_1) | set(symbols_2)),
        )
