"""Named warnings of the ISPES analysis.

They are :class:`UserWarning` subclasses (not ``RuntimeWarning``): each says
something about the *input data* that the user should know, with the number it
concerns. Turn them into errors with ``warnings.simplefilter("error", AnalysisWarning)``.
"""


class AnalysisWarning(UserWarning):
    """Base class of the analysis warnings."""


class UnconvergedPointsWarning(AnalysisWarning):
    """Grid points with finite values but ``converged = False`` are being used."""


class StressEnergyMismatchWarning(AnalysisWarning):
    """``normal_stress`` disagrees with ``-(1/A) dU/dz`` of the energy column."""


class PathNotPeriodicWarning(AnalysisWarning):
    """The sliding path did not reach a minimum equivalent to its start within the maximum length."""


class LinearFitWarning(AnalysisWarning):
    """Too few points below the threshold for a load law with standard errors."""


class LoadNoiseWarning(AnalysisWarning):
    """The noise that the load's error puts into the constant-pressure ISPES is a sizeable
    fraction of τ or of the barriers (see :mod:`flatcontact.analysis.noise`)."""


class DegenerateMinimaWarning(AnalysisWarning):
    """The landscape has inequivalent minima within the noise of the global one, and τ differs
    between them: the slider's τ depends on which of them it sits in (see
    :mod:`flatcontact.analysis.starts`)."""


class LoadFoldWarning(AnalysisWarning):
    """A column's load rises with thickness on the compressed side (a fold: a plane slips or
    opens under load, or the energy-derived load is noisy there). Every load asked lies below
    the fold, on the branch that carries P = 0; the nodes above it are not used."""


class GridResolutionWarning(AnalysisWarning):
    """The lateral grid does not resolve τ: τ on the full grid and on a coarser grid from the
    same samples differ by more than the stated fraction of τ (see
    :mod:`flatcontact.analysis.grid_error`), or the estimate could not be made."""
