#include "core/scoring/zeroed_words.h"

#include <algorithm>
#include <cassert>
#include <cstring>
#include <mutex>
#include <utility>
#include <vector>

namespace hpose {
namespace {

// Buffers given back, all zero over their whole capacity.
class ZeroPool {
 public:
  static ZeroPool& Instance() {
    static ZeroPool* pool = new ZeroPool;  // never destroyed: arrays may go at exit.
    return *pool;
  }

  // A buffer of at least n words (its capacity in *capacity), all zero.
  std::uint64_t* Take(std::size_t n, std::size_t* capacity) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      // The smallest that fits, if it is not far larger than asked.
      size_t best = free_.size();
      for (size_t i = 0; i < free_.size(); ++i) {
        const size_t c = free_[i].capacity;
        if (c >= n && c / 4 <= n && (best == free_.size() || c < free_[best].capacity)) best = i;
      }
      if (best < free_.size()) {
        const Buffer b = free_[best];
        free_[best] = free_.back();
        free_.pop_back();
        pooled_bytes_ -= b.capacity * sizeof(std::uint64_t);
        *capacity = b.capacity;
        // Every word equal to the next and the first 0: all zero (one memcmp, cheap also
        // where loads are instrumented).
        assert(b.words[0] == 0 &&
               std::memcmp(b.words, b.words + 1, (b.capacity - 1) * sizeof(std::uint64_t)) == 0);
        return b.words;
      }
    }
    // Whole pages, so that arrays of slightly different sizes share buffers.
    *capacity = (n + 511) / 512 * 512;
    return new std::uint64_t[*capacity]();
  }

  // Takes back a buffer that is all zero again.
  void Give(std::uint64_t* words, std::size_t capacity) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (pooled_bytes_ + capacity * sizeof(std::uint64_t) <= ZeroedWords::kPoolBytes) {
        free_.push_back(Buffer{words, capacity});
        pooled_bytes_ += capacity * sizeof(std::uint64_t);
        return;
      }
    }
    delete[] words;
  }

  std::size_t Buffers() {
    std::lock_guard<std::mutex> lock(mutex_);
    return free_.size();
  }

 private:
  struct Buffer {
    std::uint64_t* words;
    std::size_t capacity;
  };
  std::mutex mutex_;
  std::vector<Buffer> free_;
  std::size_t pooled_bytes_ = 0;
};

}  // namespace

ZeroedWords::ZeroedWords(std::size_t n) : size_(n) {
  if (n > 0) data_ = ZeroPool::Instance().Take(n, &capacity_);
}

ZeroedWords::~ZeroedWords() { Release(); }

ZeroedWords::ZeroedWords(ZeroedWords&& other) noexcept { *this = std::move(other); }

ZeroedWords& ZeroedWords::operator=(ZeroedWords&& other) noexcept {
  if (this != &other) {
    Release();
    data_ = std::exchange(other.data_, nullptr);
    size_ = std::exchange(other.size_, 0);
    capacity_ = std::exchange(other.capacity_, 0);
    offset_ = other.offset_;
    width_ = other.width_;
    stride_ = other.stride_;
    rows_ = std::exchange(other.rows_, 0);
  }
  return *this;
}

void ZeroedWords::MarkWritten(std::size_t offset, std::size_t width, std::size_t stride,
                              std::size_t rows) {
  if (rows == 0 || width == 0) return;
  assert(offset + (rows - 1) * stride + width <= size_);
  if (rows_ == 0) {
    offset_ = offset;
    width_ = width;
    stride_ = stride;
    rows_ = rows;
    return;
  }
  // Two rectangles: the one span from the first word of either to the last.
  const std::size_t first = std::min(offset_, offset);
  const std::size_t end =
      std::max(offset_ + (rows_ - 1) * stride_ + width_, offset + (rows - 1) * stride + width);
  offset_ = first;
  width_ = end - first;
  stride_ = 0;
  rows_ = 1;
}

std::size_t ZeroedWords::PooledBuffers() { return ZeroPool::Instance().Buffers(); }

void ZeroedWords::Release() {
  if (data_ == nullptr) return;
  for (std::size_t r = 0; r < rows_; ++r) {
    std::memset(data_ + offset_ + r * stride_, 0, width_ * sizeof(std::uint64_t));
  }
  ZeroPool::Instance().Give(data_, capacity_);
  data_ = nullptr;
  size_ = capacity_ = rows_ = 0;
}

}  // namespace hpose
