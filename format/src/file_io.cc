// SPDX-License-Identifier: MIT
#include "cbrdf/file_io.h"

#include <atomic>
#include <cerrno>
#include <cstring>
#include <string>
#include <system_error>
#include <utility>

namespace cbrdf {
namespace fs = std::filesystem;

namespace {

std::string reason(const std::error_code& ec) {
  return ec.message();
}

const char* kind_of(fs::file_type type) {
  switch (type) {
    case fs::file_type::directory:
      return "a directory";
    case fs::file_type::fifo:
      return "a FIFO (named pipe)";
    case fs::file_type::character:
      return "a character device";
    case fs::file_type::block:
      return "a block device";
    case fs::file_type::socket:
      return "a socket";
    case fs::file_type::symlink:
      return "a symbolic link";
    default:
      return "not a regular file";
  }
}

// Checks that path names an existing regular file (following links) and returns its size.
Status check_regular(const fs::path& path, std::uint64_t* size) {
  if (path.empty()) {
    return error(ErrorCode::kInvalidArgument, "no file name given (the path is empty)");
  }
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (st.type() == fs::file_type::not_found) {
    return error(ErrorCode::kNotFound, path.string() + ": no such file");
  }
  if (ec) return error(ErrorCode::kIo, path.string() + ": cannot open: " + reason(ec));
  if (st.type() == fs::file_type::directory) {
    return error(ErrorCode::kIo, path.string() + ": is a directory, not a file");
  }
  if (st.type() != fs::file_type::regular) {
    return error(ErrorCode::kIo,
                 path.string() + ": is " + kind_of(st.type()) + ", not a regular file");
  }
  const std::uintmax_t n = fs::file_size(path, ec);
  if (ec) return error(ErrorCode::kIo, path.string() + ": cannot read its size: " + reason(ec));
  *size = std::uint64_t(n);
  return ok_status();
}

Expected<std::FILE*> open_file(const fs::path& path, const char* mode) {
  errno = 0;
  std::FILE* f = std::fopen(path.string().c_str(), mode);
  if (!f) {
    const int err = errno;
    return error(ErrorCode::kIo,
                 path.string() + ": cannot open: " +
                     (err ? std::generic_category().message(err) : std::string("unknown error")));
  }
  return f;
}

// Follows symbolic links to the path they finally name (which may not exist yet).
Expected<fs::path> follow_links(fs::path p) {
  for (int hops = 0; hops < 40; ++hops) {
    std::error_code ec;
    if (!fs::is_symlink(fs::symlink_status(p, ec))) return p;
    const fs::path target = fs::read_symlink(p, ec);
    if (ec) {
      return error(ErrorCode::kIo,
                   "cannot write " + p.string() + ": cannot read the symbolic link: " + reason(ec));
    }
    p = target.is_absolute() ? target : p.parent_path() / target;
  }
  return error(ErrorCode::kIo,
               "cannot write " + p.string() + ": too many levels of symbolic links");
}

std::atomic<unsigned> temporary_counter{0};

}  // namespace

Expected<std::vector<std::uint8_t>> read_file(const fs::path& path, std::uint64_t max_bytes) {
  Expected<FileReader> reader = FileReader::open(path);
  if (!reader) return reader.status();
  if (reader->size() > max_bytes) {
    return error(ErrorCode::kLimit, path.string() + ": file is " + std::to_string(reader->size()) +
                                        " bytes, larger than the limit of " +
                                        std::to_string(max_bytes) + " bytes");
  }
  std::vector<std::uint8_t> bytes(std::size_t(reader->size()));
  CBRDF_RETURN_IF_ERROR(reader->read_exact(bytes.data(), bytes.size()));
  return bytes;
}

Expected<FileReader> FileReader::open(const fs::path& path) {
  std::uint64_t size = 0;
  CBRDF_RETURN_IF_ERROR(check_regular(path, &size));
  Expected<std::FILE*> f = open_file(path, "rb");
  if (!f) return f.status();
  return FileReader(path, *f, size);
}

FileReader::FileReader(FileReader&& other) noexcept
    : path_(std::move(other.path_)),
      file_(std::exchange(other.file_, nullptr)),
      size_(other.size_),
      offset_(other.offset_) {}

FileReader& FileReader::operator=(FileReader&& other) noexcept {
  if (this != &other) {
    if (file_) std::fclose(file_);
    path_ = std::move(other.path_);
    file_ = std::exchange(other.file_, nullptr);
    size_ = other.size_;
    offset_ = other.offset_;
  }
  return *this;
}

FileReader::~FileReader() {
  if (file_) std::fclose(file_);
}

Status FileReader::read_exact(void* dst, std::size_t n) {
  if (!file_) return error(ErrorCode::kInternal, path_.string() + ": reader is closed");
  const std::size_t got = n == 0 ? 0 : std::fread(dst, 1, n, file_);
  if (got < n) {
    if (std::ferror(file_)) {
      return error(ErrorCode::kIo, path_.string() + ": read failed at byte offset " +
                                       std::to_string(offset_ + got));
    }
    return error(ErrorCode::kTruncated, path_.string() + ": file ends at byte offset " +
                                            std::to_string(offset_ + got) + ", but " +
                                            std::to_string(n) + " bytes were needed from offset " +
                                            std::to_string(offset_));
  }
  offset_ += n;
  return ok_status();
}

Status write_file_atomic(const fs::path& path, std::span<const std::uint8_t> bytes) {
  return write_file_atomic(path, [bytes](const ChunkSink& sink) { return sink(bytes); });
}

Status write_file_atomic(const fs::path& path, const ChunkProducer& produce) {
  if (path.empty()) {
    return error(ErrorCode::kInvalidArgument, "no file name given (the path is empty)");
  }
  Expected<fs::path> target = follow_links(path);
  if (!target) return target.status();
  std::error_code ec;
  const fs::file_status st = fs::status(*target, ec);
  if (st.type() != fs::file_type::not_found && st.type() != fs::file_type::regular && !ec) {
    return error(ErrorCode::kIo, "cannot write " + path.string() + ": it is " + kind_of(st.type()) +
                                     ", not a regular file");
  }
  const fs::path dir = target->has_parent_path() ? target->parent_path() : fs::path(".");
  if (!fs::is_directory(dir, ec)) {
    return error(ErrorCode::kIo,
                 "cannot write " + path.string() + ": directory " + dir.string() +
                     (fs::exists(dir, ec) ? " is not a directory" : " does not exist"));
  }
  const fs::path temp =
      dir / ("." + target->filename().string() + ".cbrdf-tmp-" +
             std::to_string(temporary_counter.fetch_add(1, std::memory_order_relaxed)));
  Expected<std::FILE*> f = open_file(temp, "wb");
  if (!f) {
    return error(ErrorCode::kIo, "cannot write " + path.string() + ": " + f.status().message());
  }
  std::FILE* file = *f;
  Status written = produce([file, &path](std::span<const std::uint8_t> chunk) -> Status {
    if (!chunk.empty() && std::fwrite(chunk.data(), 1, chunk.size(), file) != chunk.size()) {
      return error(ErrorCode::kIo, "cannot write " + path.string() + ": the write failed");
    }
    return ok_status();
  });
  const bool closed = std::fclose(file) == 0;
  if (written.ok() && !closed) {
    written = error(ErrorCode::kIo, "cannot write " + path.string() + ": closing it failed");
  }
  // A replaced file keeps its permissions; a new one gets the process's defaults.
  if (written.ok() && st.type() == fs::file_type::regular) {
    fs::permissions(temp, st.permissions(), fs::perm_options::replace, ec);
  }
  if (written.ok()) {
    fs::rename(temp, *target, ec);
    if (ec) {
      written = error(ErrorCode::kIo, "cannot write " + path.string() + ": " + reason(ec));
    }
  }
  if (!written.ok()) fs::remove(temp, ec);
  return written;
}

}  // namespace cbrdf
