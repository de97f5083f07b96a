// SPDX-License-Identifier: MIT
/// @file
/// Plain, portable file access for the libraries (standard C++ only: `<filesystem>` and
/// `<cstdio>`): whole-file reads with a size limit, a sequential reader, and whole-file writes that
/// replace their target only once complete.
///
/// Readers open regular files only: a directory, a FIFO, a device or a socket is refused with a
/// message naming what it is (checked before opening, so nothing blocks). Writers write a temporary
/// `.NAME.cbrdf-tmp-N` beside the target, then rename it over the target: a failed write leaves an
/// existing target untouched and removes the temporary. A symbolic link is followed to its final
/// target, which is replaced (the link stays). A target that exists and is not a regular file is
/// refused. Nothing is fsync'ed (standard C++ has no way to): after a power loss the new content
/// may be lost, but never half-written over the old.
///
/// The `cbrdf` command has a POSIX layer of its own on top of these (tools/cli/files/file_io.h): it
/// also writes to /dev/stdout, devices and pipes, and removes temporaries when a signal ends it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <span>
#include <vector>

#include "cbrdf/status.h"

namespace cbrdf {

/// Reads a whole regular file. Errors: kInvalidArgument (an empty path), kNotFound ("FILE: no such
/// file"), kIo (a directory, a FIFO, a device, permission, a failed read), kLimit when the file is
/// larger than max_bytes (both sizes in the message).
Expected<std::vector<std::uint8_t>> read_file(const std::filesystem::path& path,
                                              std::uint64_t max_bytes);

/// A regular file opened for sequential reading, for parsers that read a small header first and
/// then stream the body straight into its final buffer. Move-only; closes on destruction.
class FileReader {
 public:
  /// Same errors as read_file, but for the size limit.
  static Expected<FileReader> open(const std::filesystem::path& path);

  /** Moves the open file; the moved-from reader holds none. */
  ///@{
  FileReader(FileReader&& other) noexcept;
  FileReader& operator=(FileReader&& other) noexcept;
  ///@}
  FileReader(const FileReader&) = delete;
  FileReader& operator=(const FileReader&) = delete;
  ~FileReader();

  const std::filesystem::path& path() const { return path_; }  ///< as opened
  std::uint64_t size() const { return size_; }                 ///< at open time
  std::uint64_t offset() const { return offset_; }             ///< bytes read so far
  /// Reads exactly n bytes; kTruncated (naming the offset) when the file ends first, kIo on a read
  /// error.
  Status read_exact(void* dst, std::size_t n);

 private:
  FileReader(std::filesystem::path path, std::FILE* file, std::uint64_t size)
      : path_(std::move(path)), file_(file), size_(size) {}
  std::filesystem::path path_;
  std::FILE* file_ = nullptr;
  std::uint64_t size_ = 0;
  std::uint64_t offset_ = 0;
};

/// Receives the next chunk of a file being written; returns an error when the write failed.
using ChunkSink = std::function<Status(std::span<const std::uint8_t>)>;
/// Produces a file's content by calling the sink with consecutive chunks (of any size, copied or
/// written straight through). A non-ok return aborts the write.
using ChunkProducer = std::function<Status(const ChunkSink&)>;

/// Writes bytes to path, replacing it only once complete (see the file comment). Errors name the
/// path and the reason.
Status write_file_atomic(const std::filesystem::path& path, std::span<const std::uint8_t> bytes);
/// Streaming variant: the content comes from produce, so a large table is never copied into a
/// second buffer. An error from produce is returned as is, after the temporary is removed.
Status write_file_atomic(const std::filesystem::path& path, const ChunkProducer& produce);

}  // namespace cbrdf
