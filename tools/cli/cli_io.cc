// SPDX-License-Identifier: MIT
#include "cli_io.h"

#include <unistd.h>

#include <filesystem>
#include <system_error>

#include "files/file_io.h"

namespace cbrdf::cli {
namespace fs = std::filesystem;

namespace {

bool is_stdio(const PathArg& a) {
  return a.value == kStdStream;
}

// An output that is standard output by another name (/dev/stdout, /dev/fd/1).
bool is_stdout(const PathArg& a) {
  return a.value == kStdStream || descriptor_of_path(a.value) == STDOUT_FILENO;
}

// The same file: equivalent() for files that exist (hard and symbolic links included); for an
// output that does not exist yet, the same absolute, normalised path with links resolved.
bool same_file(const std::string& a, const std::string& b) {
  std::error_code ec;
  if (fs::equivalent(a, b, ec)) return true;
  if (fs::exists(a, ec) && fs::exists(b, ec)) return false;
  const fs::path ca = fs::weakly_canonical(fs::absolute(a, ec), ec);
  if (ec) return false;
  const fs::path cb = fs::weakly_canonical(fs::absolute(b, ec), ec);
  if (ec) return false;
  return ca == cb;
}

std::string named(const PathArg& a) {
  return "the " + a.option + " " + a.value;
}

}  // namespace

std::string input_path(const std::string& arg) {
  return arg == kStdStream ? "/dev/stdin" : arg;
}

std::string output_path(const std::string& arg) {
  return arg == kStdStream ? "/dev/stdout" : arg;
}

CLI::Validator existing_file_or_stdin() {
  return CLI::Validator(
      [](std::string& value) -> std::string {
        if (value == kStdStream) return {};
        return CLI::ExistingFile(value);
      },
      "FILE or -", "existing file or -");
}

std::optional<std::string> check_paths(const std::string& command, const std::vector<PathArg>& in,
                                       const std::vector<PathArg>& out, bool allow_stdio) {
  int stdin_uses = 0, stdout_uses = 0;
  for (const PathArg& a : in) {
    if (!is_stdio(a)) continue;
    if (!allow_stdio) {
      return command + ": '-' (standard input) is not supported for " + a.option +
             "; name a file (./- for a file called -)";
    }
    ++stdin_uses;
    if (::isatty(STDIN_FILENO) == 1) {
      return command + ": standard input is a terminal; redirect a file or a pipe to it for " +
             a.option;
    }
  }
  for (const PathArg& a : out) {
    if (!is_stdio(a)) continue;
    if (!allow_stdio) {
      return command + ": '-' (standard output) is not supported for " + a.option +
             "; name a file (./- for a file called -)";
    }
    if (++stdout_uses > 1) return command + ": only one output can go to standard output ('-')";
    if (::isatty(STDOUT_FILENO) == 1) {
      return command + ": refusing to write binary data to a terminal for " + a.option +
             " -; redirect standard output to a file or a pipe";
    }
  }
  if (stdin_uses > 1) return command + ": only one input can come from standard input ('-')";
  for (std::size_t i = 0; i < out.size(); ++i) {
    const PathArg& o = out[i];
    if (o.value.empty() || is_stdio(o)) continue;
    std::error_code ec;
    // Writing a device (/dev/null) twice or "over" an input harms nothing.
    if (fs::is_character_file(o.value, ec)) continue;
    for (const PathArg& a : in) {
      if (a.value.empty() || is_stdio(a)) continue;
      if (same_file(o.value, a.value)) {
        return command + ": " + o.option + " " + o.value + " would overwrite " + named(a);
      }
    }
    for (std::size_t j = 0; j < i; ++j) {
      const PathArg& p = out[j];
      if (p.value.empty() || is_stdio(p)) continue;
      if (same_file(o.value, p.value)) {
        return command + ": " + p.option + " and " + o.option + " name the same file " + o.value;
      }
    }
  }
  return std::nullopt;
}

std::FILE* info_stream(const std::vector<PathArg>& outputs) {
  for (const PathArg& a : outputs) {
    if (is_stdout(a)) return stderr;
  }
  return stdout;
}

std::string shown(const std::string& arg, bool output) {
  if (arg != kStdStream) return arg;
  return output ? "standard output" : "standard input";
}

}  // namespace cbrdf::cli
