// The recursive path's entry (tree.hpp) and what the planar and spatial recognizers share
// (tree_common.hpp).
#include "spacar/recursive/tree.hpp"

#include <map>
#include <set>
#include <string>

#include "spacar/model/topology.hpp"
#include "spacar/recursive/closed_loop.hpp"
#include "spacar/recursive/planar_tree.hpp"
#include "spacar/recursive/spatial_tree.hpp"
#include "tree_common.hpp"

namespace spacar {

namespace {

// The tree, or its loops closed on it if it has any.
template <class Algebra, class Tree>
std::unique_ptr<RecursiveTree> with_loops(std::unique_ptr<Tree> tree, const System& sys, const Data& data,
                                          std::string* why) {
  if (!tree || !tree->loops().closed()) return tree;
  return ClosedLoopTree<Algebra>::close(std::move(tree), sys, data, why);
}

}  // namespace

std::unique_ptr<RecursiveTree> RecursiveTree::detect(const System& sys, const Data& data, std::string* why) {
  if (sys.dim == 3) return with_loops<SpatialAlgebra>(SpatialTree::detect(sys, data, why), sys, data, why);
  return with_loops<PlanarAlgebra>(PlanarTree::detect(sys, data, why), sys, data, why);
}

bool RecursiveTree::solve(const double* q, const double* qd, Eigen::VectorXd& x, Eigen::VectorXd& xd,
                          Eigen::VectorXd& xdd, double* qdd) {
  if (!solve(q, qd, qdd)) return false;
  move_coordinates(x, xd, xdd);
  return true;
}

namespace tree_detail {

std::map<int, NodeInfo> system_nodes(const System& sys) {
  std::map<int, NodeInfo> nodes;
  for (int g = 0; g < sys.nx; ++g) {
    const CoordClass c = sys.coord_class[g];
    auto [it, fresh] = nodes.try_emplace(sys.coord_label[g][0]);
    if (fresh) {
      it->second.kind = sys.coord_node_kind[g];
      it->second.coord = g;
    }
    it->second.fixed = it->second.fixed && c == CoordClass::Fixed;
    it->second.free = it->second.free && (c == CoordClass::Calculable || c == CoordClass::Dynamic);
  }
  return nodes;
}

BeamBodies group_beams(const std::vector<std::pair<int, std::vector<int>>>& beams,
                       const std::map<int, NodeInfo>& nodes, NodeKind orientation) {
  std::vector<std::vector<int>> links;
  for (const auto& [i, ids] : beams) {
    links.emplace_back();
    for (int id : ids)
      if (nodes.at(id).kind == orientation) links.back().push_back(id);
  }
  const std::vector<std::vector<int>> rigid = rigid_bodies({}, links);
  std::map<int, int> rigid_of;      // orientation node → rigid_bodies() index
  for (size_t r = 0; r < rigid.size(); ++r)
    for (int id : rigid[r]) rigid_of[id] = static_cast<int>(r);
  BeamBodies out;
  std::map<int, int> body_of_rigid;  // rigid_bodies() index → body
  for (size_t k = 0; k < beams.size(); ++k) {
    const auto& [i, ids] = beams[k];
    auto [it, fresh] = body_of_rigid.try_emplace(rigid_of.at(links[k].front()), static_cast<int>(out.points.size()));
    if (fresh) {
      out.points.emplace_back();
      out.orientations.emplace_back();
      out.beams.emplace_back();
    }
    const int b = it->second;
    out.beams[b].push_back(i);
    for (int id : ids) (nodes.at(id).kind == orientation ? out.orientations[b] : out.points[b]).insert(id);
  }
  std::set<int> moving;
  for (size_t b = 0; b < out.points.size(); ++b) {
    moving.insert(out.points[b].begin(), out.points[b].end());
    moving.insert(out.orientations[b].begin(), out.orientations[b].end());
    for (int id : out.orientations[b]) out.body_of[id] = static_cast<int>(b);
  }
  for (const auto& [id, n] : nodes)
    if (!n.fixed && !moving.count(id)) {
      out.stray = id;
      break;
    }
  return out;
}

std::vector<int> element_nodes(const System& sys, const SystemElement& se) {
  std::vector<int> nodes;
  for (int g : se.coords) {
    const int id = sys.coord_label[g][0];
    if (nodes.empty() || nodes.back() != id) nodes.push_back(id);
  }
  return nodes;
}

}  // namespace tree_detail

}  // namespace spacar
