// SPDX-License-Identifier: MIT
// How the `cbrdf` command names its files: `-` for standard input and output, checks that no
// output overwrites an input or another output, and where informational lines go.
//
// `-` stands for standard input as the input of encode, decode and info, and for standard output
// as -o of encode, decode and sample and as --exr of decode (binary data is refused on a terminal;
// informational lines then go to stderr). In report, render and imgdiff it is a usage error: write
// ./- for a file of that name.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

namespace cbrdf::cli {

inline constexpr const char* kStdStream = "-";

// The path the library reads or writes for a command-line argument: `-` becomes /dev/stdin or
// /dev/stdout (which the library reads and writes through the descriptor).
std::string input_path(const std::string& arg);
std::string output_path(const std::string& arg);

// A CLI11 check: the file exists (not a directory), or is `-`.
CLI::Validator existing_file_or_stdin();

// One named argument of a subcommand, for the checks below.
struct PathArg {
  std::string option;  // "-o", "--exr", "input"
  std::string value;   // as typed; empty when not given
};

// The usage error (without the "cbrdf: " prefix) when an output would overwrite an input (the same
// file by std::filesystem::equivalent, links followed) or another output, when two arguments
// both name standard input or output, when binary data would go to or come from a terminal, or
// when `-` is given where it is not supported (allow_stdio false). nullopt when all is well.
std::optional<std::string> check_paths(const std::string& command, const std::vector<PathArg>& in,
                                       const std::vector<PathArg>& out, bool allow_stdio = true);

// Where informational lines go: stderr when standard output carries the command's data (`-`,
// /dev/stdout).
std::FILE* info_stream(const std::vector<PathArg>& outputs);

// How an argument appears in messages: `-` as "standard input" or "standard output".
std::string shown(const std::string& arg, bool output);

}  // namespace cbrdf::cli
