"""The run directory's layout: the stage folders and the names of the files each stage writes.

The one place these names are spelled. The stages (:mod:`flatcontact.stages`) write the
files under these names, the ISPES driver its point store and ``ispes.nc``, the pipeline
reads them from upstream folders, and the report (:mod:`flatcontact.report`) and the CLI read
them back. A figure is named by its stem: the stage saves ``<stem>.png`` (and ``<stem>.svg``
with ``report.svg``), the report embeds ``<stem>.png``.

A run directory::

    run.json  config.yaml  versions.json  run.log  report.html
    01-build/    interface.extxyz  build.json  fig1_interface.{png,svg}
    02-scan/     points.db  (rerelax.db)  ispes.nc  scan.json  fig_scan_columns.{png,svg}
    03-analyze/  friction.csv  friction.nc  analyze.json  fig2_p<P>gpa.{png,svg}
    04-laws/     laws.json  fig3_laws.{png,svg}
    05-elastic/  elastic.json                       (only with elastic.enabled)
    06-contact/  contact.nc  summary.json  (fit.json)  fig4_traction  fig5_force_stiffness(_rms)
                 (fig6_experiment  fig5c_cycle_loops  fig6_lockin  fig6_fit)
    07-report/   report.html  (refusal.json: a run refused after the scan)
    08-asperity/ asperity.nc  asperity.json  fig_asperity_*  state/   (only with asperity.enabled)

and every stage folder holds its record ``stage.json`` (:data:`flatcontact.foundation.rundir.RECORD_NAME`).
"""

from __future__ import annotations

#: Stage names and their folder indices, in the order of a run.
STAGES = {
    "build": 1,
    "scan": 2,
    "analyze": 3,
    "laws": 4,
    "elastic": 5,
    "contact": 6,
    "report": 7,
    # optional (asperity.enabled), run before the report; numbered after it so that the
    # folders of existing runs keep their names
    "asperity": 8,
}


def png(stem: str) -> str:
    """The PNG file of the figure ``stem`` (the format every figure is saved in)."""
    return f"{stem}.png"


# ---- the run directory itself
#: The marker that makes a folder a flatcontact run directory.
RUN_MARKER = "run.json"
#: The run's settings as YAML, resolved.
CONFIG_YAML = "config.yaml"
#: Package versions of the run.
VERSIONS_JSON = "versions.json"
#: The run's log.
RUN_LOG = "run.log"

# ---- build
#: The relaxed reference interface (the interface contract).
INTERFACE = "interface.extxyz"
BUILD_JSON = "build.json"
BUILD_FIGURE = "fig1_interface"

# ---- scan
#: The scan's resumable point store.
POINTS_DB = "points.db"
#: The probe's finished units (:mod:`flatcontact.ispes.probe_units`), beside the store.
PROBE_JSON = "probe.json"
#: The points of folding columns relaxed again at a tighter fmax (:mod:`flatcontact.ispes.rerelax`).
RERELAX_DB = "rerelax.db"
#: The ISPES contract (:mod:`flatcontact.ispes.contract`).
ISPES_NC = "ispes.nc"
SCAN_JSON = "scan.json"
SCAN_FIGURE = "fig_scan_columns"

# ---- analyze
FRICTION_CSV = "friction.csv"
FRICTION_NC = "friction.nc"
ANALYZE_JSON = "analyze.json"
#: The energy form not reported (``analysis.energy_form``'s other): per-load table and analysis
#: warnings, which the laws stage fits (:func:`flatcontact.analysis.energy_forms.form_loads`).
OTHER_FORM_JSON = "other_form.json"


def analyze_figure(p_gpa: float) -> str:
    """The stem of Fig. 2 at the load ``p_gpa`` (GPa): ``fig2_p0.5gpa``."""
    return f"fig2_p{p_gpa:g}gpa"


# ---- laws
LAWS_JSON = "laws.json"
LAWS_FIGURE = "fig3_laws"

# ---- elastic
ELASTIC_JSON = "elastic.json"

# ---- contact
SUMMARY_JSON = "summary.json"
CONTACT_NC = "contact.nc"
#: The multi-load fit of measured curves (with ``contact.fit.csv``).
FIT_JSON = "fit.json"
FIG4_TRACTION = "fig4_traction"
FIG5_FORCE_STIFFNESS = "fig5_force_stiffness"
FIG5_FORCE_STIFFNESS_RMS = "fig5_force_stiffness_rms"
FIG6_EXPERIMENT = "fig6_experiment"
FIG5C_CYCLE_LOOPS = "fig5c_cycle_loops"
FIG6_LOCKIN = "fig6_lockin"
FIG6_FIT = "fig6_fit"
#: Effective shear strength against contact radius, concurrent and size-limited slip.
FIG_SLIP_SIZE = "fig_slip_size"

# ---- asperity (``flatcontact asperity --out DIR``; docs/asperity.md)
ASPERITY_NC = "asperity.nc"
ASPERITY_JSON = "asperity.json"
#: The saved relaxed states (resume), one folder per load.
ASPERITY_STATE = "state"
FIG_ASPERITY_FORCE = "fig_asperity_force"
FIG_ASPERITY_STICK = "fig_asperity_stick"
FIG_ASPERITY_TRACTIONS = "fig_asperity_tractions"
FIG_ASPERITY_SLIP = "fig_asperity_slip"
FIG_ASPERITY_RAMP = "fig_asperity_ramp"

# ---- report
REPORT_HTML = "report.html"
#: A refused run's refusal: the stage, its message, the gates' points, the remedies
#: (:mod:`flatcontact.report.sections.refusal`).
REFUSAL_JSON = "refusal.json"


# ---- studies (``flatcontact study ... --out DIR``)
#: A study's whole record (``studies/output.py``).
STUDY_JSON = "study.json"
#: The approximant study's collapse stress per cell at the experiment's conditions
#: (``studies/approximant_collapse.py``; with ``contact.experiment.compare``).
EXPERIMENT_COLLAPSE_JSON = "experiment_collapse.json"
