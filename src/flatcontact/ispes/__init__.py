"""The quasi-static ISPES scan: U(x, y, z) and p(x, y, z) of an interface over lateral shifts
and thicknesses, resumable and parallel.

:func:`run_scan` relaxes every grid point (:class:`GridSpec`, :class:`RelaxSettings`) into a
point store and writes ``ispes.nc`` (:func:`write_ispes`); :func:`open_ispes` reads and
checks it against the file contract (:mod:`.contract`).
"""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__,
    submod_attrs={
        "contract": ["open_ispes", "validate_ispes", "write_ispes"],
        "grid": ["GridSpec"],
        "relax": ["RelaxSettings"],
        "scan": ["ScanInterrupted", "ScanResult", "run_scan"],
        "separation": ["Adhesion", "adhesion"],
        "thicknesses": ["probe_thicknesses"],
    },
)
