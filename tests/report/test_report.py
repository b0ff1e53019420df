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


def test_monotonicity_paragraph_names_drops_beyond_noise_and_their_mechanism():
    """A drop larger than the combined noise is reported with the mechanism on both sides;
    a drop within the noise is not; a monotonic τ(P) says so."""
    import pandas as pd

    from flatcontact.report.sections.analysis import monotonicity_paragraph

    table = pd.DataFrame(
        {
            "p_gpa": [0.0, 0.5, 1.0, 1.5],
            "tau_mpa": [40.0, 39.9, 30.0, 45.0],
            "force_noise_mpa": [0.2, 0.2, 0.2, 0.2],
            "tau_limited_by": ["barrier top", "barrier top", "jump", "barrier top"],
            "n_jumps": [0, 0, 1, 0],
            "start_stacking": ["min1"] * 4,
        }
    )
    text = monotonicity_paragraph(table)
    assert "at 0.5 GPa (limited by the barrier top, 0 jumps" in text
    assert "at 1 GPa (limited by the jump, 1 jump," in text
    assert "at 0 GPa" not in text  # 40.0 -> 39.9 is within sqrt(2)·0.2
    rising = table.assign(tau_mpa=[10.0, 20.0, 30.0, 40.0])
    assert monotonicity_paragraph(rising).startswith("τ(P) does not fall")
