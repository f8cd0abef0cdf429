#pragma once
// Typed reads of JSON values by JSON pointer, with errors that name the file and the pointer
// ("run/stats.json: /datasets/0/properties/faces: expected a whole number >= 0"). For the JSON
// files dynbench reads back from its own stages (stats.json, discard.json, frame sidecars).
#include <cstdint>
#include <filesystem>
#include <string>

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

// A whole JSON file, or an error naming it (missing: kIo, bad syntax: kParse).
inline Expected<nlohmann::json> readJsonFile(const std::filesystem::path& path) {
  auto text = readWholeFile(path);
  if (!text) return std::unexpected(text.error());
  nlohmann::json j = nlohmann::json::parse(*text, nullptr, false);
  if (j.is_discarded()) return fail(ErrorCode::kParse, "{}: not valid JSON", path.string());
  return j;
}

}  // namespace dynbench
