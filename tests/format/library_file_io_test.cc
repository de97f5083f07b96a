// SPDX-License-Identifier: MIT
// The libraries' portable file layer (cbrdf/file_io.h): regular files only, refusals named, writes
// that replace their target only once complete. The command's POSIX layer is file_io_test.cc.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "cbrdf/file_io.h"
#include "test_support.h"

namespace cbrdf {
namespace {
namespace fs = std::filesystem;
using testing::bytes_of;
using testing::contains;
using testing::dir_entries;
using testing::TempDir;

std::string text_of(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

TEST(LibraryFileIo, ReadsAWholeFileAndRefusesWhatIsNotOne) {
  TempDir tmp;
  const fs::path file = tmp.path() / "a.bin";
  std::ofstream(file, std::ios::binary) << "hello";
  auto bytes = read_file(file, 100);
  ASSERT_TRUE(bytes.ok()) << bytes.status().message();
  EXPECT_EQ(*bytes, bytes_of("hello"));

  auto limited = read_file(file, 4);
  EXPECT_EQ(limited.status().code(), ErrorCode::kLimit);
  EXPECT_TRUE(contains(limited.status().message(), "limit of 4 bytes"));

  auto missing = read_file(tmp.path() / "nope.bin", 100);
  EXPECT_EQ(missing.status().code(), ErrorCode::kNotFound);
  EXPECT_TRUE(contains(missing.status().message(), "nope.bin: no such file"));

  auto empty = read_file("", 100);
  EXPECT_EQ(empty.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_TRUE(contains(empty.status().message(), "no file name given"));

  auto dir = read_file(tmp.path(), 100);
  EXPECT_EQ(dir.status().code(), ErrorCode::kIo);
  EXPECT_TRUE(contains(dir.status().message(), "is a directory"));

  // A FIFO with no writer is refused at once, not waited on.
  const fs::path fifo = tmp.path() / "fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  auto pipe = read_file(fifo, 100);
  EXPECT_EQ(pipe.status().code(), ErrorCode::kIo);
  EXPECT_TRUE(contains(pipe.status().message(), "a FIFO (named pipe), not a regular file"))
      << pipe.status().message();
}

TEST(LibraryFileIo, FileReaderReportsWhereAFileEnds) {
  TempDir tmp;
  const fs::path file = tmp.path() / "short.bin";
  std::ofstream(file, std::ios::binary) << "abcdef";
  auto reader = FileReader::open(file);
  ASSERT_TRUE(reader.ok());
  EXPECT_EQ(reader->size(), 6u);
  char buf[8] = {};
  ASSERT_TRUE(reader->read_exact(buf, 4).ok());
  EXPECT_EQ(std::string(buf, 4), "abcd");
  const Status s = reader->read_exact(buf, 4);
  EXPECT_EQ(s.code(), ErrorCode::kTruncated);
  EXPECT_TRUE(contains(s.message(), "file ends at byte offset 6")) << s.message();
  // Moving keeps the open file with the new owner.
  FileReader moved = std::move(*reader);
  EXPECT_EQ(moved.offset(), 4u);
}

TEST(LibraryFileIo, WritesReplaceTheTargetAndLeaveNoTemporary) {
  TempDir tmp;
  const fs::path out = tmp.path() / "out.bin";
  ASSERT_TRUE(write_file_atomic(out, bytes_of("first")).ok());
  ASSERT_TRUE(write_file_atomic(out, bytes_of("second")).ok());
  EXPECT_EQ(text_of(out), "second");
  EXPECT_EQ(dir_entries(tmp.path()), std::vector<std::string>{"out.bin"});

  // A producer that fails leaves the old content and no temporary.
  const Status failed = write_file_atomic(out, [](const ChunkSink& sink) -> Status {
    CBRDF_RETURN_IF_ERROR(sink(std::span<const std::uint8_t>(bytes_of("partial"))));
    return error(ErrorCode::kNumeric, "stopped on purpose");
  });
  EXPECT_EQ(failed.code(), ErrorCode::kNumeric);
  EXPECT_EQ(text_of(out), "second");
  EXPECT_EQ(dir_entries(tmp.path()), std::vector<std::string>{"out.bin"});
}

TEST(LibraryFileIo, WritesFollowSymbolicLinksAndRefuseWhatIsNotAFile) {
  TempDir tmp;
  fs::create_directory(tmp.path() / "real");
  fs::create_symlink("real/target.bin", tmp.path() / "link");
  ASSERT_TRUE(write_file_atomic(tmp.path() / "link", bytes_of("via link")).ok());
  EXPECT_TRUE(fs::is_symlink(tmp.path() / "link"));
  EXPECT_EQ(text_of(tmp.path() / "real" / "target.bin"), "via link");

  const Status dir = write_file_atomic(tmp.path() / "real", bytes_of("x"));
  EXPECT_EQ(dir.code(), ErrorCode::kIo);
  EXPECT_TRUE(contains(dir.message(), "a directory, not a regular file")) << dir.message();

  const Status missing_dir = write_file_atomic(tmp.path() / "no" / "such" / "x.bin", bytes_of("x"));
  EXPECT_EQ(missing_dir.code(), ErrorCode::kIo);
  EXPECT_TRUE(contains(missing_dir.message(), "x.bin")) << missing_dir.message();

  const Status empty = write_file_atomic("", bytes_of("x"));
  EXPECT_EQ(empty.code(), ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace cbrdf
