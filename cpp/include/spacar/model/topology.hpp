// Rigid bodies of a model: which orientation nodes move as one.
#pragma once

#include <vector>

namespace spacar {

// The rigid bodies that `links` form among `nodes`: each link is a set of nodes that move as
// one (the orientation nodes of a rigid element), and links sharing a node are one body
// (union-find). Every node is in exactly one body (a node of no link is a body by itself); the
// nodes of a body ascend and the bodies are ordered by their first node. Which elements are
// links is the caller's rule: the planar tree (tree.cpp) takes its moving rigid beams,
// spacar.compare also rigid hinges and spatial beams. Link nodes missing from `nodes` are added.
std::vector<std::vector<int>> rigid_bodies(const std::vector<int>& nodes,
                                           const std::vector<std::vector<int>>& links);

}  // namespace spacar
