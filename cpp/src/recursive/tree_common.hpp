// Pieces shared by the recognizers of planar (tree.cpp) and spatial (spatial_tree.cpp) rigid
// trees: the nodes of a system, the nodes of an element, and an element's mass projected on the
// rigid motions of a body.
#pragma once

#include <Eigen/Dense>
#include <map>
#include <set>
#include <utility>
#include <vector>

#include "spacar/model/system.hpp"

namespace spacar {
namespace tree_detail {

constexpr int kGround = -1;

struct NodeInfo {
  NodeKind kind = NodeKind::Any;
  int coord = 0;       // first coordinate
  bool fixed = true;   // every coordinate fixed
  bool free = true;    // every coordinate calculable or dynamic (DYNX)
};

// Every node of the system by number.
std::map<int, NodeInfo> system_nodes(const System& sys);

// Node numbers of an element's coordinates, in slot order.
std::vector<int> element_nodes(const System& sys, const SystemElement& se);

// Moving rigid beams joined into bodies by their shared orientation nodes (BETA or LAMBDA;
// rigid_bodies), the bodies numbered in the order of their first beam.
struct BeamBodies {
  std::vector<std::set<int>> points, orientations;  // nodes of each body
  std::vector<std::vector<int>> beams;              // elements of each body
  std::map<int, int> body_of;                       // orientation node → body
  int stray = -1;                                   // a free node on no body (no tree), or −1
};
// beams: (element index, its nodes) of every moving rigid beam.
BeamBodies group_beams(const std::vector<std::pair<int, std::vector<int>>>& beams,
                       const std::map<int, NodeInfo>& nodes, NodeKind orientation);

// Tᵀ M T of element_inertia, with its matrices' storage bounded to Max rows (on the stack) or
// not (Max = Eigen::Dynamic, on the heap).
template <int N, int Max, class Row>
Eigen::Matrix<double, N, N> projected_mass(const SystemElement& se, const Eigen::VectorXd& x, Row row) {
  const int n = static_cast<int>(se.coords.size());
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, Max, 1> xl(n), vl(n), h(n);
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, Max, Max> M(n, n);
  Eigen::Matrix<double, Eigen::Dynamic, N, 0, Max, N> T(n, N);
  vl.setZero();
  for (int a = 0; a < n; ++a) xl[a] = x[se.coords[a]];
  se.kernel->mass(xl.data(), vl.data(), M.data(), h.data());
  for (int a = 0; a < n; ++a) T.row(a) = row(se.coords[a]);
  return T.transpose() * M * T;
}

// The element's mass matrix at the positions x, projected on the rigid motions of a body:
// Tᵀ M T, with T's row a the rate of the element's coordinate a for the body's velocity (rows
// from `row`, a function of the global coordinate index). Zero without element mass.
template <int N, class Row>
Eigen::Matrix<double, N, N> element_inertia(const SystemElement& se, const Eigen::VectorXd& x, Row row) {
  if (!se.has_mass) return Eigen::Matrix<double, N, N>::Zero();
  // Up to 16 coordinates (a BEAM has 14) on the stack, the small products evaluated
  // coefficient-wise: on the heap, recognizing a 20-link tree called the general matrix product
  // and malloc 40 times each.
  constexpr int kOnStack = 16;
  if (se.coords.size() <= kOnStack) return projected_mass<N, kOnStack>(se, x, row);
  return projected_mass<N, Eigen::Dynamic>(se, x, row);
}

}  // namespace tree_detail
}  // namespace spacar
