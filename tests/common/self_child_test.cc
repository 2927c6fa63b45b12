#include "core/common/self_child.h"

#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <new>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "tests/sanitizer_build.h"

namespace hpose {
namespace {

constexpr char kVariable[] = "HPOSE_SELF_CHILD_TEST";

// This test program's own child: does what its variable says and ends before main.
[[noreturn]] void RunTestChild(const std::string& what) {
  if (what == "echo-large") {  // more than a pipe holds, so the parent must read as it goes.
    const std::string block(1 << 20, 'x');
    _exit(WriteSelfChildOutput(block.data(), block.size()) ? 0 : 1);
  }
  if (what == "status") {
    WriteSelfChildOutput("partial", 7);
    _exit(5);
  }
  if (what == "limited") {  // 512 MiB asked for under a 128 MiB limit.
    LimitSelfChildMemory(128ull << 20);
    try {
      std::vector<char> block(512u << 20);
      std::memset(block.data(), 1, block.size());
      _exit(block[block.size() - 1] == 1 ? 8 : 1);
    } catch (const std::bad_alloc&) {
      _exit(7);
    }
  }
  if (what == "killed") kill(getpid(), SIGKILL);
  if (what == "silent") std::this_thread::sleep_for(std::chrono::seconds(60));
  if (what == "talkative") {  // a write every 0.1 s for 1.2 s, then done.
    for (int i = 0; i < 12; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
      WriteSelfChildOutput(".", 1);
    }
    _exit(0);
  }
  _exit(9);
}

const bool kRanAsChild = [] {
  if (const char* what = RunningAsSelfChild(kVariable)) RunTestChild(what);
  return false;
}();

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

TEST(SelfChildTest, CollectsWhatTheChildWritesAndHowItEnded) {
  (void)kRanAsChild;
  const SelfChildRun large = RunSelfAsChild(kVariable, "echo-large", 60.0);
  ASSERT_TRUE(large.started);
  EXPECT_FALSE(large.timed_out);
  EXPECT_EQ(large.exit_status, 0);
  EXPECT_EQ(large.signal, 0);
  EXPECT_EQ(large.output, std::string(1 << 20, 'x'));

  const SelfChildRun status = RunSelfAsChild(kVariable, "status", 60.0);
  ASSERT_TRUE(status.started);
  EXPECT_EQ(status.exit_status, 5);
  EXPECT_EQ(status.output, "partial");
  EXPECT_EQ(DescribeSelfChildEnd(status, 60.0), "ended with status 5");

  const SelfChildRun killed = RunSelfAsChild(kVariable, "killed", 60.0);
  ASSERT_TRUE(killed.started);
  EXPECT_EQ(killed.signal, SIGKILL);
  EXPECT_EQ(killed.exit_status, -1);
  EXPECT_EQ(DescribeSelfChildEnd(killed, 60.0), "died of SIGKILL");
}

TEST(SelfChildTest, ASilentChildIsKilledAtItsTimeAndAWritingOneIsNot) {
  const auto start = std::chrono::steady_clock::now();
  const SelfChildRun silent = RunSelfAsChild(kVariable, "silent", 0.5);
  ASSERT_TRUE(silent.started);
  EXPECT_TRUE(silent.timed_out);
  EXPECT_LT(SecondsSince(start), 30.0);  // not the child's 60 s
  EXPECT_EQ(DescribeSelfChildEnd(silent, 0.5), "did not finish within 0.5 s");

  // 1.2 s in all, but never 0.5 s without a write (the time restarts with each).
  const SelfChildRun talkative = RunSelfAsChild(kVariable, "talkative", 0.5);
  ASSERT_TRUE(talkative.started);
  EXPECT_FALSE(talkative.timed_out);
  EXPECT_EQ(talkative.exit_status, 0);
  EXPECT_EQ(talkative.output, std::string(12, '.'));
}

TEST(SelfChildTest, AChildsMemoryLimitMakesItsAllocationsFail) {
  const SelfChildRun limited = RunSelfAsChild(kVariable, "limited", 60.0);
  ASSERT_TRUE(limited.started);
  // std::bad_alloc past the limit; AddressSanitizer's build leaves the limit off (its shadow
  // memory needs the address space), so the allocation is made there.
  EXPECT_EQ(limited.exit_status, testing::kSanitizerBuild ? 8 : 7);
  EXPECT_GE(HalfThePhysicalMemory(), 1ull << 30);
}

TEST(SelfChildTest, ChildrenRunFromSeveralThreadsAtOnce) {
  SelfChildRun runs[4];
  std::thread threads[4];
  for (int i = 0; i < 4; ++i) {
    threads[i] = std::thread([&runs, i] { runs[i] = RunSelfAsChild(kVariable, "status", 60.0); });
  }
  for (std::thread& t : threads) t.join();
  for (const SelfChildRun& run : runs) {
    ASSERT_TRUE(run.started);
    EXPECT_EQ(run.exit_status, 5);
    EXPECT_EQ(run.output, "partial");  // no child held another's pipe open
  }
}

}  // namespace
}  // namespace hpose
