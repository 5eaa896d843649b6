// Pieces shared by the recognizers of planar (tree.cpp) and spatial (spatial_tree.cpp) rigid
// trees: the nodes of a system, the nodes of an element, and an element's mass projected on the
// rigid motions of a body.
#pragma once

#include <Eigen/Dense>
#include <map>
#include <set>
#include <utility>
#include <vector>

#include "spacar/system.hpp"

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

// The element's mass matrix at the positions x, projected on the rigid motions of a body:
// Tᵀ M T, with T's row a the rate of the element's coordinate a for the body's velocity (rows
// from `row`, a function of the global coordinate index). Zero without element mass.
template <int N, class Row>
Eigen::Matrix<double, N, N> element_inertia(const SystemElement& se, const Eigen::VectorXd& x, Row row) {
  if (!se.has_mass) return Eigen::Matrix<double, N, N>::Zero();
  const int n = static_cast<int>(se.coords.size());
  Eigen::VectorXd xl(n), vl = Eigen::VectorXd::Zero(n), h(n);
  Eigen::MatrixXd M(n, n);
  Eigen::Matrix<double, Eigen::Dynamic, N> T(n, N);
  for (int a = 0; a < n; ++a) xl[a] = x[se.coords[a]];
  se.kernel->mass(xl.data(), vl.data(), M.data(), h.data());
  for (int a = 0; a < n; ++a) T.row(a) = row(se.coords[a]);
  return T.transpose() * M * T;
}

}  // namespace tree_detail
}  // namespace spacar
