"""Reading a run configuration: :func:`load_config` (a YAML file) and :func:`build_config` (a mapping).

Both lay the data over a preset (:mod:`.presets`, :mod:`.merge`), validate with the section models (:class:`~.run.RunConfig`) and turn
every problem into one :class:`~flatcontact.foundation.errors.InputError` line naming the source and the
dotted field path (:mod:`.messages`). :func:`load_config` also resolves the file fields
against the config file's directory and checks that they exist.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from pydantic import ValidationError

from flatcontact.config.merge import merge_config, replaces_model
from flatcontact.config.messages import one_line, show
from flatcontact.config.paths import suggestion
from flatcontact.config.presets import preset
from flatcontact.config.run import RunConfig
from flatcontact.config.yaml_io import MAX_CONFIG_BYTES, parse_yaml
from flatcontact.foundation.errors import InputError
from flatcontact.foundation.fileio import read_text_file
from flatcontact.structures.recipe import FILE_FIELDS as RECIPE_FILE_FIELDS

#: Names of the built-in sheets a recipe's ``sheet`` may give instead of a file
#: (:data:`flatcontact.structures.sheets.BUILTIN_SHEETS`; a test keeps them equal).
BUILTIN_SHEET_NAMES = ("graphene", "h-BN", "MoS2")
#: Fields naming an input file (relative to the config file); they must exist.
FILE_FIELDS = ("contact.experiment.csv", "report.approximant_study")
#: Fields naming a list of input files (each relative to the config file).
FILE_LIST_FIELDS = ("contact.fit.csv",)


def build_config(
    data: dict | None = None, preset_name: str | None = None, source: str = "config"
) -> RunConfig:
    """A validated :class:`RunConfig` from ``data`` laid over a preset.

    Parameters
    ----------
    data
        Nested mapping as read from YAML (may be empty or ``None``).
    preset_name
        ``quick`` or ``paper``; overrides ``data['preset']``; default ``quick``.
    source
        Name used in error messages (the file path).
    """
    data = dict(data or {})
    name = preset_name or data.pop("preset", None) or "quick"
    data.pop("preset", None)
    if name not in ("quick", "paper"):
        raise InputError(f"{source}: preset: expected quick or paper, got {show(name)}")
    base = preset(name)
    if replaces_model(data.get("potential")):
        base.pop("potential")  # a preset, a calculator or new styles: not the default's LJ
    merged = merge_config(base, data)
    if "uncertainty" in base and "uncertainty" not in data:
        # the preset's measured uncertainty belongs to the preset's interface and model only
        if merged.get("structure") != base.get("structure") or merged.get("potential") != base.get(
            "potential"
        ):
            merged.pop("uncertainty")
    try:
        return RunConfig.model_validate(merged)
    except ValidationError as exc:
        raise one_line(exc, source, suggestion) from None
    except InputError as exc:  # InteractionModel's own one-line errors ("potential intra: ...")
        text = str(exc)
        if text.startswith("potential "):
            text = "potential." + text.removeprefix("potential ")
        raise InputError(f"{source}: {text}") from None


def load_config(path: str | Path | None = None, preset_name: str | None = None) -> RunConfig:
    """Read and validate a run configuration (YAML); ``None`` gives the preset alone.

    Relative paths inside the file (``structure.file``, ``contact.experiment.csv``) are
    resolved against the file's directory; ``uncertainty`` may name a file holding the block
    (what ``flatcontact study export-uncertainty`` writes, or a study's ``uncertainty.yaml``),
    read in its place. Every problem is one :class:`InputError` line
    naming the file and the field path: a file that is missing, a directory, unreadable,
    larger than :data:`~flatcontact.config.yaml_io.MAX_CONFIG_BYTES`, not UTF-8, not YAML,
    nested deeper than :data:`~flatcontact.config.yaml_io.MAX_CONFIG_DEPTH` or with a key
    given twice; a field out of range or above a size bound (:mod:`flatcontact.foundation.limits`); a
    file field naming no readable file.
    """
    if path is None:
        return build_config({}, preset_name, "default config")
    path = Path(path)
    data = parse_yaml(read_text_file(path, "config file", MAX_CONFIG_BYTES), str(path))
    if data is None:
        data = {}
    if not isinstance(data, dict):
        raise InputError(f"{path}: expected a mapping of sections, got {type(data).__name__}")
    if isinstance(data.get("uncertainty"), str):
        data["uncertainty"] = _uncertainty_file(data["uncertainty"], path)
    for dotted in FILE_FIELDS:
        holder, key = _holder(data, dotted)
        if isinstance(holder, dict) and isinstance(holder.get(key), str):
            holder[key] = _resolved(holder[key], path.parent)
    structure = data.get("structure")
    if isinstance(structure, dict):
        _resolve_recipe_files(structure, path.parent)
    for dotted in FILE_LIST_FIELDS:
        holder, key = _holder(data, dotted)
        if isinstance(holder, dict) and isinstance(holder.get(key), list):
            holder[key] = [
                str((path.parent / Path(v).expanduser()).resolve()) if isinstance(v, str) else v
                for v in holder[key]
            ]
    try:
        cfg = build_config(data, preset_name, str(path))
    except RecursionError:
        raise InputError(f"{path}: nested too deeply; expected a mapping of sections") from None
    for dotted in FILE_FIELDS:
        value = _setting(cfg, dotted)
        if value is None:
            continue
        target = Path(value)
        if not target.exists():
            raise InputError(f"{path}: {dotted}: file {value} not found")
        if not target.is_file():
            raise InputError(f"{path}: {dotted}: {value} is not a regular file")
    for dotted, value in recipe_files(cfg.structure):
        if not Path(value).exists():
            raise InputError(f"{path}: structure.{dotted}: file {value} not found")
        if not Path(value).is_file():
            raise InputError(f"{path}: structure.{dotted}: {value} is not a regular file")
    for dotted in FILE_LIST_FIELDS:
        for value in _setting(cfg, dotted):
            if not Path(value).is_file():
                raise InputError(f"{path}: {dotted}: file {value} not found")
    return cfg


def recipe_files(recipe: Any) -> list[tuple[str, str]]:
    """(dotted field, path) of every file the recipe reads (built-in sheets excluded)."""
    out = []
    for dotted in RECIPE_FILE_FIELDS:
        obj = recipe
        for part in dotted.split("."):
            obj = getattr(obj, part, None)
        if isinstance(obj, str) and obj not in BUILTIN_SHEET_NAMES:
            out.append((dotted, obj))
    return out


def _uncertainty_file(name: str, config: Path) -> dict:
    """The ``uncertainty`` block in the file ``name`` (relative to the config file ``config``).

    The file is what ``flatcontact study export-uncertainty`` writes (JSON), or a study's
    ``uncertainty.yaml`` or ``study.json`` (the block under an ``uncertainty`` key), or a
    study directory (its ``uncertainty.yaml``); each is read as YAML.
    A missing, unreadable or non-mapping file is one InputError line naming the field.
    """
    target = Path(_resolved(name, config.parent))
    field = f"{config}: uncertainty"
    if target.is_dir():  # a study directory: its uncertainty.yaml
        target = target / "uncertainty.yaml"
    if not target.is_file():
        raise InputError(
            f"{field}: file {target} not found (expected a file written by "
            "'flatcontact study export-uncertainty', a study directory or its uncertainty.yaml)"
        )
    block = parse_yaml(read_text_file(target, "uncertainty file", MAX_CONFIG_BYTES), str(target))
    if isinstance(block, dict) and isinstance(block.get("uncertainty"), dict):
        block = block["uncertainty"]  # a study's uncertainty.yaml or study.json
    if not isinstance(block, dict):
        raise InputError(f"{field}: {target} holds no uncertainty block (expected a mapping)")
    return block


def _holder(data: dict, dotted: str) -> tuple[Any, str]:
    """The mapping of ``data`` that holds the last key of ``dotted`` (or ``None``), and that key."""
    *parents, leaf = dotted.split(".")
    holder: Any = data
    for part in parents:
        holder = holder.get(part) if isinstance(holder, dict) else None
    return holder, leaf


def _setting(cfg: RunConfig, dotted: str) -> Any:
    value: Any = cfg
    for part in dotted.split("."):
        value = getattr(value, part)
    return value


def _resolved(value: str, base: Path) -> str:
    target = Path(value).expanduser()
    return str(target if target.is_absolute() else (base / target).resolve())


def _resolve_recipe_files(structure: dict, base: Path) -> None:
    """Make the recipe's file fields (``file``, ``bulk``, ``sheet``, ``slab2.*``) relative to
    ``base``, in place; built-in sheet names (graphene, h-BN, MoS2) stay names."""
    for dotted in RECIPE_FILE_FIELDS:
        holder, leaf = _holder(structure, dotted)
        if isinstance(holder, dict) and isinstance(holder.get(leaf), str):
            if holder[leaf] not in BUILTIN_SHEET_NAMES:
                holder[leaf] = _resolved(holder[leaf], base)
