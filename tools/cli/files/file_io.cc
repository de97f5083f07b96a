// SPDX-License-Identifier: MIT
#include "files/file_io.h"

#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <string>
#include <system_error>

#include "files/temp_registry.h"

namespace cbrdf::cli {
namespace fs = std::filesystem;

namespace {

// std::error_code's message is thread-safe, unlike strerror on some libcs.
std::string os_reason(int err) {
  return std::error_code(err, std::generic_category()).message();
}

// How a path appears in messages.
std::string display(const fs::path& p) {
  if (p == "/dev/stdin") return "standard input";
  if (p == "/dev/stdout") return "standard output";
  return p.string();
}

// What a stat mode is, for messages about files that are not regular.
const char* kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISLNK(mode)) return "a symbolic link";
  return "not a regular file";
}

bool descriptor_is_open(int fd) {
  return ::fcntl(fd, F_GETFD) != -1;
}

// Opens a regular file for reading; the caller owns the returned descriptor. Non-blocking, so that
// a FIFO is refused at once instead of waiting for a writer.
Status open_for_reading(const fs::path& path, int* fd_out, std::uint64_t* size_out) {
  int fd;
  do {
    fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY);
  } while (fd < 0 && errno == EINTR);
  if (fd < 0) {
    const int err = errno;
    if (err == ENOENT) return error(ErrorCode::kNotFound, display(path) + ": no such file");
    return error(ErrorCode::kIo, display(path) + ": cannot open: " + os_reason(err));
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    const int err = errno;
    ::close(fd);
    return error(ErrorCode::kIo, display(path) + ": cannot stat: " + os_reason(err));
  }
  if (S_ISDIR(st.st_mode)) {
    ::close(fd);
    return error(ErrorCode::kIo, display(path) + ": is a directory, not a file");
  }
  if (!S_ISREG(st.st_mode)) {
    ::close(fd);
    return error(ErrorCode::kIo, display(path) + ": is " + kind_of(st.st_mode) +
                                     ", not a regular file (pipes are read from standard input)");
  }
  const int flags = ::fcntl(fd, F_GETFL);
  if (flags != -1) (void)::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK);
  *fd_out = fd;
  *size_out = std::uint64_t(st.st_size);
  return ok_status();
}

// Reads exactly n bytes from fd; a short file is kTruncated, naming where it ended.
Status read_fd_exact(int fd, const fs::path& path, std::uint64_t offset, void* dst, std::size_t n) {
  auto* out = static_cast<std::uint8_t*>(dst);
  std::size_t done = 0;
  while (done < n) {
    const ::ssize_t got = ::read(fd, out + done, n - done);
    if (got < 0) {
      if (errno == EINTR) continue;
      return error(ErrorCode::kIo, display(path) + ": read failed at byte offset " +
                                       std::to_string(offset + done) + ": " + os_reason(errno));
    }
    if (got == 0) {
      return error(ErrorCode::kTruncated,
                   display(path) + ": file ends at byte offset " + std::to_string(offset + done) +
                       ", but " + std::to_string(n) + " bytes were needed from offset " +
                       std::to_string(offset));
    }
    done += std::size_t(got);
  }
  return ok_status();
}

// Reads a descriptor to its end (a pipe, a terminal, a redirected file), refusing more than
// max_bytes before allocating for them.
Expected<std::vector<std::uint8_t>> read_stream(int fd, const fs::path& path,
                                                std::uint64_t max_bytes) {
  if (!descriptor_is_open(fd)) {
    return error(ErrorCode::kIo,
                 display(path) + ": descriptor " + std::to_string(fd) + " is not open");
  }
  std::vector<std::uint8_t> bytes;
  std::uint8_t buf[1 << 16];
  for (;;) {
    const ::ssize_t got = ::read(fd, buf, sizeof buf);
    if (got < 0) {
      if (errno == EINTR) continue;
      if (errno == EAGAIN) {
        // A non-blocking descriptor with nothing yet: wait for it instead of failing.
        const int flags = ::fcntl(fd, F_GETFL);
        if (flags != -1 && ::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) == 0) continue;
      }
      return error(ErrorCode::kIo, display(path) + ": read failed at byte offset " +
                                       std::to_string(bytes.size()) + ": " + os_reason(errno));
    }
    if (got == 0) break;
    if (bytes.size() + std::size_t(got) > max_bytes) {
      return error(ErrorCode::kLimit, display(path) + ": more than the limit of " +
                                          std::to_string(max_bytes) + " bytes");
    }
    bytes.insert(bytes.end(), buf, buf + got);
  }
  return bytes;
}

