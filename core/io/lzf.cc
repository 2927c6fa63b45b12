#include "core/io/lzf.h"

#include <cstring>

namespace hpose {

bool LzfDecompress(const std::uint8_t* in, std::size_t in_size, std::uint8_t* out,
                   std::size_t out_size) {
  std::size_t i = 0;  // next input byte.
  std::size_t o = 0;  // next output byte.
  while (i < in_size) {
    const unsigned control = in[i++];
    if (control < 32) {
      // A literal run of control + 1 bytes.
      const std::size_t run = control + 1;
      if (run > in_size - i || run > out_size - o) return false;
      std::memcpy(out + o, in + i, run);
      i += run;
      o += run;
      continue;
    }
    // A back reference: length (3 bits, 7 = more in the next byte) + 2 bytes, copied from
    // `distance` + 1 bytes back, possibly overlapping what it writes.
    std::size_t length = control >> 5;
    if (length == 7) {
      if (i >= in_size) return false;
      length += in[i++];
    }
    length += 2;
    if (i >= in_size) return false;
    const std::size_t distance = ((control & 0x1fu) << 8 | in[i++]) + 1;
    if (distance > o || length > out_size - o) return false;
    for (std::size_t k = 0; k < length; ++k, ++o) out[o] = out[o - distance];
  }
  return o == out_size;
}

}  // namespace hpose
