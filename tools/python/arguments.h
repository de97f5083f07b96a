// SPDX-License-Identifier: MIT
// Python arguments as C++ values, each refused with a message naming the argument: the same
// rules for every entry point of the extension. Internal to the extension.
#pragma once

#include <pybind11/pybind11.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace cbrdf::python {

namespace py = pybind11;

// Any buffer's bytes, in its logical (C) order.
std::vector<std::uint8_t> bytes_of(const py::handle& b);

// `path`, refused when it holds a NUL byte (the system call would cut it short).
const std::string& checked_path(const std::string& path);

// A path argument (str, bytes or os.PathLike) as the bytes the system call gets: os.fsencode, so
// a name os.listdir gave with undecodable bytes (surrogate-escaped) names that same file.
std::string path_arg(const py::handle& v, const char* name = "path");

// An int argument in lo..hi: a Python int or a NumPy integer (not a bool, not a float), any size.
long long int_arg(const py::handle& v, const char* name, long long lo, long long hi,
                  int exit_code = 2);

// A str argument (not None, not a number), text UTF-8 can hold (no lone surrogate).
std::string str_arg(const py::handle& v, const char* name, int exit_code = 2);

// The `threads` argument of the batch methods: 0 (the library's limit) to 256, as --threads.
int threads_arg(const py::handle& v);

// A real number (int, float or a NumPy real scalar such as np.float32; not a bool, str or
// complex), or nullopt; an int too large for a double is infinite.
std::optional<double> real_value(const py::object& v);

}  // namespace cbrdf::python
