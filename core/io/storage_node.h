#ifndef HPOSE_CORE_IO_STORAGE_NODE_H_
#define HPOSE_CORE_IO_STORAGE_NODE_H_

#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace hpose {

// One node of a parsed OpenCV FileStorage text file (YAML, XML or JSON; see storage_reader.h):
// nothing, a scalar, a sequence or a map whose members keep the file's order.
struct StorageNode {
  enum class Kind { kNone, kScalar, kSeq, kMap };
  Kind kind = Kind::kNone;
  std::string text;                // a scalar's text, unquoted and unescaped.
  bool quoted = false;             // a quoted scalar is a string even when it reads as a number.
  std::string type_id;             // "opencv-matrix" from a YAML tag or an XML type_id attribute.
  int line = 0;                    // where the node starts (1-based), for messages.
  std::vector<StorageNode> items;  // kSeq
  std::vector<std::pair<std::string, StorageNode>> members;  // kMap

  bool IsMap() const { return kind == Kind::kMap; }
  bool IsSeq() const { return kind == Kind::kSeq; }
  bool IsScalar() const { return kind == Kind::kScalar; }

  // The member named `key` of a map, or nullptr (also when this is not a map).
  const StorageNode* Find(std::string_view key) const;

  // A scalar that is a whole decimal integer within long long (not quoted).
  bool AsInt(long long* value) const;
  // A scalar that is a number (not quoted): decimal integers and reals, and OpenCV's .nan /
  // .inf spellings, which give non-finite values.
  bool AsNumber(double* value) const;
  // A scalar that is not a number, or any quoted scalar.
  bool IsString() const;
};

}  // namespace hpose

#endif  // HPOSE_CORE_IO_STORAGE_NODE_H_
