// Binding of topology.hpp: the one union-find of rigid bodies, for spacar.compare.
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "spacar/model/topology.hpp"

namespace spacar::bindings {

void bind_topology(py::module_& m) {
  m.def("rigid_bodies", &spacar::rigid_bodies, py::arg("nodes"), py::arg("links"),
        "The rigid bodies that `links` (lists of nodes moving as one) form among `nodes`: lists of\n"
        "ascending node numbers, ordered by their first node; links sharing a node are one body,\n"
        "a node of no link is a body by itself.");
}

}  // namespace spacar::bindings
