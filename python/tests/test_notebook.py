"""Results show themselves in a notebook: verdict, parameters with units and errors, warnings
and the figure inline; a figure saves to a file."""

import pytest

import stf_lab


@pytest.fixture(scope="module")
def result():
    import os
    from conftest import REPO

    here = os.getcwd()
    os.chdir(REPO)
    try:
        return stf_lab.fit("experiments/power_law_fit.toml")
    finally:
        os.chdir(here)


def test_the_html_shows_verdict_parameters_and_figure(result):
    html = result._repr_html_()
    assert result.verdict.split(":")[0] in html
    assert "<th>std. error</th>" in html and "N·(s/m)ⁿ" in html
    # The figure is its SVG inline, shown at its drawing's size, not a PNG.
    assert '<svg role="img" aria-label="measured_vs_fitted" style="width:' in html
    assert "data:image/png;base64," not in html and "<?xml" not in html
    assert html.count("<tr>") >= len(result.models) + 4


def test_the_text_repr_lists_each_model(result):
    text = repr(result)
    for m in result.models:
        assert m.label in text


def test_a_figure_saves_as_svg_and_png(result, tmp_path):
    fig = result.figure()
    svg = fig.save(tmp_path / "fit.svg")
    png = fig.save(tmp_path / "fit.png")
    assert open(svg).read().startswith("<svg")
    assert open(png, "rb").read(8) == b"\x89PNG\r\n\x1a\n"
    with pytest.raises(ValueError):
        fig.save(tmp_path / "fit.pdf")


def test_records_models_and_experiments_show_too(repo):
    assert "<table" in stf_lab.read_record("experiments/records/power_law_sweep.csv")._repr_html_()
    assert "N·s/m" in stf_lab.model("viscous")._repr_html_()
    assert "[[models]]" in stf_lab.Experiment.load("experiments/power_law_fit.toml")._repr_html_()
