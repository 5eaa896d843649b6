#include "spacar/model/serialize.hpp"

#include "spacar/errors.hpp"

namespace spacar {

void bad_model_state(const std::string& why) {
  throw InputError("invalid pickled spacar model: " + why);
}

ModelState model_state(const Model& m) {
  ModelState state;
  auto& [version, nodes, elements, settings, time, gravity, gravity_given, prepared] = state;
  version = kModelStateVersion;
  for (const auto& [id, n] : m.nodes) nodes.push_back(encode_record(n, kNodeFields));
  for (const auto& [id, el] : m.elements) elements.push_back(encode_record(el, kElementFields));
  settings = encode_record(m.settings, kSettingsFields);
  time = m.time;
  gravity = m.gravity;
  gravity_given = m.gravity_given;
  prepared = m.frozen();
  return state;
}

namespace {

void check_node(const Model& m, const Node& n) {
  const size_t size = n.kind == NodeKind::Any ? 4 : static_cast<size_t>(node_size(n.kind));
  if (n.id <= 0 || n.x.size() != size || n.cls.size() != size || n.xd.size() != size || n.xdd.size() != size ||
      m.nodes.count(n.id))
    bad_model_state("node " + std::to_string(n.id));
}

void check_element(const Model& m, const Element& el) {
  const ElementType& et = element_catalogue()[el.type];
  const size_t nd = static_cast<size_t>(et.n_deformations());
  bool ok = el.id > 0 && !m.elements.count(el.id) && el.nodes.size() == et.nodes.size() && el.cls.size() == nd &&
            el.e.size() == nd && el.ed.size() == nd && el.edd.size() == nd && el.e_given.size() == nd &&
            el.kinematic_of.size() == nd && el.params.size() >= static_cast<size_t>(et.n_params_min) &&
            el.params.size() <= static_cast<size_t>(et.n_params_max);
  for (size_t i = 0; ok && i < el.nodes.size(); ++i) {
    auto it = m.nodes.find(el.nodes[i]);
    ok = it != m.nodes.end() && it->second.kind == et.nodes[i];
  }
  if (!ok) bad_model_state("element " + std::to_string(el.id));
}

// Every nonholonomic deformation refers to an existing deformation.
void check_nonholonomic_references(const Model& m) {
  for (const auto& [id, el] : m.elements)
    for (size_t k = 0; k < el.cls.size(); ++k)
      if (el.cls[k] == DefClass::Nonholonomic) {
        auto it = m.elements.find(el.kinematic_of[k][0]);
        const int i = el.kinematic_of[k][1];
        if (it == m.elements.end() || i < 1 || i > static_cast<int>(it->second.cls.size()))
          bad_model_state("nonholonomic deformation of element " + std::to_string(id));
      }
}

}  // namespace

Model model_from_state(const ModelState& state) {
  const auto& [version, nodes, elements, settings, time, gravity, gravity_given, prepared] = state;
  if (version != kModelStateVersion) bad_model_state("unknown format (saved by another version of spacar?)");
  Model m;
  for (const NodeRecord& r : nodes) {
    Node n;
    decode_record(r, n, kNodeFields);
    check_node(m, n);
    m.nodes.emplace(n.id, std::move(n));
  }
  for (const ElementRecord& r : elements) {
    Element el;
    decode_record(r, el, kElementFields);
    check_element(m, el);
    m.elements.emplace(el.id, std::move(el));
  }
  check_nonholonomic_references(m);
  decode_record(settings, m.settings, kSettingsFields);
  m.time = time;
  m.gravity = gravity;
  m.gravity_given = gravity_given;
  if (prepared) m.restore_prepared();
  return m;
}

}  // namespace spacar
