#include "server/descriptor_budget.h"

#include <sys/resource.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <vector>

namespace hpose::server {
namespace {

// Lowers the soft descriptor limit for one test, and restores it.
class ScopedDescriptorLimit {
 public:
  explicit ScopedDescriptorLimit(rlim_t soft) {
    getrlimit(RLIMIT_NOFILE, &saved_);
    rlimit lowered = saved_;
    lowered.rlim_cur = soft;
    ok_ = setrlimit(RLIMIT_NOFILE, &lowered) == 0;
  }
  ~ScopedDescriptorLimit() { setrlimit(RLIMIT_NOFILE, &saved_); }
  bool ok() const { return ok_; }

 private:
  rlimit saved_{};
  bool ok_ = false;
};

TEST(DescriptorBudgetTest, CountsWhatIsOpen) {
  const int before = OpenDescriptors();
  ASSERT_GT(before, 2);  // at least standard input, output and error.
  std::vector<int> opened;
  for (int i = 0; i < 10; ++i) opened.push_back(dup(1));
  EXPECT_EQ(OpenDescriptors(), before + 10);
  for (int fd : opened) close(fd);
  EXPECT_EQ(OpenDescriptors(), before);
}

TEST(DescriptorBudgetTest, ConnectionsStopShortOfTheReserve) {
  const int open = OpenDescriptors();
  // A limit with room for the reserve and five more: the sixth connection waits.
  const int reserve = 64;  // a quarter of a 256 limit.
  const rlim_t limit = 256;
  ASSERT_LT(open + reserve + 5, static_cast<int>(limit)) << "too many open to test";
  ScopedDescriptorLimit scoped(limit);
  ASSERT_TRUE(scoped.ok());
  EXPECT_EQ(ReservedDescriptors(), reserve);
  std::vector<int> held;
  while (MayAcceptConnection() && held.size() < limit) held.push_back(dup(1));
  EXPECT_EQ(OpenDescriptors() + reserve, static_cast<int>(limit));
  EXPECT_EQ(static_cast<int>(limit) - open - reserve, static_cast<int>(held.size()));
  for (int fd : held) close(fd);
  EXPECT_TRUE(MayAcceptConnection());
}

TEST(DescriptorBudgetTest, ReserveIsAtMost128) {
  rlimit limit{};
  getrlimit(RLIMIT_NOFILE, &limit);
  if (limit.rlim_cur >= 512) EXPECT_EQ(ReservedDescriptors(), 128);
  ScopedDescriptorLimit scoped(100);
  ASSERT_TRUE(scoped.ok());
  EXPECT_EQ(ReservedDescriptors(), 25);
}

}  // namespace
}  // namespace hpose::server
