#pragma once
// Writes small analytic glTF files for tests: accessors from float vectors, nodes, animation
// channels. Independent of dynbench's reader (it only uses nlohmann::json to write).
#include <filesystem>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace dynbench::test {

// A fresh empty folder under the system temp dir, unique per test.
// This process's scratch folder, $TMPDIR/dynbench_test_PID (test_main.cpp removes it once the
// process's tests have passed).
std::filesystem::path scratchRoot();
// An empty folder `name` in it.
std::filesystem::path freshDir(const std::string& name);

std::string base64(const std::string& bytes);

struct GltfBuilder {
  nlohmann::json doc;
  std::string bin;

  GltfBuilder();
  // Appends floats to the buffer (4-byte aligned) and returns the accessor index.
  int accessor(const std::vector<float>& data, const std::string& type);
  // Appends 32-bit triangle indices and returns the accessor index.
  int indices(const std::vector<std::uint32_t>& data);
  int node(nlohmann::json node);  // appends to nodes and to the scene's roots when it has no parent
  int perspectiveCamera(double yfov = 1.0);
  // Adds a channel (and its sampler) to animation 0.
  void channel(int node, const std::string& path, const std::vector<float>& times, const std::vector<float>& values,
               const std::string& interpolation = "LINEAR");
  // Writes DIR/NAME.gltf and, when external, DIR/NAME.bin. Returns the .gltf path.
  std::filesystem::path write(const std::filesystem::path& dir, const std::string& name, bool external = true);
  // Writes a .glb container.
  std::filesystem::path writeGlb(const std::filesystem::path& dir, const std::string& name);
};

// The fly-through tests' U-turn (demo_test.cpp describes it): a wall in the plane x = 0 for z in
// [-100, 5]; a camera walking up x = -10, round the wall's end and down x = 10 (16 s), then a cut.
// Returns DIR/u_turn.gltf and the time the cut-free stretch ends.
std::pair<std::filesystem::path, double> writeUTurnDataset(const std::filesystem::path& dir);

// A quaternion (x, y, z, w) for a rotation of `degrees` about world +Y.
std::vector<float> yawQuat(double degrees);

}  // namespace dynbench::test
