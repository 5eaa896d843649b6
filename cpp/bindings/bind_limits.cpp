// The limits of an analysis as Python context managers: the memory limit, a thread's deadline
// over several calls into the core (linearize, state_space: each call checks it where a run
// would), and the cancellation that stops a sweep's threads when Ctrl-C reaches the main thread.
#include <atomic>
#include <memory>

#include "bindings.hpp"
#include "spacar/limits.hpp"

namespace spacar::bindings {

namespace {

// `with _core.Deadline(limit):` — the calls into the core made by this thread inside the block
// share one deadline `limit` seconds from its start (0: none).
struct DeadlineBlock {
  double limit;
  std::unique_ptr<DeadlineScope> scope;  // while inside the block
};

// A flag shared by the threads of a sweep; `with flag.watch():` makes this thread's analyses stop
// (Interrupted, KeyboardInterrupt in Python) once `cancel()` is called from any thread.
struct Cancellation {
  std::shared_ptr<std::atomic<bool>> flag = std::make_shared<std::atomic<bool>>(false);
};

struct CancelWatch {
  std::shared_ptr<std::atomic<bool>> flag;
  std::unique_ptr<CancelScope> scope;
};

}  // namespace

void bind_limits(py::module_& m) {
  m.def("memory_limit", &memory_limit, "Bytes one analysis may allocate for its work and result arrays.");
  m.def("set_memory_limit", &set_memory_limit, py::arg("bytes"));
  m.def("deadline_passed", &thread_deadline_passed, "Whether this thread's deadline (a Deadline block) has passed.");

  py::class_<DeadlineBlock>(m, "Deadline")
      .def(py::init([](double limit) { return DeadlineBlock{limit, nullptr}; }), py::arg("limit"))
      .def("__enter__", [](DeadlineBlock& d) -> DeadlineBlock& { d.scope = std::make_unique<DeadlineScope>(d.limit); return d; },
           py::return_value_policy::reference)
      .def("__exit__", [](DeadlineBlock& d, const py::args&) { d.scope.reset(); return false; });
  m.def("check_deadline", [](const std::string& where) { check_thread_deadline(where.c_str()); }, py::arg("where"),
        "TimeLimitError naming `where` if this thread's deadline has passed; Interrupted if its analyses are "
        "cancelled.");

  py::class_<CancelWatch>(m, "CancelWatch")
      .def("__enter__", [](CancelWatch& w) -> CancelWatch& { w.scope = std::make_unique<CancelScope>(w.flag.get()); return w; },
           py::return_value_policy::reference)
      .def("__exit__", [](CancelWatch& w, const py::args&) { w.scope.reset(); return false; });

  py::class_<Cancellation>(m, "Cancellation")
      .def(py::init<>())
      .def("cancel", [](Cancellation& c) { c.flag->store(true); })
      .def_property_readonly("cancelled", [](const Cancellation& c) { return c.flag->load(); })
      .def("watch", [](const Cancellation& c) { return CancelWatch{c.flag, nullptr}; },
           "A context manager: this thread's analyses inside it stop once cancel() is called.");
}

}  // namespace spacar::bindings
