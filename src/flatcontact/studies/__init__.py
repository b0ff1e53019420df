"""Studies over many runs of one interface: convergence under refinement, spread over models.

:mod:`.convergence` (``flatcontact study convergence``) refines one setting at a time
(:mod:`.variants`, the ``refine`` section) until a step no longer moves τ and σ_MSS;
:mod:`.models` (``flatcontact study models``) runs the same interface and scan with several
interaction models. Every variant is an ordinary run directory run by
:class:`flatcontact.pipeline.Pipeline` (:mod:`.runner`); :mod:`.output` writes ``study.json``,
``study.csv``, the figures and the ``uncertainty`` block a run configuration accepts
(with :mod:`flatcontact.stages.measured_on` fingerprints). docs/studies.md.
"""
