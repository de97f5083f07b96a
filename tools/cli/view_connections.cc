// SPDX-License-Identifier: MIT
#include "view_connections.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <sys/ioctl.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <deque>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace cbrdf::cli {
namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

// Waits are sliced so that a stop request ends them within this.
constexpr milliseconds kStopSlice{100};
// Descriptors kept free when accept() has run out of them: requests open files.
constexpr std::size_t kSpareDescriptors = 8;

struct Connection {
  explicit Connection(int f, std::atomic<std::size_t>* open_count)
      : fd(f), open(open_count), idle_since(Clock::now()) {}
  ~Connection() {
    ::shutdown(fd, SHUT_RDWR);
    ::close(fd);
    open->fetch_sub(1);
  }
  Connection(const Connection&) = delete;
  Connection& operator=(const Connection&) = delete;

  int fd;
  std::atomic<std::size_t>* open;
  Clock::time_point idle_since;
  std::size_t requests = 0;
  std::string pending;  // bytes read past the last request (a pipelined next request)
};
using ConnectionPtr = std::unique_ptr<Connection>;

// Waits for `events` on fd until the deadline or a stop request. True when the socket is ready
// (or in error: the following read or write then reports it).
bool wait_for(int fd, short events, Clock::time_point deadline, const std::atomic<bool>& stop) {
  for (;;) {
    if (stop.load()) return false;
    const auto left = std::chrono::duration_cast<milliseconds>(deadline - Clock::now());
    if (left.count() <= 0) return false;
    pollfd p{fd, events, 0};
    const int r = ::poll(&p, 1, static_cast<int>(std::min(left, kStopSlice).count()));
    if (r > 0) return true;
    if (r < 0 && errno != EINTR) return false;
  }
}

std::string ip_of(const sockaddr_storage& a, int* port) {
  char buf[INET6_ADDRSTRLEN] = "";
  if (a.ss_family == AF_INET) {
    const auto& in = reinterpret_cast<const sockaddr_in&>(a);
    ::inet_ntop(AF_INET, &in.sin_addr, buf, sizeof buf);
    *port = ntohs(in.sin_port);
  } else if (a.ss_family == AF_INET6) {
    const auto& in6 = reinterpret_cast<const sockaddr_in6&>(a);
    ::inet_ntop(AF_INET6, &in6.sin6_addr, buf, sizeof buf);
    *port = ntohs(in6.sin6_port);
  }
  return buf;
}

// One request's view of a connection, for httplib: reads are buffered (httplib reads the head
// a byte at a time) and capped at the request-head limit; the head must arrive within the I/O
// timeout, and every write must make progress within it.
class ConnectionStream final : public httplib::Stream {
 public:
  ConnectionStream(Connection& c, const ConnectionLimits& limits, const std::atomic<bool>& stop)
      : c_(c), limits_(limits), stop_(stop), read_deadline_(Clock::now() + limits.io_timeout) {}

  bool is_readable() const override {
    return !c_.pending.empty() || wait_for(c_.fd, POLLIN, read_deadline_, stop_);
  }
  bool is_writable() const override {
    return wait_for(c_.fd, POLLOUT, Clock::now() + limits_.io_timeout, stop_);
  }

  ssize_t read(char* ptr, std::size_t size) override {
    if (read_total_ >= limits_.max_request_bytes) {
      failed_ = true;  // a head this long is refused (400) and the connection closed
      return -1;
    }
    size = std::min(size, limits_.max_request_bytes - read_total_);
    if (c_.pending.empty()) {
      char buf[4096];
      ssize_t n;
      for (;;) {
        n = ::recv(c_.fd, buf, sizeof buf, 0);
        if (n >= 0) break;
        if (errno == EINTR) continue;
        if ((errno == EAGAIN || errno == EWOULDBLOCK) &&
            wait_for(c_.fd, POLLIN, read_deadline_, stop_)) {
          continue;
        }
        failed_ = true;
        return -1;
      }
      c_.pending.assign(buf, static_cast<std::size_t>(n));
      if (n == 0) return 0;
    }
    const std::size_t k = std::min(size, c_.pending.size());
    std::memcpy(ptr, c_.pending.data(), k);
    c_.pending.erase(0, k);
    read_total_ += k;
    return static_cast<ssize_t>(k);
  }

