#pragma once
// Typed reads of JSON values by JSON pointer, with errors that name the file and the pointer
// ("run/stats.json: /datasets/0/properties/faces: expected a whole number >= 0"). For the JSON
// files dynbench reads back from its own stages (stats.json, discard.json, frame sidecars).
#include <algorithm>
#include <cstdint>
#include <iterator>
#include <limits>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/files.h"

namespace dynbench {

class JsonFields {
 public:
  JsonFields(const nlohmann::json& root, std::filesystem::path file) : root_(root), file_(std::move(file)) {}

  bool has(const std::string& pointer) const { return root_.contains(nlohmann::json::json_pointer(pointer)); }

  Expected<const nlohmann::json*> value(const std::string& pointer) const {
    const nlohmann::json::json_pointer p(pointer);
    if (!root_.contains(p)) return fail(ErrorCode::kInvalidData, "{}: {}: missing", file_.string(), pointer);
    return &root_.at(p);
  }
  Expected<double> number(const std::string& pointer) const {
    auto v = value(pointer);
    if (!v) return std::unexpected(v.error());
    if (!(*v)->is_number()) return bad(pointer, "a number");
    return (*v)->get<double>();
  }
  Expected<std::uint64_t> count(const std::string& pointer) const {
    auto v = value(pointer);
    if (!v) return std::unexpected(v.error());
    if (!(*v)->is_number_unsigned()) return bad(pointer, "a whole number >= 0");
    return (*v)->get<std::uint64_t>();
  }
  Expected<long long> integer(const std::string& pointer) const {
    auto v = value(pointer);
    if (!v) return std::unexpected(v.error());
    if (!(*v)->is_number_integer()) return bad(pointer, "a whole number");
    return (*v)->get<long long>();
  }
  Expected<bool> boolean(const std::string& pointer) const {
    auto v = value(pointer);
    if (!v) return std::unexpected(v.error());
    if (!(*v)->is_boolean()) return bad(pointer, "true or false");
    return (*v)->get<bool>();
  }
  Expected<std::string> string(const std::string& pointer) const {
    auto v = value(pointer);
    if (!v) return std::unexpected(v.error());
    if (!(*v)->is_string()) return bad(pointer, "a string");
    return (*v)->get<std::string>();
  }
  const std::filesystem::path& file() const { return file_; }

 private:
  std::unexpected<Error> bad(const std::string& pointer, const char* expected) const {
    return fail(ErrorCode::kInvalidData, "{}: {}: expected {}, found {}", file_.string(), pointer, expected,
                root_.at(nlohmann::json::json_pointer(pointer)).dump());
  }
  const nlohmann::json& root_;
  std::filesystem::path file_;
};

// Typed reads of a settings document's optional keys, each with the range its command-line option
// checks; an absent key keeps the value it has (the struct's default). For job files (--job).
class JsonSettingsReader {
 public:
  JsonSettingsReader(const nlohmann::json& document, const std::filesystem::path& source) : document_(document), fields_(document, source) {}

  // A job document's frame: an object of `what` ("the render job") with no top-level key but
  // `keys` (a misspelt setting is not silently ignored) and `versionKey` equal to `version`.
  template <typename Keys>
  Expected<void> jobDocument(const std::string& what, const Keys& keys, const std::string& versionKey, int version) const {
    if (!document_.is_object()) return bad("", fmt::format("an object ({}, docs/cli.md)", what));
    for (const auto& [key, value] : document_.items())
      if (std::find_if(std::begin(keys), std::end(keys), [&](const char* k) { return key == k; }) == std::end(keys))
        return bad("/" + key, fmt::format("one of {}'s keys ({}), not \"{}\"", what, fmt::join(keys, ", "), key));
    const std::string pointer = "/" + versionKey;
    if (!has(pointer)) return bad(pointer, fmt::format("{} (the version of {} this dynbench reads), missing", version, what));
    int found = 0;
    return integer(pointer, found, version, version);
  }

