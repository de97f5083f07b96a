// SPDX-License-Identifier: MIT
#include "errors.h"

#include "bindings.h"

namespace cbrdf::python {

py::object& error_class() {
  static py::object* cls = new py::object(py::reinterpret_borrow<py::object>(PyExc_ValueError));
  return *cls;
}

py::object& type_error_class() {
  static py::object* cls = new py::object(py::reinterpret_borrow<py::object>(PyExc_TypeError));
  return *cls;
}

py::str text(const std::string& s) {
  return py::reinterpret_steal<py::str>(
      PyUnicode_DecodeUTF8(s.data(), py::ssize_t(s.size()), "backslashreplace"));
}

std::string repr_text(const py::handle& v) {
  std::string r = py::reinterpret_steal<py::str>(PyObject_ASCII(v.ptr())).cast<std::string>();
  return r.size() > 80 ? r.substr(0, 77) + "..." : r;
}

namespace {

[[noreturn]] void raise_as(const py::object& cls, const Status& s, int exit_code) {
  py::object inst;
  if (cls.ptr() == PyExc_ValueError || cls.ptr() == PyExc_TypeError) {
    inst = cls(text(s.message()));
  } else {
    inst = cls(text(s.message()), int(s.code()), error_code_name(s.code()), exit_code);
  }
  PyErr_SetObject(cls.ptr(), inst.ptr());
  throw py::error_already_set();
}

}  // namespace

void raise_status(const Status& s, int exit_code) {
  raise_as(error_class(), s, exit_code);
}

void raise_invalid(const std::string& message, int exit_code) {
  raise_status(error(ErrorCode::kInvalidArgument, message), exit_code);
}

void raise_type(const std::string& message) {
  raise_as(type_error_class(), error(ErrorCode::kInvalidArgument, message), 2);
}

void bind_errors(py::module_& m) {
  m.def(
      "_set_error_class",
      [](py::object cls, py::object type_cls) {
        error_class() = std::move(cls);
        type_error_class() = std::move(type_cls);
      },
      "Sets the exception classes raised for library errors (cbrdf.Error) and arguments of the "
      "wrong type (cbrdf.ArgumentTypeError).");
  py::dict codes;
  for (int c = 0; c <= int(ErrorCode::kCancelled); ++c) {
    codes[py::int_(c)] = error_code_name(ErrorCode(c));
  }
  m.attr("ERROR_CODES") = codes;
}

}  // namespace cbrdf::python
