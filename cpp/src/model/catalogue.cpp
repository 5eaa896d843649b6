#include "spacar/model/catalogue.hpp"

#include <stdexcept>

#include "spacar/elements/registry.hpp"

namespace spacar {

int node_size(NodeKind kind) {
  switch (kind) {
    case NodeKind::XY: return 2;
    case NodeKind::Beta: return 1;
    case NodeKind::XYZ: return 3;
    case NodeKind::Lambda: return 4;
    case NodeKind::Any: return 4;
  }
  return 0;
}

const char* node_keyword(NodeKind kind) {
  switch (kind) {
    case NodeKind::XY: return "XY";
    case NodeKind::Beta: return "BETA";
    case NodeKind::XYZ: return "XYZ";
    case NodeKind::Lambda: return "LAMBDA";
    case NodeKind::Any: return "X";
  }
  return "?";
}

bool is_orientation(NodeKind kind) { return kind == NodeKind::Beta || kind == NodeKind::Lambda; }

int ElementType::n_coordinates() const {
  int n = 0;
  for (NodeKind k : nodes) n += node_size(k);
  return n;
}

namespace {

// The rows of the list (spacar/elements/list.hpp), in its order, each checked once.
std::vector<ElementType> build_catalogue() {
  std::vector<ElementType> table = {
#define SPACAR_ELEMENT(name) name##_element_type(),
#include "spacar/elements/list.hpp"
#undef SPACAR_ELEMENT
  };
  int automatic = 0;
  for (size_t i = 0; i < table.size(); ++i) {
    automatic += table[i].automatic;
    for (size_t j = 0; j < i; ++j)
      if (table[j].name == table[i].name) throw std::logic_error("element type " + table[i].name + " is listed twice");
  }
  if (automatic != 1) throw std::logic_error("the catalogue needs exactly one automatic element type (L2MIN1)");
  return table;
}

}  // namespace

const std::vector<ElementType>& element_catalogue() {
  static const std::vector<ElementType> table = build_catalogue();
  return table;
}

int find_element_type(const std::string& name) {
  const auto& t = element_catalogue();
  for (size_t i = 0; i < t.size(); ++i)
    if (t[i].name == name) return static_cast<int>(i);
  return -1;
}

int automatic_element_type() {
  static const int index = [] {
    const auto& t = element_catalogue();
    for (size_t i = 0; i < t.size(); ++i)
      if (t[i].automatic) return static_cast<int>(i);
    return -1;
  }();
  return index;
}

}  // namespace spacar
