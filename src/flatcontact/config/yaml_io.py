"""YAML in and out: the safe, strict loader with size and depth bounds, and :func:`to_yaml`.

In: :func:`parse_yaml` reads with ``yaml.SafeLoader`` (no Python objects), refuses a key
given twice in one mapping and nesting deeper than :data:`MAX_CONFIG_DEPTH`; the file itself
is read within :data:`MAX_CONFIG_BYTES` (:func:`flatcontact.foundation.fileio.read_text_file`).

Anchors and aliases (``&name`` / ``*name``) are allowed, but the document they expand to is
bounded: before anything is constructed, the composed node graph is counted as the tree the
aliases expand to (each alias counts every node below its anchor, memoised per node, so the
count itself is linear in the file) and a document of more than :data:`MAX_CONFIG_NODES`
expanded nodes, or an alias that refers to a node containing it, is refused in one line
naming the file. A run configuration has a few hundred nodes; the bound stops a
"billion laughs" document (nested aliases, 10⁹ nodes from a few hundred bytes) before it
reaches the settings.

Out: :func:`to_yaml` prints a configuration with every field's description as a comment
above it (``flatcontact config --show-default``).
"""

from __future__ import annotations

import json
from typing import Any

import yaml
from pydantic import BaseModel

from flatcontact.config.analysis import AnalysisConfig
from flatcontact.config.contact import ContactConfig
from flatcontact.config.elastic import ElasticConfig
from flatcontact.config.messages import show
from flatcontact.config.report import ReportConfig
from flatcontact.config.run import RunConfig
from flatcontact.config.scan import ScanConfig
from flatcontact.config.section import Section
from flatcontact.foundation.errors import InputError
from flatcontact.potentials.model import InteractionModel

#: Largest configuration file read (bytes): a run configuration is a few kB.
MAX_CONFIG_BYTES = 1_000_000
#: Deepest nesting of a configuration (sections are 3 levels deep; kwargs a few more).
MAX_CONFIG_DEPTH = 32
#: Most nodes a configuration may expand to once its aliases are expanded (scalars, lists
#: and mappings each count one; a run configuration has a few hundred, a 1000-load list
#: about a thousand).
MAX_CONFIG_NODES = 100_000


class StrictLoader(yaml.SafeLoader):
    """``yaml.SafeLoader`` that refuses a key given twice in one mapping.

    Plain YAML keeps the last value, so a second ``scan:`` silently replaced the first.
    """

    def construct_mapping(self, node, deep=False):
        seen: dict[Any, int] = {}
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=deep)
            try:
                hash(key)
            except TypeError:
                continue  # SafeLoader refuses it itself, with its own message
            if key in seen:
                raise _DuplicateKey(key, key_node.start_mark.line + 1, seen[key])
            seen[key] = key_node.start_mark.line + 1
        return super().construct_mapping(node, deep=deep)

    def construct_document(self, node):
        _check_expansion(node)
        return super().construct_document(node)


StrictLoader.add_constructor(
    yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, StrictLoader.construct_mapping
)


class _DuplicateKey(Exception):
    def __init__(self, key: Any, line: int, first: int):
        super().__init__(key, line, first)
        self.key, self.line, self.first = key, line, first


class _Expansion(Exception):
    """A document whose aliases expand past :data:`MAX_CONFIG_NODES` or into themselves."""


def _check_expansion(root: yaml.Node) -> None:
    """Refuse ``root`` if its aliases expand past :data:`MAX_CONFIG_NODES` or loop.

    The composer shares one node object per anchor, so the graph is a DAG (or, for an alias
    inside its own anchor, cyclic); the expanded size of a node is 1 + the sizes of its
    children, memoised by node identity: linear in the number of distinct nodes.
    """
    sizes: dict[int, int] = {}
    open_nodes: set[int] = set()
    # iterative post-order walk: (node, children visited?)
    stack: list[tuple[yaml.Node, bool]] = [(root, False)]
    while stack:
        node, done = stack.pop()
        key = id(node)
        if done:
            children = _children(node)
            sizes[key] = 1 + sum(sizes[id(c)] for c in children)
            open_nodes.discard(key)
            if sizes[key] > MAX_CONFIG_NODES:
                raise _Expansion(
                    f"its aliases expand to more than {MAX_CONFIG_NODES} values "
                    f"(line {node.start_mark.line + 1}); expected a plain run configuration"
                )
            continue
        if key in sizes:
            continue
        if key in open_nodes:
            raise _Expansion(
                f"an alias refers to a node that contains it (line {node.start_mark.line + 1})"
            )
        open_nodes.add(key)
        stack.append((node, True))
        stack.extend((c, False) for c in _children(node) if id(c) not in sizes)


