"""The stages of a study, one module each, and the only code that writes a stage's files.

Every stage is a function ``<stage>_stage(settings, inputs, folder, progress=None)``:

- ``settings`` is the validated run configuration (:class:`flatcontact.config.RunConfig`);
  the stage reads only its own sections (and ``report.svg`` for its figures);
- ``inputs`` is a small frozen dataclass naming what the stage reads from upstream (files,
  or values such as the fitted laws), so the stage never looks into a run directory;
- ``folder`` receives the stage's files (``None``: compute and write nothing);
- ``progress`` is an optional callback (the scan calls ``progress(done, total)``).

It returns a typed result whose ``to_json()`` defines the keys of the stage's JSON file
once. ``flatcontact <stage>`` (:mod:`flatcontact.cli`) and ``flatcontact run``
(:mod:`flatcontact.pipeline`) both call these functions, so they write the same files.

=========  =====================================  ==========================================
stage      function                               files
=========  =====================================  ==========================================
build      :func:`.build.build_stage`             interface.extxyz, build.json, fig1_interface
scan       :func:`.scan.scan_stage`               points.db, (rerelax.db), probe.json, ispes.nc, scan.json, fig_scan_columns
analyze    :func:`.analyze.analyze_stage`         friction.csv, friction.nc, analyze.json, other_form.json, fig2_p*
laws       :func:`.laws.laws_stage`               laws.json, fig3_laws
elastic    :func:`.elastic.elastic_stage`         elastic.json
contact    :func:`.contact.contact_stage`         contact.nc, summary.json, fig4, fig5, (fig6)
report     :func:`.report.report_stage`           report.html, (refusal.json: a run refused after the scan)
asperity   :func:`.asperity.asperity_stage`       asperity.nc, asperity.json, fig_asperity_*, state/
=========  =====================================  ==========================================
"""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__,
    submod_attrs={
        "analyze": ["AnalyzeInputs", "analyze_stage"],
        "asperity": ["AsperityInputs", "asperity_stage"],
        "build": ["BuildInputs", "build_stage"],
        "contact": ["ContactInputs", "contact_stage"],
        "elastic": ["ElasticInputs", "elastic_stage"],
        "laws": ["LawsInputs", "laws_stage"],
        "report": ["ReportInputs", "report_stage"],
        "scan": ["ScanInputs", "scan_stage"],
    },
)