  ssize_t write(const char* ptr, std::size_t size) override {
    if (size == 0) return 0;
    for (;;) {
      const ssize_t n = ::send(c_.fd, ptr, size, MSG_NOSIGNAL);
      if (n > 0) return n;
      if (n < 0 && errno == EINTR) continue;
      if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK) &&
          wait_for(c_.fd, POLLOUT, Clock::now() + limits_.io_timeout, stop_)) {
        continue;
      }
      failed_ = true;  // a reader that stalls for the whole timeout is dropped
      return -1;
    }
  }

  void get_remote_ip_and_port(std::string& ip, int& port) const override {
    sockaddr_storage a{};
    socklen_t len = sizeof a;
    if (::getpeername(c_.fd, reinterpret_cast<sockaddr*>(&a), &len) == 0) ip = ip_of(a, &port);
  }
  void get_local_ip_and_port(std::string& ip, int& port) const override {
    sockaddr_storage a{};
    socklen_t len = sizeof a;
    if (::getsockname(c_.fd, reinterpret_cast<sockaddr*>(&a), &len) == 0) ip = ip_of(a, &port);
  }
  socket_t socket() const override { return c_.fd; }

  bool failed() const { return failed_; }

 private:
  Connection& c_;
  const ConnectionLimits& limits_;
  const std::atomic<bool>& stop_;
  const Clock::time_point read_deadline_;
  std::size_t read_total_ = 0;
  bool failed_ = false;
};

// Closing a socket with unread input sends a reset, which can destroy the response before the
// client reads it (a refused request whose headers or body were not all read): the write side is
// shut first and the input drained for a moment.
void drain_before_close(Connection& c, const std::atomic<bool>& stop) {
  int unread = 0;
  if (c.pending.empty() && (::ioctl(c.fd, FIONREAD, &unread) != 0 || unread == 0)) return;
  ::shutdown(c.fd, SHUT_WR);
  const auto deadline = Clock::now() + std::chrono::seconds(1);
  char buf[16384];
  for (std::size_t total = 0;
       total < (std::size_t(1) << 20) && wait_for(c.fd, POLLIN, deadline, stop);) {
    const ssize_t n = ::recv(c.fd, buf, sizeof buf, 0);
    if (n == 0 || (n < 0 && errno != EINTR && errno != EAGAIN && errno != EWOULDBLOCK)) return;
    if (n > 0) total += std::size_t(n);
  }
}

}  // namespace

struct ConnectionLoop::State {
  int listen_fd = -1;
  int wake_read = -1, wake_write = -1;
  ConnectionLimits limits;
  ServeOne serve;
  std::atomic<bool> stop{false};
  std::atomic<std::size_t> open{0};

  std::mutex mutex;
  std::condition_variable ready_cv;
  std::deque<ConnectionPtr> ready;      // a request is arriving: for the workers
  std::vector<ConnectionPtr> returned;  // served and kept open: back to the poller

  void wake() noexcept {
    const char b = 1;
    [[maybe_unused]] const ssize_t n = ::write(wake_write, &b, 1);  // full pipe: already woken
  }

  void worker() {
    for (;;) {
      ConnectionPtr c;
      {
        std::unique_lock<std::mutex> lock(mutex);
        ready_cv.wait(lock, [&] { return stop.load() || !ready.empty(); });
        if (stop.load()) return;
        c = std::move(ready.front());
        ready.pop_front();
      }
      bool keep = true;
      do {  // a request already buffered (pipelined) is served at once: poll() cannot see it
        ConnectionStream s(*c, limits, stop);
        const bool last = ++c->requests >= limits.max_requests_per_connection;
        keep = serve(s, last) && !last && !s.failed() && !stop.load();
      } while (keep && !c->pending.empty());
      if (keep) {
        std::lock_guard<std::mutex> lock(mutex);
        returned.push_back(std::move(c));
      } else {
        drain_before_close(*c, stop);
      }
      c.reset();
      wake();  // a connection came back or was closed: the poller updates its set and cap
    }
  }

  // Starts the workers; they leave SIGINT and SIGTERM to the calling thread. Fails only when
  // not even one could start.
  Status start_workers(std::vector<std::thread>& workers) {
    sigset_t stop_signals, previous;
    sigemptyset(&stop_signals);
    sigaddset(&stop_signals, SIGINT);
    sigaddset(&stop_signals, SIGTERM);
    ::pthread_sigmask(SIG_BLOCK, &stop_signals, &previous);
    try {
      for (std::size_t i = 0; i < limits.threads; ++i) workers.emplace_back([this] { worker(); });
    } catch (const std::system_error& e) {
      if (workers.empty()) {
        ::pthread_sigmask(SIG_SETMASK, &previous, nullptr);
        return error(ErrorCode::kIo, std::string("view: cannot start a thread: ") + e.what());
      }
    }
    ::pthread_sigmask(SIG_SETMASK, &previous, nullptr);
    return Status::ok_status();
  }

