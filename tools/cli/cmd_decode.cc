// SPDX-License-Identifier: MIT
// `cbrdf decode`: .cbrdf -> MERL .binary (and OpenEXR for inspection).
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>

#include "cbrdf/encoder.h"
#include "cbrdf/exr_table.h"
#include "cbrdf/merl_io.h"
#include "cli.h"
#include "cli_io.h"
#include "files/file_io.h"

namespace cbrdf::cli {
namespace {

struct DecodeOptions {
  std::string input, output, exr;
};

// An output file can be written only into an existing, writable folder. Checked for every output
// before any is written, so a bad second path never leaves the first one written.
std::optional<std::string> check_output_folder(const std::string& option, const std::string& path) {
  if (path.empty() || path == kStdStream) return std::nullopt;
  std::filesystem::path folder = std::filesystem::path(path).parent_path();
  if (folder.empty()) folder = ".";
  std::error_code ec;
  if (!std::filesystem::is_directory(folder, ec)) {
    return "decode: " + option + " " + path + ": the folder " + folder.string() +
           " does not exist (nothing was written)";
  }
  if (::access(folder.c_str(), W_OK) != 0) {
    return "decode: " + option + " " + path + ": the folder " + folder.string() +
           " is not writable (nothing was written)";
  }
  return std::nullopt;
}

int run_decode(const DecodeOptions& o, const Context& ctx) {
  if (o.output.empty() && o.exr.empty()) {
    return usage_error("decode: give -o OUT.binary, --exr OUT.exr or both");
  }
  const std::vector<PathArg> outputs = {{"-o", o.output}, {"--exr", o.exr}};
  if (auto bad = check_paths("decode", {{"input", o.input}}, outputs)) return usage_error(*bad);
  for (const PathArg& out : outputs) {
    if (auto bad = check_output_folder(out.option, out.value)) {
      return fail(error(ErrorCode::kIo, *bad));
    }
  }
  std::FILE* info = info_stream(outputs);
  auto bytes = read_file(input_path(o.input), kMaxContainerBytes);
  if (!bytes.ok()) return fail(bytes.status());
  auto table = decode_table(*bytes);
  if (!table.ok()) return fail(table.status().with_context(shown(o.input, false)));
  if (!o.output.empty()) {
    if (Status s = write_merl_output(output_path(o.output), *table); !s.ok()) return fail(s);
    if (!ctx.quiet) std::fprintf(info, "wrote %s\n", shown(o.output, true).c_str());
  }
  if (!o.exr.empty()) {
    if (Status s = write_exr_table(output_path(o.exr), *table); !s.ok()) return fail(s);
    if (!ctx.quiet) std::fprintf(info, "wrote %s\n", shown(o.exr, true).c_str());
  }
  return kExitOk;
}

}  // namespace

void add_decode_command(CLI::App& app, const Context& ctx, Action* action) {
  auto o = std::make_shared<DecodeOptions>();
  CLI::App* cmd = app.add_subcommand("decode", "Rebuild a MERL .binary from a .cbrdf file");
  cmd->add_option("input", o->input, "Input .cbrdf file (- for standard input)")
      ->required()
      ->check(existing_file_or_stdin());
  cmd->add_option("-o,--output", o->output, "Output MERL .binary (- for standard output)");
  cmd->add_option("--exr", o->exr,
                  "Also write the table as OpenEXR: theta_d slices tiled 10 x 9, each 180 phi_d "
                  "x 90 theta_h");
  cmd->callback([o, &ctx, action] { *action = [o, &ctx] { return run_decode(*o, ctx); }; });
}

}  // namespace cbrdf::cli
