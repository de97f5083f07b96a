#include "cbrdf/file_io.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <string>
#include <system_error>

namespace cbrdf {
namespace fs = std::filesystem;

namespace {

// std::error_code's message is thread-safe, unlike strerror on some libcs.
std::string os_reason(int err) {
  return std::error_code(err, std::generic_category()).message();
}

// How a path appears in messages.
std::string display(const fs::path& p) {
  return p.string();
}

// Opens a regular file for reading; the caller owns the returned descriptor.
Status open_for_reading(const fs::path& path, int* fd_out, std::uint64_t* size_out) {
  int fd;
  do {
    fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
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
    return error(ErrorCode::kIo, display(path) + ": not a regular file");
  }
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

// A temporary file beside the target that either becomes the target (commit) or disappears.
class AtomicWriter {
 public:
  explicit AtomicWriter(fs::path target) : target_(std::move(target)) {}
  AtomicWriter(const AtomicWriter&) = delete;
  AtomicWriter& operator=(const AtomicWriter&) = delete;
  ~AtomicWriter() {
    if (fd_ >= 0) ::close(fd_);
    if (!tmp_.empty() && !committed_) ::unlink(tmp_.c_str());
  }

  Status create() {
    if (target_.filename().empty()) {
      return error(ErrorCode::kInvalidArgument, display(target_) + ": not a file name");
    }
    struct stat st {};
    const bool target_exists = ::stat(target_.c_str(), &st) == 0;
    if (target_exists && S_ISDIR(st.st_mode)) {
      return error(ErrorCode::kIo,
                   display(target_) + ": is a directory, cannot write a file there");
    }
    const fs::path dir = target_.has_parent_path() ? target_.parent_path() : fs::path(".");
    static std::atomic<unsigned> counter{0};
    // O_EXCL makes the name ours alone; a stale temporary from a crashed run just costs a retry.
    for (int attempt = 0; attempt < 100; ++attempt) {
      tmp_ = dir / ("." + target_.filename().string() + ".tmp." + std::to_string(::getpid()) + "." +
                    std::to_string(counter++));
      do {
        fd_ = ::open(tmp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
      } while (fd_ < 0 && errno == EINTR);
      if (fd_ >= 0) break;
      const int err = errno;
      if (err == EEXIST) continue;
      tmp_.clear();
      if (err == ENOENT) {
        return error(ErrorCode::kIo, "cannot write " + display(target_) + ": directory " +
                                         display(dir) + " does not exist");
      }
      return error(ErrorCode::kIo, "cannot write " + display(target_) +
                                       ": cannot create a temporary file in " + display(dir) +
                                       ": " + os_reason(err));
    }
    if (fd_ < 0) {
      tmp_.clear();
      return error(ErrorCode::kIo, "cannot write " + display(target_) +
                                       ": no free temporary file name in " + display(dir));
    }
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
    if (::fsync(fd_) != 0) return os_failure("fsync failed", errno);
    const int fd = fd_;
    fd_ = -1;
    if (::close(fd) != 0) return os_failure("close failed", errno);
    if (::rename(tmp_.c_str(), target_.c_str()) != 0) {
      return os_failure("cannot rename the temporary file over it", errno);
    }
    committed_ = true;
    // Makes the rename itself durable. The new file is already complete and in place, so a
    // failure here is not reported: there is nothing the caller could undo.
    const fs::path dir = target_.has_parent_path() ? target_.parent_path() : fs::path(".");
    const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dfd >= 0) {
      (void)::fsync(dfd);
      ::close(dfd);
    }
    return ok_status();
  }

 private:
  static constexpr std::size_t kBufferSize = 1 << 16;

  Status flush() {
    if (buffer_.empty()) return ok_status();
    Status s = write_through(buffer_.data(), buffer_.size());
    buffer_.clear();
    return s;
  }

  Status write_through(const std::uint8_t* data, std::size_t n) {
    Status s = write_fd_all(fd_, data, n);
    if (!s.ok()) {
      return error(ErrorCode::kIo, "cannot write " + display(target_) + ": write failed after " +
                                       std::to_string(written_) + " bytes: " + s.message());
    }
    written_ += n;
    return ok_status();
  }

  Status os_failure(const char* what, int err) const {
    return error(ErrorCode::kIo,
                 "cannot write " + display(target_) + ": " + what + ": " + os_reason(err));
  }

  fs::path target_;
  fs::path tmp_;
  int fd_ = -1;
  bool committed_ = false;
  std::uint64_t written_ = 0;
  std::vector<std::uint8_t> buffer_;
};

}  // namespace

Expected<std::vector<std::uint8_t>> read_file(const fs::path& path, std::uint64_t max_bytes) {
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

Expected<FileReader> FileReader::open(const fs::path& path) {
  int fd = -1;
  std::uint64_t size = 0;
  CBRDF_RETURN_IF_ERROR(open_for_reading(path, &fd, &size));
  return FileReader(path, fd, size);
}

FileReader::FileReader(FileReader&& other) noexcept
    : path_(std::move(other.path_)), fd_(other.fd_), size_(other.size_), offset_(other.offset_) {
  other.fd_ = -1;
}

FileReader& FileReader::operator=(FileReader&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    path_ = std::move(other.path_);
    fd_ = other.fd_;
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
  if (fd_ < 0) return error(ErrorCode::kInternal, display(path_) + ": read from a closed file");
  CBRDF_RETURN_IF_ERROR(read_fd_exact(fd_, path_, offset_, dst, n));
  offset_ += n;
  return ok_status();
}

Status write_file_atomic(const fs::path& path, std::span<const std::uint8_t> bytes) {
  return write_file_atomic(path, [bytes](const ChunkSink& sink) -> Status { return sink(bytes); });
}

Status write_file_atomic(const fs::path& path, const ChunkProducer& produce) {
  AtomicWriter writer(path);
  CBRDF_RETURN_IF_ERROR(writer.create());
  const ChunkSink sink = [&writer](std::span<const std::uint8_t> chunk) {
    return writer.write(chunk);
  };
  CBRDF_RETURN_IF_ERROR(produce(sink));
  return writer.commit();
}

}  // namespace cbrdf
