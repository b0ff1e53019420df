"""How the report writes numbers: table cells and values with their standard errors."""

from __future__ import annotations

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
    """``value ± err`` (3 and 2 significant digits; ``value`` alone without ``err``; 'n/a')."""
    if value is None:
        return "n/a"
    return f"{value:.3g} ± {err:.2g}" if err is not None else f"{value:.3g}"
