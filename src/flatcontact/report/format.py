"""How the report writes numbers and warnings: table cells, values with their standard
errors, and the stages' warnings one box per kind."""

from __future__ import annotations

import math
import re
from typing import Any

import numpy as np

#: The four law coefficients: (key, key of its standard error, label), in table order.
LAW_COEFFICIENTS = (
    ("k_mpa_per_gpa", "k_stderr_mpa_per_gpa", "k (MPa/GPa)"),
    ("tau0_mpa", "tau0_stderr_mpa", "τ0 (MPa)"),
    ("mu_mpa_per_gpa", "mu_stderr_mpa_per_gpa", "μ (MPa/GPa)"),
    ("sigma0_mpa", "sigma0_stderr_mpa", "σ0 (MPa)"),
)


def fmt(value: Any, digits: int = 4) -> str:
    """A number for a table cell (4 significant digits; 'n/a' for None and non-finite)."""
    if value is None or (isinstance(value, float) and not np.isfinite(value)):
        return "n/a"
    if isinstance(value, float):
        return f"{value:.{digits}g}"
    return str(value)


def pm(value: float | None, err: float | None) -> str:
    """``value ± err`` (3 and 2 significant digits; ``value`` alone without ``err``; 'n/a').

    A value whose third significant digit is coarser than the error's second is written to
    the error's decimal place instead, so the digits the error resolves are not rounded away
    (τ0 of Ni(111): ``5876.02 ± 0.87``, not ``5.88e+03 ± 0.87``).
    """
    if value is None:
        return "n/a"
    if err is None:
        return f"{value:.3g}"
    if value != 0 and err > 0 and math.isfinite(value) and math.isfinite(err):
        value_step = 10.0 ** (math.floor(math.log10(abs(value))) - 2)
        decimals = 1 - math.floor(math.log10(err))  # the error's second significant digit
        if value_step > 10.0**-decimals * (1 + 1e-12) and decimals >= 0:
            return f"{value:.{decimals}f} ± {err:.{decimals}f}"
    return f"{value:.3g} ± {err:.2g}"


#: A stage warning ``"Category: <source> at P = <p> GPa<detail>: <message>"``.
_WARNING = re.compile(
    r"^(?P<kind>[A-Za-z]+): (?:.*? )?at P = (?P<p>[-+0-9.eE]+) GPa(?P<detail>[^:]*): (?P<body>.*)$",
    re.DOTALL,
)


def _kind_words(kind: str) -> str:
    """``DegenerateMinimaWarning`` → ``Degenerate minima``."""
    words = re.findall(r"[A-Z][a-z]*|[a-z]+", kind.removesuffix("Warning"))
    text = " ".join(w.lower() for w in words)
    return text[:1].upper() + text[1:]


def grouped_warnings(lines: list[str]) -> list[str]:
    """One box per warning kind: the kind, the loads it occurs at, then each load's message.

    ``lines`` are a stage's warnings as stored (``"Category: message"``); a message of the
    form ``"<source> at P = <p> GPa<detail>: <text>"`` is grouped with the others of its
    category under ``"<Kind> at P = p1, p2 GPa:"`` with one line ``"P = p GPa<detail>:
    <text>"`` per load (the file path of the source left out); any other line is kept as it
    is, repeated lines once. Lines of a box are separated by newlines.
    """
    groups: dict[str, list[tuple[str, str]]] = {}
    out: list[str] = []
    slots: dict[str, int] = {}
    for line in lines:
        m = _WARNING.match(line)
        if m is None:
            if line not in out:
                out.append(line)
            continue
        kind = m.group("kind")
        if kind not in slots:
            slots[kind] = len(out)
            out.append("")
        groups.setdefault(kind, []).append(
            (m.group("p"), f"P = {m.group('p')} GPa{m.group('detail')}: {m.group('body')}")
        )
    for kind, items in groups.items():
        loads = ", ".join(dict.fromkeys(p for p, _ in items))
        out[slots[kind]] = "\n".join(
            [f"{_kind_words(kind)} at P = {loads} GPa:", *(text for _, text in items)]
        )
    return out
