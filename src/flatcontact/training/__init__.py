"""Training and validating interaction models for SiO₂: SNAP fits to teacher labels
(:func:`train_snap`), their validation against the teacher and experiment
(:func:`validate_potential`), and the ISPES comparison of models on one interface
(:func:`compare_ispes`).

Names load on first use (:mod:`lazy_loader`); code inside flatcontact imports them from the
module that defines them.
"""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__,
    submod_attrs={
        "dataset": ["read_dataset", "write_dataset"],
        "ispes_check": ["compare_ispes", "comparison_table", "scan_and_analyze"],
        "recipe": ["sio2_recipe"],
        "train": ["train_snap"],
        "validate": ["targets_met", "validate_potential"],
    },
)
