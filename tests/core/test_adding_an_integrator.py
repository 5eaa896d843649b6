"""The walk-through "Adding an integrator" of docs/architecture.md is true (issue 35).

* Every code block of the section marked `<!-- excerpt: path -->` is found verbatim in that file
  (blocks inside a list item are indented on the page, not in the file).
* The method table of stepper.cpp has one row for every value of `enum class Method`, in the
  order of `spacar._core.integration_methods`; every factory it names is a `make` of a class
  derived from `Stepper`, and nothing outside the table and the stepper's own files names a
  method's class to make it.
"""
import re

import pytest

from spacar import _core
from support.paths import ROOT

PAGE = ROOT / "docs" / "architecture.md"
BLOCK = re.compile(r"^(?P<indent> *)<!-- excerpt: (?P<path>\S+) -->\n(?P=indent)```\w*\n(?P<code>.*?)\n(?P=indent)```",
                   re.S | re.M)


def section():
    text = PAGE.read_text(encoding="utf-8")
    start = text.index("## Adding an integrator")
    return text[start:text.index("\n## ", start + 1)]


def unindent(code, indent):
    return "\n".join(line[len(indent):] if line.startswith(indent) else line for line in code.split("\n"))


def blocks():
    return [(m.group("path"), unindent(m.group("code"), m.group("indent"))) for m in BLOCK.finditer(section())]


def test_the_section_has_its_blocks():
    paths = [p for p, _ in blocks()]
    for path in ("cpp/include/spacar/integrators/stepper.hpp", "cpp/src/integrators/stepper.cpp",
                 "cpp/src/integrators/integrator.cpp", "tests/core/test_steppers.py"):
        assert path in paths


@pytest.mark.parametrize("path,code", blocks(), ids=lambda v: v if "\n" not in v else "")
def test_excerpt_is_verbatim_in_its_file(path, code):
    assert code in (ROOT / path).read_text(encoding="utf-8")


def table_rows():
    text = (ROOT / "cpp" / "src" / "integrators" / "stepper.cpp").read_text(encoding="utf-8")
    body = text[text.index("const MethodEntry kMethods[] = {"):]
    body = body[:body.index("};")]
    return re.findall(r'\{Method::(\w+), "(\w+)", (true|false), (nullptr|&(\w+)::make)\}', body)


def test_the_table_has_every_method_once():
    header = (ROOT / "cpp" / "include" / "spacar" / "integrators" / "stepper.hpp").read_text(encoding="utf-8")
    enum = re.search(r"enum class Method \{([^}]*)\}", header).group(1)
    values = [v.strip() for v in enum.split(",")]
    rows = table_rows()
    assert sorted(r[0] for r in rows) == sorted(values)
    assert tuple(r[1] for r in rows) == _core.integration_methods
    assert tuple(r[1] for r in rows if r[2] == "true") == _core.implicit_methods


def test_every_factory_is_a_stepper():
    include = ROOT / "cpp" / "include" / "spacar"
    for method, name, _, make, cls in table_rows():
        if method == "AUTO":
            assert make == "nullptr"
            continue
        declared = [p for p in include.rglob("*.hpp") if re.search(rf"class {cls} : public Stepper\b", p.read_text())]
        assert len(declared) == 1, cls
        assert "static std::unique_ptr<Stepper> make(Method method, const StepperSetup& setup);" in declared[0].read_text()


def test_the_run_names_no_method_class():
    """The run (simulate*.cpp) makes its steppers from the table only."""
    run = "".join(p.read_text(encoding="utf-8") for p in (ROOT / "cpp" / "src" / "analyses").glob("simulate*.cpp"))
    text = re.sub(r'"[^"\n]*"', '""', run)  # the code, not its messages
    for cls in {row[4] for row in table_rows() if row[4]}:
        assert not re.search(rf"\b{cls}\b", text), cls
    assert "make_stepper(" in text and "is_same_v" not in text