Status write_fd_all(int fd, const std::uint8_t* data, std::size_t n) {
  while (n > 0) {
    const ::ssize_t put = ::write(fd, data, n);
    if (put < 0) {
      if (errno == EINTR) continue;
      return error(ErrorCode::kIo, os_reason(errno));
    }
    data += put;
    n -= std::size_t(put);
  }
  return ok_status();
}

// Follows symbolic links to the path they finally name (which may not exist yet), stopping early
// at a path that names a descriptor. ELOOP-style cycles are refused.
Expected<fs::path> follow_links(fs::path p) {
  for (int hops = 0; hops < 40; ++hops) {
    if (descriptor_of_path(p) >= 0) return p;
    struct stat st {};
    if (::lstat(p.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) return p;
    char buf[PATH_MAX];
    const ::ssize_t n = ::readlink(p.c_str(), buf, sizeof buf);
    if (n < 0 || std::size_t(n) >= sizeof buf) {
      return error(ErrorCode::kIo, "cannot write " + display(p) +
                                       ": cannot read the symbolic link: " +
                                       os_reason(n < 0 ? errno : ENAMETOOLONG));
    }
    const fs::path target(std::string(buf, std::size_t(n)));
    p = target.is_absolute() ? target : p.parent_path() / target;
  }
  return error(ErrorCode::kIo,
               "cannot write " + display(p) + ": too many levels of symbolic links");
}

// The longest file name the target's directory takes (255 on common filesystems).
std::size_t name_max(const fs::path& dir) {
  const long n = ::pathconf(dir.c_str(), _PC_NAME_MAX);
  return n > 0 ? std::size_t(n) : 255;
}

}  // namespace

std::string temporary_name(const std::string& target_name, std::size_t max_name, long pid,
                           unsigned counter) {
  const std::string suffix = ".cbrdf-tmp-" + std::to_string(pid) + "-" + std::to_string(counter);
  std::string base = target_name;
  const std::size_t room = max_name > suffix.size() + 1 ? max_name - suffix.size() - 1 : 0;
  if (base.size() > room) {
    base.resize(room);
    // Cut at a character boundary, so a UTF-8 name stays readable.
    while (!base.empty() && (static_cast<unsigned char>(base.back()) & 0xC0) == 0x80)
      base.pop_back();
    if (!base.empty() && static_cast<unsigned char>(base.back()) >= 0xC0) base.pop_back();
  }
  return "." + base + suffix;
}

namespace {

// Where write_file_atomic's bytes go: a temporary that becomes the target on commit, or a stream
// (a device, a FIFO, an open descriptor) written through.
class OutputWriter {
 public:
  explicit OutputWriter(fs::path target) : requested_(std::move(target)) {}
  OutputWriter(const OutputWriter&) = delete;
  OutputWriter& operator=(const OutputWriter&) = delete;
  ~OutputWriter() {
    if (fd_ >= 0 && owns_fd_) ::close(fd_);
    if (!tmp_.empty() && !committed_) ::unlink(tmp_.c_str());
    temp_registry::remove(slot_);
  }

