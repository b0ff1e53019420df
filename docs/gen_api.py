"""Write docs/api.md, the reference of flatcontact's public Python names, from their docstrings.

    python docs/gen_api.py          # rewrites docs/api.md
    python docs/gen_api.py --check  # exit 1 if docs/api.md is not what the code gives

Every name of ``flatcontact.__all__`` gets its signature, the module that defines it and the
first paragraph of its docstring; ``tests/test_docs.py`` fails when the page is stale.
"""

from __future__ import annotations

import inspect
import sys
from pathlib import Path

PAGE = Path(__file__).resolve().parent / "api.md"

HEADER = """# Python API reference

Generated from the docstrings by `python docs/gen_api.py` (do not edit by hand; the test
suite fails when this page and the code disagree). Every name is importable from the top
level, `from flatcontact import NAME`, and loaded on first use. The full docstring of each
(parameters, units, conventions, equations) is `help(flatcontact.NAME)`.

A scan with the calculator in hand, its analysis and the contact on its laws:

```python
from ase.build import fcc111
from ase.calculators.emt import EMT
from flatcontact import analyze_ispes, contact_from_laws, make_interface, scan_interface

slab = fcc111("Cu", size=(1, 1, 3), a=3.59, orthogonal=False, periodic=True)
interface = make_interface(slab, gap_angstrom=2.1, face_atoms=1)
ispes = scan_interface(interface, EMT(), grid=(3, 3), p_range_gpa=(-1.0, 3.0, 5))
result = analyze_ispes(ispes, [0.0, 0.5, 1.0, 1.5])        # tau, sigma_MSS per load, laws
contact = contact_from_laws(result.laws, [0.5], radius_um=5.0,
                            contact_modulus_gpa=70.0, shear_modulus_gpa=100.0)
contact.records()[0]["effective_shear_strength_mpa"]
```

This example runs as a doctest in the test suite (`flatcontact.notebook`'s module docstring).
The whole study from a configuration is `Pipeline(load_config("my.yaml"), "run").run()`
([tutorial.md](tutorial.md)).
"""


def _summary(obj) -> str:
    doc = inspect.getdoc(obj) or "(no docstring)"
    return doc.split("\n\n", 1)[0].replace("\n", " ")


def _signature(name: str, obj) -> str:
    try:
        sig = str(inspect.signature(obj))
    except (TypeError, ValueError):
        return name
    return f"{name}{sig}"


def render() -> str:
    """The page's text from the installed code."""
    import flatcontact

    groups: dict[str, list[str]] = {}
    for name in sorted(n for n in flatcontact.__all__ if n != "__version__"):
        obj = getattr(flatcontact, name)
        module = getattr(obj, "__module__", "flatcontact")
        kind = "class" if inspect.isclass(obj) else "function" if callable(obj) else "value"
        entry = [f"### `{name}`", "", f"{kind} in `{module}`", ""]
        if callable(obj):
            entry += ["```python", _signature(name, obj), "```", ""]
        entry += [_summary(obj), ""]
        groups.setdefault(module.split(".")[1] if "." in module else module, []).append(
            "\n".join(entry)
        )
    parts = [HEADER]
    for group in sorted(groups):
        parts.append(f"## {group}\n")
        parts.extend(groups[group])
    return "\n".join(parts).rstrip() + "\n"


def main(argv: list[str]) -> int:
    text = render()
    if "--check" in argv:
        return 0 if PAGE.read_text(encoding="utf-8") == text else 1
    PAGE.write_text(text, encoding="utf-8")
    print(f"wrote {PAGE.name} ({text.count('### ')} names)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
