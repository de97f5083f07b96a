// SPDX-License-Identifier: MIT
// cbrdf view FILE...: serves the browser viewer (viewer/), cbrdf.wasm and the given files on
// 127.0.0.1 and prints the address; the page evaluates models on the GPU (viewer/README.md).
// This file is the command: options, finding the folders, printing, signals. The server (what is
// served, HTTP, limits) is view_server.h. Ctrl-C (SIGINT) or SIGTERM stops it.
#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <system_error>
#include <vector>

#include "cli.h"
#include "view_server.h"

#ifndef CBRDF_VIEWER_DIR
#define CBRDF_VIEWER_DIR ""
#endif
#ifndef CBRDF_WASM_DIRS
#define CBRDF_WASM_DIRS ""
#endif
// Where `cmake --install` puts the page and cbrdf.wasm, relative to the installed command's folder
// (cmake/install_viewer.cmake).
#ifndef CBRDF_VIEWER_INSTALLED
#define CBRDF_VIEWER_INSTALLED ""
#endif
#ifndef CBRDF_WASM_INSTALLED
#define CBRDF_WASM_INSTALLED ""
#endif

namespace cbrdf::cli {
namespace {

namespace fs = std::filesystem;

// The server a signal stops (request_stop is async-signal-safe).
ViewServer* volatile g_server = nullptr;
void on_signal(int) {
  if (ViewServer* s = g_server) s->request_stop();
}

struct ViewOptions {
  std::vector<std::string> files;
  int port = 8642;
  bool no_open = false;
  std::string viewer_dir, wasm_dir;
};

bool has_file(const fs::path& dir, const char* name) {
  std::error_code ec;
  return !dir.empty() && fs::is_regular_file(dir / name, ec);
}

// The folder `relative` names from the running command's own folder; empty when unknown.
fs::path beside_command(const char* relative) {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (ec || !*relative) return {};
  return (self.parent_path() / relative).lexically_normal();
}

// What a candidate folder lacks of `names`: "" when it has them all, else " (no such folder)" or
// " (no a, b)", for the message that lists the folders tried.
std::string lacks(const fs::path& dir, std::span<const char* const> names) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return " (no such folder)";
  std::string missing;
  for (const char* n : names) {
    if (!has_file(dir, n)) missing += (missing.empty() ? "" : ", ") + std::string(n);
  }
  return missing.empty() ? "" : " (no " + missing + ")";
}

// The first of: the option, the environment variable, the defaults ('|'-separated), that holds
// every one of `names`; `tried` lists the others with what each lacks.
std::optional<fs::path> locate(const std::string& option, const char* env,
                               const std::string& defaults, std::span<const char* const> names,
                               std::string* tried) {
  std::vector<std::string> candidates;
  if (!option.empty()) {
    candidates.push_back(option);
  } else {
    if (const char* e = std::getenv(env); e && *e) candidates.emplace_back(e);
    std::string d = defaults;
    for (std::size_t b = 0; b <= d.size();) {
      const std::size_t e = std::min(d.find('|', b), d.size());
      if (e > b) candidates.push_back(d.substr(b, e - b));
      b = e + 1;
    }
  }
  for (const std::string& c : candidates) {
    const std::string lack = lacks(c, names);
    if (lack.empty()) return fs::path(c);
    *tried += (tried->empty() ? "" : ", ") + c + lack;
  }
  return std::nullopt;
}

void open_browser(const std::string& url) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int null = ::open("/dev/null", O_WRONLY);
    if (null >= 0) {
      ::dup2(null, 1);
      ::dup2(null, 2);
    }
    ::execlp("xdg-open", "xdg-open", url.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
}

int run_view(const Context& ctx, const ViewOptions& o) {
  for (const std::string& f : o.files) {
    std::error_code ec;
    if (!fs::is_regular_file(f, ec)) {
      return fail(
          cbrdf::error(ErrorCode::kNotFound,
                       "view: " + f + ": no such file (give .cbrdf or MERL .binary files)"));
    }
  }
  // An installed command (its page beside it, in ../share/cbrdf/viewer) uses the installed
  // folders only: the build tree it was made in may be gone or hold another version.
  const fs::path installed_viewer = beside_command(CBRDF_VIEWER_INSTALLED);
  const bool installed = has_file(installed_viewer, "index.html");
  const std::string viewer_defaults = installed ? installed_viewer.string() : CBRDF_VIEWER_DIR;
  const std::string wasm_defaults =
      installed ? beside_command(CBRDF_WASM_INSTALLED).string() : CBRDF_WASM_DIRS;
  std::string tried_viewer, tried_wasm;
  static constexpr const char* kPage[] = {"index.html"};
  const auto viewer =
      locate(o.viewer_dir, "CBRDF_VIEWER_DIR", viewer_defaults, kPage, &tried_viewer);
  if (!viewer) {
    return fail(cbrdf::error(ErrorCode::kNotFound,
                             "view: no folder with the viewer's page (index.html): tried " +
                                 tried_viewer +
                                 "; pass --viewer DIR (the repository's viewer/ folder)"));
  }
  const auto wasm =
      locate(o.wasm_dir, "CBRDF_WASM_DIR", wasm_defaults, kViewWasmFiles, &tried_wasm);
  if (!wasm) {
    const std::string need =
        "no folder with cbrdf.wasm, cbrdf.mjs and glsl.mjs: tried " + tried_wasm;
    if (installed && o.wasm_dir.empty() && !std::getenv("CBRDF_WASM_DIR")) {
      return fail(cbrdf::error(
          ErrorCode::kNotFound,
          "view: " + need +
              ": this installation was made without a WebAssembly build. Build one "
              "(tools/wasm/README.md: emcmake cmake -S . -B build-wasm -DCBRDF_DECODER_ONLY=ON, "
              "then cmake --build build-wasm) and run cmake --install again, or pass --wasm DIR"));
    }
    return fail(cbrdf::error(
        ErrorCode::kNotFound,
        "view: " + need +
            "; build them (tools/wasm/README.md; a wasm build older than the npm package lacks "
            "glsl.mjs) and pass --wasm DIR (e.g. build-wasm/wasm)"));
  }

  auto allowlist = ViewAllowlist::build(*viewer, *wasm, o.files);
  if (!allowlist) return fail(allowlist.status());
  auto listening = ViewServer::listen(std::move(allowlist).value(), o.port);
  if (!listening) return fail(listening.status());
  std::unique_ptr<ViewServer> server = std::move(listening).value();
  const std::string url = "http://127.0.0.1:" + std::to_string(server->port()) + "/";

  g_server = server.get();
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  ::sigaction(SIGINT, &sa, nullptr);
  ::sigaction(SIGTERM, &sa, nullptr);
  struct sigaction ign {};
  ign.sa_handler = SIG_IGN;
  ign.sa_flags = SA_NOCLDWAIT;  // the browser opener is not waited for
  ::sigaction(SIGCHLD, &ign, nullptr);

  std::printf("%s\n", url.c_str());
  if (!ctx.quiet) {
    std::fprintf(stderr, "cbrdf view: serving %zu file%s at %s (Ctrl-C stops)\n", o.files.size(),
                 o.files.size() == 1 ? "" : "s", url.c_str());
  }
  std::fflush(stdout);
  if (!o.no_open) open_browser(url);

  const Status served = server->run();
  g_server = nullptr;
  if (!served.ok()) return fail(served);
  if (!ctx.quiet) std::fprintf(stderr, "cbrdf view: stopped\n");
  return kExitOk;
}

}  // namespace

void add_view_command(CLI::App& app, const Context& ctx, Action* action) {
  auto opts = std::make_shared<ViewOptions>();
  CLI::App* cmd = app.add_subcommand(
      "view", "Serve the browser viewer for .cbrdf and MERL .binary files on 127.0.0.1");
  cmd->add_option("files", opts->files, "Files to show (.cbrdf, .binary); more can be dropped");
  cmd->add_option("--port", opts->port, "Port on 127.0.0.1 (0: any free port)")
      ->check(CLI::Range(0, 65535));
  cmd->add_flag("--no-open", opts->no_open, "Do not open a browser (print the address only)");
  cmd->add_option("--viewer", opts->viewer_dir, "The viewer's folder (default: the build's)");
  cmd->add_option("--wasm", opts->wasm_dir,
                  "Folder of cbrdf.wasm and cbrdf.mjs (default: the build's wasm builds)");
  cmd->callback([&ctx, opts, action] { *action = [&ctx, opts] { return run_view(ctx, *opts); }; });
}

}  // namespace cbrdf::cli
