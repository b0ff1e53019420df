"""The static import graph of flatcontact's own modules, read from the source with :mod:`ast`.

Nothing is imported: each ``.py`` file below the package is parsed and every ``import`` /
``from ... import`` statement found anywhere in it (module level, inside functions, under
``if TYPE_CHECKING:``) that names a flatcontact module becomes an edge. Conventions:

- module names are dotted (``flatcontact.ispes.scan``); a package is named by its
  ``__init__.py`` (``flatcontact.ispes``);
- relative imports are resolved against the importing module's package;
- ``from pkg import name`` is an edge to ``pkg.name`` when that is a module (a submodule
  imported by name), and to ``pkg`` otherwise;
- importing a module runs the ``__init__`` of each of its parent packages, so every module
  depends on its parent packages (``flatcontact.ispes.scan`` -> ``flatcontact.ispes`` ->
  ``flatcontact``); :func:`import_closure` follows those edges too.

Two users: the stage fingerprints (:func:`closure_digest` of each stage module's closure,
:mod:`flatcontact.pipeline`) and the layer contract (``tests/test_architecture.py``).
"""

from __future__ import annotations

import ast
import functools
import hashlib
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path

from flatcontact.foundation.fileio import file_sha256

PACKAGE = "flatcontact"
#: The installed source tree: the folder that holds the ``flatcontact`` package.
SOURCE_ROOT = Path(__file__).resolve().parents[2]
#: Folder name of package data (shipped files beside a sub-package's modules).
DATA_DIR = "data"


@dataclass(frozen=True)
class Edge:
    """One import statement from ``source`` to ``target`` (both dotted module names).

    ``line`` is the statement's line in ``source``; ``function_level`` says the statement
    sits inside a function (run when the function is called, not when the module loads).
    """

    source: str
    target: str
    line: int
    function_level: bool


@dataclass(frozen=True)
class ImportGraph:
    """Modules (dotted name -> source file) and the import edges between them."""

    root: Path
    files: dict[str, Path]
    edges: tuple[Edge, ...]

    def imports(self, module: str) -> set[str]:
        """The modules ``module`` imports directly (its parent packages included)."""
        out = {e.target for e in self.edges if e.source == module}
        return out | set(parent_packages(module))

    def adjacency(self) -> dict[str, set[str]]:
        """Every module -> the modules it imports directly (parent packages included)."""
        adj: dict[str, set[str]] = {m: set(parent_packages(m)) for m in self.files}
        for e in self.edges:
            adj[e.source].add(e.target)
        return adj


def parent_packages(module: str) -> list[str]:
    """``"a.b.c"`` -> ``["a.b", "a"]``: the packages whose ``__init__`` importing it runs."""
    parts = module.split(".")
    return [".".join(parts[:i]) for i in range(len(parts) - 1, 0, -1)]


def _module_files(root: Path, package: str) -> dict[str, Path]:
    files = {}
    for path in sorted((root / package).rglob("*.py")):
        if "__pycache__" in path.parts:
            continue
        parts = list(path.relative_to(root).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        files[".".join(parts)] = path
    return files


_BODIES = ("body", "orelse", "finalbody", "handlers", "cases")


def _import_statements(
    body: list[ast.AST], in_function: bool = False
) -> Iterator[tuple[ast.Import | ast.ImportFrom, bool]]:
    """Every import statement in ``body`` and the blocks nested in it, with whether it sits
    inside a function. Only statements are visited: an import is always a statement."""
    for node in body:
        if isinstance(node, ast.Import | ast.ImportFrom):
            yield node, in_function
            continue
        inner = in_function or isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef)
        for field in _BODIES:
            for child in getattr(node, field, ()):
                if isinstance(child, ast.stmt):
                    yield from _import_statements([child], inner)
                else:  # an except handler or a match case: a block of statements
                    yield from _import_statements(child.body, inner)


def _resolve(module: str, is_package: bool, level: int, name: str | None) -> str:
    """The absolute module named by ``from <level dots><name> import ...`` in ``module``."""
    if level == 0:
        return name or ""
    base = module.split(".")
    if not is_package:
        base = base[:-1]
    base = base[: len(base) - (level - 1)]
    return ".".join(base + ([name] if name else []))


def _existing(name: str, files: dict[str, Path]) -> str:
    """``name`` or its nearest enclosing module that exists (``""`` if none)."""
    while name and name not in files:
        name = name.rpartition(".")[0]
    return name


