// SPDX-License-Identifier: MIT
// What write_file_atomic and the readers do with every kind of path: devices, FIFOs, sockets,
// symbolic links, descriptors, long names, and signals during a write (cbrdf/file_io.h).
#include "files/file_io.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "files/temp_registry.h"
#include "test_support.h"

namespace cbrdf::cli {
namespace {
using testing::bytes_of;
using testing::contains;
namespace fs = std::filesystem;
using testing::dir_entries;
using testing::TempDir;

std::string text_of(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Makes a device node in a test directory (never in /dev); false where that is not permitted.
bool make_node(const fs::path& p, mode_t kind, unsigned major_no, unsigned minor_no) {
  return ::mknod(p.c_str(), kind | 0666, makedev(major_no, minor_no)) == 0;
}

// ---------------------------------------------------------------------------------------------
// Outputs that are not regular files

// A character device is written through, not replaced by a regular file (as root, `-o /dev/null`
// used to turn /dev/null into a 35 MB file).
TEST(WriteOutput, CharacterDeviceIsWrittenThroughNotReplaced) {
  TempDir tmp;
  const fs::path null_node = tmp / "null";
  if (!make_node(null_node, S_IFCHR, 1, 3)) GTEST_SKIP() << "mknod not permitted here";
  const Status s = write_file_atomic(null_node, std::vector<std::uint8_t>(200000, 7));
  ASSERT_TRUE(s.ok()) << s.message();
  struct stat st {};
  ASSERT_EQ(::lstat(null_node.c_str(), &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode)) << "the device node was replaced";
  EXPECT_EQ(dir_entries(tmp.path()), std::vector<std::string>{"null"}) << "a temporary was left";
}

TEST(WriteOutput, FifoIsWrittenThrough) {
  TempDir tmp;
  const fs::path fifo = tmp / "pipe";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::vector<std::uint8_t> content(300000, 0x5A);
  std::string received;
  std::thread reader([&] {
    std::ifstream in(fifo, std::ios::binary);
    received.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  });
  const Status s = write_file_atomic(fifo, content);
  reader.join();
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(received.size(), content.size());
  EXPECT_EQ(received, std::string(content.begin(), content.end()));
  struct stat st {};
  ASSERT_EQ(::lstat(fifo.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
}

TEST(WriteOutput, BlockDeviceAndSocketAreRefusedAndKept) {
  TempDir tmp;
  const fs::path block = tmp / "disk";
  if (make_node(block, S_IFBLK, 7, 0)) {
    const Status s = write_file_atomic(block, bytes_of("data"));
    EXPECT_EQ(s.code(), ErrorCode::kIo);
    EXPECT_TRUE(contains(s.message(), "it is a block device")) << s.message();
    struct stat st {};
    ASSERT_EQ(::lstat(block.c_str(), &st), 0);
    EXPECT_TRUE(S_ISBLK(st.st_mode));
  }
  const fs::path sock_path = tmp / "sock";
  const int sock = ::socket(AF_UNIX, SOCK_STREAM, 0);
  ASSERT_GE(sock, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  ASSERT_LT(sock_path.string().size(), sizeof addr.sun_path);
  std::strcpy(addr.sun_path, sock_path.c_str());
  ASSERT_EQ(::bind(sock, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  const Status s = write_file_atomic(sock_path, bytes_of("data"));
  ::close(sock);
  EXPECT_EQ(s.code(), ErrorCode::kIo);
  EXPECT_TRUE(contains(s.message(), "it is a socket")) << s.message();
  EXPECT_TRUE(fs::is_socket(sock_path));
}

// A symbolic link is followed (every level) and its final target replaced atomically; the links
// stay links. A dangling link creates its target; a loop is refused.
TEST(WriteOutput, SymbolicLinksAreFollowed) {
  TempDir tmp;
  fs::create_directory(tmp / "real");
  std::ofstream(tmp / "real" / "target.bin") << "old";
  fs::create_symlink("real/target.bin", tmp / "link1");
  fs::create_symlink(tmp / "link1", tmp / "link2");
  const Status s = write_file_atomic(tmp / "link2", bytes_of("new content"));
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_TRUE(fs::is_symlink(tmp / "link1"));
  EXPECT_TRUE(fs::is_symlink(tmp / "link2"));
  EXPECT_EQ(text_of(tmp / "real" / "target.bin"), "new content");
  EXPECT_EQ(dir_entries(tmp / "real"), std::vector<std::string>{"target.bin"});

  fs::create_symlink("created.bin", tmp / "dangling");
  ASSERT_TRUE(write_file_atomic(tmp / "dangling", bytes_of("x")).ok());
  EXPECT_TRUE(fs::is_symlink(tmp / "dangling"));
  EXPECT_EQ(text_of(tmp / "created.bin"), "x");

  fs::create_symlink("loop-b", tmp / "loop-a");
  fs::create_symlink("loop-a", tmp / "loop-b");
  const Status loop = write_file_atomic(tmp / "loop-a", bytes_of("x"));
  EXPECT_EQ(loop.code(), ErrorCode::kIo);
  EXPECT_TRUE(contains(loop.message(), "too many levels of symbolic links")) << loop.message();
}

// A path naming a descriptor writes to that descriptor at its offset: `-o /dev/stdout >> log`
// appends instead of replacing the log.
TEST(WriteOutput, DescriptorPathWritesToTheDescriptor) {
  TempDir tmp;
  const fs::path log = tmp / "log";
  std::ofstream(log) << "head|";
  const int fd = ::open(log.c_str(), O_WRONLY | O_APPEND);
  ASSERT_GE(fd, 0);
  const Status s = write_file_atomic("/dev/fd/" + std::to_string(fd), bytes_of("tail"));
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_TRUE(::fcntl(fd, F_GETFD) != -1) << "the caller's descriptor was closed";
  ::close(fd);
  EXPECT_EQ(text_of(log), "head|tail");
  EXPECT_EQ(dir_entries(tmp.path()), std::vector<std::string>{"log"});

  int p[2];
  ASSERT_EQ(::pipe(p), 0);
  ASSERT_TRUE(write_file_atomic("/proc/self/fd/" + std::to_string(p[1]), bytes_of("piped")).ok());
  ::close(p[1]);
  char buf[16] = {};
  EXPECT_EQ(::read(p[0], buf, sizeof buf), 5);
  ::close(p[0]);
  EXPECT_EQ(std::string(buf), "piped");

  const Status closed = write_file_atomic("/dev/fd/987", bytes_of("x"));
  EXPECT_EQ(closed.code(), ErrorCode::kIo);
  EXPECT_TRUE(contains(closed.message(), "descriptor 987 is not open")) << closed.message();
}

TEST(WriteOutput, DescriptorPathsAreRecognised) {
  EXPECT_EQ(descriptor_of_path("/dev/stdin"), 0);
  EXPECT_EQ(descriptor_of_path("/dev/stdout"), 1);
  EXPECT_EQ(descriptor_of_path("/dev/stderr"), 2);
  EXPECT_EQ(descriptor_of_path("/dev/fd/63"), 63);
  EXPECT_EQ(descriptor_of_path("/proc/self/fd/5"), 5);
  EXPECT_EQ(descriptor_of_path("/dev/fd/"), -1);
  EXPECT_EQ(descriptor_of_path("/dev/fd/5x"), -1);
  EXPECT_EQ(descriptor_of_path("dev/stdout"), -1);
  EXPECT_EQ(descriptor_of_path("-"), -1);
}

// ---------------------------------------------------------------------------------------------
// Temporaries: names that fit, none visible, none left after a signal

// The temporary's name fits wherever the target's does (a 255-byte name used to fail with "File
// name too long" because the temporary's was longer).
TEST(WriteOutput, LongestFileNameWorks) {
  TempDir tmp;
  const std::string name(255, 'n');
  const Status s = write_file_atomic(tmp / name, bytes_of("long"));
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(text_of(tmp / name), "long");
  EXPECT_EQ(dir_entries(tmp.path()), std::vector<std::string>{name});
}

TEST(TemporaryName, FitsAndIsRecognisable) {
  for (std::size_t n : {1u, 10u, 200u, 240u, 254u, 255u}) {
    const std::string t = temporary_name(std::string(n, 'a'), 255, 4194304, 4000000000u);
    EXPECT_LE(t.size(), 255u) << n;
    EXPECT_EQ(t.front(), '.');
    EXPECT_TRUE(contains(t, ".cbrdf-tmp-4194304-4000000000")) << t;
  }
  EXPECT_EQ(temporary_name("out.binary", 255, 42, 7), ".out.binary.cbrdf-tmp-42-7");
  // A cut never splits a UTF-8 character: "é" is two bytes.
  std::string accents;
  for (int i = 0; i < 127; ++i) accents += "\xC3\xA9";
  const std::string t = temporary_name(accents, 255, 42, 7);
  EXPECT_LE(t.size(), 255u);
  const std::string suffix = ".cbrdf-tmp-42-7";
  ASSERT_GT(t.size(), 1 + suffix.size()) << t;
  EXPECT_EQ(t.substr(t.size() - suffix.size()), suffix) << t;
  const std::string kept = t.substr(1, t.size() - 1 - suffix.size());
  EXPECT_EQ(kept.size() % 2, 0u) << t;  // whole two-byte characters only
  EXPECT_EQ(kept, accents.substr(0, kept.size())) << t;
}

// Where the filesystem has O_TMPFILE (ext4, tmpfs, xfs, btrfs), nothing is visible while the
// content is produced, so no kill at any moment but the rename itself can leave a temporary.
TEST(WriteOutput, NoNamedTemporaryWhileWriting) {
  TempDir tmp;
  std::vector<std::string> seen;
  const Status s = write_file_atomic(tmp / "out.bin", [&](const ChunkSink& sink) -> Status {
    CBRDF_RETURN_IF_ERROR(sink(std::vector<std::uint8_t>(100000, 1)));
    seen = dir_entries(tmp.path());
    return sink(std::vector<std::uint8_t>(100000, 2));
  });
  ASSERT_TRUE(s.ok()) << s.message();
  const int probe = ::open(tmp.path().c_str(), O_TMPFILE | O_WRONLY, 0600);
  if (probe >= 0) {
    ::close(probe);
    EXPECT_TRUE(seen.empty()) << "visible during the write: " << seen.front();
  } else {
    // No O_TMPFILE here: a named temporary, recognisable by its name.
    ASSERT_EQ(seen.size(), 1u);
    EXPECT_EQ(seen[0].rfind(".out.bin.cbrdf-tmp-" + std::to_string(::getpid()) + "-", 0), 0u)
        << seen[0];
  }
  EXPECT_EQ(dir_entries(tmp.path()), std::vector<std::string>{"out.bin"});
}

// Runs body in a child process and returns its wait status.
template <typename Body>
int in_child(Body body) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    body();
    ::_exit(0);
  }
  int wstatus = 0;
  ::waitpid(pid, &wstatus, 0);
  return wstatus;
}

// The handlers remove registered temporaries and then let the signal end the process with its
// usual status.
TEST(SignalCleanup, RegisteredTemporaryIsRemovedOnIntTermHup) {
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
    TempDir tmp;
    const fs::path tmp_file = tmp / ".out.binary.cbrdf-tmp-1-0";
    std::ofstream(tmp_file) << "partial";
    const int wstatus = in_child([&] {
      remove_temporaries_on_signals();
      temp_registry::add(tmp_file.c_str());
      ::raise(sig);
      ::_exit(3);  // not reached: the signal ends the process
    });
    ASSERT_TRUE(WIFSIGNALED(wstatus)) << "signal " << sig;
    EXPECT_EQ(WTERMSIG(wstatus), sig);
    EXPECT_FALSE(fs::exists(tmp_file)) << "signal " << sig;
  }
}

// A signal during a real write leaves nothing: neither the target nor a temporary, named or not.
TEST(SignalCleanup, SignalDuringWriteLeavesNoFiles) {
  TempDir tmp;
  const int wstatus = in_child([&] {
    remove_temporaries_on_signals();
    (void)write_file_atomic(tmp / "out.bin", [](const ChunkSink& sink) -> Status {
      CBRDF_RETURN_IF_ERROR(sink(std::vector<std::uint8_t>(1 << 20, 1)));
      ::raise(SIGTERM);
      return sink(std::vector<std::uint8_t>(1 << 20, 2));
    });
    ::_exit(3);
  });
  ASSERT_TRUE(WIFSIGNALED(wstatus));
  EXPECT_EQ(WTERMSIG(wstatus), SIGTERM);
  EXPECT_TRUE(dir_entries(tmp.path()).empty());
}

// A signal the caller ignores (nohup) stays ignored; a removed registration is not unlinked.
TEST(SignalCleanup, IgnoredSignalStaysIgnored) {
  TempDir tmp;
  const fs::path kept = tmp / "kept";
  std::ofstream(kept) << "x";
  const int wstatus = in_child([&] {
    ::signal(SIGHUP, SIG_IGN);
    remove_temporaries_on_signals();
    temp_registry::remove(temp_registry::add(kept.c_str()));
    ::raise(SIGHUP);
    ::_exit(0);
  });
  ASSERT_TRUE(WIFEXITED(wstatus));
  EXPECT_EQ(WEXITSTATUS(wstatus), 0);
  EXPECT_TRUE(fs::exists(kept));
}

// ---------------------------------------------------------------------------------------------
// Inputs

// A FIFO named as an input is refused at once; it used to block in open() forever.
TEST(ReadInput, FifoAndDevicesAreRefusedAtOnce) {
  TempDir tmp;
  const fs::path fifo = tmp / "f";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  auto r = read_file(fifo, 100);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), ErrorCode::kIo);
  EXPECT_TRUE(contains(r.status().message(), "is a FIFO (named pipe), not a regular file"))
      << r.status().message();
  auto fr = FileReader::open(fifo);
  ASSERT_FALSE(fr.ok());
  EXPECT_EQ(fr.status().code(), ErrorCode::kIo);
  const fs::path zero = tmp / "zero";
  if (make_node(zero, S_IFCHR, 1, 5)) {
    auto z = read_file(zero, 100);
    ASSERT_FALSE(z.ok());
    EXPECT_TRUE(contains(z.status().message(), "is a character device")) << z.status().message();
  }
}

// A descriptor path reads the descriptor to its end (standard input as a pipe), within the limit.
TEST(ReadInput, DescriptorPathReadsAPipe) {
  int p[2];
  ASSERT_EQ(::pipe(p), 0);
  const std::string content(100000, 'q');
  std::thread writer([&] {
    (void)!::write(p[1], content.data(), content.size());
    ::close(p[1]);
  });
  auto r = read_file("/dev/fd/" + std::to_string(p[0]), 200000);
  writer.join();
  ::close(p[0]);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(std::string(r->begin(), r->end()), content);

  // 5000 bytes fit in the pipe's buffer: the write completes before the reader gives up.
  ASSERT_EQ(::pipe(p), 0);
  ASSERT_EQ(::write(p[1], content.data(), 5000), 5000);
  ::close(p[1]);
  auto limited = FileReader::open("/dev/fd/" + std::to_string(p[0]), 1000);
  ::close(p[0]);
  ASSERT_FALSE(limited.ok());
  EXPECT_EQ(limited.status().code(), ErrorCode::kLimit);
  EXPECT_TRUE(contains(limited.status().message(), "more than the limit of 1000 bytes"))
      << limited.status().message();
}

TEST(ReadInput, BufferedStreamReaderReadsAndTruncates) {
  int p[2];
  ASSERT_EQ(::pipe(p), 0);
  ASSERT_EQ(::write(p[1], "0123456789", 10), 10);
  ::close(p[1]);
  auto r = FileReader::open("/dev/fd/" + std::to_string(p[0]));
  ::close(p[0]);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(r->size(), 10u);
  char buf[8] = {};
  ASSERT_TRUE(r->read_exact(buf, 4).ok());
  EXPECT_EQ(std::string(buf, 4), "0123");
  const Status s = r->read_exact(buf, 8);
  EXPECT_EQ(s.code(), ErrorCode::kTruncated);
  EXPECT_TRUE(
      contains(s.message(), "ends at byte offset 10, but 8 bytes were needed from offset 4"))
      << s.message();
}

}  // namespace
}  // namespace cbrdf::cli
