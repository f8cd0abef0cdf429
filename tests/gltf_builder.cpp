#include "gltf_builder.h"

#include <cmath>
#include <cstring>
#include <fstream>

#include <unistd.h>

namespace dynbench::test {

namespace fs = std::filesystem;

fs::path scratchRoot() { return fs::temp_directory_path() / ("dynbench_test_" + std::to_string(::getpid())); }

fs::path freshDir(const std::string& name) {
  const fs::path dir = scratchRoot() / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string base64(const std::string& bytes) {
  static const char* alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const unsigned v = (static_cast<unsigned char>(bytes[i]) << 16) | (static_cast<unsigned char>(bytes[i + 1]) << 8) |
                       static_cast<unsigned char>(bytes[i + 2]);
    for (int k = 3; k >= 0; --k) out += alphabet[(v >> (6 * k)) & 63];
  }
  if (i + 1 == bytes.size()) {
    const unsigned v = static_cast<unsigned char>(bytes[i]) << 16;
    out += alphabet[(v >> 18) & 63];
    out += alphabet[(v >> 12) & 63];
    out += "==";
  } else if (i + 2 == bytes.size()) {
    const unsigned v = (static_cast<unsigned char>(bytes[i]) << 16) | (static_cast<unsigned char>(bytes[i + 1]) << 8);
    out += alphabet[(v >> 18) & 63];
    out += alphabet[(v >> 12) & 63];
    out += alphabet[(v >> 6) & 63];
    out += '=';
  }
  return out;
}

GltfBuilder::GltfBuilder() {
  doc = {{"asset", {{"version", "2.0"}}},
         {"scene", 0},
         {"scenes", {{{"nodes", nlohmann::json::array()}}}},
         {"nodes", nlohmann::json::array()},
         {"accessors", nlohmann::json::array()},
         {"bufferViews", nlohmann::json::array()}};
}

int GltfBuilder::accessor(const std::vector<float>& data, const std::string& type) {
  const int components = type == "SCALAR" ? 1 : type == "VEC2" ? 2 : type == "VEC3" ? 3 : type == "VEC4" ? 4 : 16;
  while (bin.size() % 4) bin.push_back('\0');
  const std::size_t offset = bin.size();
  bin.append(reinterpret_cast<const char*>(data.data()), data.size() * sizeof(float));
  const int view = static_cast<int>(doc["bufferViews"].size());
  doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", data.size() * sizeof(float)}});
  nlohmann::json a = {{"bufferView", view}, {"componentType", 5126}, {"count", data.size() / components}, {"type", type}};
  if (type == "SCALAR" && !data.empty()) {
    float lo = data[0], hi = data[0];
    for (float v : data) {
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
    a["min"] = {lo};
    a["max"] = {hi};
  }
  doc["accessors"].push_back(a);
  return static_cast<int>(doc["accessors"].size()) - 1;
}

int GltfBuilder::indices(const std::vector<std::uint32_t>& data) {
  while (bin.size() % 4) bin.push_back('\0');
  const std::size_t offset = bin.size();
  bin.append(reinterpret_cast<const char*>(data.data()), data.size() * sizeof(std::uint32_t));
  doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", data.size() * sizeof(std::uint32_t)}});
  doc["accessors"].push_back({{"bufferView", doc["bufferViews"].size() - 1}, {"componentType", 5125}, {"count", data.size()}, {"type", "SCALAR"}});
  return static_cast<int>(doc["accessors"].size()) - 1;
}

int GltfBuilder::node(nlohmann::json n) {
  doc["nodes"].push_back(std::move(n));
  const int index = static_cast<int>(doc["nodes"].size()) - 1;
  doc["scenes"][0]["nodes"].push_back(index);
  return index;
}

int GltfBuilder::perspectiveCamera(double yfov) {
  doc["cameras"].push_back({{"type", "perspective"}, {"perspective", {{"yfov", yfov}, {"znear", 0.1}}}});
  return static_cast<int>(doc["cameras"].size()) - 1;
}

void GltfBuilder::channel(int node, const std::string& path, const std::vector<float>& times,
                          const std::vector<float>& values, const std::string& interpolation) {
  if (!doc.contains("animations")) doc["animations"] = {{{"samplers", nlohmann::json::array()}, {"channels", nlohmann::json::array()}}};
  const int input = accessor(times, "SCALAR");
  const std::string type = path == "rotation" ? "VEC4" : path == "weights" ? "SCALAR" : "VEC3";
  const int output = accessor(values, type);
  auto& animation = doc["animations"][0];
  animation["samplers"].push_back({{"input", input}, {"output", output}, {"interpolation", interpolation}});
  animation["channels"].push_back(
      {{"sampler", animation["samplers"].size() - 1}, {"target", {{"node", node}, {"path", path}}}});
}

fs::path GltfBuilder::write(const fs::path& dir, const std::string& name, bool external) {
  nlohmann::json d = doc;
  d["buffers"] = {{{"byteLength", bin.size()}}};
  if (external) {
    d["buffers"][0]["uri"] = name + ".bin";
    std::ofstream(dir / (name + ".bin"), std::ios::binary) << bin;
  } else {
    d["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64(bin);
  }
  const fs::path path = dir / (name + ".gltf");
  std::ofstream(path) << d.dump(1);
  return path;
}

fs::path GltfBuilder::writeGlb(const fs::path& dir, const std::string& name) {
  nlohmann::json d = doc;
  d["buffers"] = {{{"byteLength", bin.size()}}};
  std::string json = d.dump();
  while (json.size() % 4) json.push_back(' ');
  std::string body = bin;
  while (body.size() % 4) body.push_back('\0');
  auto u32 = [](std::uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
  const std::uint32_t total = static_cast<std::uint32_t>(12 + 8 + json.size() + 8 + body.size());
  std::string glb = "glTF" + u32(2) + u32(total) + u32(static_cast<std::uint32_t>(json.size())) + "JSON" + json +
                    u32(static_cast<std::uint32_t>(body.size())) + std::string("BIN\0", 4) + body;
  const fs::path path = dir / (name + ".glb");
  std::ofstream(path, std::ios::binary) << glb;
  return path;
}

std::vector<float> yawQuat(double degrees) {
  const double half = degrees * 3.14159265358979323846 / 360.0;
  return {0.0f, static_cast<float>(std::sin(half)), 0.0f, static_cast<float>(std::cos(half))};
}

std::pair<std::filesystem::path, double> writeUTurnDataset(const std::filesystem::path& dir) {
  GltfBuilder b;
  const int wallPositions = b.accessor({0, -50, -100, 0, 50, -100, 0, 50, 5, 0, -50, 5}, "VEC3");
  b.doc["meshes"] = nlohmann::json::array({{{"primitives", nlohmann::json::array({{{"attributes", {{"POSITION", wallPositions}}},
                                                                                   {"indices", b.indices({0, 1, 2, 0, 2, 3})}}})}}});
  b.node({{"name", "wall"}, {"mesh", 0}});
  std::vector<float> times, values;
  auto key = [&](double t, double x, double z) {
    times.push_back(static_cast<float>(t));
    values.insert(values.end(), {static_cast<float>(x), 0.0f, static_cast<float>(z)});
  };
  double t = 0;
  for (int z = -60; z <= 10; z += 10, t += 1.0) key(t, -10, z);
  key(t, 0, 10), t += 1.0;
  for (int z = 10; z >= -60; z -= 10, t += 1.0) key(t, 10, z);
  const double stretchEnd = t - 1.0;
  key(t, 200, 200);
  key(t + 1.0, 200, 205);
  const int cam = b.node({{"name", "eye"},
                          {"camera", b.perspectiveCamera()},
                          {"extras", {{"dynbench_camera_cuts", {{{"from", stretchEnd}, {"time", t}, {"reason", "respawn"}}}}}}});
  b.channel(cam, "translation", times, values);
  return {b.write(dir, "u_turn"), stretchEnd};
}

}  // namespace dynbench::test
