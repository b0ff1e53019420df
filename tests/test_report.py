"""The HTML report is self-contained and escapes its content."""

import base64

import matplotlib.pyplot as plt

from flatcontact.report import Figure, Section, Table, render_html, write_report


def test_report_embeds_figures_and_escapes(tmp_path):
    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, 1])
    png = tmp_path / "f.png"
    fig.savefig(png)
    plt.close(fig)
    section = Section(
        "Load laws",
        paragraphs=["τ = k·p + τ0 <fit>"],
        tables=[Table(["quantity", "value"], [["k (MPa/GPa)", "4.52"]])],
        figures=[Figure(png, "Fig. 3")],
    )
    out = write_report(tmp_path / "report.html", "flatcontact report", [section])
    text = out.read_text()
    assert "&lt;fit&gt;" in text and "<fit>" not in text
    assert base64.b64encode(png.read_bytes()).decode() in text
    assert "http://" not in text and "https://" not in text
    assert render_html("t", []).startswith("<!DOCTYPE html>")
