// SPDX-License-Identifier: MIT
// `cbrdf view`'s server against a hostile client: the real command on port 0 with --no-open, a
// temporary viewer folder (with a symlink out of it) and wasm folder, probed over raw sockets:
// paths out of the allowlist, malformed requests, huge headers, a wrong Host, other methods,
// more idle connections than the server has file descriptors, and slow readers of a large file.
// CBRDF_VIEW_TEST_CLI names another build of the command to probe (e.g. an older one).
#include <arpa/inet.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "test_support.h"

namespace cbrdf {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using testing::contains;
using testing::TempDir;

void write_bytes(const fs::path& p, const std::string& bytes) {
  std::ofstream out(p, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  ASSERT_TRUE(out.good()) << p;
}

std::string cli_path() {
  const char* other = std::getenv("CBRDF_VIEW_TEST_CLI");
  return other && *other ? other : CBRDF_CLI_PATH;
}

// A running `cbrdf view`, killed by its destructor if still running.
class ViewProcess {
 public:
  // nofile > 0: the server's RLIMIT_NOFILE, soft and hard (as `ulimit -n`).
  ViewProcess(const std::vector<std::string>& args, const fs::path& err_file, rlim_t nofile = 0)
      : err_file_(err_file) {
    int out[2];
    if (::pipe2(out, O_CLOEXEC) != 0) return;
    pid_ = ::fork();
    if (pid_ == 0) {
      ::dup2(out[1], 1);
      const int err = ::open(err_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (err >= 0) ::dup2(err, 2);
      if (nofile > 0) {
        const rlimit lim{nofile, nofile};
        if (::setrlimit(RLIMIT_NOFILE, &lim) != 0) ::_exit(126);
      }
      std::vector<char*> argv;
      const std::string cli = cli_path();
      argv.push_back(const_cast<char*>(cli.c_str()));
      for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      ::execv(argv[0], argv.data());
      ::_exit(127);
    }
    ::close(out[1]);
    // The first line on stdout is the address, http://127.0.0.1:PORT/.
    std::string line;
    const auto deadline = Clock::now() + std::chrono::seconds(30);
    while (line.find('\n') == std::string::npos && Clock::now() < deadline) {
      pollfd p{out[0], POLLIN, 0};
      if (::poll(&p, 1, 100) <= 0) continue;
      char buf[256];
      const ssize_t n = ::read(out[0], buf, sizeof buf);
      if (n <= 0) break;
      line.append(buf, std::size_t(n));
    }
    ::close(out[0]);
    const std::string prefix = "http://127.0.0.1:";
    if (line.rfind(prefix, 0) == 0) port_ = std::atoi(line.c_str() + prefix.size());
  }
  ~ViewProcess() {
    if (running()) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
  }
  ViewProcess(const ViewProcess&) = delete;
  ViewProcess& operator=(const ViewProcess&) = delete;

  int port() const { return port_; }
  pid_t pid() const { return pid_; }
  bool running() {
    if (pid_ <= 0 || exited_) return false;
    int status = 0;
    if (::waitpid(pid_, &status, WNOHANG) == pid_) {
      exited_ = true;
      status_ = status;
      return false;
    }
    return true;
  }
  // Sends the signal and waits; the exit status as the shell shows it (128 + N for a signal).
  int stop(int sig) {
    if (running()) {
      ::kill(pid_, sig);
      ::waitpid(pid_, &status_, 0);
      exited_ = true;
    }
    return WIFEXITED(status_) ? WEXITSTATUS(status_) : 128 + WTERMSIG(status_);
  }
  std::string err() const { return testing::read_text(err_file_); }
  // VmRSS in bytes (0 when unknown).
  std::size_t rss() const {
    std::ifstream in("/proc/" + std::to_string(pid_) + "/status");
    for (std::string line; std::getline(in, line);) {
      if (line.rfind("VmRSS:", 0) == 0) return std::stoull(line.substr(6)) * 1024;
    }
    return 0;
  }

 private:
  fs::path err_file_;
  pid_t pid_ = -1;
  int port_ = 0;
  bool exited_ = false;
  int status_ = 0;
};

int connect_to(int port, bool nonblocking = false) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return -1;
  // Generous: a reply that does not come within this is a server that stopped serving.
  const timeval tv{10, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  ::setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  if (nonblocking) ::fcntl(fd, F_SETFL, O_NONBLOCK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 && errno != EINPROGRESS) {
    ::close(fd);
    return -1;
  }
  return fd;
}

bool send_all(int fd, const std::string& s) {
  for (std::size_t at = 0; at < s.size();) {
    const ssize_t n = ::send(fd, s.data() + at, s.size() - at, MSG_NOSIGNAL);
    if (n <= 0) return false;
    at += std::size_t(n);
  }
  return true;
}

struct Reply {
  int status = 0;  // 0: no response (refused, reset or closed)
  std::string head, body;
};

// Sends the raw request and reads the response until the server closes the connection.
Reply transact(int port, const std::string& request) {
  Reply r;
  const int fd = connect_to(port);
  if (fd < 0) return r;
  std::string got;
  if (send_all(fd, request)) {
    char buf[65536];
    for (ssize_t n; (n = ::recv(fd, buf, sizeof buf, 0)) > 0;) got.append(buf, std::size_t(n));
  }
  ::close(fd);
  const std::size_t end = got.find("\r\n\r\n");
  if (got.rfind("HTTP/1.1 ", 0) != 0 || end == std::string::npos) return r;
  r.status = std::atoi(got.c_str() + 9);
  r.head = got.substr(0, end + 2);
  r.body = got.substr(end + 4);
  return r;
}

std::string request(const std::string& method, const std::string& target, int port,
                    const std::string& extra = "") {
  return method + " " + target + " HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port) +
         "\r\nConnection: close\r\n" + extra + "\r\n";
}

Reply get(int port, const std::string& target) {
  return transact(port, request("GET", target, port));
}

bool valid_utf8(const std::string& s) {
  for (std::size_t i = 0; i < s.size();) {
    const auto c = static_cast<unsigned char>(s[i]);
    const int n = c < 0x80 ? 0 : (c >> 5) == 6 ? 1 : (c >> 4) == 14 ? 2 : (c >> 3) == 30 ? 3 : -1;
    if (n < 0 || i + std::size_t(n) >= s.size()) return false;
    for (int k = 1; k <= n; ++k) {
      if ((static_cast<unsigned char>(s[i + std::size_t(k)]) >> 6) != 2) return false;
    }
    i += std::size_t(n) + 1;
  }
  return true;
}

class ViewServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    viewer_ = tmp_ / "viewer";
    wasm_ = tmp_ / "wasm";
    fs::create_directories(viewer_);
    fs::create_directories(wasm_);
    fs::create_directories(tmp_ / "outside");
    write_bytes(viewer_ / "index.html", "<!doctype html><title>viewer</title>\n");
    write_bytes(viewer_ / "app.mjs", "export const x = 1;\n");
    write_bytes(tmp_ / "outside" / "secret.mjs", "export const secret = 'outside';\n");
    fs::create_symlink(tmp_ / "outside" / "secret.mjs", viewer_ / "leak.mjs");
    fs::create_directory_symlink(tmp_ / "outside", viewer_ / "out");
    write_bytes(wasm_ / "cbrdf.wasm", std::string("\0asm\1\0\0\0", 8));
    write_bytes(wasm_ / "cbrdf.mjs", "export function load() {}\n");
    write_bytes(wasm_ / "glsl.mjs", "export const cbrdfGlsl = '';\n");
    write_bytes(wasm_ / "three.mjs", "export class CbrdfMaterial {}\n");
    small_ = tmp_ / "small.binary";
    std::string bytes(100000, '\0');
    std::mt19937 rng(7);
    for (char& c : bytes) c = static_cast<char>(rng());
    write_bytes(small_, bytes);
    small_bytes_ = bytes;
    odd_name_ = tmp_ / "bad\xff\x01name.binary";
    write_bytes(odd_name_, "x");
  }

  std::vector<std::string> args(const std::vector<fs::path>& files) const {
    std::vector<std::string> a = {"view",     "--no-open",      "--port", "0",
                                  "--viewer", viewer_.string(), "--wasm", wasm_.string()};
    for (const fs::path& f : files) a.push_back(f.string());
    return a;
  }

  TempDir tmp_;
  fs::path viewer_, wasm_, small_, odd_name_;
  std::string small_bytes_;
};

TEST_F(ViewServerTest, ServesTheViewerTheWasmAndTheGivenFilesAndNothingElse) {
  ViewProcess view(args({small_, odd_name_}), tmp_ / "err.txt");
  ASSERT_GT(view.port(), 0) << view.err();
  const int port = view.port();

  const Reply index = get(port, "/index.html");
  EXPECT_EQ(index.status, 200) << index.head;
  EXPECT_EQ(index.body, "<!doctype html><title>viewer</title>\n");
  EXPECT_TRUE(contains(index.head, "Cache-Control: no-store")) << index.head;
  EXPECT_TRUE(contains(index.head, "X-Content-Type-Options: nosniff")) << index.head;
  EXPECT_TRUE(contains(index.head, "text/html")) << index.head;
  EXPECT_EQ(get(port, "/").body, index.body);
  EXPECT_EQ(get(port, "/app.mjs").status, 200);
  EXPECT_TRUE(contains(get(port, "/app.mjs").head, "text/javascript"));
  const Reply wasm = get(port, "/cbrdf.wasm");
  EXPECT_EQ(wasm.status, 200);
  EXPECT_EQ(wasm.body, std::string("\0asm\1\0\0\0", 8));
  EXPECT_TRUE(contains(wasm.head, "application/wasm")) << wasm.head;
  EXPECT_EQ(get(port, "/cbrdf.mjs").status, 200);
  const Reply glsl = get(port, "/glsl.mjs");
  EXPECT_EQ(glsl.status, 200);
  EXPECT_EQ(glsl.body, "export const cbrdfGlsl = '';\n");
  const Reply small = get(port, "/files/0");
  EXPECT_EQ(small.status, 200);
  EXPECT_TRUE(small.body == small_bytes_) << small.body.size() << " bytes";
  const Reply head = transact(port, request("HEAD", "/files/0", port));
  EXPECT_EQ(head.status, 200);
  EXPECT_TRUE(contains(head.head, "Content-Length: 100000")) << head.head;
  EXPECT_TRUE(head.body.empty());
  EXPECT_EQ(get(port, "/index.html?v=2").status, 200);  // a query is ignored

  // files.json: valid UTF-8 and JSON for a name that is neither (0xff, 0x01).
  const Reply list = get(port, "/files.json");
  EXPECT_EQ(list.status, 200);
  EXPECT_TRUE(valid_utf8(list.body)) << list.body;
  EXPECT_TRUE(contains(list.body, "\"name\":\"small.binary\",\"url\":\"/files/0\"")) << list.body;
  EXPECT_TRUE(contains(list.body, "\"name\":\"bad\xEF\xBF\xBD\\u0001name.binary\"")) << list.body;

  // Nothing outside the allowlist: absolute paths, "..", encoded dots and slashes, a symlink
  // out of the folder, a file of the wasm folder other than the three, an index out of range.
  for (const char* target : {"//etc/passwd",
                             "//proc/self/cmdline",
                             "/..%2f..%2fetc/passwd",
                             "/%2e%2e/%2e%2e/etc/passwd",
                             "/%2E%2E%2F%2E%2E%2Fetc%2Fpasswd",
                             "/../../../../etc/passwd",
                             "/..",
                             "/./index.html",
                             "/leak.mjs",
                             "/out/secret.mjs",
                             "/%6ceak.mjs",
                             "/..\\..\\etc\\passwd",
                             "/files/2",
                             "/files/00",
                             "/files/-1",
                             "/files/",
                             "/small.binary",
                             "/index.html%00.mjs",
                             "/app.mjs/",
                             "/etc/passwd",
                             "/three.mjs"}) {
    const Reply r = get(port, target);
    EXPECT_GE(r.status, 400) << target;
    EXPECT_LT(r.status, 500) << target;
    EXPECT_FALSE(contains(r.body, "root:")) << target;
    EXPECT_FALSE(contains(r.body, "outside")) << target;
  }
  EXPECT_EQ(transact(port, "GET /app.mjs HTTP/1.1\r\nHost: LocalHost:" + std::to_string(port) +
                               "\r\nConnection: close\r\n\r\n")
                .status,
            200);
  // A file of the folder replaced by a symlink out of it after start-up is not followed.
  fs::remove(viewer_ / "app.mjs");
  fs::create_symlink(tmp_ / "outside" / "secret.mjs", viewer_ / "app.mjs");
  const Reply swapped = get(port, "/app.mjs");
  EXPECT_EQ(swapped.status, 404);
  EXPECT_FALSE(contains(swapped.body, "outside"));
  EXPECT_EQ(get(port, "//etc/passwd").status, 400);
  EXPECT_EQ(get(port, "/..%2f..%2fetc/passwd").status, 400);
  EXPECT_EQ(get(port, "/leak.mjs").status, 404);
  EXPECT_TRUE(view.running());
}

// A wasm folder staged before the npm package had glsl.mjs: the page could not import its shader,
// so the command refuses at start-up and names the file.
TEST_F(ViewServerTest, RefusesAWasmFolderWithoutGlslMjs) {
  fs::remove(wasm_ / "glsl.mjs");
  ViewProcess view(args({small_}), tmp_ / "err.txt");
  EXPECT_EQ(view.port(), 0);
  EXPECT_NE(view.stop(SIGKILL), 0);
  // The folder tried and what it lacks (a wasm build from before the npm package).
  EXPECT_TRUE(contains(view.err(), wasm_.string() + " (no glsl.mjs)")) << view.err();
  EXPECT_TRUE(contains(view.err(), "tools/wasm/README.md")) << view.err();
}

TEST_F(ViewServerTest, MalformedRequestsGet4xxAndTheServerGoesOn) {
  ViewProcess view(args({small_}), tmp_ / "err.txt");
  ASSERT_GT(view.port(), 0) << view.err();
  const int port = view.port();
  const std::string host = "Host: 127.0.0.1:" + std::to_string(port) + "\r\n";
  struct Probe {
    const char* what;
    std::string bytes;
    int status;
  };
  const std::vector<Probe> probes = {
      {"empty target", "GET  HTTP/1.1\r\n" + host + "\r\n", 400},
      {"query only", "GET ?x HTTP/1.1\r\n" + host + "\r\n", 400},
      {"relative target", "GET index.html HTTP/1.1\r\n" + host + "\r\n", 400},
      {"absolute URL", "GET http://example.com/index.html HTTP/1.1\r\n" + host + "\r\n", 400},
      {"no version", "GET /index.html\r\n" + host + "\r\n", 400},
      {"unknown method", "BREW /index.html HTTP/1.1\r\n" + host + "\r\n", 400},
      {"garbage", std::string("\x16\x03\x01\x02\x00\x01\x00\x01\xfc\x03\x03\r\n\r\n", 15), 400},
      {"huge header",
       request("GET", "/index.html", port, "X-Big: " + std::string(100000, 'a') + "\r\n"), 400},
      {"many headers",
       [&] {
         std::string h;
         for (int i = 0; i < 2000; ++i)
           h += "X-" + std::to_string(i) + ": " + std::string(50, 'b') + "\r\n";
         return request("GET", "/index.html", port, h);
       }(),
       400},
      {"wrong Host",
       "GET /index.html HTTP/1.1\r\nHost: evil.example:" + std::to_string(port) + "\r\n\r\n", 403},
      {"Host without port", "GET /index.html HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n", 403},
      {"no Host", "GET /index.html HTTP/1.1\r\n\r\n", 403},
      {"two Hosts", "GET /index.html HTTP/1.1\r\n" + host + "Host: evil.example\r\n\r\n", 403},
      {"POST", request("POST", "/index.html", port, "Content-Length: 5\r\n") + "hello", 405},
      {"PUT", request("PUT", "/index.html", port, "Content-Length: 0\r\n"), 405},
      {"DELETE", request("DELETE", "/index.html", port), 405},
      {"OPTIONS", request("OPTIONS", "/index.html", port), 405},
  };
  for (const Probe& p : probes) {
    const Reply r = transact(port, p.bytes);
    EXPECT_EQ(r.status, p.status) << p.what << ": " << r.head;
    ASSERT_TRUE(view.running()) << p.what << " ended the server: " << view.err();
    EXPECT_EQ(get(port, "/index.html").status, 200) << "after " << p.what;
  }
  // Keep-alive: two requests on one connection, then one with a body that is not read.
  const int fd = connect_to(port);
  ASSERT_GE(fd, 0);
  ASSERT_TRUE(send_all(fd, "GET /app.mjs HTTP/1.1\r\n" + host + "\r\nGET /index.html HTTP/1.1\r\n" +
                               host + "Connection: close\r\n\r\n"));
  std::string got;
  char buf[4096];
  for (ssize_t n; (n = ::recv(fd, buf, sizeof buf, 0)) > 0;) got.append(buf, std::size_t(n));
  ::close(fd);
  EXPECT_TRUE(contains(got, "export const x = 1;")) << got;
  EXPECT_TRUE(contains(got, "<title>viewer</title>")) << got;

  EXPECT_EQ(view.stop(SIGTERM), 0);
  EXPECT_TRUE(contains(view.err(), "cbrdf view: stopped")) << view.err();
}

// More idle connections than the server has file descriptors (its RLIMIT_NOFILE set as
// `ulimit -n` does): a client that then asks for a page is served, and the server goes on. At
// 1,024 as the issue had it, and at 256, where a server that ends on EMFILE gets there sooner
// (the old one accepted about 16 connections a second on a loaded machine, and let each go after
// 30 s).
TEST_F(ViewServerTest, KeepsServingThroughMoreIdleConnectionsThanDescriptors) {
  rlimit own{};
  ASSERT_EQ(::getrlimit(RLIMIT_NOFILE, &own), 0);
  if (own.rlim_cur < 1300 && own.rlim_max > own.rlim_cur) {
    own.rlim_cur = std::min<rlim_t>(own.rlim_max, 1300);
    ::setrlimit(RLIMIT_NOFILE, &own);
  }
  for (const rlim_t wanted : {rlim_t(1024), rlim_t(256)}) {
    // This process needs a descriptor per connection too: at a lower limit both scale down.
    const rlim_t server_limit = std::min<rlim_t>(wanted, (own.rlim_cur - 64) * 1024 / 1100);
    const std::size_t idle_count = std::size_t(server_limit) * 1100 / 1024;
    ViewProcess view(args({small_}), tmp_ / "err.txt", server_limit);
    ASSERT_GT(view.port(), 0) << view.err();
    const auto t_open = Clock::now();
    std::vector<int> idle;
    for (std::size_t i = 0; i < idle_count; ++i) {
      const int fd = connect_to(view.port());
      if (fd < 0) break;
      idle.push_back(fd);
    }
    const double open_seconds = std::chrono::duration<double>(Clock::now() - t_open).count();
    EXPECT_EQ(idle.size(), idle_count) << "connections refused: " << view.err();
    const auto t0 = Clock::now();
    const Reply r = get(view.port(), "/index.html");
    const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    EXPECT_EQ(r.status, 200) << view.err();
    std::printf(
        "%zu idle connections (opened in %.2f s) at RLIMIT_NOFILE %llu: /index.html "
        "answered %d in %.3f s\n",
        idle.size(), open_seconds, static_cast<unsigned long long>(server_limit), r.status,
        seconds);
    EXPECT_TRUE(view.running()) << view.err();
    for (const int fd : idle) ::close(fd);
    EXPECT_EQ(get(view.port(), "/app.mjs").status, 200);
    EXPECT_EQ(view.stop(SIGTERM), 0) << view.err();
  }
}

// The same when the descriptors run out below the server's own cap on connections (its limit
// lowered while it runs, as another part of a process could use them up): accept() fails with
// EMFILE, and the server closes its oldest idle connection to make room instead of stopping.
TEST_F(ViewServerTest, SurvivesAcceptRunningOutOfDescriptors) {
  ViewProcess view(args({small_}), tmp_ / "err.txt");
  ASSERT_GT(view.port(), 0) << view.err();
  // A server that has served a request already, as one does when its descriptors run out (and
  // UBSan's type checks, which need a descriptor the first time a type is checked, have run).
  ASSERT_EQ(get(view.port(), "/app.mjs").status, 200);
  const rlimit lowered{200, 200};
  ASSERT_EQ(::prlimit(view.pid(), RLIMIT_NOFILE, &lowered, nullptr), 0) << std::strerror(errno);
  std::vector<int> idle;
  for (int i = 0; i < 300; ++i) {
    const int fd = connect_to(view.port());
    if (fd < 0) break;
    idle.push_back(fd);
  }
  EXPECT_EQ(idle.size(), 300u) << "connections refused: " << view.err();
  const Reply r = get(view.port(), "/index.html");
  EXPECT_EQ(r.status, 200) << view.err();
  EXPECT_TRUE(view.running()) << view.err();
  EXPECT_TRUE(contains(view.err(), "out of file descriptors")) << view.err();
  for (const int fd : idle) ::close(fd);
  EXPECT_EQ(view.stop(SIGTERM), 0) << view.err();
}

// 20 clients ask for a 35 MB file and never read: the server streams it, so its memory stays
// bounded, and a normal client is served meanwhile.
TEST_F(ViewServerTest, SlowReadersOfALargeFileKeepTheServerSmallAndResponsive) {
  const fs::path large = tmp_ / "large.binary";
  {
    std::string block(1 << 20, '\0');
    for (std::size_t i = 0; i < block.size(); ++i)
      block[i] = static_cast<char>(i * 2654435761u >> 24);
    std::ofstream out(large, std::ios::binary);
    for (int i = 0; i < 35; ++i) out.write(block.data(), std::streamsize(block.size()));
    ASSERT_TRUE(out.good());
  }
  ViewProcess view(args({large}), tmp_ / "err.txt");
  ASSERT_GT(view.port(), 0) << view.err();
  const int port = view.port();
  std::vector<int> readers;
  for (int i = 0; i < 20; ++i) {
    const int fd = connect_to(port);
    ASSERT_GE(fd, 0);
    ASSERT_TRUE(send_all(fd, request("GET", "/files/0", port)));
    readers.push_back(fd);
  }
  // Until every reader has its response's first bytes (the server has taken up every request),
  // at most 15 s, sampling the server's resident memory.
  std::size_t peak = 0;
  const auto deadline = Clock::now() + std::chrono::seconds(15);
  for (;;) {
    peak = std::max(peak, view.rss());
    std::vector<pollfd> p;
    for (const int fd : readers) p.push_back({fd, POLLIN, 0});
    const int ready = ::poll(p.data(), p.size(), 50);
    if (ready == int(readers.size()) || Clock::now() > deadline) break;
  }
  peak = std::max(peak, view.rss());
  const auto t0 = Clock::now();
  const Reply r = get(port, "/index.html");
  const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  peak = std::max(peak, view.rss());
  EXPECT_EQ(r.status, 200) << view.err();
  EXPECT_GT(peak, 0u);
  EXPECT_LT(peak, std::size_t(200) << 20);
  std::printf(
      "20 non-reading clients of a 35 MB file: server VmRSS peak %.1f MB; /index.html "
      "answered %d in %.3f s\n",
      double(peak) / (1 << 20), r.status, seconds);
  // Every reader's first bytes are its response's head: each request was taken up.
  for (const int fd : readers) {
    char head[64];
    const ssize_t n = ::recv(fd, head, sizeof head, MSG_DONTWAIT);
    EXPECT_TRUE(n > 0 && std::string(head, std::size_t(n)).rfind("HTTP/1.1 200", 0) == 0);
  }
  for (const int fd : readers) ::close(fd);
  EXPECT_TRUE(view.running()) << view.err();
  EXPECT_EQ(view.stop(SIGINT), 0) << view.err();
}

}  // namespace
}  // namespace cbrdf
