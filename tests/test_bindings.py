"""The bindings are generated from the core's field tables (model.hpp) and parse options once:
the pickled records and the properties list the same fields in the same order, and the entry
points that take an integration method refuse an unknown one alike."""
from __future__ import annotations

from pathlib import Path

import spacar
from spacar import _core

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "slidercrank.dat"


def properties(cls):
    return [name for name, value in vars(cls).items() if isinstance(value, property)]


def test_the_pickled_records_hold_the_properties_in_their_order():
    model = spacar.read(EXAMPLE)
    core = model._core
    _, nodes, elements, settings, *_ = core.__getstate__()
    node, element = core.nodes[1], core.elements[1]
    node_fields = properties(_core.Node)
    assert len(nodes[0]) == len(node_fields)
    for name, stored in zip(node_fields, nodes[0]):
        value = getattr(node, name)
        assert stored == (int(value) if name == "kind" else [int(c) for c in value] if name == "cls" else value)
    element_fields = [n for n in properties(_core.Element) if n != "type_name"]
    assert len(elements[0]) == len(element_fields)
    for name, stored in zip(element_fields, elements[0]):
        value = getattr(element, name)
        if name == "type":
            assert stored == element.type_name
        elif name == "cls":
            assert stored == [int(c) for c in value]
        elif name == "kinematic_of":
            assert [list(v) for v in stored] == [list(v) for v in value]
        else:
            assert stored == value
    settings_fields = properties(_core.Settings)
    assert list(settings) == [getattr(core.settings, name) for name in settings_fields]
