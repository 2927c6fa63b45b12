#include "core/io/intrinsics_json.h"

#include <cmath>
#include <exception>
#include <filesystem>
#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "core/io/atomic_file.h"

namespace hpose {
namespace {

using Json = nlohmann::json;

const char* const kIntKeys[] = {"width", "height"};
const char* const kRealKeys[] = {"fx", "fy", "cx", "cy"};

Error Invalid(const std::string& origin, const std::string& what) {
  return MakeError(ErrorCode::kInvalidArgument, origin + ": " + what);
}

}  // namespace

Result<Intrinsics> ParseIntrinsicsJson(const std::string& text, const std::string& origin) {
  Json json;
  try {
    json = Json::parse(text);
  } catch (const Json::exception& e) {
    // e.what() names the byte offset and what was read; NaN and Infinity are not JSON, and
    // numbers beyond double (1e999) are rejected too.
    return Invalid(origin, std::string("not valid JSON: ") + e.what());
  }
  if (!json.is_object()) {
    return Invalid(origin, std::string("expected a JSON object, got ") + json.type_name());
  }
  const std::set<std::string> known = {"width", "height", "fx", "fy", "cx", "cy"};
  for (const auto& item : json.items()) {
    if (known.count(item.key()) == 0) {
      return Invalid(origin,
                     "unknown key '" + item.key() + "' (expected width, height, fx, fy, cx, cy)");
    }
  }
  for (const std::string& key : known) {
    if (!json.contains(key)) return Invalid(origin, "missing key '" + key + "'");
  }

  Intrinsics k;
  int* const ints[] = {&k.width, &k.height};
  for (int i = 0; i < 2; ++i) {
    const Json& value = json.at(kIntKeys[i]);
    // 640.0 is accepted as 640; 640.5, strings and NaN-like values are not.
    const bool integral = value.is_number_integer() ||
                          (value.is_number_float() && std::isfinite(value.get<double>()) &&
                           std::floor(value.get<double>()) == value.get<double>());
    if (!integral) {
      return Invalid(origin,
                     std::string("'") + kIntKeys[i] + "' must be an integer, got " + value.dump());
    }
    const double number = value.get<double>();
    if (number <= 0 || number > 8192) {
      return Invalid(
          origin, std::string("'") + kIntKeys[i] + "' = " + value.dump() + " is outside [1, 8192]");
    }
    *ints[i] = static_cast<int>(number);
  }
  double* const reals[] = {&k.fx, &k.fy, &k.cx, &k.cy};
  for (int i = 0; i < 4; ++i) {
    const Json& value = json.at(kRealKeys[i]);
    if (!value.is_number()) {
      return Invalid(origin,
                     std::string("'") + kRealKeys[i] + "' must be a number, got " + value.dump());
    }
    *reals[i] = value.get<double>();
  }
  const Status valid = k.Validate();
  if (!valid.ok()) return Invalid(origin, valid.error().message);
  return k;
}

Result<Intrinsics> ReadIntrinsicsJson(const std::string& path) {
  Result<std::string> text = ReadFile(path);
  if (!text.ok()) return text.error();
  return ParseIntrinsicsJson(*text, path);
}

std::string IntrinsicsToJson(const Intrinsics& intrinsics) {
  Json json;
  json["width"] = intrinsics.width;
  json["height"] = intrinsics.height;
  json["fx"] = intrinsics.fx;
  json["fy"] = intrinsics.fy;
  json["cx"] = intrinsics.cx;
  json["cy"] = intrinsics.cy;
  // Non-finite values would be written as null; Validate() before writing files rejects them.
  return json.dump(2) + "\n";
}

Status WriteIntrinsicsJson(const Intrinsics& intrinsics, const std::string& path) {
  const Status valid = intrinsics.Validate();
  if (!valid.ok()) {
    return MakeError(ErrorCode::kInvalidArgument, path + ": " + valid.error().message);
  }
  return WriteFileAtomically(path, IntrinsicsToJson(intrinsics));
}

std::string IntrinsicsJsonBeside(const std::string& frame_path) {
  const std::filesystem::path dir = std::filesystem::path(frame_path).parent_path();
  return ((dir.empty() ? std::filesystem::path(".") : dir) / "intrinsics.json").string();
}

}  // namespace hpose
