"""flatcontact: the onset of sliding of a Hertzian asperity with an atomically flat crystalline contact.

The pipeline (see ``DESIGN.md`` of the project)::

    crystal -> two-slab interface -> ISPES scan U(x, y, z), p(x, y, z)
      -> constant-pressure ISPES -> sliding path -> tau, sigma_MSS, shear stiffness per load
      -> load laws tau = k p + tau0, sigma = mu p + sigma0
      -> modified Mindlin contact (Hertz + adhesion) -> Q(u), lateral stiffness
"""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("flatcontact")
except PackageNotFoundError:  # running from a source tree without installation
    __version__ = "0.0.0+unknown"

__all__ = ["__version__"]
