#ifndef HPOSE_CORE_IO_LZF_H_
#define HPOSE_CORE_IO_LZF_H_

#include <cstddef>
#include <cstdint>

namespace hpose {

// Decompresses LZF data (the format of liblzf, used by PCL's binary_compressed PCDs and its
// .pclzf images) into exactly `out_size` bytes at `out`. Returns false, having written nothing
// past `out + out_size`, when the data is corrupt (a back reference before the start, a run
// past either end) or does not produce exactly `out_size` bytes.
bool LzfDecompress(const std::uint8_t* in, std::size_t in_size, std::uint8_t* out,
                   std::size_t out_size);

}  // namespace hpose

#endif  // HPOSE_CORE_IO_LZF_H_
