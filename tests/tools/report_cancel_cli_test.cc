// SPDX-License-Identifier: MIT
// Ctrl-C during `cbrdf report` (issue 41, item 4): the running encodes stop through their
// progress callbacks, no report is written (not even its directory), the command says
// "cbrdf: cancelled" and exits with 130. The time from the signal to the exit is printed.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <thread>

#include "cbrdf/merl_io.h"
#include "cbrdf/samples.h"
#include "test_support.h"

namespace cbrdf {
namespace {
namespace fs = std::filesystem;
using testing::TempDir;

struct Exit {
  int status = -1;  // waitpid's
  double ms_after_signal = 0;
  std::string err;
};

// Runs `cbrdf report in -o out --jobs 1 --progress always`, sends SIGINT after `delay`, waits.
Exit interrupt_report(const fs::path& in, const fs::path& out, const fs::path& err,
                      std::chrono::milliseconds delay) {
  std::fflush(stdout);  // else the child's freopen writes out what the parent buffered
  const pid_t pid = ::fork();
  if (pid == 0) {
    // A shell that starts a job in the background ignores SIGINT in it; the test wants the
    // disposition a terminal's job has.
    ::signal(SIGINT, SIG_DFL);
    std::FILE* e = std::freopen(err.c_str(), "w", stderr);
    std::FILE* o = std::freopen("/dev/null", "w", stdout);
    if (e == nullptr || o == nullptr) ::_exit(127);
    ::execl(CBRDF_CLI_PATH, "cbrdf", "report", in.c_str(), "-o", out.c_str(), "--jobs", "1",
            "--progress", "always", static_cast<char*>(nullptr));
    ::_exit(127);
  }
  Exit r;
  if (pid < 0) return r;
  std::this_thread::sleep_for(delay);
  const auto sent = std::chrono::steady_clock::now();
  ::kill(pid, SIGINT);
  ::waitpid(pid, &r.status, 0);
  r.ms_after_signal =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - sent).count();
  r.err = testing::read_text(err);
  return r;
}

TEST(ReportCancelCli, CtrlCCancelsTheEncodesAndWritesNoReport) {
  TempDir tmp;
  const fs::path in = tmp / "gold.binary";
  auto table = make_sample("gold-metallic-paint");
  ASSERT_TRUE(table.ok()) << table.status().message();
  ASSERT_TRUE(write_merl(in, *table).ok());
  const fs::path out = tmp / "report", err = tmp / "err.txt";
  // During the first fit, and later in the sweep.
  for (int delay_ms : {400, 1500}) {
    const Exit r = interrupt_report(in, out, err, std::chrono::milliseconds(delay_ms));
    ASSERT_TRUE(WIFEXITED(r.status)) << "signal after " << delay_ms << " ms: ended by signal "
                                     << (WIFSIGNALED(r.status) ? WTERMSIG(r.status) : 0);
    EXPECT_EQ(WEXITSTATUS(r.status), 130) << r.err;
    EXPECT_TRUE(testing::contains(r.err, "cbrdf: cancelled")) << r.err;
    EXPECT_FALSE(fs::exists(out));
    EXPECT_EQ(testing::dir_entries(tmp.path()),
              (std::vector<std::string>{"err.txt", "gold.binary"}));
    std::printf("cbrdf report, SIGINT after %d ms: exited %.1f ms later\n", delay_ms,
                r.ms_after_signal);
  }
}

}  // namespace
}  // namespace cbrdf