def module_edges(module: str, path: Path, files: dict[str, Path], package: str) -> list[Edge]:
    """The import edges of one source file to the modules in ``files``."""
    tree = ast.parse(path.read_bytes(), filename=str(path))
    is_package = path.name == "__init__.py"
    edges = []
    for node, in_function in _import_statements(tree.body):
        targets: list[str] = []
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        else:
            base = _resolve(module, is_package, node.level, node.module)
            for alias in node.names:
                sub = f"{base}.{alias.name}"
                targets.append(sub if sub in files else base)
        for name in targets:
            if name != package and not name.startswith(package + "."):
                continue
            target = _existing(name, files)
            if target and target != module:
                edges.append(Edge(module, target, node.lineno, in_function))
    return sorted(set(edges), key=lambda e: (e.line, e.target))


@functools.cache
def import_graph(root: Path = SOURCE_ROOT, package: str = PACKAGE) -> ImportGraph:
    """The import graph of ``package`` under the source folder ``root``.

    Parameters
    ----------
    root
        The folder that holds the package folder (``src/``, or a copy of it); default: the
        installed flatcontact.
    package
        The top-level package's name.

    The graph is computed once per ``root`` and process: a tree whose import lines change
    after the first call keeps its first graph (file contents are read afresh by
    :func:`closure_digest`).
    """
    root = Path(root).resolve()
    files = _module_files(root, package)
    edges: list[Edge] = []
    for module, path in files.items():
        edges.extend(module_edges(module, path, files, package))
    edges.sort(key=lambda e: (e.source, e.line, e.target))
    return ImportGraph(root, files, tuple(edges))


def import_closure(
    module: str,
    root: Path = SOURCE_ROOT,
    exclude: Iterable[str] = (),
    package: str = PACKAGE,
) -> frozenset[str]:
    """Every flatcontact module that importing ``module`` can load, ``module`` included.

    Parameters
    ----------
    module
        Dotted module name (``"flatcontact.stages.scan"``).
    root
        The source folder holding the package (default: the installed flatcontact).
    exclude
        Dotted prefixes (``"flatcontact.plots"``): modules equal to or below one are left
        out of the result. Their imports are still followed, so a module reached only
        through an excluded one is in the closure.
    package
        The top-level package's name.
    """
    graph = import_graph(Path(root).resolve(), package)
    if module not in graph.files:
        raise ValueError(f"import_closure: {module!r} is not a module of {graph.root / package}")
    excluded = tuple(exclude)

    def skipped(name: str) -> bool:
        return any(name == p or name.startswith(p + ".") for p in excluded)

    adjacency = graph.adjacency()
    seen = {module}
    todo = [module]
    while todo:
        for target in adjacency[todo.pop()]:
            if target not in seen:
                seen.add(target)
                todo.append(target)
    return frozenset(m for m in seen if m == module or not skipped(m))


def closure_files(modules: Iterable[str], root: Path = SOURCE_ROOT) -> list[Path]:
    """The files a set of modules runs: their sources and their sub-packages' data.

    Package data is the files below a ``data/`` folder of a sub-package in ``modules``
    (``structures/data/``, the shipped reference slab). The top-level ``flatcontact/data/``
    (the bundled potentials) is not included: a stage reads those files as inputs, and they
    enter its fingerprint by content through the interaction model.
    """
    graph = import_graph(Path(root).resolve())
    files: set[Path] = set()
    for module in modules:
        path = graph.files[module]
        files.add(path)
        if path.name == "__init__.py" and "." in module:
            data = path.parent / DATA_DIR
            if data.is_dir():
                files.update(
                    f for f in data.rglob("*") if f.is_file() and "__pycache__" not in f.parts
                )
    return sorted(files)


def closure_digest(modules: Iterable[str], root: Path = SOURCE_ROOT) -> str:
    """SHA-256 over the sorted (path relative to ``root``, content digest) of the modules'
    files (:func:`closure_files`): it changes when, and only when, one of them does."""
    root = Path(root).resolve()
    digest = hashlib.sha256()
    for path in closure_files(modules, root):
        digest.update(path.relative_to(root).as_posix().encode() + b"\0")
        digest.update(bytes.fromhex(file_sha256(path)))
    return digest.hexdigest()
