"""The ``report`` section: the HTML report and its figures."""

from __future__ import annotations

from pydantic import Field

from flatcontact.config.section import Section
from flatcontact.foundation.numbers import physical


class ReportConfig(Section):
    """The HTML report (stage ``report``)."""

    title: str = Field("flatcontact run", description="report title")
    fig2_p_gpa: list[physical(-1e3, 1e3, "GPa")] | None = Field(
        None,
        description="pressures (GPa, among analysis.p_gpa) with a Fig. 2 panel; null: lowest, "
        "middle and highest",
    )
    svg: bool = Field(True, description="also write SVG figures next to the PNGs")
    approximant_study: str | None = Field(
        None,
        description="study.json of a 'flatcontact study approximants --out DIR' of this "
        "interface (relative to the config file): the report tables its cells toward the "
        "incommensurate contact (and their collapse stresses, DIR/experiment_collapse.json) "
        "beside this run's commensurate cell; null: no such table",
    )
