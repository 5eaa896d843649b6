"""Notebooks handed out as HTML (docs/getting-started.md, "Sharing a notebook"): the exported page
keeps what spacar shows, offline::

    spacar.notebook.to_html("07_flexures.ipynb", "07_flexures.html")   # or: spacar html NOTEBOOK

nbconvert alone renders a widget (``spacar.explore``) as an empty box when the notebook holds no
widget state, and drops a plotly figure (``spacar.view3d``) it cannot represent. Here each
output that has both a widget view and a static picture keeps the picture (``explore`` displays
the PNG of its last state beside its widget), and each plotly figure becomes its self-contained
HTML (plotly.js written once into the page, not fetched from a network). The equations of the
markdown cells ($…$, $$…$$), which nbconvert leaves to MathJax fetched from a network (raw TeX
offline), become MathML, which browsers draw themselves (with latex2mathml installed; it is in
the classroom extra). The page then fetches nothing from a network: nbconvert's require.js and
widget manager are left out (they serve widget views without a picture only), and MathJax too
unless TeX is left that latex2mathml could not convert. Needs nbconvert (``pip install ".[classroom]"``) and, for
figures, plotly.
"""
from __future__ import annotations

import re
from pathlib import Path

from .errors import InputError

WIDGET = "application/vnd.jupyter.widget-view+json"
PLOTLY = "application/vnd.plotly.v1+json"
STATIC = ("image/png", "image/svg+xml", "text/html")


def static_outputs(nb) -> int:
    """Replace, in place, the outputs of notebook ``nb`` (an nbformat node) that an HTML page
    cannot show: a widget view with a static picture beside it loses the view; a plotly figure
    gets its HTML (plotly.js in the first). Returns the number of outputs changed."""
    changed, plotly_js = 0, True
    for cell in nb.get("cells", []):
        for output in cell.get("outputs", []) if cell.get("cell_type") == "code" else []:
            data = output.get("data")
            if not data:
                continue
            if WIDGET in data and any(kind in data for kind in STATIC):
                del data[WIDGET]
                changed += 1
            if PLOTLY in data:   # its own HTML, whatever the output held (view3d's has plotly.js once a session)
                import plotly.io

                data["text/html"] = plotly.io.to_html(data[PLOTLY], include_plotlyjs=plotly_js, full_html=False)
                plotly_js = False  # loaded once for the page
                changed += 1
    return changed


_DISPLAY = re.compile(r"\$\$(.+?)\$\$", re.S)
# Inline $…$ as Pandoc reads it: the opening $ followed by a non-space, the closing one preceded by
# a non-space and not followed by a digit ("costs $5 and $10" is no equation); no blank line inside.
_INLINE = re.compile(r"(?<![\\$])\$(?![\s$])((?:[^$\n]|\n(?!\s*\n))+?)(?<![\s\\])\$(?!\d)")
# Code that keeps its dollars: fenced blocks and code spans.
_CODE = re.compile(r"(```.*?```|~~~.*?~~~|`[^`\n]*`)", re.S)


# nbconvert's lab page without the scripts it fetches from a network when the page does not need
# them: require.js and the widget manager (for widget views drawn from saved widget state only;
# plotly.js is inline) and MathJax (for TeX left after MathML). Mermaid is fetched by the page
# only where a diagram is.
_OFFLINE_TEMPLATE = """{%- extends 'index.html.j2' -%}
{%- block html_head_js_requirejs -%}
{%- if resources.spacar_widgets -%}{{ super() }}{%- endif -%}
{%- endblock html_head_js_requirejs -%}
{%- block jupyter_widgets -%}
{%- if resources.spacar_widgets -%}{{ super() }}{%- endif -%}
{%- endblock jupyter_widgets -%}
{%- block html_head_js_mathjax -%}
{%- if resources.spacar_mathjax -%}{{ super() }}{%- endif -%}
{%- endblock html_head_js_mathjax -%}
"""


def _offline_exporter(html_exporter):
    from jinja2 import DictLoader

    return html_exporter(template_file="spacar_offline.html.j2",
                         extra_loaders=[DictLoader({"spacar_offline.html.j2": _OFFLINE_TEMPLATE})])