  Status create() {
    if (requested_.filename().empty()) {
      return error(ErrorCode::kInvalidArgument, display(requested_) + ": not a file name");
    }
    if (const int fd = descriptor_of_path(requested_); fd >= 0) return open_descriptor(fd);
    Expected<fs::path> final_path = follow_links(requested_);
    if (!final_path.ok()) return final_path.status();
    target_ = *final_path;
    if (const int fd = descriptor_of_path(target_); fd >= 0) return open_descriptor(fd);
    struct stat st {};
    const bool target_exists = ::stat(target_.c_str(), &st) == 0;
    if (target_exists && S_ISDIR(st.st_mode)) {
      return error(ErrorCode::kIo,
                   display(requested_) + ": is a directory, cannot write a file there");
    }
    if (target_exists && (S_ISCHR(st.st_mode) || S_ISFIFO(st.st_mode))) return open_stream();
    if (target_exists && !S_ISREG(st.st_mode)) {
      return error(ErrorCode::kIo, "cannot write " + display(requested_) + ": it is " +
                                       kind_of(st.st_mode) +
                                       "; cbrdf writes regular files, character devices and FIFOs");
    }
    dir_ = target_.has_parent_path() ? target_.parent_path() : fs::path(".");
    CBRDF_RETURN_IF_ERROR(open_unnamed());
    if (fd_ < 0) CBRDF_RETURN_IF_ERROR(open_named());
    // Replacing a file keeps its permissions, as editing it in place would.
    if (target_exists) (void)::fchmod(fd_, st.st_mode & 07777);
    return ok_status();
  }

  Status write(std::span<const std::uint8_t> chunk) {
    if (chunk.size() >= kBufferSize) {
      CBRDF_RETURN_IF_ERROR(flush());
      return write_through(chunk.data(), chunk.size());
    }
    if (buffer_.size() + chunk.size() > kBufferSize) CBRDF_RETURN_IF_ERROR(flush());
    if (buffer_.capacity() < kBufferSize) buffer_.reserve(kBufferSize);
    buffer_.insert(buffer_.end(), chunk.begin(), chunk.end());
    return ok_status();
  }

  Status commit() {
    CBRDF_RETURN_IF_ERROR(flush());
    if (stream_) {
      committed_ = true;
      if (owns_fd_) {
        const int fd = fd_;
        fd_ = -1;
        if (::close(fd) != 0) return os_failure("close failed", errno);
      }
      return ok_status();
    }
    if (::fsync(fd_) != 0) return os_failure("fsync failed", errno);
    if (tmp_.empty()) CBRDF_RETURN_IF_ERROR(link_unnamed());
    const int fd = fd_;
    fd_ = -1;
    if (::close(fd) != 0) return os_failure("close failed", errno);
    if (::rename(tmp_.c_str(), target_.c_str()) != 0) {
      return os_failure("cannot rename the temporary file over it", errno);
    }
    committed_ = true;
    temp_registry::remove(slot_);
    slot_ = -1;
    // Makes the rename itself durable. The new file is already complete and in place, so a
    // failure here is not reported: there is nothing the caller could undo.
    const int dfd = ::open(dir_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dfd >= 0) {
      (void)::fsync(dfd);
      ::close(dfd);
    }
    return ok_status();
  }

 private:
  static constexpr std::size_t kBufferSize = 1 << 16;

  Status open_descriptor(int fd) {
    if (!descriptor_is_open(fd)) {
      return error(ErrorCode::kIo, "cannot write " + display(requested_) + ": descriptor " +
                                       std::to_string(fd) + " is not open");
    }
    fd_ = fd;
    owns_fd_ = false;
    stream_ = true;
    return ok_status();
  }

  Status open_stream() {
    do {
      fd_ = ::open(target_.c_str(), O_WRONLY | O_CLOEXEC | O_NOCTTY);
    } while (fd_ < 0 && errno == EINTR);
    if (fd_ < 0) return os_failure("cannot open", errno);
    stream_ = true;
    return ok_status();
  }

  // An O_TMPFILE file: never visible under a name until commit, so nothing is left by a crash.
  // Leaves fd_ at -1 (without an error) where the filesystem or kernel has no O_TMPFILE.
  Status open_unnamed() {
#ifdef O_TMPFILE
    static const bool proc_fd = ::access("/proc/self/fd", X_OK) == 0;
    if (!proc_fd) return ok_status();
    do {
      fd_ = ::open(dir_.c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0666);
    } while (fd_ < 0 && errno == EINTR);
    if (fd_ >= 0) return ok_status();
    const int err = errno;
    if (err == EOPNOTSUPP || err == EISDIR || err == EINVAL) return ok_status();
    return create_failure(err);
#else
    return ok_status();
#endif
  }

