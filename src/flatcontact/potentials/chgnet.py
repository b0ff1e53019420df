"""The one CHGNet constructor (Deng et al., Nat. Mach. Intell. 5, 1031 (2023)).

CHGNet 0.4 ships its weights in the wheel (``model_name="r2scan"`` works offline). It is an
optional extra (``pip install torch==2.13.0 && pip install 'flatcontact[teacher]'``), imported
only here and only when asked.
"""

from __future__ import annotations

import contextlib
import sys

from flatcontact.foundation.errors import InputError


def chgnet_available() -> bool:
    """Whether CHGNet (and torch) can be imported."""
    try:
        import chgnet  # noqa: F401
        import torch  # noqa: F401
    except ImportError:
        return False
    return True


def chgnet_calculator(model_name: str = "r2scan", threads: int | None = None, **kwargs):
    """A CPU ``CHGNetCalculator`` for ``model_name`` (one-line InputError if not installed).

    ``threads`` sets torch's thread count when given; ``kwargs`` go to ``CHGNetCalculator``
    (e.g. ``on_isolated_atoms="ignore"``).
    """
    if not chgnet_available():
        raise InputError(
            "CHGNet is not installed; install the optional extra: pip install torch==2.13.0 && "
            "pip install 'flatcontact[teacher]'"
        )
    import torch
    from chgnet.model import CHGNet
    from chgnet.model.dynamics import CHGNetCalculator

    if threads is not None:
        torch.set_num_threads(int(threads))
    with contextlib.redirect_stdout(sys.stderr):  # CHGNet prints banners on stdout
        model = CHGNet.load(model_name=model_name, use_device="cpu", verbose=False)
        return CHGNetCalculator(model=model, use_device="cpu", **kwargs)
