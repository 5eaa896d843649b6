"""The worked example of docs/adding-an-element.md is true (issue 18).

* Every code block of the page marked `<!-- excerpt: path -->` is found verbatim in that file,
  and the excerpts of the element's file, in the order of the page, are the whole file: the page
  shows all of PLTRUSS's file, nothing else.
* The blocks marked `<!-- run -->` run.
* The keyword is written in cpp/ only in its own file and in the list (everything else asks the
  catalogue).
* PLTRUSS, as written on the page, passes the generic finite-difference checks of B, the
  convective term and the stress Hessian, the rigid-motion invariance and the mass checks
  (tests/support/element_checks.py).
"""
import re
from pathlib import Path

import pytest

from support.element_checks import (  # noqa: F401  (record: fixture used by the generic checks)
    ElementCase,
    GenericElementChecks,
    chord,
    record,
)
from support.paths import ROOT

PAGE = ROOT / "docs" / "adding-an-element.md"
ELEMENT_FILE = "cpp/src/elements/truss.cpp"
LIST_FILE = "cpp/include/spacar/elements/list.hpp"
BLOCK = re.compile(r"<!-- (excerpt: (?P<path>\S+)|run) -->\n```\w*\n(?P<code>.*?)\n```", re.S)


def blocks():
    """(path or None for a block to run, code) of the marked blocks, in page order."""
    return [(m.group("path"), m.group("code")) for m in BLOCK.finditer(PAGE.read_text(encoding="utf-8"))]


def source(path):
    """The file a block names; a test module is looked for under tests/ by name (tests live in
    folders by subject)."""
    p = ROOT / path
    if not p.exists() and path.startswith("tests/"):
        (p,) = (ROOT / "tests").rglob(Path(path).name)
    return p.read_text(encoding="utf-8")


def test_the_page_has_its_blocks():
    paths = [p for p, _ in blocks()]
    assert paths.count(ELEMENT_FILE) >= 3 and LIST_FILE in paths and None in paths
    assert any(p and p.startswith("tests/") for p in paths) and "docs/generate.py" in paths


@pytest.mark.parametrize("path,code", [b for b in blocks() if b[0]], ids=lambda v: v if "\n" not in v else "")
def test_excerpt_is_verbatim_in_its_file(path, code):
    assert code in source(path)


def test_the_element_file_is_shown_whole():
    shown = [code for path, code in blocks() if path == ELEMENT_FILE]
    assert "\n\n".join(shown) + "\n" == source(ELEMENT_FILE)


def test_the_list_line_is_a_whole_line():
    (line,) = [code for path, code in blocks() if path == LIST_FILE]
    assert line in source(LIST_FILE).splitlines()


@pytest.mark.parametrize("code", [c for p, c in blocks() if p is None])
def test_block_runs(code):
    exec(compile(code, str(PAGE), "exec"), {})


def test_keyword_only_in_its_file_and_the_list():
    files = {p.relative_to(ROOT).as_posix() for p in (ROOT / "cpp").rglob("*.[ch]pp")
             if re.search(r"\bpltruss\b", p.read_text(encoding="utf-8"), re.I)}
    assert files == {ELEMENT_FILE, LIST_FILE}


@pytest.fixture(params=[ElementCase("PLTRUSS", chord, label="PLTRUSS (worked example)")], ids=str)
def case(request):
    return request.param


class TestWorkedExample(GenericElementChecks):
    pass
