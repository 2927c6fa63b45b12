#ifndef HPOSE_CORE_SCORING_TABLE_ARENA_H_
#define HPOSE_CORE_SCORING_TABLE_ARENA_H_

#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <type_traits>
#include <vector>

namespace hpose {

// Memory for a template's cell tables (tens of MB read at scattered places by every bound of a
// search): carved out of large regions that the kernel is asked to back with 2 MB pages
// (madvise MADV_HUGEPAGE, where transparent huge pages are enabled or on request), so that a
// search's table lookups miss the TLB far less than in 4 KB pages. A bump allocator:
// nothing is returned before the arena goes, and it must outlive whatever it allocated.
// Thread-safe (tables are made on first use by whichever search thread needs them).
class TableArena {
 public:
  TableArena() = default;
  ~TableArena();
  TableArena(const TableArena&) = delete;
  TableArena& operator=(const TableArena&) = delete;

  // `bytes` of memory aligned to a cache line (std::bad_alloc when the system has none).
  void* Allocate(std::size_t bytes);
  // Bytes of the regions mapped so far (their allocations and the unused rest).
  std::size_t mapped_bytes() const;

 private:
  struct Region {
    void* base;
    std::size_t bytes;
  };
  mutable std::mutex mutex_;
  std::vector<Region> regions_;
  char* next_ = nullptr;
  char* end_ = nullptr;
  std::size_t next_region_bytes_ = 0;  // the next region's size (doubling up to a limit).
};

// A std::allocator-compatible allocator taking its memory from a TableArena (deallocation is
// then a no-op: the arena frees everything at once); without an arena, from operator new. The
// arena travels with a container on copy, move and swap.
template <typename T>
class TableAllocator {
 public:
  using value_type = T;
  using propagate_on_container_copy_assignment = std::true_type;
  using propagate_on_container_move_assignment = std::true_type;
  using propagate_on_container_swap = std::true_type;

  TableAllocator() = default;
  explicit TableAllocator(TableArena* arena) : arena_(arena) {}
  template <typename U>
  TableAllocator(const TableAllocator<U>& other) : arena_(other.arena()) {}  // NOLINT

  T* allocate(std::size_t n) {
    if (arena_ == nullptr) return std::allocator<T>().allocate(n);
    return static_cast<T*>(arena_->Allocate(n * sizeof(T)));
  }
  void deallocate(T* p, std::size_t n) {
    if (arena_ == nullptr) std::allocator<T>().deallocate(p, n);
  }
  TableArena* arena() const { return arena_; }

  template <typename U>
  bool operator==(const TableAllocator<U>& other) const {
    return arena_ == other.arena();
  }
  template <typename U>
  bool operator!=(const TableAllocator<U>& other) const {
    return arena_ != other.arena();
  }

 private:
  TableArena* arena_ = nullptr;
};

// A table's words: in its template's arena, or on the heap when made without one.
using TableWords = std::vector<std::uint64_t, TableAllocator<std::uint64_t>>;

}  // namespace hpose

#endif  // HPOSE_CORE_SCORING_TABLE_ARENA_H_
