// A program that commits one chosen error, for the sanitized build's own tests
// (tests/sanitizers/CMakeLists.txt): they check that the sanitizers report it, so that a change
// of flags or of ubsan_ignorelist.txt that silences them shows as a failed test.
//
//   sanitizer_canary signed-overflow   integer overflow in hpose's own code (UBSan)
//   sanitizer_canary shift             a negative value shifted left in hpose's own code (UBSan)
//   sanitizer_canary heap-overflow     std::accumulate, inline code of a system header, reads
//                                      past a heap block (ASan still instruments that code)
#include <cstdio>
#include <cstring>
#include <numeric>
#include <vector>

namespace {

// Kept out of constant folding: the values come from the command line's length.
int SignedOverflow(int seed) {
  volatile int big = 2147483600 + seed;
  return big + 100;
}

int ShiftNegative(int seed) {
  volatile int negative = -seed - 1;
  return negative << 3;
}

int HeapOverflow(int seed) {
  std::vector<int> values(static_cast<size_t>(seed) + 4, 1);
  // One element past the end, read inside the standard library's inline code.
  return std::accumulate(values.begin(), values.end() + 1, 0);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: sanitizer_canary signed-overflow|shift|heap-overflow\n");
    return 2;
  }
  const int seed = static_cast<int>(std::strlen(argv[0]) % 2);
  int value = 0;
  if (std::strcmp(argv[1], "signed-overflow") == 0) {
    value = SignedOverflow(seed);
  } else if (std::strcmp(argv[1], "shift") == 0) {
    value = ShiftNegative(seed);
  } else if (std::strcmp(argv[1], "heap-overflow") == 0) {
    value = HeapOverflow(seed);
  } else {
    std::fprintf(stderr, "sanitizer_canary: unknown error '%s'\n", argv[1]);
    return 2;
  }
  std::printf("no report; value %d\n", value);
  return 0;
}
