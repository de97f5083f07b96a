// SPDX-License-Identifier: MIT
// cbrdf view FILE...: serves the browser viewer (viewer/), cbrdf.wasm and the given files on
// 127.0.0.1 and prints the address; the page evaluates models on the GPU (viewer/README.md).
// A small HTTP/1.1 server over POSIX sockets: one request per connection (a thread each), GET and
// HEAD only, loopback only (and only for Host headers naming the loopback, against DNS
// rebinding). Ctrl-C (SIGINT) or SIGTERM stops it.
#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <pthread.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <optional>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include "cli.h"

#ifndef CBRDF_VIEWER_DIR
#define CBRDF_VIEWER_DIR ""
#endif
#ifndef CBRDF_WASM_DIRS
#define CBRDF_WASM_DIRS ""
#endif

namespace cbrdf::cli {
namespace {

namespace fs = std::filesystem;

volatile sig_atomic_t g_stop = 0;
void on_signal(int) {
  g_stop = 1;
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

// The first of: the option, the environment variable, the build's defaults ('|'-separated).
std::optional<fs::path> locate(const std::string& option, const char* env, const char* defaults,
                               const char* marker, std::string* tried) {
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
    if (has_file(c, marker)) return fs::path(c);
    *tried += (tried->empty() ? "" : ", ") + c;
  }
  return std::nullopt;
}

std::string mime_of(const fs::path& p) {
  const std::string e = p.extension().string();
  if (e == ".html") return "text/html; charset=utf-8";
  if (e == ".mjs" || e == ".js") return "text/javascript; charset=utf-8";
  if (e == ".css") return "text/css; charset=utf-8";
  if (e == ".json") return "application/json";
  if (e == ".wasm") return "application/wasm";
  if (e == ".png") return "image/png";
  if (e == ".svg") return "image/svg+xml";
  return "application/octet-stream";
}

std::optional<std::string> slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) return std::nullopt;
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

bool send_all(int fd, const char* data, std::size_t n) {
  while (n > 0) {
    const ssize_t w = ::send(fd, data, n, MSG_NOSIGNAL);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return false;
    data += w;
    n -= std::size_t(w);
  }
  return true;
}

void respond(int fd, int code, const char* reason, const std::string& type, const std::string& body,
             bool head) {
  std::string h = "HTTP/1.1 " + std::to_string(code) + " " + reason + "\r\nContent-Type: " + type +
                  "\r\nContent-Length: " + std::to_string(body.size()) +
                  "\r\nCache-Control: no-store\r\nX-Content-Type-Options: nosniff"
                  "\r\nConnection: close\r\n\r\n";
  if (!head) h += body;
  send_all(fd, h.data(), h.size());
}

std::string json_string(const std::string& s) {
  std::string o = "\"";
  for (const char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    if (static_cast<unsigned char>(c) < 0x20) continue;
    o += c;
  }
  return o + "\"";
}

// A request path is served from a folder only when it is made of safe characters and has no
// ".." component.
bool safe_path(const std::string& p) {
  if (p.empty() || p.find("..") != std::string::npos) return false;
  for (const char c : p) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '/' || c == '.' || c == '_' ||
          c == '-'))
      return false;
  }
  return true;
}

class Server {
 public:
  Server(const ViewOptions& o, fs::path viewer, fs::path wasm, int port)
      : o_(o), viewer_(std::move(viewer)), wasm_(std::move(wasm)), port_(port) {}

  void handle(int fd) const {
    std::string req;
    char buf[4096];
    while (req.find("\r\n\r\n") == std::string::npos && req.size() < 65536) {
      const ssize_t r = ::recv(fd, buf, sizeof buf, 0);
      if (r < 0 && errno == EINTR) {
        if (g_stop) return;
        continue;
      }
      if (r <= 0) return;
      req.append(buf, std::size_t(r));
    }
    const std::size_t sp1 = req.find(' '), sp2 = req.find(' ', sp1 + 1);
    if (sp1 == std::string::npos || sp2 == std::string::npos) {
      respond(fd, 400, "Bad Request", "text/plain", "bad request\n", false);
      return;
    }
    const std::string method = req.substr(0, sp1);
    std::string path = req.substr(sp1 + 1, sp2 - sp1 - 1);
    const bool head = method == "HEAD";
    if (method != "GET" && !head) {
      respond(fd, 405, "Method Not Allowed", "text/plain", "GET and HEAD only\n", false);
      return;
    }
    if (!host_ok(req)) {
      respond(fd, 403, "Forbidden", "text/plain", "the Host header must name 127.0.0.1\n", head);
      return;
    }
    if (const std::size_t q = path.find('?'); q != std::string::npos) path.resize(q);
    if (path == "/") path = "/index.html";
    if (path == "/files.json") {
      std::string j = "[";
      for (std::size_t i = 0; i < o_.files.size(); ++i) {
        const std::string name = fs::path(o_.files[i]).filename().string();
        j += (i ? "," : "") + std::string("{\"name\":") + json_string(name) + ",\"url\":\"/files/" +
             std::to_string(i) + "\"}";
      }
      respond(fd, 200, "OK", "application/json", j + "]", head);
      return;
    }
    if (path.rfind("/files/", 0) == 0) {
      const std::string n = path.substr(7);
      char* end = nullptr;
      const unsigned long i = std::strtoul(n.c_str(), &end, 10);
      if (!n.empty() && *end == '\0' && i < o_.files.size()) {
        if (auto body = slurp(o_.files[i])) {
          respond(fd, 200, "OK", "application/octet-stream", *body, head);
        } else {
          respond(fd, 500, "Internal Server Error", "text/plain",
                  "cannot read " + o_.files[i] + "\n", head);
        }
        return;
      }
    }
    const std::string rel = path.substr(1);
    if (safe_path(rel)) {
      const fs::path dir = rel == "cbrdf.mjs" || rel == "cbrdf.wasm" ? wasm_ : viewer_;
      std::error_code ec;
      if (fs::is_regular_file(dir / rel, ec)) {
        if (auto body = slurp(dir / rel)) {
          respond(fd, 200, "OK", mime_of(rel), *body, head);
          return;
        }
      }
    }
    respond(fd, 404, "Not Found", "text/plain", "not found: " + path + "\n", head);
  }

