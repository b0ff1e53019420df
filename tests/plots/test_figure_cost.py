"""Figures cost what they show: a map is one image inside the vector file (issue 33).

Fig. 2's constant-pressure map is a 160×160 pcolormesh; drawn as vector paths it made each
SVG 4.9 MB (one path per cell). Rasterised, the SVG holds the map as one embedded image and
keeps the axes, the path and the text as vector elements.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from flatcontact.analysis import synthetic as syn
from flatcontact.analysis.analyze import analyze_ispes
from flatcontact.analysis.options import AnalysisOptions
from flatcontact.plots import save_figure
from flatcontact.plots.analysis import figure_pressure

#: Cells of the map drawn by figure_pressure (160 × 160).
MAP_CELLS = 160 * 160


@pytest.fixture(scope="module")
def fig2_svg(tmp_path_factory):
    a1, a2 = syn.hexagonal_cell(4.916)
    grid = syn.SyntheticInterface(
        a1, a2, syn.three_cosine(a1, a2), corrugation_ev_per_a2=-2e-4
    ).grid(9, 9, np.linspace(24.3, 26.4, 36))
    result = analyze_ispes(grid, [1.0], AnalysisOptions(direction_deg=90.0, threshold_gpa=None))
    folder = tmp_path_factory.mktemp("fig2")
    (svg,) = save_figure(figure_pressure(result.pressures[0], result), folder / "fig2", ("svg",))
    return svg.read_text()


def test_the_map_is_one_embedded_image_and_the_rest_stays_vector(fig2_svg):
    images = re.findall(r"<image\b", fig2_svg)
    # the map and the colour bar's gradient (each a raster); nothing else
    assert 1 <= len(images) <= 2
    assert 'xlink:href="data:image/png;base64,' in fig2_svg
    paths = len(re.findall(r"<path\b", fig2_svg))
    # axes, ticks, lines, arrows and glyphs: far fewer elements than the map has cells
    assert 0 < paths < MAP_CELLS // 20
    # the titles stay in the file as vector glyphs (matplotlib writes a comment per text)
    assert "constant-P ISPES" in fig2_svg


def test_fig2_svg_is_small(fig2_svg):
    # 4.9 MB with one vector path per cell; about 0.13 MB rasterised (quick run)
    assert len(fig2_svg.encode()) < 400_000
