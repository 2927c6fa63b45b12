#ifndef HPOSE_CORE_SCORING_ZEROED_WORDS_H_
#define HPOSE_CORE_SCORING_ZEROED_WORDS_H_

#include <cstddef>
#include <cstdint>

namespace hpose {

// An array of 64-bit words that reads all zero when made, for tables that are mostly zero and
// written in one rectangle of rows (the search's occupancy levels: a cluster's cells in a box
// that every lookup of the search may reach, ten to a hundred times the cells' area). Instead of
// zeroing the whole array on every frame, its buffer comes from a process-wide pool of buffers
// that were all zero when given back: the owner declares the rectangle it writes
// (MarkWritten), and only that is zeroed again when the array goes. Writing outside the
// declared rectangle breaks the pool's promise to the next owner (debug builds check it).
//
// Move-only. The pool is thread-safe and keeps at most kPoolBytes of buffers; beyond that a
// buffer given back is freed.
class ZeroedWords {
 public:
  static constexpr std::size_t kPoolBytes = std::size_t{48} << 20;

  ZeroedWords() = default;
  // `n` words, all 0.
  explicit ZeroedWords(std::size_t n);
  ~ZeroedWords();
  ZeroedWords(ZeroedWords&& other) noexcept;
  ZeroedWords& operator=(ZeroedWords&& other) noexcept;
  ZeroedWords(const ZeroedWords&) = delete;
  ZeroedWords& operator=(const ZeroedWords&) = delete;

  std::uint64_t* data() { return data_; }
  const std::uint64_t* data() const { return data_; }
  std::size_t size() const { return size_; }
  std::uint64_t& operator[](std::size_t i) { return data_[i]; }
  const std::uint64_t& operator[](std::size_t i) const { return data_[i]; }

  // Declares the words [offset + r * stride, offset + r * stride + width) for r in [0, rows)
  // written (rows of a 2-D table). Declared twice, the span from the first declared word to the
  // last is taken. Within size().
  void MarkWritten(std::size_t offset, std::size_t width, std::size_t stride, std::size_t rows);
  // The whole array.
  void MarkAllWritten() { MarkWritten(0, size_, 0, size_ > 0 ? 1 : 0); }

  // Buffers the pool holds now (for tests).
  static std::size_t PooledBuffers();

 private:
  void Release();

  std::uint64_t* data_ = nullptr;
  std::size_t size_ = 0;
  std::size_t capacity_ = 0;
  // The written rectangle (rows_ = 0: nothing written).
  std::size_t offset_ = 0, width_ = 0, stride_ = 0, rows_ = 0;
};

}  // namespace hpose

#endif  // HPOSE_CORE_SCORING_ZEROED_WORDS_H_
