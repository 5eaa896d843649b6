"""The element catalogue and the keyword table against the manual (§5.1-5.6) and formulation.md §4.

The expected tables are transcribed from those documents in support/manual.py, not taken from the code.
"""
import re

import pytest

import spacar
import spacar._testing  # noqa: F401  (element_kernel, also when this file runs alone)
from support.manual import ELEMENTS, KEYWORDS
from support.paths import ROOT

# Manual §5.1 (the element types) and every keyword of §5.1-5.6.
MANUAL_KEYWORDS = list(ELEMENTS) + KEYWORDS


@pytest.fixture(scope="module")
def catalogue():
    return {t.name: t for t in spacar.element_catalogue()}


def test_catalogue_has_the_14_element_types_of_the_manual(catalogue):
    assert len(ELEMENTS) == 14
    assert set(ELEMENTS) <= set(catalogue)
    # anything else is a marked extension
    assert all(catalogue[name].extension for name in set(catalogue) - set(ELEMENTS))


@pytest.mark.parametrize("name", list(ELEMENTS))
def test_element_type(catalogue, name):
    kinds, n_def, (pmin, pmax) = ELEMENTS[name]
    t = catalogue[name]
    assert tuple(k.name for k in t.nodes) == kinds
    assert len(t.node_roles) == len(kinds)
    assert t.n_deformations == n_def == len(t.deformations)
    assert (t.n_params_min, t.n_params_max) == (pmin, pmax)
    assert not t.extension


def test_every_manual_keyword_is_known():
    assert len(MANUAL_KEYWORDS) == len(set(MANUAL_KEYWORDS)) == 14 + 5 + 8 + 9 + 6 + 13
    assert [k for k in MANUAL_KEYWORDS if k not in spacar.KEYWORDS] == []


@pytest.mark.parametrize("name", [k for k in MANUAL_KEYWORDS if k not in ("END", "EOF")])
def test_manual_keyword_is_read(name):
    """The reader knows every manual keyword, in any case."""
    (block,) = spacar.parse(f"{name.lower()} " + " ".join(["1"] * _arity(name)) + "\nEND\n")
    assert block.commands[0].keyword == name


def test_end_and_eof_are_read():
    blocks = spacar.parse("FIX 1\nend\nFIX 2\nEnD\neof\n")
    assert [[c.args for c in b.commands] for b in blocks] == [[(1,)], [(2,)]]


def _arity(name):
    kw = spacar.KEYWORDS[name]
    return sum(p.count_min for p in kw.params)


def _node_numbers(kinds, start):
    return list(range(start, start + len(kinds)))


@pytest.mark.parametrize("name", list(ELEMENTS))
def test_every_element_type_has_a_builder_method(name):
    kinds, n_def, (pmin, pmax) = ELEMENTS[name]
    method = getattr(spacar.Model, name.lower())
    m = spacar.Model()
    params = {3: [0.0, 1.0, 0.0], 10: [1.0] * 10, 2: [0.1, 0.2]}.get(pmin, [])
    if name == "PLWHEEL":
        params = [0.1, 1.0, 0.0]
    method(m, 5, *_node_numbers(kinds, 1), *params)
    el = m.elements[5]
    assert el.type_name == name
    assert list(el.nodes) == _node_numbers(kinds, 1)
    assert list(el.params) == params
    assert [m.nodes[n].kind.name for n in el.nodes] == list(kinds)
    assert len(el.cls) == n_def
    # the builder line is also a reader line with the same effect
    line = f"{name} 5 " + " ".join(map(str, _node_numbers(kinds, 1) + params))
    (block,) = spacar.parse(line + "\nEND\n")
    assert block.commands[0].args == (5, *_node_numbers(kinds, 1), *params)


def test_lambda_nodes_get_an_automatic_l2min1():
    """Manual §5.1: L2MIN1 is usually created automatically for every Euler-parameter node;
    formulation §1.1: numbered after the largest element, in ascending node order."""
    m = spacar.read_string("BEAM 3 1 2 4 5 0 1 0\nX 4 1 0 0\nEND\n")
    s = m.summary()
    assert s.elements == {"BEAM": 1, "L2MIN1": 2}
    dump = m.dump().splitlines()
    assert "L2MIN1     4   2" in dump and "L2MIN1     5   5" in dump


# --- the catalogue row and the kernel agree (issue 18: sizes declared once) --------------------

# Definition-line numbers that make a valid element of each type (test_elements_*.py cover the
# physics; here only the sizes matter).
DEFINITION_NUMBERS = {"BEAM": [0.0, 1.0, 0.3], "BEAMNL": [0.0, 1.0, 0.3], "BEAMC": [0.0, 1.0, 0.3], "BEAMW": [0.0, 1.0, 0.3],
                      "HINGE": [0.0, 0.0, 1.0],
                      "BEARING": [0.0, 0.0, 1.0], "SURFACE": [1.0] * 10, "PLBELT": [0.1, 0.2],
                      "PLWHEEL": [0.1, 1.0, 0.0], "WHEEL": [0.0, 1.0, 0.0, 0.3]}
