// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// msf::Error and its kinds as Python exceptions carrying the library's message: msfusion.Error
// (a RuntimeError) and its subclasses, which also derive from the built-in exception a Python
// user would catch for them: IOError from OSError, the others from ValueError. An IOError that
// knows its errno is raised as the msfusion subclass of the matching built-in (FileNotFoundError,
// FileExistsError, ...), with errno, strerror and filename set.
#include "bindings.h"

#include <msf/common/exceptions.h>

#include <pybind11/eval.h>

#include <cstring>
#include <string>
#include <utility>
#include <vector>

namespace msf::python {

namespace {

// Owned by the module's attributes, which live as long as the interpreter.
PyObject* error_class = nullptr;
PyObject* io_error_class = nullptr;
PyObject* calibration_error_class = nullptr;
PyObject* config_error_class = nullptr;
PyObject* invalid_input_error_class = nullptr;
std::vector<std::pair<PyObject*, PyObject*>> os_error_kinds; // (built-in OSError subclass, ours)

PyObject* newException(py::module_& m, const char* name, const py::tuple& bases, const char* doc,
                       PyObject* dict = nullptr) {
  const std::string qualified = std::string("msfusion.") + name;
  PyObject* type = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, bases.ptr(), dict);
  if (!type)
    throw py::error_already_set();
  m.attr(name) = py::reinterpret_steal<py::object>(type);
  return type;
}

/// The class of an IOError: ours of the built-in that OSError(errno, ...) would be, else IOError.
PyObject* ioErrorKind(int code) {
  if (code == 0)
    return io_error_class;
  const py::object probe = py::reinterpret_borrow<py::object>(PyExc_OSError)(code, "");
  for (const auto& [builtin, ours] : os_error_kinds)
    if (Py_TYPE(probe.ptr()) == reinterpret_cast<PyTypeObject*>(builtin))
      return ours;
  return io_error_class;
}

void raiseIOError(const IOError& e) {
  PyObject* kind = ioErrorKind(e.code());
  py::object error = py::reinterpret_borrow<py::object>(kind)(e.what());
  if (e.code() != 0) {
    error.attr("errno") = e.code();
    error.attr("strerror") = std::strerror(e.code());
  }
  if (!e.path().empty())
    error.attr("filename") = e.path();
  PyErr_SetObject(kind, error.ptr());
}

void translate(std::exception_ptr thrown) {
  try {
    std::rethrow_exception(thrown);
  } catch (const IOError& e) {
    raiseIOError(e);
  } catch (const CalibrationError& e) {
    PyErr_SetString(calibration_error_class, e.what());
  } catch (const ConfigError& e) {
    PyErr_SetString(config_error_class, e.what());
  } catch (const InvalidInputError& e) {
    PyErr_SetString(invalid_input_error_class, e.what());
  } catch (const Error& e) {
    PyErr_SetString(error_class, e.what());
  }
}

} // namespace

void bindErrors(py::module_& m) {
  const py::handle runtime_error(PyExc_RuntimeError), os_error(PyExc_OSError), value_error(PyExc_ValueError);
  error_class = newException(m, "Error", py::make_tuple(runtime_error),
                             "Base of every error of msfusion; the message names the file, key or value at fault.");
  const py::handle error(error_class);
  // The library's message, whole: OSError's own str would show errno, strerror and filename instead.
  py::dict io_error_namespace;
  py::exec("def __str__(self):\n    return str(self.args[0]) if self.args else ''\n", py::globals(),
           io_error_namespace);
  io_error_class = newException(m, "IOError", py::make_tuple(error, os_error),
                                "A file that cannot be read or written, or whose content is malformed.",
                                io_error_namespace.ptr());
  const std::pair<const char*, PyObject*> os_kinds[] = {{"FileNotFoundError", PyExc_FileNotFoundError},
                                                        {"FileExistsError", PyExc_FileExistsError},
                                                        {"NotADirectoryError", PyExc_NotADirectoryError},
                                                        {"IsADirectoryError", PyExc_IsADirectoryError},
                                                        {"PermissionError", PyExc_PermissionError}};
  for (const auto& [name, builtin] : os_kinds) {
    const py::tuple bases = py::make_tuple(py::handle(io_error_class), py::handle(builtin));
    os_error_kinds.emplace_back(builtin, newException(m, name, bases, "An IOError that is also the built-in of its name."));
  }
  calibration_error_class = newException(m, "CalibrationError", py::make_tuple(error, value_error),
                                         "A calibration that is missing a key or has a matrix of the wrong size.");
  config_error_class = newException(m, "ConfigError", py::make_tuple(error, value_error),
                                    "A configuration key with a wrong type or an out-of-range value.");
  invalid_input_error_class = newException(
      m, "InvalidInputError", py::make_tuple(error, value_error),
      "Input a stage cannot work on: an array of the wrong shape, dtype or size, a frame without a pose...");
  py::register_exception_translator(&translate);
}

} // namespace msf::python
