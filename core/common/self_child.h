#ifndef HPOSE_CORE_COMMON_SELF_CHILD_H_
#define HPOSE_CORE_COMMON_SELF_CHILD_H_

#include <string>

namespace hpose {

// How a child started by RunSelfAsChild ended.
struct SelfChildRun {
  bool started = false;    // false: no child could be started (nothing else is set)
  bool timed_out = false;  // killed after the time given without a write
  int exit_status = -1;    // its exit status when it exited, else -1
  int signal = 0;          // the signal that ended it, else 0
  std::string output;      // what it wrote to descriptor 3 (SelfChildOutputFd)
};

// Runs this program again (/proc/self/exe) as a child with `variable`=`value` added to its
// environment, for work that may crash or hang in a third-party library (a damaged file): the
// program stops the child before main with a static initialiser that sees the variable
// (RunningAsSelfChild), does the work and _exits with a status of its own choosing. What the
// child writes to SelfChildOutputFd() is collected; a child that runs `timeout_s` without
// writing (the time starts again with each write, so work in steps can report each) is killed.
// Thread-safe; the caller's standard streams are the child's too.
SelfChildRun RunSelfAsChild(const std::string& variable, const std::string& value,
                            double timeout_s);

// The value of `variable` when this process is a child started with it, else nullptr.
const char* RunningAsSelfChild(const char* variable);

// In a child: limits its memory (address space) to `bytes`, so a file that makes a library
// allocate without end fails there (std::bad_alloc, or the child's death) instead of taking the
// machine's memory. Does nothing in a build with AddressSanitizer, whose shadow memory needs a
// far larger address space.
void LimitSelfChildMemory(unsigned long long bytes);

// Half the machine's physical memory, at least 1 GiB: a child's memory limit.
unsigned long long HalfThePhysicalMemory();

// The descriptor a child writes its result to (a pipe to its parent).
int SelfChildOutputFd();

// Writes all of `data` to SelfChildOutputFd(); false when the parent is gone.
bool WriteSelfChildOutput(const void* data, size_t bytes);

// "died of SIGSEGV", "ended with status 3" or "did not finish within 20 s".
std::string DescribeSelfChildEnd(const SelfChildRun& run, double timeout_s);

}  // namespace hpose

#endif  // HPOSE_CORE_COMMON_SELF_CHILD_H_
