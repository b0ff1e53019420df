"""Crystal slabs and two-slab interfaces that follow the interface contract.

Build an interface from a ``structure:`` recipe (:func:`build_interface`), from two slabs
(:func:`make_interface`), or read a finished one (:func:`read_interface`); the contract of
``interface.extxyz`` (slab/surface tags, held layers, thickness) is
:mod:`.interface_contract`.
"""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__,
    submod_attrs={
        "assemble": ["make_interface"],
        "construct": ["build_interface"],
        "interface_contract": ["fixed_mask", "in_plane_vectors", "thickness", "validate_interface"],
        "interface_io": ["read_interface", "write_interface"],
        "placement": ["place_slab2"],
        "recipe": ["parse_recipe"],
    },
)