  // A named temporary (O_EXCL makes the name ours alone; a stale one just costs a retry),
  // registered so that a signal handler can remove it.
  Status open_named() {
    for (int attempt = 0; attempt < 100; ++attempt) {
      next_temp_name();
      do {
        fd_ = ::open(tmp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
      } while (fd_ < 0 && errno == EINTR);
      if (fd_ >= 0) return ok_status();
      const int err = errno;
      temp_registry::remove(slot_);
      slot_ = -1;
      if (err == EEXIST) continue;
      tmp_.clear();
      return create_failure(err);
    }
    tmp_.clear();
    return error(ErrorCode::kIo, "cannot write " + display(requested_) +
                                     ": no free temporary file name in " + display(dir_));
  }

  // Gives the unnamed temporary a name beside the target, for the rename.
  Status link_unnamed() {
    const std::string proc = "/proc/self/fd/" + std::to_string(fd_);
    for (int attempt = 0; attempt < 100; ++attempt) {
      next_temp_name();
      if (::linkat(AT_FDCWD, proc.c_str(), AT_FDCWD, tmp_.c_str(), AT_SYMLINK_FOLLOW) == 0) {
        return ok_status();
      }
      const int err = errno;
      temp_registry::remove(slot_);
      slot_ = -1;
      if (err == EEXIST) continue;
      tmp_.clear();
      return os_failure("cannot name the temporary file", err);
    }
    tmp_.clear();
    return error(ErrorCode::kIo, "cannot write " + display(requested_) +
                                     ": no free temporary file name in " + display(dir_));
  }

  // Picks the next temporary name and registers it (before it exists, so no window is missed).
  void next_temp_name() {
    static std::atomic<unsigned> counter{0};
    tmp_ = dir_ /
           temporary_name(target_.filename().string(), name_max(dir_), long(::getpid()), counter++);
    slot_ = temp_registry::add(tmp_.c_str());
  }

  Status create_failure(int err) const {
    if (err == ENOENT) {
      return error(ErrorCode::kIo, "cannot write " + display(requested_) + ": directory " +
                                       display(dir_) + " does not exist");
    }
    return error(ErrorCode::kIo, "cannot write " + display(requested_) +
                                     ": cannot create a temporary file in " + display(dir_) + ": " +
                                     os_reason(err));
  }

  Status flush() {
    if (buffer_.empty()) return ok_status();
    Status s = write_through(buffer_.data(), buffer_.size());
    buffer_.clear();
    return s;
  }

  Status write_through(const std::uint8_t* data, std::size_t n) {
    Status s = write_fd_all(fd_, data, n);
    if (!s.ok()) {
      return error(ErrorCode::kIo, "cannot write " + display(requested_) + ": write failed after " +
                                       std::to_string(written_) + " bytes: " + s.message());
    }
    written_ += n;
    return ok_status();
  }

  Status os_failure(const char* what, int err) const {
    return error(ErrorCode::kIo,
                 "cannot write " + display(requested_) + ": " + what + ": " + os_reason(err));
  }

  fs::path requested_;  // as the caller named it, for messages
  fs::path target_;     // after following links
  fs::path dir_;
  fs::path tmp_;
  int fd_ = -1;
  int slot_ = -1;  // temp_registry slot of tmp_
  bool owns_fd_ = true;
  bool stream_ = false;
  bool committed_ = false;
  std::uint64_t written_ = 0;
  std::vector<std::uint8_t> buffer_;
};

}  // namespace

int descriptor_of_path(const fs::path& path) {
  const std::string s = path.string();
  if (s == "/dev/stdin") return 0;
  if (s == "/dev/stdout") return 1;
  if (s == "/dev/stderr") return 2;
  for (const std::string_view prefix : {"/dev/fd/", "/proc/self/fd/"}) {
    if (s.size() > prefix.size() && s.compare(0, prefix.size(), prefix) == 0) {
      int fd = -1;
      const char* begin = s.data() + prefix.size();
      const char* end = s.data() + s.size();
      const auto [ptr, ec] = std::from_chars(begin, end, fd);
      if (ec == std::errc() && ptr == end && fd >= 0) return fd;
    }
  }
  return -1;
}

Expected<std::vector<std::uint8_t>> read_file(const fs::path& path, std::uint64_t max_bytes) {
  if (const int fd = descriptor_of_path(path); fd >= 0) return read_stream(fd, path, max_bytes);
  Expected<FileReader> reader = FileReader::open(path);
  if (!reader) return reader.status();
  const std::uint64_t size = reader->size();
  if (size > max_bytes) {
    return error(ErrorCode::kLimit, display(path) + ": file is " + std::to_string(size) +
                                        " bytes, larger than the limit of " +
                                        std::to_string(max_bytes) + " bytes");
  }
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(size));
  CBRDF_RETURN_IF_ERROR(reader->read_exact(bytes.data(), bytes.size()));
  return bytes;
}

