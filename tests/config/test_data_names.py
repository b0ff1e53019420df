"""The names and paths the settings hold as data are the physics cores' own."""

from flatcontact.config import contact as contact_section
from flatcontact.config import load, presets, scan
from flatcontact.contact.cycle import DEFAULT_AMPLITUDE_FRACTIONS
from flatcontact.ispes.order import PREFERENCES
from flatcontact.ispes.relax import OPTIMIZERS, RelaxSettings
from flatcontact.potentials.files import BUNDLED_DIR
from flatcontact.potentials.lj import ALPHA_QUARTZ_NUMBER_DENSITY_PER_NM3
from flatcontact.structures.build import SHIPPED_DENSE_SLAB
from flatcontact.structures.sheets import BUILTIN_SHEETS


def test_scan_names_are_the_scan_cores():
    assert scan.OPTIMIZERS == OPTIMIZERS
    assert scan.DEFAULT_OPTIMIZER == RelaxSettings().optimizer
    assert scan.PREFERENCES == PREFERENCES


def test_cycle_fractions_are_the_cycle_cores():
    assert contact_section.CYCLE_AMPLITUDE_FRACTIONS == DEFAULT_AMPLITUDE_FRACTIONS


def test_preset_paths_and_densities_are_the_cores():
    assert presets.BUNDLED_POTENTIALS_DIR == BUNDLED_DIR
    assert presets.SHIPPED_DENSE_SLAB == SHIPPED_DENSE_SLAB
    assert presets.quartz_number_density_per_nm3() == ALPHA_QUARTZ_NUMBER_DENSITY_PER_NM3


def test_builtin_sheet_names_are_the_sheets():
    assert set(load.BUILTIN_SHEET_NAMES) == set(BUILTIN_SHEETS)