def _widget_views_left(nb) -> bool:
    """Whether widget views remain that the page draws from saved widget state (through
    require.js and the widget manager, both fetched from a network)."""
    return "widgets" in nb.get("metadata", {}) and any(
        WIDGET in output.get("data", {}) for cell in nb.get("cells", []) if cell.get("cell_type") == "code"
        for output in cell.get("outputs", []))


def _markdown_parts(cell) -> list:
    """A markdown cell's source split at its code: even entries prose, odd ones code spans and
    blocks (their dollars are not TeX)."""
    source = cell.get("source", "")
    return _CODE.split("".join(source) if isinstance(source, list) else source)


_OTHER_TEX = re.compile(r"\\\(|\\\[|\\begin\{")


def _tex_left(nb) -> bool:
    """Whether the page still holds TeX, which needs MathJax: in a markdown cell (outside code,
    $…$, $$…$$, \\(…\\), \\[…\\], environments) or an output as LaTeX or markdown (IPython's
    Math, sympy)."""
    for cell in nb.get("cells", []):
        if cell.get("cell_type") == "code":
            if any("text/latex" in out.get("data", {}) or "text/markdown" in out.get("data", {})
                   for out in cell.get("outputs", [])):
                return True
            continue
        if cell.get("cell_type") != "markdown":
            continue
        text = "".join(_markdown_parts(cell)[::2])
        if _DISPLAY.search(text) or _INLINE.search(text) or _OTHER_TEX.search(text):
            return True
    return False


def mathml_equations(nb) -> int:
    """Replace, in place, the TeX equations of the markdown cells of ``nb`` by MathML (display
    equations as blocks), outside code spans and blocks. Returns the number replaced; 0 without
    latex2mathml. An equation it does not convert fully (a command it does not know comes out as
    text) stays as it was, for MathJax where there is a network."""
    try:
        from latex2mathml.converter import convert
    except ImportError:
        return 0
    count = 0

    def replace(match, display):
        nonlocal count
        try:
            math = convert(match.group(1).strip(), display="block" if display else "inline")
        except Exception:  # noqa: BLE001 - any TeX it cannot read: leave the equation as written
            return match.group(0)
        if "\\" in math or "<mi>&</mi>" in math or "&amp;" in math:  # an unknown command, an alignment
            return match.group(0)
        count += 1
        return math

    def convert_text(text):
        text = _DISPLAY.sub(lambda m: replace(m, True), text)
        return _INLINE.sub(lambda m: replace(m, False), text)
    for cell in nb.get("cells", []):
        if cell.get("cell_type") != "markdown":
            continue
        parts = _markdown_parts(cell)   # odd entries: the code, kept as written
        cell["source"] = "".join(part if k % 2 else convert_text(part) for k, part in enumerate(parts))
    return count


def to_html(notebook, path=None) -> str:
    """The HTML page of a notebook (a path, its outputs as saved) with :func:`static_outputs`
    applied; written to ``path`` if given. Returns the page."""
    try:
        import nbformat
        from nbconvert import HTMLExporter
    except ImportError:
        raise ImportError('spacar.notebook.to_html needs nbconvert: pip install ".[classroom]"') from None
    source = Path(notebook)
    if not source.is_file():
        raise InputError(f"{source}: no such notebook")
    try:
        nb = nbformat.read(source, as_version=4)
    except Exception as err:  # nbformat raises its own and JSON errors
        raise InputError(f"{source}: not a readable notebook ({type(err).__name__}: {err})") from None
    static_outputs(nb)
    mathml_equations(nb)
    html, _ = _offline_exporter(HTMLExporter).from_notebook_node(
        nb, resources={"spacar_mathjax": _tex_left(nb), "spacar_widgets": _widget_views_left(nb)})
    if path is not None:
        from .io.files import write_replacing

        def write(temporary):
            Path(temporary).write_text(html, encoding="utf-8")

        write_replacing(str(path), write, "write the page")
    return html
