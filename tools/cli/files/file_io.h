// SPDX-License-Identifier: MIT
// The command's file layer (POSIX): whole-file reads with a size limit, a streaming reader, and
// atomic file writes that know every kind of output a shell hands a program. The libraries use the
// plain, portable cbrdf/file_io.h instead; this layer is the application's (the `cbrdf` command),
// with the same names in namespace cbrdf::cli, so that code inside that namespace uses it.
//
// Every writer of the command goes through write_file_atomic. What it does depends on what the path
// names:
// - a new name or a regular file: the bytes go to a temporary file in the target's directory, are
//   fsync'ed, and the temporary is renamed over the target. A failed write leaves an existing
//   target untouched and no temporary, so no run leaves a partial file behind. The temporary is an
//   unnamed O_TMPFILE file where the filesystem supports it, given a name only for the instant
//   before the rename; elsewhere it is named `.NAME.cbrdf-tmp-PID-N` (NAME shortened so that the
//   temporary's name fits wherever NAME fits). remove_temporaries_on_signals() removes named
//   temporaries when SIGINT, SIGTERM or SIGHUP ends the process; after SIGKILL or a power loss a
//   `.NAME.cbrdf-tmp-PID-N` file may remain and can be deleted.
// - a symbolic link: followed through every level; its final target is replaced as above and the
//   link itself stays (as cp, gzip and zstd do).
// - an existing character device (/dev/null, a terminal) or FIFO: opened and written through, with
//   no temporary (a failed write may leave part of the output there).
// - a path naming an open descriptor (/dev/stdout, /dev/stderr, /dev/fd/N, /proc/self/fd/N): the
//   bytes are written to that descriptor at its current offset, whatever it refers to.
// - a directory, a block device or a socket: refused (kIo), naming the kind.
//
// Readers (read_file, FileReader) open regular files only: a FIFO, device or socket named by a path
// is refused at once (it is opened non-blocking, never waited on). A path naming an open descriptor
// (/dev/stdin, /dev/fd/N, /proc/self/fd/N) is read from that descriptor to its end, whatever it is.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <span>
#include <utility>
#include <vector>

#include "cbrdf/brdf_table.h"
#include "cbrdf/file_io.h"  // ChunkSink, ChunkProducer
#include "cbrdf/merl_io.h"
#include "cbrdf/status.h"

namespace cbrdf::cli {

// Reads a whole regular file. Errors: kNotFound ("FILE: no such file"), kIo (a directory, a FIFO,
// a device, permission, a failed read), kLimit when the file is larger than max_bytes (both sizes
// in the message).
Expected<std::vector<std::uint8_t>> read_file(const std::filesystem::path& path,
                                              std::uint64_t max_bytes);

// A regular file opened for sequential reading, for parsers that read a small header first and then
// stream the body straight into its final buffer. Move-only; closes on destruction.
class FileReader {
 public:
  // Same errors as read_file for a missing file, a directory or a refused open. A path naming a
  // descriptor (a pipe on standard input) is read into memory up to max_stream_bytes (kLimit past
  // it), so size() is known as for a file.
  static Expected<FileReader> open(const std::filesystem::path& path,
                                   std::uint64_t max_stream_bytes = kMaxStreamBytes);
  static constexpr std::uint64_t kMaxStreamBytes = std::uint64_t{256} << 20;

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
  std::vector<std::uint8_t> buffered_;  // the whole content, for a stream
  std::uint64_t size_ = 0;
  std::uint64_t offset_ = 0;
};

// Writes bytes to path atomically (see the file comment). Errors name the path and the OS reason.
Status write_file_atomic(const std::filesystem::path& path, std::span<const std::uint8_t> bytes);
// Streaming variant: the content comes from produce, so a large table is never copied into a
// second buffer. An error from produce is returned as is, after the temporary is removed.
Status write_file_atomic(const std::filesystem::path& path, const ChunkProducer& produce);

// The descriptor a path names (/dev/stdin 0, /dev/stdout 1, /dev/stderr 2, /dev/fd/N,
// /proc/self/fd/N), or -1 for any other path. Such paths are read and written through the
// descriptor (see the file comment).
int descriptor_of_path(const std::filesystem::path& path);

// read_merl and write_merl (cbrdf/merl_io.h) through this layer: a path naming a descriptor
// (/dev/stdin, /dev/stdout) is read or written through it, a FIFO is refused at once, and so on.
Expected<BrdfTable> read_merl_input(const std::filesystem::path& path,
                                    const MerlReadOptions& options = {}, MerlInfo* info = nullptr);
Status write_merl_output(const std::filesystem::path& path, const BrdfTable& table);

// Installs handlers for SIGINT, SIGTERM and SIGHUP (those not ignored) that remove the named
// temporaries of writes in progress, then let the signal end the process as it would have. For
// programs (the `cbrdf` command calls it first thing); a library never installs handlers itself.
void remove_temporaries_on_signals();

// While `flag` is set here (not null), the first SIGINT sets *flag instead of ending the process
// (handled once: a second SIGINT ends it, removing temporaries, as before), for work that stops
// cleanly when asked, such as an encode watching the flag from its progress callback. Null: back
// to ending the process. Needs remove_temporaries_on_signals() first.
void interrupt_sets_flag(std::atomic<bool>* flag);

// SIGINT sets *flag while the scope lasts (interrupt_sets_flag).
class InterruptScope {
 public:
  explicit InterruptScope(std::atomic<bool>* flag) { interrupt_sets_flag(flag); }
  ~InterruptScope() { end(); }
  // From here SIGINT ends the process again (removing the temporaries of writes).
  void end() { interrupt_sets_flag(nullptr); }
  InterruptScope(const InterruptScope&) = delete;
  InterruptScope& operator=(const InterruptScope&) = delete;
};

}  // namespace cbrdf::cli
