#include "core/scoring/table_arena.h"

#include <sys/mman.h>

#include <algorithm>
#include <cstdint>
#include <new>

namespace hpose {
namespace {

constexpr std::size_t kHugePage = std::size_t{2} << 20;
constexpr std::size_t kFirstRegion = kHugePage;         // one huge page: small templates.
constexpr std::size_t kLargestRegion = 16 * kHugePage;  // 32 MB.
constexpr std::size_t kAlign = 64;

}  // namespace

TableArena::~TableArena() {
  for (const Region& r : regions_) munmap(r.base, r.bytes);
}

void* TableArena::Allocate(std::size_t bytes) {
  bytes = std::max<std::size_t>(kAlign, (bytes + kAlign - 1) & ~(kAlign - 1));
  std::lock_guard<std::mutex> lock(mutex_);
  if (next_ == nullptr || static_cast<std::size_t>(end_ - next_) < bytes) {
    // A new region, 2 MB aligned, of whole huge pages: the next size in the doubling, or the
    // request's own size when that is larger.
    next_region_bytes_ =
        next_region_bytes_ == 0 ? kFirstRegion : std::min(2 * next_region_bytes_, kLargestRegion);
    const std::size_t usable =
        std::max(next_region_bytes_, (bytes + kHugePage - 1) / kHugePage * kHugePage);
    const std::size_t mapped = usable + kHugePage;  // room to align.
    void* base = mmap(nullptr, mapped, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (base == MAP_FAILED) throw std::bad_alloc();
    regions_.push_back({base, mapped});
    const std::uintptr_t start =
        (reinterpret_cast<std::uintptr_t>(base) + kHugePage - 1) & ~(kHugePage - 1);
    next_ = reinterpret_cast<char*>(start);
    end_ = next_ + usable;
#ifdef MADV_HUGEPAGE
    // Only advice: where the kernel has no transparent huge pages the region keeps 4 KB pages.
    madvise(next_, usable, MADV_HUGEPAGE);
#endif
  }
  void* out = next_;
  next_ += bytes;
  return out;
}

std::size_t TableArena::mapped_bytes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::size_t total = 0;
  for (const Region& r : regions_) total += r.bytes;
  return total;
}

}  // namespace hpose
