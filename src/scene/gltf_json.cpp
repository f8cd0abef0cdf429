#include "scene/gltf_reader.h"

namespace dynbench::scene::gltf_detail {

std::string GltfReader::child(std::string_view pointer, std::string_view key) {
  return fmt::format("{}/{}", pointer, key);
}

std::string GltfReader::child(std::string_view pointer, std::size_t index) {
  return fmt::format("{}/{}", pointer, index);
}

const json* GltfReader::member(const json& object, std::string_view key) const {
  auto it = object.find(key);
  return it == object.end() ? nullptr : &*it;
}

const json& GltfReader::array(const json& object, std::string_view key, std::string_view pointer) const {
  static const json empty = json::array();
  const json* v = member(object, key);
  if (!v) return empty;
  if (!v->is_array()) invalid(child(pointer, key), "expected an array");
  return *v;
}

const json& GltfReader::objectAt(const json& array, std::size_t i, std::string_view pointer) const {
  if (!array[i].is_object()) invalid(child(pointer, i), "expected an object");
  return array[i];
}

// An index into a top-level array of `limit` elements; -1 when absent and not required.
int GltfReader::index(const json& object, std::string_view key, std::string_view pointer, std::size_t limit, std::string_view what, bool required) const {
  const json* v = member(object, key);
  const auto p = child(pointer, key);
  if (!v) {
    if (required) invalid(p, fmt::format("missing; expected the index of a {}", what));
    return -1;
  }
  if (!v->is_number_integer() || v->get<long long>() < 0)
    invalid(p, fmt::format("expected a non-negative integer index of a {}, got {}", what, v->dump()));
  const auto i = v->get<long long>();
  if (static_cast<std::size_t>(i) >= limit)
    invalid(p, fmt::format("{} index {} is out of range (the file has {} {}s)", what, i, limit, what));
  return static_cast<int>(i);
}

// An array of indices into a top-level array of `limit` elements.
std::vector<int> GltfReader::indexList(const json& object, std::string_view key, std::string_view pointer, std::size_t limit, std::string_view what) const {
  const json& list = array(object, key, pointer);
  std::vector<int> out;
  out.reserve(list.size());
  for (std::size_t k = 0; k < list.size(); ++k) {
    const json& v = list[k];
    if (!v.is_number_integer() || v.get<long long>() < 0 || static_cast<std::size_t>(v.get<long long>()) >= limit)
      invalid(child(child(pointer, key), k), fmt::format("expected a {} index below {}, got {}", what, limit, v.dump()));
    out.push_back(v.get<int>());
  }
  return out;
}

std::vector<double> GltfReader::numberList(const json& object, std::string_view key, std::string_view pointer) const {
  const json& list = array(object, key, pointer);
  std::vector<double> out;
  out.reserve(list.size());
  for (std::size_t k = 0; k < list.size(); ++k) {
    if (!list[k].is_number() || !std::isfinite(list[k].get<double>()))
      invalid(child(child(pointer, key), k), fmt::format("expected a finite number, got {}", list[k].dump()));
    out.push_back(list[k].get<double>());
  }
  return out;
}

double GltfReader::number(const json& object, std::string_view key, std::string_view pointer, double fallback, bool required) const {
  const json* v = member(object, key);
  if (!v) {
    if (required) invalid(child(pointer, key), "missing; expected a number");
    return fallback;
  }
  if (!v->is_number()) invalid(child(pointer, key), fmt::format("expected a number, got {}", v->dump()));
  const double d = v->get<double>();
  if (!std::isfinite(d)) invalid(child(pointer, key), "expected a finite number");
  return d;
}

std::string GltfReader::string(const json& object, std::string_view key, std::string_view pointer, std::string fallback) const {
  const json* v = member(object, key);
  if (!v) return fallback;
  if (!v->is_string()) invalid(child(pointer, key), fmt::format("expected a string, got {}", v->dump()));
  return v->get<std::string>();
}

bool GltfReader::boolean(const json& object, std::string_view key, std::string_view pointer, bool fallback) const {
  const json* v = member(object, key);
  if (!v) return fallback;
  if (!v->is_boolean()) invalid(child(pointer, key), fmt::format("expected true or false, got {}", v->dump()));
  return v->get<bool>();
}

const json* GltfReader::extension(const json& object, std::string_view name) const {
  const json* ext = member(object, "extensions");
  if (!ext || !ext->is_object()) return nullptr;
  const json* e = member(*ext, name);
  return e && e->is_object() ? e : nullptr;
}

// Resolves a relative URI inside the dataset's folder; refuses absolute paths, URLs and `..`
// escapes so that a dataset can never make dynbench read files outside itself.
fs::path GltfReader::resolveUri(const std::string& uri, std::string_view pointer) const {
  const std::string decoded = percentDecode(uri);
  const auto colon = decoded.find(':');
  const auto slash = decoded.find('/');
  if (colon != std::string::npos && (slash == std::string::npos || colon < slash))
    invalid(pointer, fmt::format("'{}' is a URL or drive path; dynbench reads only data: URIs and "
                                 "relative paths inside the dataset's folder", uri));
  if (!decoded.empty() && (decoded[0] == '/' || decoded[0] == '\\'))
    invalid(pointer, fmt::format("'{}' is an absolute path; URIs must be relative to the dataset's folder", uri));
  const fs::path relative = fs::path(decoded).lexically_normal();
  if (relative.empty() || *relative.begin() == "..")
    invalid(pointer, fmt::format("'{}' leaves the dataset's folder; URIs must stay inside it", uri));
  return baseDir_ / relative;
}
}  // namespace dynbench::scene::gltf_detail
