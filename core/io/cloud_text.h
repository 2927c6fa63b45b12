#ifndef HPOSE_CORE_IO_CLOUD_TEXT_H_
#define HPOSE_CORE_IO_CLOUD_TEXT_H_

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace hpose {

// Text helpers of the PCD and PLY readers (headers and ASCII data).

// The whitespace-separated words of text[begin, end).
std::vector<std::string> SplitWords(const std::string& text, std::size_t begin, std::size_t end);

// A non-negative decimal integer filling the whole word.
bool ParseUnsigned(const std::string& word, std::uint64_t* value);

// A decimal floating-point number filling the whole word, independent of the locale; "nan",
// "inf" and their negatives included (PCL writes "nan" for invalid points).
bool ParseFloat(const std::string& word, float* value);
bool ParseDouble(const std::string& word, double* value);

}  // namespace hpose

#endif  // HPOSE_CORE_IO_CLOUD_TEXT_H_
