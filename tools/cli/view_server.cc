// SPDX-License-Identifier: MIT
#include "view_server.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <httplib.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <string>
#include <system_error>
#include <vector>

namespace cbrdf::cli {
namespace {

namespace fs = std::filesystem;
using httplib::Request;
using httplib::Response;

// The piece of a file read and sent at a time: a response holds this much, whatever the file.
constexpr std::size_t kChunkBytes = 64 * 1024;

// Set by the handlers of the request a worker is serving: close the connection after the
// response (a refused request, or one whose body is not read).
thread_local bool t_close_after = false;

// httplib's request processing, over our connections (process_request is protected).
class HttpServer : public httplib::Server {
 public:
  bool serve_one(httplib::Stream& s, bool last, bool& closed) {
    return process_request(s, last, closed, nullptr);
  }
  // httplib writes a content provider's data only while it has a listening socket.
  void set_listening(int fd) { svr_sock_ = fd; }
};

struct OpenFile {
  explicit OpenFile(int f) : fd(f) {}
  ~OpenFile() { ::close(fd); }
  OpenFile(const OpenFile&) = delete;
  OpenFile& operator=(const OpenFile&) = delete;
  int fd;
  std::vector<char> buffer;
};

void respond_text(Response& res, int status, const std::string& message, bool close) {
  res.status = status;
  res.set_content(message, "text/plain; charset=utf-8");
  if (close) t_close_after = true;
}

// Whether the open descriptor is the file found at start-up: its real path now (symlinks and
// renamed folders resolved, no race with the open) is the one recorded then.
bool still_the_file(int fd, const ServedFile& f) {
  std::error_code ec;
  const fs::path now = fs::read_symlink("/proc/self/fd/" + std::to_string(fd), ec);
  if (!ec) return now == f.path;
  return fs::canonical(f.path, ec) == f.path && !ec;  // no /proc: the path's resolution
}

}  // namespace

struct ViewServer::Impl {
  ViewAllowlist allowlist;
  HttpServer http;
  std::string host_ip, host_name;  // the Host headers accepted

  // Host names are case-insensitive ("LOCALHOST:8642" is this server too).
  bool host_ok(std::string host) const {
    for (char& c : host) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return host == host_ip || host == host_name;
  }

  httplib::Server::HandlerResponse handle(const Request& req, Response& res) {
    if (!target_is_acceptable(req.target)) {
      respond_text(res, 400,
                   "bad request target: only the viewer's files, /files.json and /files/N are "
                   "served\n",
                   true);
    } else if (req.method != "GET" && req.method != "HEAD") {
      res.set_header("Allow", "GET, HEAD");
      respond_text(res, 405, "GET and HEAD only\n", true);
    } else if (req.get_header_value_count("Host") != 1 || !host_ok(req.get_header_value("Host"))) {
      respond_text(res, 403, "the Host header must name " + host_ip + " or " + host_name + "\n",
                   true);
    } else {
      // A body is never read: the connection cannot be reused after one.
      if (req.has_header("Transfer-Encoding") ||
          (req.has_header("Content-Length") && req.get_header_value("Content-Length") != "0")) {
        t_close_after = true;
      }
      const std::string path = req.target.substr(0, req.target.find('?'));
      if (path == "/files.json") {
        res.set_content(allowlist.files_json(), "application/json");
      } else if (const ServedFile* f = allowlist.find(path)) {
        serve_file(*f, path, res);
      } else {
        respond_text(res, 404, "not found: " + path + "\n", false);
      }
    }
    return httplib::Server::HandlerResponse::Handled;
  }

