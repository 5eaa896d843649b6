"""The element catalogue and the keyword table against the manual (§5.1-5.6) and formulation.md §4.

The expected tables are transcribed from those documents in support/manual.py, not taken from the code.
"""
import pytest

import spacar
from support.manual import ELEMENTS, KEYWORDS

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
