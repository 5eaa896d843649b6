"""The one union-find of rigid bodies (cpp/src/model/topology.cpp, `_core.rigid_bodies`) against a
breadth-first search over the same links, and on the manual's slider-crank's geometry."""
import random

import pytest

import spacar
from spacar import _core
from support.paths import EXAMPLES


def components(nodes, links):
    """The connected components by breadth-first search (the reference)."""
    neighbours = {n: set() for n in nodes}
    for link in links:
        for a in link:
            neighbours[a] |= set(link) - {a}
    seen, out = set(), []
    for n in sorted(nodes):
        if n in seen:
            continue
        stack, group = [n], set()
        while stack:
            k = stack.pop()
            if k not in group:
                group.add(k)
                stack.extend(neighbours[k] - group)
        seen |= group
        out.append(sorted(group))
    return out


def test_a_node_of_no_link_is_a_body_and_shared_nodes_join_links():
    assert _core.rigid_bodies([1, 2, 3, 4, 5], [[1, 2], [2, 3]]) == [[1, 2, 3], [4], [5]]
    assert _core.rigid_bodies([7, 3], []) == [[3], [7]]


@pytest.mark.parametrize("seed", range(5))
def test_random_links_give_the_connected_components(seed):
    rng = random.Random(seed)
    nodes = rng.sample(range(1, 200), 60)
    links = [rng.sample(nodes, rng.randint(1, 3)) for _ in range(35)]
    assert _core.rigid_bodies(nodes, links) == components(nodes, links)


def test_the_coupler_triangle_of_the_fourbar_example_is_one_body():
    """examples/fourbar_coupler.dat: the coupler's three rigid beams (orientation nodes 5, 7, 12,
    welded by rigid hinges) are one body carrying position nodes 3, 6 and 11."""
    model = spacar.read(EXAMPLES / "fourbar_coupler.dat")
    res = spacar.simulate(model, progress=False)
    assert res.geometry.rigid_bodies() == [((5, 7, 12), (3, 6, 11))]