Expected<FileReader> FileReader::open(const fs::path& path, std::uint64_t max_stream_bytes) {
  if (const int fd = descriptor_of_path(path); fd >= 0) {
    Expected<std::vector<std::uint8_t>> bytes = read_stream(fd, path, max_stream_bytes);
    if (!bytes.ok()) return bytes.status();
    FileReader reader(path, -1, bytes->size());
    reader.buffered_ = std::move(*bytes);
    return reader;
  }
  int fd = -1;
  std::uint64_t size = 0;
  CBRDF_RETURN_IF_ERROR(open_for_reading(path, &fd, &size));
  return FileReader(path, fd, size);
}

FileReader::FileReader(FileReader&& other) noexcept
    : path_(std::move(other.path_)),
      fd_(other.fd_),
      buffered_(std::move(other.buffered_)),
      size_(other.size_),
      offset_(other.offset_) {
  other.fd_ = -1;
}

FileReader& FileReader::operator=(FileReader&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    path_ = std::move(other.path_);
    fd_ = other.fd_;
    buffered_ = std::move(other.buffered_);
    size_ = other.size_;
    offset_ = other.offset_;
    other.fd_ = -1;
  }
  return *this;
}

FileReader::~FileReader() {
  if (fd_ >= 0) ::close(fd_);
}

Status FileReader::read_exact(void* dst, std::size_t n) {
  if (fd_ < 0) {
    // A stream read into memory at open.
    if (offset_ + n > buffered_.size()) {
      return error(ErrorCode::kTruncated,
                   display(path_) + ": input ends at byte offset " +
                       std::to_string(buffered_.size()) + ", but " + std::to_string(n) +
                       " bytes were needed from offset " + std::to_string(offset_));
    }
    if (n > 0) std::memcpy(dst, buffered_.data() + offset_, n);
    offset_ += n;
    return ok_status();
  }
  CBRDF_RETURN_IF_ERROR(read_fd_exact(fd_, path_, offset_, dst, n));
  offset_ += n;
  return ok_status();
}

Status write_file_atomic(const fs::path& path, std::span<const std::uint8_t> bytes) {
  return write_file_atomic(path, [bytes](const ChunkSink& sink) -> Status { return sink(bytes); });
}

Status write_file_atomic(const fs::path& path, const ChunkProducer& produce) {
  OutputWriter writer(path);
  CBRDF_RETURN_IF_ERROR(writer.create());
  const ChunkSink sink = [&writer](std::span<const std::uint8_t> chunk) {
    return writer.write(chunk);
  };
  CBRDF_RETURN_IF_ERROR(produce(sink));
  return writer.commit();
}

void remove_temporaries_on_signals() {
  temp_registry::install_signal_handlers();
}

void interrupt_sets_flag(std::atomic<bool>* flag) {
  temp_registry::interrupt_sets(flag);
}

Expected<BrdfTable> read_merl_input(const fs::path& path, const MerlReadOptions& options,
                                    MerlInfo* info) {
  Expected<FileReader> reader = FileReader::open(path);
  if (!reader) return reader.status();
  const MerlReadExact read = [&reader](void* dst, std::size_t n) {
    return reader->read_exact(dst, n);
  };
  return read_merl_stream(reader->size(), read, display(path), options, info);
}

Status write_merl_output(const fs::path& path, const BrdfTable& table) {
  return write_file_atomic(path,
                           [&table](const ChunkSink& sink) { return write_merl(table, sink); });
}

}  // namespace cbrdf::cli