  // Takes back the connections the workers kept open, and closes those idle too long.
  void take_returned(std::deque<ConnectionPtr>& idle, Clock::time_point now) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      for (ConnectionPtr& c : returned) {
        c->idle_since = now;
        idle.push_back(std::move(c));
      }
      returned.clear();
    }
    while (!idle.empty() && now - idle.front()->idle_since >= limits.idle_timeout) {
      idle.pop_front();
    }
  }

  // Connections whose request is arriving (or that the client closed) go to the workers.
  // fds[i + 2] is idle[i]'s poll entry.
  void hand_over_ready(std::deque<ConnectionPtr>& idle, const std::vector<pollfd>& fds) {
    std::deque<ConnectionPtr> still_idle;
    std::lock_guard<std::mutex> lock(mutex);
    for (std::size_t i = 0; i < idle.size(); ++i) {
      if (fds[i + 2].revents) {
        ready.push_back(std::move(idle[i]));
        ready_cv.notify_one();
      } else {
        still_idle.push_back(std::move(idle[i]));
      }
    }
    idle.swap(still_idle);
  }

  // Accepts all that wait. At the cap, or out of descriptors, the oldest idle connection makes
  // room; with none idle (every connection in a request), accepting pauses briefly: the
  // workers' timeouts bound how long that lasts. An error means the server cannot go on.
  Status accept_waiting(std::deque<ConnectionPtr>& idle, Clock::time_point& accept_paused_until) {
    const auto evict_oldest = [&idle] {
      if (idle.empty()) return false;
      idle.pop_front();
      return true;
    };
    for (;;) {
      if (open.load() >= limits.max_connections) {
        // Room is made only for a connection that is waiting (not, say, by closing the one
        // just accepted while its request is on its way).
        pollfd waiting{listen_fd, POLLIN, 0};
        if (::poll(&waiting, 1, 0) <= 0) break;
        while (open.load() >= limits.max_connections && evict_oldest()) {
        }
        if (open.load() >= limits.max_connections) {
          accept_paused_until = Clock::now() + milliseconds(50);
          break;
        }
      }
      const int c = ::accept4(listen_fd, nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK);
      if (c >= 0) {
        open.fetch_add(1);
        idle.push_back(std::make_unique<Connection>(c, &open));
        continue;
      }
      const int e = errno;
      if (e == EAGAIN || e == EWOULDBLOCK) break;
      if (e == EMFILE || e == ENFILE || e == ENOBUFS || e == ENOMEM) {
        // The descriptors ran out below the cap (something else holds some): the cap drops to
        // leave a few spare for the files requests open, and the oldest idle connections make
        // room (at the top of the loop).
        const std::size_t opened = open.load();
        const std::size_t cap = opened > kSpareDescriptors ? opened - kSpareDescriptors : 1;
        if (cap < limits.max_connections) {
          limits.max_connections = cap;
          std::fprintf(stderr,
                       "cbrdf view: out of file descriptors at %zu connections (%s): at most %zu "
                       "from now on, the oldest idle ones closed to admit new ones\n",
                       opened, std::strerror(e), cap);
          continue;
        }
        accept_paused_until = Clock::now() + milliseconds(50);  // none of ours to close
        break;
      }
      // A connection that failed before it was accepted is the client's problem (accept(2):
      // Linux passes pending network errors on); the loop goes on.
      if (e == EINTR || e == ECONNABORTED || e == EPROTO || e == EPERM || e == ENETDOWN ||
          e == ENOPROTOOPT || e == EHOSTDOWN || e == ENONET || e == EHOSTUNREACH ||
          e == EOPNOTSUPP || e == ENETUNREACH || e == ETIMEDOUT) {
        continue;
      }
      stop.store(true);
      return error(ErrorCode::kIo, std::string("view: accept: ") + std::strerror(e) +
                                       " (the server cannot accept connections any more)");
    }
    return Status::ok_status();
  }

  // Stops the workers and closes every connection not idle in the poller.
  void stop_workers(std::vector<std::thread>& workers) {
    stop.store(true);
    {
      std::lock_guard<std::mutex> lock(mutex);
      ready_cv.notify_all();
    }
    for (std::thread& t : workers) t.join();
    {
      std::lock_guard<std::mutex> lock(mutex);
      ready.clear();
      returned.clear();
    }
  }
};

