#include "core/io/cloud_text.h"

#include <cctype>
#include <charconv>

namespace hpose {
namespace {

template <typename T>
bool ParseWhole(const std::string& word, T* value) {
  const char* first = word.data();
  const char* last = word.data() + word.size();
  if (first != last && *first == '+') ++first;  // from_chars takes no plus sign.
  const std::from_chars_result r = std::from_chars(first, last, *value);
  return first != last && r.ec == std::errc() && r.ptr == last;
}

}  // namespace

std::vector<std::string> SplitWords(const std::string& text, std::size_t begin, std::size_t end) {
  std::vector<std::string> words;
  std::size_t i = begin;
  while (i < end) {
    while (i < end && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
    const std::size_t start = i;
    while (i < end && !std::isspace(static_cast<unsigned char>(text[i]))) ++i;
    if (i > start) words.emplace_back(text, start, i - start);
  }
  return words;
}

bool ParseUnsigned(const std::string& word, std::uint64_t* value) {
  return ParseWhole(word, value);
}

bool ParseFloat(const std::string& word, float* value) { return ParseWhole(word, value); }

bool ParseDouble(const std::string& word, double* value) { return ParseWhole(word, value); }

}  // namespace hpose
