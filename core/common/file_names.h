#ifndef HPOSE_CORE_COMMON_FILE_NAMES_H_
#define HPOSE_CORE_COMMON_FILE_NAMES_H_

#include <string>

namespace hpose {

// `s` with its ASCII letters in lower case (file extensions compare so).
std::string LowerCase(std::string s);

// Whether `s` ends with `suffix` (case-sensitive).
bool EndsWith(const std::string& s, const std::string& suffix);

// The extension of the last path component, with its dot, in lower case ("a/B.PNG" -> ".png");
// "" when that component has no dot.
std::string LowerExtension(const std::string& path);

}  // namespace hpose

#endif  // HPOSE_CORE_COMMON_FILE_NAMES_H_
