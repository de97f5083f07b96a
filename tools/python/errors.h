// SPDX-License-Identifier: MIT
// How the extension reports errors: every Status the library returns becomes cbrdf.Error (a
// ValueError subclass defined in cbrdf/__init__.py), a value of the wrong type
// cbrdf.ArgumentTypeError (also a TypeError). Internal to the extension.
#pragma once

#include <pybind11/pybind11.h>

#include <string>
#include <utility>

#include "cbrdf/codec.h"

namespace cbrdf::python {

namespace py = pybind11;

// The classes raised; ValueError and TypeError until __init__.py sets its own (bind_errors).
py::object& error_class();
py::object& type_error_class();

// Message text as a str: a path's bytes need not be UTF-8, and a message must still print.
py::str text(const std::string& s);

// The repr of a Python value, for messages (at most about 80 characters).
std::string repr_text(const py::handle& v);

// Raises cbrdf.Error(message, code, code_name, exit_code): exit_code is what `cbrdf` would exit
// with (1 bad data, 2 bad usage).
[[noreturn]] void raise_status(const Status& s, int exit_code = 1);
[[noreturn]] void raise_invalid(const std::string& message, int exit_code = 1);
// An argument of the wrong type (None, a list, a str for a number): bad usage, exit code 2.
[[noreturn]] void raise_type(const std::string& message);

// The value of `e`, or cbrdf.Error with its status (prefixed with `context` when given).
template <typename T>
T take(Expected<T>&& e, const std::string& context = {}) {
  if (!e.ok()) raise_status(context.empty() ? e.status() : e.status().with_context(context));
  return std::move(e).value();
}

}  // namespace cbrdf::python