NODE_SIZE = {"XY": 2, "BETA": 1, "XYZ": 3, "LAMBDA": 4}


def kernel_of_a_prepared_element(t):
    """The kernel of one element of type t at distinct node positions, from the element record
    the model made (definition line, reference geometry)."""
    m = spacar.Model()
    nodes = list(range(1, len(t.nodes) + 1))
    getattr(m, t.name.lower())(1, *nodes, *DEFINITION_NUMBERS.get(t.name, []))
    for n, kind in zip(nodes, t.nodes):
        if kind.name in ("XY", "XYZ"):
            m.x(n, *[float(n), 0.5 * n, 0.25][: NODE_SIZE[kind.name]])
    m.prepare()
    el = m.elements[1]
    return spacar._testing.element_kernel(t.name, params=list(el.params), l0=el.l0 or 1.0, lgeomy=list(el.lgeomy))


@pytest.mark.parametrize("t", spacar.element_catalogue(), ids=lambda t: t.name)
def test_catalogue_sizes_are_the_kernels(t):
    """The deformation count and the velocity-level rows of the catalogue are the kernel's (the
    row is made from the kernel, element_type<Kernel> in registry.hpp), and the node slots give
    the kernel's coordinates."""
    k = kernel_of_a_prepared_element(t)
    assert k.n_deformations == t.n_deformations == len(t.velocity_level)
    assert [k.velocity_level(i) for i in range(k.n_deformations)] == list(t.velocity_level)
    assert k.n_coords == sum(NODE_SIZE[kind.name] for kind in t.nodes)


def test_velocity_level_rows_are_the_wheel_slips():
    cat = {t.name: t for t in spacar.element_catalogue()}
    assert [n for n, t in cat.items() if any(t.velocity_level)] == ["PLWHEEL", "WHEEL"]
    assert list(cat["PLWHEEL"].velocity_level) == [True, True]
    assert list(cat["WHEEL"].velocity_level) == [False, True, True]


def test_catalogue_flags():
    """The flags that replace comparisons of type names outside the element files."""
    cat = {t.name: t for t in spacar.element_catalogue()}
    assert [n for n, t in cat.items() if t.automatic] == ["L2MIN1"]
    assert [n for n, t in cat.items() if t.signed_emass_extras] == ["PLBELT"]
    families = {n: t.family.name for n, t in cat.items()}
    assert [n for n, f in families.items() if f == "Beam"] == ["BEAM", "BEAMNL", "BEAMC", "BEAMW", "PLBEAM", "PLBEAMNL",
                                                                     "PLBEAMC"]
    assert [n for n, f in families.items() if f == "Hinge"] == ["HINGE", "PLHINGE"]
    assert [n for n, f in families.items() if f == "Truss"] == ["TRUSS", "PLTRUSS"]
    assert [n for n, f in families.items() if f == "Wheel"] == ["PLWHEEL", "WHEEL"]
    assert [n for n, f in families.items() if f == "Belt"] == ["PLBELT"]
    assert sorted(n for n, f in families.items() if f == "Bearing") == ["BEARING", "PLBEAR"]


def test_plbelt_winding_factors_may_be_negative_other_emass_not():
    m = spacar.Model()
    m.plbelt(1, 1, 2, 3, 4, 0.1, 0.2)
    m.emass(1, 1.0, -0.5, 0.5)
    assert list(m.elements[1].emass) == [1.0, -0.5, 0.5]
    with pytest.raises(spacar.InputError):
        m.emass(1, -1.0, 0.5, 0.5)
    m.beam(2, 5, 6, 7, 8, 0.0, 1.0, 0.0)
    with pytest.raises(spacar.InputError):
        m.emass(2, 1.0, -0.1)


def _code_without_comments(path):
    text = path.read_text(encoding="utf-8")
    if path.suffix == ".py":
        return "\n".join(line.split("#", 1)[0] for line in text.splitlines())
    return "\n".join(line.split("//", 1)[0] for line in text.splitlines())


def test_type_names_are_written_only_in_their_element_files():
    """Code outside an element's own file does not compare element type names: it asks the
    catalogue (flags, family). Checked for the C++ core and the drawing and docs code."""
    files = [p for p in (ROOT / "cpp").rglob("*.[ch]pp") if "elements" not in p.relative_to(ROOT / "cpp").parts]
    files += [ROOT / "python" / "spacar" / name for name in ("geometry.py", "docgen.py", "plotting.py")]
    names = [t.name for t in spacar.element_catalogue()]
    found = [(p.name, n) for p in files for n in names
             if re.search(rf"[\"']{n}[\"']", _code_without_comments(p))]
    assert found == []
