"""The interaction model: one type for every way flatcontact computes energies and forces.

:class:`InteractionModel` is the run configuration's ``potential:`` section, as data. It holds

- the **intra** model of each slab (or each layer): LAMMPS pair styles as data
  (:class:`~flatcontact.potentials.styles.LammpsStyle`), or a named model (``vashishta``,
  ``tersoff``, ``snap:<name|path>``, ``ase:module:factory``, ``none``;
  :mod:`flatcontact.potentials.names`), or a named preset (:mod:`flatcontact.potentials.presets`);
- the **coupling** across the interface (:mod:`flatcontact.potentials.coupling`): ``lj``
  (Lennard-Jones from Tkatchenko–Scheffler C6, :class:`~flatcontact.potentials.coupling.LJSpec`),
  ``same`` (the intra potential acts across the interface too: a bonded or metallic contact;
  the zero-load ISPES is then the generalized-stacking-fault γ-surface of that potential),
  ``interlayer`` (a registry-dependent interlayer potential such as ``kolmogorov/crespi/full``
  or ``ilp/graphene/hbn`` between all layers, beside the intralayer one; molecule ids =
  ``atoms.arrays["layer"]``) or ``none``;
- or an ASE **calculator** ``module:callable`` with keyword arguments
  (:class:`~flatcontact.potentials.styles.AseCalculatorSpec`), for the whole interface or per
  slab (then with the coupling ``lj`` or ``none`` across).

The model is frozen, picklable and hashable; its JSON form is canonical. What it describes:
:attr:`~InteractionModel.label`, :attr:`~InteractionModel.elements`,
:meth:`~InteractionModel.check_atoms`, :meth:`~InteractionModel.input_files`,
:meth:`~InteractionModel.fingerprint`. Its calculators are built from it by
:mod:`flatcontact.potentials.engines` (``calculator_factory(model)``,
``make_calculator(model, atoms)``, ``bulk_calculator(model, atoms)``).

LAMMPS typing (:func:`flatcontact.potentials.lammps_setup.compile_setup`): one type per
(group, element), groups being the slabs (``intra_scope: slab``), the layers
(``intra_scope: layer``) or all atoms (``coupling: same``); types in group order then element
order (alphabetical), every group with every element, so the α-quartz interface has
1 = O(slab 1), 2 = Si(slab 1), 3 = O(slab 2), 4 = Si(slab 2). Each intra style gets one
``hybrid/overlay`` instance per group, mapped with ``NULL`` on every other group's types:
LAMMPS builds a skip neighbour list per instance, so many-body terms (Tersoff bond order, SW
angles, SNAP bispectrum, REBO) of one group never see another group's atoms and the energy is
exactly the sum of the groups' energies plus the coupling (tested).
"""

from __future__ import annotations

import functools
import json
from pathlib import Path
from typing import Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from flatcontact.foundation.errors import InputError
from flatcontact.foundation.fileio import file_sha256
from flatcontact.potentials.coupling import Coupling, LJSpec
from flatcontact.potentials.lj import ts_elements
from flatcontact.potentials.names import (
    ResolvedIntra,
    named_styles,
    normalize_potential_name,
    resolve_intra,
)
from flatcontact.potentials.presets import PRESETS
from flatcontact.potentials.styles import AseCalculatorSpec, LammpsStyle, check_element