def _children(node: yaml.Node) -> list[yaml.Node]:
    if isinstance(node, yaml.MappingNode):
        return [n for pair in node.value for n in pair]
    if isinstance(node, yaml.SequenceNode):
        return list(node.value)
    return []


def _depth(value: Any, limit: int, level: int = 0) -> int:
    """Nesting depth of ``value`` (lists and mappings), stopping once past ``limit``."""
    if level > limit:
        return level
    if isinstance(value, dict):
        items = list(value.values())
    elif isinstance(value, list):
        items = value
    else:
        return level
    return max([_depth(v, limit, level + 1) for v in items], default=level + 1)


def parse_yaml(text: str, source: str) -> Any:
    """YAML ``text`` as data; duplicate keys, bad syntax and deep nesting are one-line errors."""
    try:
        data = yaml.load(text, Loader=StrictLoader)
    except _Expansion as exc:
        raise InputError(f"{source}: {exc}") from None
    except _DuplicateKey as dup:
        raise InputError(
            f"{source}: key {show(dup.key)} given twice (lines {dup.first} and {dup.line}); "
            "expected each key once"
        ) from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" (line {mark.line + 1})" if mark is not None else ""
        problem = getattr(exc, "problem", None)
        raise InputError(
            f"{source}: not valid YAML{where}" + (f": {problem}" if problem else "")
        ) from None
    except RecursionError:
        raise InputError(
            f"{source}: nested deeper than {MAX_CONFIG_DEPTH} levels; expected a mapping of sections"
        ) from None
    if _depth(data, MAX_CONFIG_DEPTH) > MAX_CONFIG_DEPTH:
        raise InputError(
            f"{source}: nested deeper than {MAX_CONFIG_DEPTH} levels; expected a mapping of sections"
        )
    return data


def _descriptions(model: type[BaseModel]) -> dict[str, str]:
    return {name: (f.description or "") for name, f in model.model_fields.items()}


def _section_model(name: str) -> type[BaseModel] | None:
    ann = RunConfig.model_fields[name].annotation
    for cand in (
        InteractionModel,
        ScanConfig,
        AnalysisConfig,
        ElasticConfig,
        ContactConfig,
        ReportConfig,
    ):
        if ann is cand or (hasattr(ann, "__args__") and cand in ann.__args__):
            return cand
    return None


def _yaml_value(value: Any) -> str:
    return (
        yaml.safe_dump(value, default_flow_style=True, allow_unicode=True, width=1000)
        .strip()
        .removesuffix("\n...")
        .removesuffix("...")
        .strip()
    )


def _with_defaults_shown(config: RunConfig) -> dict:
    """``config.to_dict()`` with the fields a section leaves out of its dump at their default
    (``exclude_if``, to keep fingerprints) put back, so the YAML shows every setting."""
    data = config.to_dict()
    out: dict = {}
    for name in type(config).model_fields:
        section = getattr(config, name)
        if not isinstance(section, Section):
            if name in data:
                out[name] = data[name]
            continue
        dumped = data.get(name, {})
        out[name] = {
            field: dumped[field]
            if field in dumped
            else json.loads(json.dumps(getattr(section, field), default=str))
            for field in type(section).model_fields
        }
    return out


def to_yaml(config: RunConfig, comments: bool = True) -> str:
    """The configuration as YAML, with each field's description as a comment above it."""
    # the commented YAML documents every setting; the bare one is exactly to_dict()
    data = _with_defaults_shown(config) if comments else config.to_dict()
    lines = [
        "# flatcontact run configuration (units in the names: GPa, MPa, Å, eV, µm, J/m²)",
        "# values not given in a file come from the preset",
    ]
    top = _descriptions(RunConfig)
    for key, value in data.items():
        if comments and top.get(key):
            lines.append(f"# {top[key]}")
        if not isinstance(value, dict):
            lines.append(f"{key}: {_yaml_value(value)}")
            continue
        lines.append(f"{key}:")
        obj = getattr(config, key, None)
        model = type(obj) if key == "structure" else _section_model(key)
        desc = _descriptions(model) if model is not None else {}
        for sub, subval in value.items():
            if comments and desc.get(sub):
                lines.append(f"  # {desc[sub]}")
            if isinstance(subval, dict) and subval:
                lines.append(f"  {sub}:")
                # a sub-section (contact.cycle, scan.p_range_gpa) documents its fields too
                inner = getattr(obj, sub, None)
                inner_desc = _descriptions(type(inner)) if isinstance(inner, Section) else {}
                for k2, v2 in subval.items():
                    if comments and inner_desc.get(k2):
                        lines.append(f"    # {inner_desc[k2]}")
                    lines.append(f"    {k2}: {_yaml_value(v2)}")
            else:
                lines.append(f"  {sub}: {_yaml_value(subval)}")
    return "\n".join(lines) + "\n"