  void serve_file(const ServedFile& f, const std::string& path, Response& res) {
    // O_NOFOLLOW: a file of the viewer folder replaced by a symlink since start-up is refused.
    const int flags = O_RDONLY | O_CLOEXEC | (f.confined_to.empty() ? 0 : O_NOFOLLOW);
    const int fd = ::open(f.path.c_str(), flags);
    if (fd < 0) {
      const int e = errno;
      if (e == EMFILE || e == ENFILE) {
        res.set_header("Retry-After", "1");
        respond_text(res, 503, "out of file descriptors: try again\n", true);
      } else {
        // ELOOP: a symlink where a file of the folder was at start-up (O_NOFOLLOW).
        const bool gone = e == ENOENT || e == ENOTDIR || e == ELOOP;
        respond_text(res, gone ? 404 : 500,
                     gone ? "not found: " + path + "\n"
                          : "cannot open " + path + ": " + std::strerror(e) + "\n",
                     false);
      }
      return;
    }
    auto file = std::make_shared<OpenFile>(fd);
    struct stat st {};
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) ||
        (!f.confined_to.empty() && !still_the_file(fd, f))) {
      respond_text(res, 404, "not found: " + path + "\n", false);
      return;
    }
    const auto size = static_cast<std::size_t>(st.st_size);
    if (size == 0) {
      res.set_content("", f.mime);
      return;
    }
    res.set_content_provider(
        size, f.mime, [file](std::size_t offset, std::size_t length, httplib::DataSink& sink) {
          if (file->buffer.empty()) file->buffer.resize(kChunkBytes);
          const std::size_t n = std::min(length, kChunkBytes);
          ssize_t r;
          do {
            r = ::pread(file->fd, file->buffer.data(), n, static_cast<off_t>(offset));
          } while (r < 0 && errno == EINTR);
          // A file that shrank or fails ends the response (and the
          // connection) short.
          if (r <= 0) return false;
          return sink.write(file->buffer.data(), static_cast<std::size_t>(r));
        });
  }
};

ViewServer::~ViewServer() = default;

Expected<std::unique_ptr<ViewServer>> ViewServer::listen(ViewAllowlist allowlist, int port,
                                                         ConnectionLimits limits) {
  limits.threads = std::max<std::size_t>(1, limits.threads);
  limits.max_requests_per_connection = std::max<std::size_t>(1, limits.max_requests_per_connection);
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd < 0) {
    return error(ErrorCode::kIo, std::string("view: socket: ") + std::strerror(errno));
  }
  const int one = 1;
  ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  if (::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 || ::listen(fd, 1024) != 0) {
    const std::string why = std::strerror(errno);
    ::close(fd);
    return error(ErrorCode::kIo, "view: cannot listen on 127.0.0.1:" + std::to_string(port) + ": " +
                                     why + " (choose another with --port, 0 for any)");
  }
  socklen_t len = sizeof addr;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);

  std::unique_ptr<ViewServer> server(new ViewServer());
  server->port_ = ntohs(addr.sin_port);
  server->impl_ = std::make_unique<Impl>();
  Impl& impl = *server->impl_;
  impl.allowlist = std::move(allowlist);
  impl.host_ip = "127.0.0.1:" + std::to_string(server->port_);
  impl.host_name = "localhost:" + std::to_string(server->port_);
  impl.http.set_pre_routing_handler(
      [&impl](const Request& req, Response& res) { return impl.handle(req, res); });
  impl.http.set_post_routing_handler([](const Request&, Response& res) {
    res.set_header("Cache-Control", "no-store");
    res.set_header("X-Content-Type-Options", "nosniff");
    // Other sites' pages may not include these responses (a <script> or <img> of theirs).
    res.set_header("Cross-Origin-Resource-Policy", "same-origin");
    if (res.status >= 400) t_close_after = true;  // httplib's own 400s too
    if (t_close_after && !res.has_header("Connection")) res.set_header("Connection", "close");
  });
  impl.http.set_payload_max_length(0);  // no request body is ever read
  // What the Keep-Alive response header announces; the connection loop enforces both.
  impl.http.set_keep_alive_max_count(limits.max_requests_per_connection);
  impl.http.set_keep_alive_timeout(
      std::chrono::duration_cast<std::chrono::seconds>(limits.idle_timeout).count());
  impl.http.set_listening(fd);

  // Descriptors beyond the connections: a file open per worker, the standard ones, the pipe.
  limits.max_connections = std::min(
      limits.max_connections, connection_capacity(limits.max_connections, limits.threads + 32));
  auto loop = ConnectionLoop::create(fd, limits, [&impl](httplib::Stream& s, bool last) {
    t_close_after = false;
    bool closed = false;
    const bool ok = impl.http.serve_one(s, last, closed);
    return ok && !closed && !t_close_after;
  });
  if (!loop) return loop.status();
  server->loop_ = std::move(loop).value();
  return server;
}

Status ViewServer::run() {
  Status s = loop_->run();
  impl_->http.set_listening(-1);
  return s;
}

void ViewServer::request_stop() noexcept {
  loop_->request_stop();
}

}  // namespace cbrdf::cli
