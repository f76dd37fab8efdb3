// The extension module sonarbench._core; python/sonarbench/__init__.py re-exports it.
#include "bindings.hpp"
#include "sonarbench/base/error.hpp"
#include "sonarbench/io/version.hpp"

namespace sonarbench::python {

std::string PathArg(const py::object& path) {
  if (!py::isinstance<py::str>(path) && !py::hasattr(path, "__fspath__")) {
    throw py::type_error("expected a path (str or os.PathLike), got " +
                         py::repr(path).cast<std::string>());
  }
  return py::module_::import("os").attr("fspath")(path).cast<std::string>();
}

void CheckSignals() {
  if (PyErr_CheckSignals() != 0) throw py::error_already_set();
}

}  // namespace sonarbench::python

PYBIND11_MODULE(_core, m) {
  namespace sbp = sonarbench::python;
  namespace py = pybind11;
  m.doc() = "sonarbench: simulate, map and score a mechanical scanning sonar (C++ core).";
  m.attr("__version__") = sonarbench::io::kVersion;
  // Bad input (the CLI's exit 2): a ValueError carrying the CLI's one-line message. The machine
  // refusing (a read-only disk, no permission): also an OSError.
  const auto input_error =
      py::register_exception<sonarbench::InputError>(m, "InputError", PyExc_ValueError);
  const py::object machine_bases = py::make_tuple(input_error, py::handle(PyExc_OSError));
  py::register_exception<sonarbench::EnvironmentError>(m, "MachineError", machine_bases.ptr());
  sbp::BindSweep(m);
  sbp::BindScene(m);
  sbp::BindData(m);
  sbp::BindMapper(m);
  sbp::BindScore(m);
}
