"""The documentation (issue #7): the generated keyword reference and element catalogue are up to
date and complete against the manual's §5 (transcribed in support/manual.py, not taken from the
code), every element type has its figure, links resolve, the README keeps its two commands, and
the notebooks are committed without outputs."""
import json
import re
import subprocess
import sys
import xml.etree.ElementTree as ET

import pytest

import spacar
import spacar.docgen
from spacar.io.matasc import STATE_FILES
from support.manual import ELEMENTS, KEYWORDS
from support.paths import ROOT

DOCS = ROOT / "docs"

# Manual §5.1: the element types with their deformation counts (formulation.md §4).
MANUAL_ELEMENTS = {name: n_deformations for name, (_, n_deformations, _) in ELEMENTS.items()}
# Manual §5.2-5.6: every other keyword.
MANUAL_KEYWORDS = KEYWORDS
HAND_WRITTEN = ["index.md", "getting-started.md", "input-format.md", "python-api.md", "formulation.md",
                "matasc.md", "performance.md", "stiff-integration.md"]
README_COMMANDS = [
    'python3 -m venv .venv && . .venv/bin/activate && pip install . && spacar run examples/slidercrank.dat',
    'python3 -m venv .venv && . .venv/bin/activate && pip install ".[test]" && pytest',
]
NOTEBOOKS = ["01_slidercrank.ipynb", "02_fourbar.ipynb", "03_cantilever.ipynb", "04_rigid_body.ipynb",
             "05_rolling_wheel_and_bicycle.ipynb", "06_peer_comparison.ipynb", "07_flexures.ipynb", "08_mechatronics.ipynb",
             "09_explore.ipynb", "10_flexure_stage_3d.ipynb", "11_mechanism_exercises.ipynb"]


def read(name):
    return (DOCS / name).read_text(encoding="utf-8")


def table_rows(text):
    """{keyword: row} of the reference tables: rows whose first cell holds `KEYWORD`."""
    rows = {}
    for line in text.splitlines():
        m = re.match(r"^\| (?:<a id=\"[^\"]+\"></a>)?`([A-Z0-9]+)` \|", line)
        if m:
            rows[m.group(1)] = line
    return rows


@pytest.mark.parametrize("name", sorted(spacar.docgen.GENERATED))
def test_generated_file_is_up_to_date(name):
    committed = read(name)
    assert committed == spacar.docgen.GENERATED[name](), f"docs/{name} is out of date: run python docs/generate.py"


def test_generate_script_check_mode():
    out = subprocess.run([sys.executable, str(DOCS / "generate.py"), "--check"], capture_output=True, text=True)
    assert out.returncode == 0, out.stdout + out.stderr
    assert "up to date" in out.stdout


@pytest.mark.parametrize("keyword", list(MANUAL_ELEMENTS) + MANUAL_KEYWORDS)
def test_keyword_reference_lists_every_keyword_of_the_manual(keyword):
    rows = table_rows(read("keywords.md"))
    assert keyword in rows, f"{keyword} (manual §5) is missing from docs/keywords.md"
    row = rows[keyword]
    kw = spacar.KEYWORDS[keyword]
    assert f"`Model.{kw.builder}`" in row or keyword in ("END", "EOF")
    assert f'<a id="{keyword.lower()}"></a>' in row


def test_keyword_reference_lists_every_keyword_of_the_table():
    rows = table_rows(read("keywords.md"))
    assert set(rows) == set(spacar.KEYWORDS)
    # the extensions are marked as such
    for name, kw in spacar.KEYWORDS.items():
        if kw.extension:
            assert "extension" in rows[name], name


@pytest.mark.parametrize("element", list(MANUAL_ELEMENTS))
def test_element_catalogue_lists_every_element_of_the_manual_with_its_deformations(element):
    text = read("elements.md")
    t = {c.name: c for c in spacar.element_catalogue()}[element]
    assert f"## {element}: " in text, f"{element} (manual §5.1) is missing from docs/elements.md"
    section = text.split(f"## {element}: ", 1)[1].split("\n## ", 1)[0]
    rows = re.findall(r"^\| e(\d+) \| (.+) \|$", section, re.M)
    assert len(rows) == MANUAL_ELEMENTS[element] == t.n_deformations
    assert [name for _, name in rows] == list(t.deformations)
    assert f"`{element} e " in section            # the input line
    if t.estiff:
        assert f"ESTIFF: {t.estiff}" in section


