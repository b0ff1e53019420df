"""The run settings: what a run configuration says, read from YAML, checked, and printed.

A configuration is a YAML mapping with the sections of :class:`RunConfig` (``structure``,
``potential``, ``scan``, ``analysis``, ``elastic``, ``uncertainty``, ``contact``,
``report``) and an optional ``preset`` key. Values not given come from the preset (``quick``
by default, or ``paper``), so a file only lists what it changes::

    preset: quick
    scan:
      grid: [8, 8]
    contact:
      p0_gpa: [0.5, 1.0, 2.0]
      cycle:
        enabled: true

Every field carries its unit in its name (``radius_um``, ``p0_gpa``,
``fmax_ev_per_angstrom``) and a description (``flatcontact config --show-default`` prints
them as comments). Unknown keys are refused. :func:`load_config` turns every problem into one
:class:`~flatcontact.foundation.errors.InputError` line that names the file and the dotted path of the
field, e.g. ``config.yaml: scan.grid: expected two positive integers, got [0, 4]``. Units:
atomistic quantities in eV and Å, loads in GPa, laws in MPa and MPa/GPa, contact geometry in
µm/nm.

The package, one job per module: :mod:`.run` (the root model) and one module per section
(:mod:`.scan`, :mod:`.analysis`, :mod:`.elastic`, :mod:`.uncertainty`, :mod:`.contact`,
:mod:`.report`; :mod:`.section` their base), :mod:`.presets`, :mod:`.merge`,
:mod:`.paths` (every dotted settings path and its field), :mod:`.messages` (error
wording; an unknown key names the setting it probably meant), :mod:`.yaml_io` (the strict YAML reader, :func:`to_yaml`) and :mod:`.load`. The
settings import no physics beyond the two data models they hold (the structure recipe and
the interaction model); the checks that need files or the physics cores run before a run in
:mod:`flatcontact.stages.preflight`.
"""

from flatcontact.config.load import build_config, load_config, recipe_files
from flatcontact.config.merge import merge_config
from flatcontact.config.presets import (
    BUNDLED_SNAP,
    MEASURED_LAW_UNCERTAINTY,
    default_potential,
    preset,
)
from flatcontact.config.run import RunConfig
from flatcontact.config.yaml_io import to_yaml

__all__ = [
    "BUNDLED_SNAP",
    "MEASURED_LAW_UNCERTAINTY",
    "RunConfig",
    "build_config",
    "default_potential",
    "load_config",
    "merge_config",
    "preset",
    "recipe_files",
    "to_yaml",
]
