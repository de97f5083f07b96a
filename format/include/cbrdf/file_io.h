// Whole-file reads with a size limit, a streaming reader, and atomic file writes.
//
// Every writer in cbrdf goes through write_file_atomic: the bytes go to a temporary file in the
// target's directory (unique name, created with O_EXCL), are fsync'ed, and the temporary is renamed
// over the target. A failed write removes the temporary and leaves an existing target untouched, so
// no run ever leaves a partial file behind. POSIX only.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <span>
#include <utility>
#include <vector>

#include "cbrdf/status.h"

namespace cbrdf {

// Reads a whole regular file. Errors: kNotFound ("FILE: no such file"), kIo (a directory,
// permission, a failed read), kLimit when the file is larger than max_bytes (both sizes in the
// message).
Expected<std::vector<std::uint8_t>> read_file(const std::filesystem::path& path,
                                              std::uint64_t max_bytes);

// A regular file opened for sequential reading, for parsers that read a small header first and then
// stream the body straight into its final buffer. Move-only; closes on destruction.
class FileReader {
 public:
  // Same errors as read_file for a missing file, a directory or a refused open.
  static Expected<FileReader> open(const std::filesystem::path& path);

  FileReader(FileReader&& other) noexcept;
  FileReader& operator=(FileReader&& other) noexcept;
  FileReader(const FileReader&) = delete;
  FileReader& operator=(const FileReader&) = delete;
  ~FileReader();

  const std::filesystem::path& path() const { return path_; }
  std::uint64_t size() const { return size_; }      // at open time
  std::uint64_t offset() const { return offset_; }  // bytes read so far
  // Reads exactly n bytes; kTruncated (naming the offset) when the file ends first, kIo on an OS
  // error.
  Status read_exact(void* dst, std::size_t n);

 private:
  FileReader(std::filesystem::path path, int fd, std::uint64_t size)
      : path_(std::move(path)), fd_(fd), size_(size) {}
  std::filesystem::path path_;
  int fd_ = -1;
  std::uint64_t size_ = 0;
  std::uint64_t offset_ = 0;
};

// Receives the next chunk of a file being written; returns an error when the write failed.
using ChunkSink = std::function<Status(std::span<const std::uint8_t>)>;
// Produces a file's content by calling the sink with consecutive chunks (of any size, copied or
// written straight through). A non-ok return aborts the write.
using ChunkProducer = std::function<Status(const ChunkSink&)>;

// Writes bytes to path atomically (see the file comment). Errors name the path and the OS reason.
Status write_file_atomic(const std::filesystem::path& path, std::span<const std::uint8_t> bytes);
// Streaming variant: the content comes from produce, so a large table is never copied into a
// second buffer. An error from produce is returned as is, after the temporary is removed.
Status write_file_atomic(const std::filesystem::path& path, const ChunkProducer& produce);

}  // namespace cbrdf
