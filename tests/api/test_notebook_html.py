"""Notebooks handed out as HTML (issue 41): spacar.notebook.to_html and `spacar html` keep
spacar.explore's widget as the picture of its last state and spacar.view3d's plotly figure as its
self-contained HTML, where nbconvert alone gives an empty box (and drops a plain plotly figure;
view3d's output carries its HTML for it). The pages of the shipped notebooks in a browser:
tests/notebooks/test_notebooks.py."""
from __future__ import annotations

import base64
import re

import pytest

nbformat = pytest.importorskip("nbformat")
pytest.importorskip("nbconvert")
pytest.importorskip("plotly")
pytest.importorskip("ipywidgets")

from support.paths import EXAMPLES, spacar_env  # noqa: E402

import spacar  # noqa: E402
from spacar.notebook import PLOTLY, WIDGET, static_outputs, to_html  # noqa: E402


def executed_notebook(tmp_path):
    """A notebook with an explore cell and a view3d cell, run by a kernel as a student would."""
    from nbclient import NotebookClient

    nb = nbformat.v4.new_notebook()
    nb.cells = [
        nbformat.v4.new_code_cell("import spacar\n"
                                  f"model = spacar.read({str(EXAMPLES / 'slidercrank.dat')!r})\n"
                                  "spacar.explore(model)"),
        nbformat.v4.new_code_cell(f"res = spacar.simulate(spacar.read({str(EXAMPLES / 'slidercrank3d.dat')!r}))\n"
                                  "spacar.view3d(res)"),
    ]
    NotebookClient(nb, timeout=300, kernel_name="python3",
                   resources={"metadata": {"path": str(tmp_path)}}).execute(env=spacar_env())
    path = tmp_path / "class.ipynb"
    nbformat.write(nb, path)
    return nb, path


def test_widget_and_3d_view_survive_the_export(tmp_path):
    nb, path = executed_notebook(tmp_path)
    explore_out = nb.cells[0].outputs[-1]["data"]
    assert WIDGET in explore_out and "image/png" in explore_out      # the widget and its picture
    png = base64.b64decode(explore_out["image/png"])
    assert png.startswith(b"\x89PNG")
    view_out = nb.cells[1].outputs[-1]["data"]
    assert PLOTLY in view_out and "Plotly.newPlot" in view_out["text/html"]   # the figure and its HTML
    assert "plotly.js v" in view_out["text/html"]                              # plotly.js: the session's first

    # nbconvert alone: the widget view wins (an empty box without widget state); view3d's figure is
    # kept as its HTML (a plain plotly figure is dropped: "not able to be represented").
    from nbconvert import HTMLExporter

    plain, _ = HTMLExporter().from_notebook_node(nbformat.read(path, as_version=4))
    assert explore_out["image/png"][:200] not in plain and "Plotly.newPlot" in plain

    html = to_html(path, tmp_path / "class.html")
    assert (tmp_path / "class.html").read_text(encoding="utf-8") == html
    assert explore_out["image/png"][:200] in html                      # the explore picture
    assert "Plotly.newPlot" in html and html.count("plotly.js v") >= 1  # the figure, plotly.js inline
    assert not re.search(r"<script[^>]*src=\"https?://", html)        # no require.js, no MathJax: no network


def test_static_outputs_changes_only_what_html_cannot_show():
    nb = nbformat.v4.new_notebook()
    cell = nbformat.v4.new_code_cell("")
    cell.outputs = [nbformat.v4.new_output("display_data", data={WIDGET: {"model_id": "x"}, "text/plain": "VBox()"}),
                    nbformat.v4.new_output("display_data", data={WIDGET: {"model_id": "y"}, "image/png": "iVBOR"})]
    nb.cells = [cell]
    assert static_outputs(nb) == 1
    assert WIDGET in cell.outputs[0]["data"] and WIDGET not in cell.outputs[1]["data"]


def test_cli_writes_the_page(tmp_path):
    import subprocess
    import sys

    _, path = executed_notebook(tmp_path)
    out = subprocess.run([sys.executable, "-m", "spacar", "html", str(path)], capture_output=True, text=True,
                         env=spacar_env(), cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert (tmp_path / "class.html").is_file() and "wrote" in out.stdout
    with pytest.raises(spacar.InputError, match="no such notebook"):
        to_html(tmp_path / "missing.ipynb")


def test_equations_become_mathml_that_needs_no_network():
    # nbconvert leaves $…$ to MathJax fetched from a network: raw TeX offline. The page of notebook
    # 02 carries Freudenstein's equation and the ratios as MathML instead; code cells keep their $.
    pytest.importorskip("latex2mathml")
    from support.paths import ROOT

    html = to_html(ROOT / "notebooks" / "02_fourbar.ipynb")
    body = html.split("<body", 1)[1]
    assert body.count("<math") == 3 and 'display="block"' in body
    assert "$$" not in body and "\\psi" not in body
    from spacar.notebook import mathml_equations

    nb = nbformat.v4.new_notebook()
    nb.cells = [nbformat.v4.new_markdown_cell("costs $5 and $x^2$ and \\$3, $\\unknowncommand{x}$"),
                nbformat.v4.new_markdown_cell("A ticket costs $5 and a meal $10; `echo $HOME` and $a_1$"),
                nbformat.v4.new_markdown_cell("$$\\begin{aligned} a &= b \\end{aligned}$$"),
                nbformat.v4.new_code_cell("s = '$x$'")]
    assert mathml_equations(nb) == 2
    first, second, aligned, code = (c.source for c in nb.cells)
    assert first.startswith("costs $5 and <math") and "x^2" not in first          # the equation, not "5 and"
    assert first.endswith("\\$3, $\\unknowncommand{x}$")                           # unknown TeX left for MathJax
    assert second.startswith("A ticket costs $5 and a meal $10; `echo $HOME` and <math")
    assert aligned == "$$\\begin{aligned} a &= b \\end{aligned}$$"
    assert code == "s = '$x$'"
