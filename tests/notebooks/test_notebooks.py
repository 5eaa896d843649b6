"""The teaching notebooks (notebooks/*.ipynb), run as a student runs them and handed out as a web
page (issue 41).

Each notebook runs top to bottom in a Jupyter kernel, in its own folder, each cell within 120 s
(what nbmake did before). Its page, written by ``spacar.notebook.to_html`` from the outputs, is
then opened in headless Chromium with no network (tests/support/browser.py): every picture is
drawn (matplotlib's figures, the animation player's frames, explore's picture of its state),
every 3-D view is drawn by plotly.js in the page, the equations are MathML, and the page asks
nothing of a network. Without Chromium (Debian's ``chromium``; .ci/run installs it) the pages
are not opened; without nbconvert they are not written.
"""
from __future__ import annotations

import re

import pytest

nbformat = pytest.importorskip("nbformat")
nbclient = pytest.importorskip("nbclient")

from support.browser import chromium, open_page  # noqa: E402
from support.paths import ROOT, spacar_env  # noqa: E402

NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
_executed: dict = {}


def executed(path):
    """The notebook at ``path`` with its outputs, run once for the tests of this module."""
    if path not in _executed:
        nb = nbformat.read(path, as_version=4)
        client = nbclient.NotebookClient(nb, timeout=120, kernel_name="python3",
                                         resources={"metadata": {"path": str(path.parent)}})
        _executed[path] = None
        client.execute(env=spacar_env())
        _executed[path] = nb
    if _executed[path] is None:
        pytest.skip(f"{path.name} did not run (see test_notebook_runs)")
    return _executed[path]


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_notebook_runs(path):
    nb = executed(path)
    errors = [out for cell in nb.cells if cell.cell_type == "code" for out in cell.outputs
              if out.output_type == "error"]
    assert not errors


def _outputs(nb, kind):
    return [out for cell in nb.cells if cell.cell_type == "code" for out in cell.outputs
            if kind in out.get("data", {})]


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_notebook_page_in_a_browser(path, tmp_path):
    pytest.importorskip("nbconvert")
    if chromium() is None:
        pytest.skip("no Chromium (Debian's chromium, or SPACAR_CHROMIUM)")
    from PIL import Image

    from spacar.notebook import PLOTLY, mathml_equations, static_outputs, to_html

    nb = executed(path)
    saved = tmp_path / path.name
    nbformat.write(nb, saved)
    page = tmp_path / path.with_suffix(".html").name
    to_html(saved, page)
    seen = open_page(page, tmp_path / "page.png")

    assert seen.requests == [], f"the page of {path.name} asks a network for {seen.requests}"
    # What the page shows, output by output of the notebook the page was made from.
    shown = nbformat.read(saved, as_version=4)
    static_outputs(shown)
    for out in _outputs(shown, "image/png"):           # matplotlib's figures, explore's picture
        assert out["data"]["image/png"][:200] in seen.dom
    drawn = re.sub(r"<script\b[^>]*>.*?</script>", "", seen.dom, flags=re.S)   # not plotly.js's own text
    figures = len(_outputs(nbformat.read(saved, as_version=4), PLOTLY))
    assert len(re.findall(r'class="[^"]*\bjs-plotly-plot\b', drawn)) == figures   # drawn by plotly.js
    assert drawn.count("<canvas") >= figures and "no-webgl" not in drawn    # a WebGL 3-D scene each
    assert drawn.count("<math") >= mathml_equations(shown)
    colours = Image.open(seen.screenshot).convert("RGB").getcolors(1 << 16)
    assert colours is None or len(colours) > 50              # a page with content, not a blank one


def test_explore_and_the_3d_view_are_in_the_shipped_notebooks():
    # The pages above show spacar.explore's picture (notebook 09) and spacar.view3d: the top of
    # notebook 04, a spatial mechanism, and the flexure stage of notebook 10.
    sources = {p.name: "".join(c.source for c in nbformat.read(p, as_version=4).cells if c.cell_type == "code")
               for p in NOTEBOOKS}
    assert "spacar.explore(" in sources["09_explore.ipynb"]
    assert "spacar.view3d(" in sources["10_flexure_stage_3d.ipynb"]
    assert "spacar.view3d(" in sources["04_rigid_body.ipynb"]
