"""The one registry of offline teachers: universal ML potentials that label SiO₂ frames.

A teacher is an ASE calculator whose weights ship inside its Python wheel (nothing is
downloaded at run time), run on the CPU with one torch thread. Every place that needs a
teacher by name — ``flatcontact train-snap --label``, ``validate-potential --reference``,
``flatcontact elastic --potential`` (:func:`flatcontact.potentials.engines.bulk_calculator`),
the ISPES comparison (:mod:`flatcontact.training.ispes_check`) and the labelling helpers
(:mod:`flatcontact.training.label`) — resolves it here, so a new teacher is one entry in
:data:`TEACHERS`.

Registered (measured α-quartz lattice and Cij against experiment: docs/teachers.md):

* ``chgnet-r2scan`` (alias ``chgnet``): CHGNet 0.4, r2SCAN weights (Deng et al., Nat. Mach.
  Intell. 5, 1031 (2023)); the teacher of the bundled ``sio2-snap``.
* ``sevennet-0``: SevenNet-0 (11Jul2024), PBE, trained on MPtrj (Park et al., J. Chem.
  Theory Comput. 20, 4857 (2024)).
* ``sevennet-mf-0-r2scan`` / ``sevennet-mf-0-pbe``: the multi-fidelity SevenNet-MF-0
  checkpoint with its r2SCAN or PBE head (Kim et al., J. Am. Chem. Soc. 147, 1042 (2025));
  the r2SCAN head is the teacher of ``sio2-snap-mf0``.

They are optional: ``torch`` (CPU build, install it first) plus ``chgnet`` or ``sevenn``.
This module imports neither until a calculator is asked for.
"""

from __future__ import annotations

import importlib.metadata as md
from dataclasses import asdict, dataclass
from types import MappingProxyType

from flatcontact.foundation.errors import InputError
from flatcontact.potentials.chgnet import chgnet_calculator
from flatcontact.potentials.loader import load_callable


@dataclass(frozen=True)
class Teacher:
    """One offline teacher.

    Attributes
    ----------
    name
        Registry name (lower case, hyphenated).
    package
        Distribution that provides the model and its weights (``chgnet``, ``sevenn``).
    model
        The checkpoint's name inside that package (``r2scan``, ``7net-0``, ``7net-mf-0``).
    head
        Fidelity head of a multi-fidelity checkpoint (SevenNet ``modal``), or None.
    functional
        The DFT level the labels stand for (``r2SCAN``, ``PBE``).
    factory
        ``module:callable`` of a no-argument factory returning a fresh CPU ASE calculator.
    description
        One line for humans (what it is, what it was trained on).
    """

    name: str
    package: str
    model: str
    head: str | None
    functional: str
    factory: str
    description: str

    def metadata(self) -> dict:
        """JSON-able description plus the installed versions of its package and torch."""
        out = asdict(self)
        for pkg in (self.package, "torch"):
            try:
                out[f"{pkg}_version"] = md.version(pkg)
            except md.PackageNotFoundError:
                out[f"{pkg}_version"] = None
        return out


def _torch_one_thread() -> None:
    try:
        import torch

        torch.set_num_threads(1)
    except ImportError:  # pragma: no cover - without torch the factory fails just below
        pass


def chgnet_r2scan():
    """CHGNet 0.4 with its r2SCAN weights, CPU, one torch thread."""
    return chgnet_calculator("r2scan", threads=1)


def _sevennet(model: str, modal: str | None):
    try:
        from sevenn.calculator import SevenNetCalculator
    except ImportError as exc:
        raise InputError(
            f"SevenNet is not installed ({exc}); install torch==2.13.0 (CPU) and then 'sevenn'"
        ) from None
    _torch_one_thread()
    kwargs = {"modal": modal} if modal else {}
    return SevenNetCalculator(model, device="cpu", **kwargs)


def sevennet_0():
    """SevenNet-0 (PBE, MPtrj; 11Jul2024 checkpoint shipped in the ``sevenn`` wheel), CPU."""
    return _sevennet("7net-0", None)


def sevennet_mf0_r2scan():
    """SevenNet-MF-0, r2SCAN head (multi-fidelity checkpoint shipped in the wheel), CPU."""
    return _sevennet("7net-mf-0", "R2SCAN")


def sevennet_mf0_pbe():
    """SevenNet-MF-0, PBE head, CPU."""
    return _sevennet("7net-mf-0", "PBE")


_HERE = __name__
#: Offline teachers by name.
TEACHERS: MappingProxyType[str, Teacher] = MappingProxyType(
    {
        t.name: t
        for t in (
            Teacher(
                "chgnet-r2scan",
                "chgnet",
                "r2scan",
                None,
                "r2SCAN",
                f"{_HERE}:chgnet_r2scan",
                "CHGNet 0.4, r2SCAN weights (MP r2SCAN relaxations)",
            ),
            Teacher(
                "sevennet-0",
                "sevenn",
                "7net-0",
                None,
                "PBE",
                f"{_HERE}:sevennet_0",
                "SevenNet-0 11Jul2024, PBE(+U), trained on MPtrj",
            ),
            Teacher(
                "sevennet-mf-0-r2scan",
                "sevenn",
                "7net-mf-0",
                "R2SCAN",
                "r2SCAN",
                f"{_HERE}:sevennet_mf0_r2scan",
                "SevenNet-MF-0 multi-fidelity checkpoint, r2SCAN head (MP r2SCAN)",
            ),
            Teacher(
                "sevennet-mf-0-pbe",
                "sevenn",
                "7net-mf-0",
                "PBE",
                "PBE",
                f"{_HERE}:sevennet_mf0_pbe",
                "SevenNet-MF-0 multi-fidelity checkpoint, PBE head (MPtrj)",
            ),
        )
    }
)
#: Other spellings accepted for a teacher (``chgnet`` was the only teacher before).
ALIASES = MappingProxyType({"chgnet": "chgnet-r2scan"})


def is_teacher(name: str) -> bool:
    """Whether ``name`` (or an alias) is a registered teacher."""
    name = name.strip()
    return name in TEACHERS or name in ALIASES


def get_teacher(name: str, field: str = "teacher") -> Teacher:
    """The :class:`Teacher` called ``name`` (aliases resolved).

    Raises
    ------
    InputError
        One line naming ``field``, the value and the registered names.
    """
    key = ALIASES.get(name.strip(), name.strip())
    if key not in TEACHERS:
        raise InputError(
            f"{field} {name!r}: not an offline teacher; expected one of "
            f"{', '.join(TEACHERS)} (or alias {', '.join(ALIASES)})"
        )
    return TEACHERS[key]


def teacher_calculator(name: str = "chgnet-r2scan", field: str = "teacher"):
    """A fresh CPU ASE calculator of the teacher ``name`` (one torch thread)."""
    teacher = get_teacher(name, field)
    return load_callable(teacher.factory, f"{field} {teacher.name}")()


def teacher_info(name: str = "chgnet-r2scan", field: str = "teacher") -> dict:
    """Provenance of the teacher ``name``: registry entry and installed package versions.

    Keys: ``teacher`` (registry name), ``package``, ``model``, ``head``, ``functional``,
    ``factory``, ``description``, ``<package>_version``, ``torch_version``.
    """
    meta = get_teacher(name, field).metadata()
    meta["teacher"] = meta.pop("name")
    return meta