Expected<std::unique_ptr<ConnectionLoop>> ConnectionLoop::create(int listen_fd,
                                                                 ConnectionLimits limits,
                                                                 ServeOne serve) {
  auto s = std::make_unique<State>();
  s->listen_fd = listen_fd;
  s->limits = limits;
  s->limits.threads = std::max<std::size_t>(1, limits.threads);
  s->limits.max_connections = std::max<std::size_t>(1, limits.max_connections);
  s->serve = std::move(serve);
  int p[2];
  if (::pipe2(p, O_CLOEXEC | O_NONBLOCK) != 0) {
    ::close(listen_fd);
    return error(ErrorCode::kIo, std::string("view: pipe: ") + std::strerror(errno));
  }
  s->wake_read = p[0];
  s->wake_write = p[1];
  return std::unique_ptr<ConnectionLoop>(new ConnectionLoop(std::move(s)));
}

ConnectionLoop::ConnectionLoop(std::unique_ptr<State> state) : s_(std::move(state)) {}

ConnectionLoop::~ConnectionLoop() {
  ::close(s_->listen_fd);
  ::close(s_->wake_read);
  ::close(s_->wake_write);
}

void ConnectionLoop::request_stop() noexcept {
  s_->stop.store(true);
  s_->wake();
}

bool ConnectionLoop::stopping() const noexcept {
  return s_->stop.load();
}

Status ConnectionLoop::run() {
  State& s = *s_;
  std::vector<std::thread> workers;
  CBRDF_RETURN_IF_ERROR(s.start_workers(workers));

  std::deque<ConnectionPtr> idle;  // oldest first
  Clock::time_point accept_paused_until{};
  Status result;
  std::vector<pollfd> fds;
  while (!s.stop.load()) {
    const Clock::time_point now = Clock::now();
    s.take_returned(idle, now);
    const bool accepting = now >= accept_paused_until;
    fds.clear();
    fds.push_back({s.wake_read, POLLIN, 0});
    fds.push_back({accepting ? s.listen_fd : -1, POLLIN, 0});
    for (const ConnectionPtr& c : idle) fds.push_back({c->fd, POLLIN, 0});
    Clock::time_point next = idle.empty() ? now + std::chrono::hours(1)
                                          : idle.front()->idle_since + s.limits.idle_timeout;
    if (!accepting) next = std::min(next, accept_paused_until);
    const auto wait = std::chrono::duration_cast<milliseconds>(next - now) + milliseconds(1);
    const int r = ::poll(fds.data(), fds.size(), static_cast<int>(wait.count()));
    if (r < 0) {
      if (errno == EINTR) continue;
      result = error(ErrorCode::kIo, std::string("view: poll: ") + std::strerror(errno));
      break;
    }
    if (fds[0].revents) {
      char buf[256];
      while (::read(s.wake_read, buf, sizeof buf) > 0) {
      }
    }
    s.hand_over_ready(idle, fds);
    if (!(fds[1].revents & POLLIN)) continue;
    if (Status accepted = s.accept_waiting(idle, accept_paused_until); !accepted.ok()) {
      result = std::move(accepted);
      break;
    }
  }
  s.stop_workers(workers);
  return result;
}

std::size_t connection_capacity(std::size_t wanted, std::size_t reserve) {
  rlimit lim{};
  if (::getrlimit(RLIMIT_NOFILE, &lim) != 0) return 64;
  const rlim_t target = static_cast<rlim_t>(wanted + reserve);
  if (lim.rlim_cur != RLIM_INFINITY && lim.rlim_cur < target) {
    rlimit raised = lim;
    raised.rlim_cur = lim.rlim_max == RLIM_INFINITY ? target : std::min(lim.rlim_max, target);
    if (::setrlimit(RLIMIT_NOFILE, &raised) == 0) lim = raised;
  }
  const std::size_t have =
      lim.rlim_cur == RLIM_INFINITY ? wanted + reserve : static_cast<std::size_t>(lim.rlim_cur);
  return have > reserve + 16 ? std::min(wanted, have - reserve) : 16;
}

}  // namespace cbrdf::cli
