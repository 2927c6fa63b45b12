// ReadPcd: the x, y, z of a PCD file (ascii or binary data, 4-byte float fields).
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "hpose/client.h"

namespace hpose::client {

namespace {

constexpr int kInvalidArgument = 3;
constexpr int kNotFound = 5;

struct PcdHeader {
  std::vector<std::string> fields;
  std::vector<int> sizes;
  std::vector<char> types;
  std::vector<int> counts;
  std::size_t points = 0;
  std::string data;  // "ascii", "binary" or "binary_compressed".
};

// Reads header lines up to DATA; "" when well formed, else what is wrong.
std::string ReadHeader(std::istream& in, PcdHeader* h) {
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream words(line);
    std::string key;
    words >> key;
    if (key == "FIELDS") {
      for (std::string f; words >> f;) h->fields.push_back(f);
    } else if (key == "SIZE") {
      for (int v; words >> v;) h->sizes.push_back(v);
    } else if (key == "TYPE") {
      for (char v; words >> v;) h->types.push_back(v);
    } else if (key == "COUNT") {
      for (int v; words >> v;) h->counts.push_back(v);
    } else if (key == "POINTS") {
      words >> h->points;
    } else if (key == "DATA") {
      words >> h->data;
      if (h->counts.empty()) h->counts.assign(h->fields.size(), 1);
      if (h->sizes.size() != h->fields.size() || h->types.size() != h->fields.size() ||
          h->counts.size() != h->fields.size()) {
        return "FIELDS, SIZE, TYPE and COUNT disagree in length";
      }
      return "";
    }
  }
  return "no DATA line";
}

}  // namespace

Status ReadPcd(const std::string& path, PointCloud* out) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status{kNotFound, path + ": cannot be opened"};
  PcdHeader h;
  if (std::string bad = ReadHeader(in, &h); !bad.empty()) {
    return Status{kInvalidArgument, path + ": not a PCD file (" + bad + ")"};
  }
  // Byte offset and value index of x, y, z within a point.
  int offset[3] = {-1, -1, -1}, index[3] = {-1, -1, -1};
  int bytes = 0, values = 0;
  for (std::size_t i = 0; i < h.fields.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      if (h.fields[i] != std::string(1, static_cast<char>('x' + a))) continue;
      if (h.sizes[i] != 4 || h.types[i] != 'F' || h.counts[i] != 1) {
        return Status{kInvalidArgument, path + ": field " + h.fields[i] + " is not a 4-byte float"};
      }
      offset[a] = bytes;
      index[a] = values;
    }
    bytes += h.sizes[i] * h.counts[i];
    values += h.counts[i];
  }
  if (offset[0] < 0 || offset[1] < 0 || offset[2] < 0) {
    return Status{kInvalidArgument, path + ": the FIELDS lack x, y or z"};
  }
  out->xyz.clear();
  const auto add = [out](const float p[3]) {
    if (std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2])) {
      out->xyz.insert(out->xyz.end(), p, p + 3);
    }
  };
  const auto truncated = [&](std::size_t n) {
    return Status{kInvalidArgument, path + ": ends after " + std::to_string(n) + " of " +
                                        std::to_string(h.points) + " points"};
  };
  if (h.data == "binary") {
    std::vector<char> point(bytes);
    for (std::size_t n = 0; n < h.points; ++n) {
      if (!in.read(point.data(), bytes)) {
        return truncated(n);
      }
      float p[3];
      for (int a = 0; a < 3; ++a) std::memcpy(&p[a], point.data() + offset[a], sizeof(float));
      add(p);
    }
  } else if (h.data == "ascii") {
    std::vector<std::string> words(values);
    for (std::size_t n = 0; n < h.points; ++n) {
      for (std::string& w : words) {
        if (!(in >> w)) {
          return truncated(n);
        }
      }
      float p[3];
      for (int a = 0; a < 3; ++a) p[a] = std::strtof(words[index[a]].c_str(), nullptr);
      add(p);
    }
  } else {
    return Status{kInvalidArgument,
                  path + ": DATA " + h.data + " is not supported (ascii or binary are)"};
  }
  return Status{};
}

}  // namespace hpose::client
