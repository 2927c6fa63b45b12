#ifndef HPOSE_CORE_IO_STORAGE_READER_H_
#define HPOSE_CORE_IO_STORAGE_READER_H_

#include <cstdint>
#include <string>
#include <string_view>

#include <Eigen/Core>

#include "core/common/status.h"
#include "core/io/storage_node.h"

namespace hpose {

// Reads the text files OpenCV's cv::FileStorage writes (stereo calibrations, marker options)
// without handing them to OpenCV's own parsers, which fuzzing showed can hang for ever or
// allocate without bound on malformed input. Accepted:
// - YAML: an optional "%YAML:1.0" / "%YAML 1.0" first line and "---"; block maps and
//   sequences by indentation; flow [ ... ] and { ... } collections, which may span lines;
//   plain, 'single' and "double" quoted scalars; "!!opencv-matrix"-style tags; # comments.
// - XML: <?xml ...?>, then <opencv_storage> holding one element per entry; an element with
//   child elements is a map (children named "_" make a sequence), one with text is a scalar
//   (one token) or a sequence (several); the type_id attribute is kept; comments and the five
//   predefined entities are understood.
// - JSON: one object, as OpenCV writes it.
// The root is whatever the file holds (a map, for every file hpose reads). Parsing takes time
// linear in the text; nesting deeper than kMaxStorageDepth is refused.
constexpr int kMaxStorageDepth = 32;

// Parses `text`; `origin` (a path) starts every error message. Fails with kDataLoss naming the
// line and what is wrong.
Result<StorageNode> ParseStorageText(std::string_view text, const std::string& origin);

// Calibration and option files are a few kilobytes; this is the default limit of what is read.
constexpr std::uint64_t kMaxStorageFileBytes = std::uint64_t{1} << 20;

// Reads and parses a file of at most `max_bytes` (CheckInputFile's errors for a missing,
// special or oversized file).
Result<StorageNode> ReadStorageFile(const std::string& path,
                                    std::uint64_t max_bytes = kMaxStorageFileBytes);

// A matrix entry: an opencv-matrix map (rows, cols, dt, data with rows x cols numbers, one
// channel) or a plain sequence of numbers, read as one row. At most `max_values` values; they
// may be non-finite. Fails with kInvalidArgument; `where` and `name` start the message.
Result<Eigen::MatrixXd> StorageMatrix(const StorageNode& node, const std::string& where,
                                      const std::string& name, int max_values);

}  // namespace hpose

#endif  // HPOSE_CORE_IO_STORAGE_READER_H_
