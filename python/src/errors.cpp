// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// msf::Error and its kinds as Python exceptions carrying the library's message: msfusion.Error
// (a RuntimeError) and its subclasses, which also derive from the built-in exception a Python
// user would catch for them: IOError from OSError, the others from ValueError.
#include "bindings.h"

#include <msf/common/exceptions.h>

#include <string>

namespace msf::python {

namespace {

// Owned by the module's attributes, which live as long as the interpreter.
PyObject* error_class = nullptr;
PyObject* io_error_class = nullptr;
PyObject* calibration_error_class = nullptr;
PyObject* config_error_class = nullptr;
PyObject* invalid_input_error_class = nullptr;

PyObject* newException(py::module_& m, const char* name, const py::tuple& bases, const char* doc) {
  const std::string qualified = std::string("msfusion.") + name;
  PyObject* type = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, bases.ptr(), nullptr);
  if (!type)
    throw py::error_already_set();
  m.attr(name) = py::reinterpret_steal<py::object>(type);
  return type;
}

void translate(std::exception_ptr thrown) {
  try {
    std::rethrow_exception(thrown);
  } catch (const IOError& e) {
    PyErr_SetString(io_error_class, e.what());
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
  io_error_class = newException(m, "IOError", py::make_tuple(error, os_error),
                                "A file that cannot be read or written, or whose content is malformed.");
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
