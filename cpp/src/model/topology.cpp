#include "spacar/model/topology.hpp"

#include <algorithm>
#include <map>

namespace spacar {

std::vector<std::vector<int>> rigid_bodies(const std::vector<int>& nodes,
                                           const std::vector<std::vector<int>>& links) {
  std::map<int, int> parent;  // union-find; a root is the smallest node of its body
  auto root = [&](int a) {
    while (parent.at(a) != a) a = parent[a] = parent[parent[a]];  // path halving
    return a;
  };
  for (int n : nodes) parent.emplace(n, n);
  for (const std::vector<int>& link : links) {
    for (int n : link) parent.emplace(n, n);
    for (size_t i = 1; i < link.size(); ++i) {
      const int a = root(link[0]), b = root(link[i]);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  }
  // In ascending node order: a body appears at its smallest node, which is its root.
  std::map<int, size_t> body_of_root;
  std::vector<std::vector<int>> bodies;
  for (const auto& entry : parent) {
    const int n = entry.first;
    const auto [it, fresh] = body_of_root.try_emplace(root(n), bodies.size());
    if (fresh) bodies.emplace_back();
    bodies[it->second].push_back(n);
  }
  return bodies;
}

}  // namespace spacar