  // Without a range: any value of Int (the range is then checked by whoever uses it).
  template <typename Int>
  Expected<void> integer(const std::string& pointer, Int& value, long long low = std::numeric_limits<Int>::min(),
                         long long high = std::numeric_limits<Int>::max()) const {
    if (!fields_.has(pointer)) return {};
    auto v = fields_.integer(pointer);
    if (!v) return std::unexpected(v.error());
    if (*v < low || *v > high) return bad(pointer, fmt::format("a whole number in [{}, {}], found {}", low, high, *v));
    value = static_cast<Int>(*v);
    return {};
  }
  // A whole number >= 0 of any size (seeds).
  Expected<void> count(const std::string& pointer, std::uint64_t& value) const {
    if (!fields_.has(pointer)) return {};
    auto v = fields_.count(pointer);
    if (!v) return std::unexpected(v.error());
    value = *v;
    return {};
  }
  Expected<void> number(const std::string& pointer, double& value, double low = -std::numeric_limits<double>::infinity(),
                        double high = std::numeric_limits<double>::infinity(), bool lowOpen = false) const {
    if (!fields_.has(pointer)) return {};
    auto v = fields_.number(pointer);
    if (!v) return std::unexpected(v.error());
    if (!(lowOpen ? *v > low : *v >= low) || !(*v <= high))
      return bad(pointer, fmt::format("a number in {}{}, {}], found {}", lowOpen ? "(" : "[", low, high, *v));
    value = *v;
    return {};
  }
  Expected<void> boolean(const std::string& pointer, bool& value) const {
    if (!fields_.has(pointer)) return {};
    auto v = fields_.boolean(pointer);
    if (!v) return std::unexpected(v.error());
    value = *v;
    return {};
  }
  template <typename T>
  Expected<void> string(const std::string& pointer, T& value) const {
    if (!fields_.has(pointer)) return {};
    auto v = fields_.string(pointer);
    if (!v) return std::unexpected(v.error());
    value = *v;
    return {};
  }
  // An array of strings.
  Expected<std::vector<std::string>> strings(const std::string& pointer) const {
    auto v = fields_.value(pointer);
    if (!v) return std::unexpected(v.error());
    if (!(*v)->is_array()) return bad(pointer, fmt::format("an array of strings, found {}", (*v)->dump()));
    std::vector<std::string> out;
    for (std::size_t i = 0; i < (*v)->size(); ++i) {
      auto item = fields_.string(fmt::format("{}/{}", pointer, i));
      if (!item) return std::unexpected(item.error());
      out.push_back(*item);
    }
    return out;
  }
  bool has(const std::string& pointer) const { return fields_.has(pointer); }
  std::unexpected<Error> bad(const std::string& pointer, const std::string& expected) const {
    return fail(ErrorCode::kInvalidData, "{}: {}: expected {}", fields_.file().string(), pointer, expected);
  }

 private:
  const nlohmann::json& document_;
  JsonFields fields_;
};

// A whole JSON file, or an error naming it (missing: kIo, bad syntax: kParse).
inline Expected<nlohmann::json> readJsonFile(const std::filesystem::path& path) {
  auto text = readWholeFile(path);
  if (!text) return std::unexpected(text.error());
  nlohmann::json j = nlohmann::json::parse(*text, nullptr, false);
  if (j.is_discarded()) return fail(ErrorCode::kParse, "{}: not valid JSON", path.string());
  return j;
}

// The text of a JSON document as every dynbench stage writes its files: indented by 2, a newline at
// the end. A stage's document is an nlohmann::json (`xJson(const XRun&)`, beside its reader); the
// CLI writes this text of it and the Python module converts the object itself.
inline std::string jsonFileText(const nlohmann::json& document) { return document.dump(2) + "\n"; }

// A JSON file read and given to `parse(document, path)` (a job file's reader).
template <typename Parse>
auto readJsonDocument(const std::filesystem::path& path, Parse parse) -> decltype(parse(nlohmann::json{}, path)) {
  auto document = readJsonFile(path);
  if (!document) return std::unexpected(document.error());
  return parse(*document, path);
}

}  // namespace dynbench