def test_every_element_has_its_figure():
    text = read("elements.md")
    for t in spacar.element_catalogue():
        ref = f"figures/elements/{t.name.lower()}.svg"
        assert f"![{t.name}]({ref})" in text
        root = ET.parse(DOCS / ref).getroot()
        assert root.tag.endswith("svg")
        # the figure names the element and its deformations (text kept as text in the SVG)
        svg = (DOCS / ref).read_text(encoding="utf-8")
        assert t.name in svg and "e1" in svg


@pytest.mark.parametrize("name", HAND_WRITTEN)
def test_hand_written_pages_exist(name):
    assert len(read(name)) > 500


def _links(text):
    return re.findall(r"\]\(([^)\s]+)\)", text)


@pytest.mark.parametrize("page", [*(f"docs/{n}" for n in HAND_WRITTEN + list(spacar.docgen.GENERATED)), "README.md"])
def test_relative_links_resolve(page):
    path = ROOT / page
    for link in _links(path.read_text(encoding="utf-8")):
        if re.match(r"^[a-z]+://", link):
            continue
        target, _, anchor = link.partition("#")
        file = (path.parent / target).resolve() if target else path
        assert file.exists(), f"{page}: broken link {link}"
        if anchor and file.suffix == ".md":
            assert f'id="{anchor}"' in file.read_text(encoding="utf-8"), f"{page}: missing anchor {link}"


def test_index_links_every_page():
    links = set(_links(read("index.md")))
    for name in HAND_WRITTEN + list(spacar.docgen.GENERATED):
        if name != "index.md":
            assert name in links, name


def test_python_api_mentions_every_public_name():
    text = read("python-api.md")
    for name in spacar.__all__:
        assert re.search(rf"\b{name}\b", text), name
    for method in ("to_pandas", "save", "load", "concatenate", "node", "element", "deformation", "coordinate",
                   "eigenfrequencies", "buckling_factors", "output_stem", "on_output", "progress"):
        assert method in text, method


def test_matasc_reference_lists_every_file():
    text = read("matasc.md")
    for suffix in list(STATE_FILES) + ["lin", "eig", "buck"]:
        assert f"`<stem>_{suffix}.asc`" in text, suffix
    assert "%.15E" in text


def test_formulation_notes_cover_what_users_need():
    text = read("formulation.md").lower()
    for topic in ("units", "radians", "counter-clockwise", "tension", "reaction", "consistent", "lumped",
                  "epsint", "epsind", "epskin", "hmax", "dop853", "references"):
        assert topic in text, topic


def test_readme_keeps_its_two_commands_and_points_to_the_docs():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    blocks = re.findall(r"```[a-z]*\n(.*?)```", text, re.S)
    assert [b.strip() for b in blocks[:2]] == README_COMMANDS
    assert text.index("```bash\n" + README_COMMANDS[0]) < text.index("## Using spacar")
    using = text.split("## Using spacar", 1)[1]
    assert "docs/index.md" in using and "notebooks" in using


@pytest.mark.parametrize("name", NOTEBOOKS)
def test_notebooks_are_committed_without_outputs(name):
    nb = json.loads((ROOT / "notebooks" / name).read_text(encoding="utf-8"))
    code = [c for c in nb["cells"] if c["cell_type"] == "code"]
    assert code and all(c.get("outputs") == [] and c.get("execution_count") is None for c in code)
    # explained for students: starts with a title and has more than one explanation
    assert nb["cells"][0]["cell_type"] == "markdown" and "".join(nb["cells"][0]["source"]).startswith("# ")
    assert sum(c["cell_type"] == "markdown" for c in nb["cells"]) >= 4


def test_only_the_planned_notebooks():
    assert sorted(p.name for p in (ROOT / "notebooks").glob("*.ipynb")) == NOTEBOOKS


def test_a_type_without_its_own_figure_gets_the_default_figure(tmp_path, monkeypatch):
    """docs/generate.py draws the default figure (node slots, deformation names) for an element
    type that has no figure of its own yet."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("docs_generate", DOCS / "generate.py")
    generate = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(generate)
    monkeypatch.delitem(generate.FIGURES_BY_TYPE, "PLBEAR")
    written = generate.write_figures(tmp_path)
    assert {p.name for p in written} == {f"{t.name.lower()}.svg" for t in spacar.element_catalogue()}
    svg = (tmp_path / "plbear.svg").read_text(encoding="utf-8")
    assert "Default figure" in svg and "PLBEAR" in svg and "relative rotation" in svg
    assert "Default figure" not in (tmp_path / "pltruss.svg").read_text(encoding="utf-8")