class InteractionModel(BaseModel):
    """Intra model + coupling across the interface, or an ASE calculator (module docstring).

    Attributes
    ----------
    preset
        Name of a preset (:data:`flatcontact.potentials.presets.PRESETS`) the other fields
        start from; fields given beside it override the preset's.
    intra
        A named model (``vashishta``, ``tersoff``, ``snap:<name|path>``, ``ase:module:factory``
        — a no-argument factory per slab —, ``none``) or a list of :class:`LammpsStyle`.
    intra_scope
        ``slab``: one instance of each intra style per slab; ``layer``: one per layer
        (``atoms.arrays["layer"]``), as 2D materials need.
    coupling
        ``lj``, ``same``, ``interlayer`` or ``none`` (module docstring).
    interlayer
        The interlayer style (or styles) for ``coupling: interlayer``.
    charges
        Charge per element (e) for the interlayer Coulomb term (``coul/shield``); 0 for
        elements not given.
    type_per_plane
        One LAMMPS type per atomic plane of each element within a group (``ilp/tmd`` takes
        a TMD atom's normal from neighbours of its own type: the two chalcogen planes of a
        layer must be different types).
    lj
        The LJ of ``coupling: lj`` (reset to its default for any other coupling).
    calculator
        An ASE calculator instead of LAMMPS styles (``intra`` is then ``none``).
    """

    model_config = ConfigDict(frozen=True, extra="forbid", allow_inf_nan=False)

    preset: str | None = Field(
        None,
        description=f"a named model ({', '.join(PRESETS)}; docs/potentials.md); "
        "fields given beside it override the preset's",
    )
    intra: str | tuple[LammpsStyle, ...] = Field(
        "vashishta",
        description="intra-slab model: vashishta, tersoff, snap:<name|path>, ase:module:factory, "
        "none, or a list of LAMMPS styles {pair_style, pair_coeff, elements}",
    )
    intra_scope: Literal["slab", "layer"] = Field(
        "slab", description="one instance of each intra style per slab or per layer"
    )
    coupling: Coupling = Field(
        "lj",
        description="across the interface: lj (TS C6), same (the intra potential, bonded or "
        "metallic contact), interlayer (KC/ILP between layers), none",
    )
    interlayer: LammpsStyle | tuple[LammpsStyle, ...] | None = Field(
        None,
        description="the interlayer LAMMPS style(s) of coupling interlayer (KC, ILP, and e.g. "
        "coul/shield)",
    )
    charges: dict[str, float] = Field(
        default_factory=dict,
        description="atomic charges per element (e), for coul/shield beside an ILP",
    )
    type_per_plane: bool = Field(
        False,
        description="one LAMMPS type per atomic plane of each element within a group "
        "(ilp/tmd needs the top and bottom chalcogen planes of a layer as different types)",
    )
    lj: LJSpec = Field(default_factory=LJSpec, description="the LJ of coupling lj")
    calculator: AseCalculatorSpec | None = Field(
        None, description="an ASE calculator {target: module:callable, kwargs, scope} instead"
    )

    def __init__(self, *args, **kwargs):
        try:
            super().__init__(*args, **kwargs)
        except InputError:
            raise
        except ValueError as exc:  # pydantic ValidationError -> one line
            errors = getattr(exc, "errors", None)
            if callable(errors):
                # of a union's alternatives, the error that got furthest names the real problem
                first = max(errors(), key=lambda e: len(e.get("loc", ())))
                where = ".".join(
                    str(p)
                    for p in first.get("loc", ())
                    if not str(p).startswith(("str", "tuple[", "function-", "LammpsStyle"))
                )
                msg = first.get("msg", str(exc)).removeprefix("Value error, ")
                if first.get("type") == "finite_number":
                    msg = f"expected a finite number, got {first.get('input')!r}"
                raise InputError(
                    f"potential {where}: {msg}".replace("potential : ", "potential: ")
                ) from None
            raise InputError(f"potential: {exc}") from None

    # ---------------------------------------------------------------- validation
    @model_validator(mode="before")
    @classmethod
    def _expand_preset(cls, data: Any) -> Any:
        if not isinstance(data, dict):
            return data
        data = dict(data)
        intra = data.get("intra")
        if isinstance(intra, str) and intra.strip() in PRESETS and not data.get("preset"):
            data["preset"] = intra.strip()
            data.pop("intra")
        if data.get("calculator") is not None and "intra" not in data:
            data["intra"] = "none"
        name = data.get("preset")
        if name is None:
            return data
        if name not in PRESETS:
            raise InputError(
                f"potential preset: unknown preset {name!r}; expected one of {list(PRESETS)}"
            )
        return {**PRESETS[name], **data}

    @field_validator("intra", mode="before")
    @classmethod
    def _intra(cls, value: Any) -> Any:
        if isinstance(value, str):
            value = normalize_potential_name(value)
            resolve_intra(value)  # raises InputError on unknown names / missing files
            return value
        if isinstance(value, dict | LammpsStyle):
            return (value,)
        return value

    @model_validator(mode="after")
    def _consistent(self) -> InteractionModel:
        calc = self.calculator
        if calc is not None and self.intra != "none":
            raise ValueError("give either calculator or intra (LAMMPS styles), not both")
        if calc is not None and calc.scope == "interface" and self.coupling not in ("none",):
            object.__setattr__(self, "coupling", "none")  # the calculator sees both slabs
        if calc is not None and self.coupling not in ("lj", "none"):
            raise ValueError(f"coupling {self.coupling!r}: a per-slab calculator takes lj or none")
        if self.coupling == "interlayer" and self.interlayer is None:
            raise ValueError("coupling 'interlayer' needs 'interlayer' (a LAMMPS pair style)")
        if self.coupling != "interlayer" and self.interlayer is not None:
            raise ValueError(
                f"'interlayer' is only used with coupling 'interlayer', not {self.coupling!r}"
            )
        if self.charges and self.coupling != "interlayer":
            raise ValueError("charges need coupling 'interlayer' (atom_style full)")
        for symbol in self.charges:
            check_element(symbol, "charges")
        if self.coupling == "same" and not self.intra_styles:
            raise ValueError("coupling 'same' needs LAMMPS intra styles")
        if self.coupling != "lj" and self.lj != LJSpec():
            object.__setattr__(self, "lj", LJSpec())  # unused: canonical form drops it
        for style in self.intra_styles:
            if not style.map_elements and (self.coupling != "same" or len(self.intra_styles) > 1):
                raise ValueError(
                    f"pair_style {style.name} without an element map must be the only intra style "
                    "with coupling 'same'"
                )
        return self

    def __hash__(self) -> int:
        return hash(self.model_dump_json())

    # ---------------------------------------------------------------- description
    @property
    def intra_styles(self) -> tuple[LammpsStyle, ...]:
        """The intra LAMMPS styles (a named model resolved, :func:`~flatcontact.potentials.names.named_styles`)."""
        if isinstance(self.intra, str):
            return named_styles(self.intra)
        return tuple(self.intra)

    @property
    def interlayer_styles(self) -> tuple[LammpsStyle, ...]:
        """The interlayer styles as a tuple (empty without one)."""
        if self.interlayer is None:
            return ()
        if isinstance(self.interlayer, LammpsStyle):
            return (self.interlayer,)
        return tuple(self.interlayer)

    @property
    def engine(self) -> Literal["lammps", "ase-slab", "ase-interface"]:
        """Which engine evaluates the model."""
        if self.calculator is not None:
            return "ase-slab" if self.calculator.scope == "slab" else "ase-interface"
        if isinstance(self.intra, str) and self.intra.startswith("ase:"):
            return "ase-slab"
        return "lammps"

    @property
    def kind(self) -> str:
        """The engine family: ``"lammps"`` or ``"ase"`` (either ASE engine)."""
        return "lammps" if self.engine == "lammps" else "ase"

    @property
    def resolved(self) -> ResolvedIntra:
        """The model as a :class:`~flatcontact.potentials.names.ResolvedIntra`: style, files (absolute paths), elements, factory."""
        if isinstance(self.intra, str) and self.calculator is None:
            return resolve_intra(self.intra)
        styles = "+".join(s.name for s in self.intra_styles) or "none"
        if self.calculator is not None:
            return ResolvedIntra(style="ase", factory=self.calculator.target, elements=None)
        files = tuple(str(p) for p in self.input_files())
        elements = tuple(sorted(self.elements)) if self.elements is not None else None
        return ResolvedIntra(style=styles, files=files, elements=elements)

    @property
    def label(self) -> str:
        """Short human-readable description, e.g. ``vashishta+LJ(ts, rc=10 Å)``."""
        if self.calculator is not None:
            c = self.calculator
            kw = f" {json.dumps(c.kwargs, sort_keys=True)}" if c.kwargs else ""
            base = f"ASE {c.target}{kw}" + (" per slab" if c.scope == "slab" else "")
            return base + (self._lj_label() if c.scope == "slab" and self.coupling == "lj" else "")
        if isinstance(self.intra, str):
            intra = self.intra
        else:
            intra = " + ".join(s.label for s in self.intra) + (
                " per layer" if self.intra_scope == "layer" else ""
            )
        prefix = f"{self.preset}: " if self._preset_intra else ""
        if self.coupling == "lj":
            return prefix + intra + self._lj_label()
        if self.coupling == "same":
            return prefix + intra + " (same potential across the interface)"
        if self.coupling == "interlayer":
            across = " + ".join(style.label for style in self.interlayer_styles)
            return prefix + f"{intra} + {across} between layers"
        return prefix + intra + " (no coupling across the interface)"

    @property
    def _preset_intra(self) -> bool:
        """Whether the model has a preset and the preset's own intra model (a preset whose
        ``intra`` was given beside it is named by that intra model, not by the preset)."""
        return bool(self.preset) and self.intra == _preset_model(self.preset).intra

    @property
    def name(self) -> str:
        """The shortest name: the preset (with its own intra model), the named intra model,
        the styles or the calculator."""
        if self._preset_intra:
            return self.preset
        if self.calculator is not None:
            return self.calculator.target
        if isinstance(self.intra, str):
            return self.intra
        return "+".join(s.label for s in self.intra)

    def _lj_label(self) -> str:
        lj = self.lj
        extra = ""
        if lj.c6_ev_a6:
            extra += ", user C6 " + ",".join(f"{k}={v:g}" for k, v in lj.c6_ev_a6.items())
        if lj.volume_ratio:
            extra += ", v=" + ",".join(f"{k}:{v:g}" for k, v in lj.volume_ratio.items())
        if lj.hamaker_zj is not None:
            extra += f", C6 scaled to A={lj.hamaker_zj:g} zJ"
        elif lj.c6_scale != 1.0:
            extra += f", C6×{lj.c6_scale:g}"
        return f"+LJ({lj.c6_source}{extra}, rc={lj.cutoff_angstrom:g} Å)"

    @property
    def elements(self) -> frozenset[str] | None:
        """The elements the model can compute; ``None`` when unknown (ASE calculators)."""
        if self.engine != "lammps":
            known = self.calculator.elements if self.calculator is not None else None
            return frozenset(known) if known is not None else None
        styles = self.intra_styles
        if styles:
            out = frozenset(e for s in styles for e in s.known_elements)
        elif self.lj.c6_source == "user":
            out = frozenset(e for key in self.lj.c6_ev_a6 for e in key.split("-"))
        else:
            out = ts_elements()
        for style in self.interlayer_styles:  # per-pair styles (Coulomb) restrict nothing
            if style.pair_coeff_pairs is None:
                out = out & frozenset(style.known_elements)
        return out

    def input_files(self) -> list[Path]:
        """The files whose content defines the model (potential files), sorted, no repeats."""
        files = [p for s in self.intra_styles for p in s.files]
        for style in self.interlayer_styles:
            files += list(style.files)
        return sorted({Path(p) for p in files}, key=lambda p: (p.name, str(p)))

    def fingerprint(self) -> dict:
        """JSON-able, content-based identity: the canonical data with files by name + SHA-256."""
        text = self.model_dump_json()
        files = self.input_files()
        for path in sorted(files, key=lambda p: -len(str(p))):
            text = text.replace(str(path), path.name)
        return {"model": json.loads(text), "files_sha256": {p.name: file_sha256(p) for p in files}}

    @property
    def couples_slabs(self) -> bool:
        """Whether anything acts across the interface: a coupling (``lj``, ``same``,
        ``interlayer``) or an ASE calculator over the whole interface (its ``coupling: none``
        only says the calculator itself sees both slabs). A per-slab model (LAMMPS styles per
        slab or layer, an ASE calculator per slab) with ``coupling: none`` computes each slab
        alone: the energy of two slabs is then the same at every stacking and no load acts
        between them (a flat ISPES, τ = 0)."""
        return self.coupling != "none" or self.engine == "ase-interface"

    # ---------------------------------------------------------------- checks
    def check_couples_slabs(self, field: str = "potential.coupling") -> None:
        """Refuse, in one line naming ``field``, a model with nothing across the interface
        (:attr:`couples_slabs`): scanning two slabs with it can only give a flat ISPES.

        Raises
        ------
        InputError
            ``<field>: 'none' with the per-slab model <name>: ...; expected lj, same or
            interlayer, or an ASE calculator over the whole interface``.
        """
        if self.couples_slabs:
            return
        raise InputError(
            f"{field}: 'none' with the per-slab model {self.name}: nothing acts across the "
            "interface, so every stacking of the two slabs has the same energy and no normal "
            "load (a flat ISPES, τ = 0); expected lj, same or interlayer, or an ASE calculator "
            "over the whole interface (calculator.scope: interface)"
        )

    def check_atoms(self, atoms) -> None:
        """Refuse, in one line naming element and model, a structure the model cannot compute."""
        symbols = set(atoms.get_chemical_symbols())
        known = self.elements
        if known is not None and not symbols <= known:
            missing = sorted(symbols - known)
            raise InputError(
                f"potential '{self.name}' has no parameters for element(s) {missing} of the "
                f"structure (it knows {sorted(known)})"
            )
        if self.coupling == "lj":
            groups = slab_ids(atoms)
            if len(set(groups.tolist())) > 1:
                sym = np.array(atoms.get_chemical_symbols())
                self.lj.table(sorted(set(sym[groups == 1])), sorted(set(sym[groups != 1])))
        if self.engine == "lammps" and not self.intra_styles and self.coupling != "lj":
            raise InputError(f"potential {self.label}: nothing to compute (no intra model, no LJ)")


@functools.cache
def _preset_model(name: str) -> InteractionModel:
    """The model of the preset ``name`` as it ships (no field overridden)."""
    return InteractionModel(preset=name)


def slab_ids(atoms) -> np.ndarray:
    """``atoms.arrays["slab"]`` as ints, or all ones when absent (a single body)."""
    if "slab" in atoms.arrays:
        return np.asarray(atoms.arrays["slab"], dtype=int)
    return np.ones(len(atoms), dtype=int)