 private:
  bool host_ok(const std::string& req) const {
    const std::string p = std::to_string(port_);
    for (const std::string& h : {"127.0.0.1:" + p, "localhost:" + p}) {
      for (const char* key : {"\r\nHost: ", "\r\nhost: ", "\r\nHOST: "}) {
        if (req.find(key + h + "\r\n") != std::string::npos) return true;
      }
    }
    return false;
  }

  ViewOptions o_;
  fs::path viewer_, wasm_;
  int port_;
};

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
  std::string tried_viewer, tried_wasm;
  const auto viewer =
      locate(o.viewer_dir, "CBRDF_VIEWER_DIR", CBRDF_VIEWER_DIR, "index.html", &tried_viewer);
  if (!viewer) {
    return fail(cbrdf::error(ErrorCode::kNotFound,
                             "view: the viewer's page (index.html) is not in " + tried_viewer +
                                 "; pass --viewer DIR (the repository's viewer/ folder)"));
  }
  const auto wasm =
      locate(o.wasm_dir, "CBRDF_WASM_DIR", CBRDF_WASM_DIRS, "cbrdf.wasm", &tried_wasm);
  if (!wasm || !has_file(*wasm, "cbrdf.mjs")) {
    return fail(cbrdf::error(
        ErrorCode::kNotFound,
        "view: cbrdf.wasm and cbrdf.mjs are not in " +
            (tried_wasm.empty() ? o.wasm_dir : tried_wasm) +
            "; build them (tools/wasm/README.md) and pass --wasm DIR (e.g. build-wasm/wasm)"));
  }

  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0)
    return fail(cbrdf::error(ErrorCode::kIo, std::string("view: socket: ") + std::strerror(errno)));
  const int one = 1;
  ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr.sin_port = htons(static_cast<std::uint16_t>(o.port));
  if (::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 || ::listen(fd, 16) != 0) {
    const std::string why = std::strerror(errno);
    ::close(fd);
    return fail(
        cbrdf::error(ErrorCode::kIo, "view: cannot listen on 127.0.0.1:" + std::to_string(o.port) +
                                         ": " + why + " (choose another with --port, 0 for any)"));
  }
  socklen_t len = sizeof addr;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
  const int port = ntohs(addr.sin_port);
  const std::string url = "http://127.0.0.1:" + std::to_string(port) + "/";

  struct sigaction sa {};
  sa.sa_handler = on_signal;  // no SA_RESTART: accept() returns EINTR
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

  // One thread per connection, so that a connection a browser opens ahead of time and leaves
  // idle does not hold up the others; idle ones are dropped after 30 s. The threads block SIGINT
  // and SIGTERM, so that the signal interrupts accept() here.
  auto server = std::make_shared<const Server>(o, *viewer, *wasm, port);
  sigset_t stop_signals, previous;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGINT);
  sigaddset(&stop_signals, SIGTERM);
  while (!g_stop) {
    const int c = ::accept4(fd, nullptr, nullptr, SOCK_CLOEXEC);
    if (c < 0) {
      if (errno == EINTR || errno == ECONNABORTED) continue;
      break;
    }
    const timeval idle{30, 0};
    ::setsockopt(c, SOL_SOCKET, SO_RCVTIMEO, &idle, sizeof idle);
    ::pthread_sigmask(SIG_BLOCK, &stop_signals, &previous);
    try {
      std::thread([server, c] {
        server->handle(c);
        ::close(c);
      }).detach();
    } catch (const std::system_error&) {
      server->handle(c);  // no thread to be had: serve it here
      ::close(c);
    }
    ::pthread_sigmask(SIG_SETMASK, &previous, nullptr);
  }
  ::close(fd);
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
