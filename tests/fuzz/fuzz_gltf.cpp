// Fuzz target: the glTF / GLB loader (scene/load_gltf.cpp) on untrusted bytes. An input starting
// with the GLB magic is loaded as .glb, anything else as .gltf JSON. Any error is fine; a crash, a
// sanitizer report or a hang is a bug. Seeds: the Khronos samples in ../shared/testdata.
#include <cstring>

#include "fuzz_input.h"
#include "scene/load.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const bool glb = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
  const auto path = dynbench::fuzz::scratchDir() / (glb ? "input.glb" : "input.gltf");
  dynbench::fuzz::writeBytes(path, data, size);
  (void)dynbench::scene::loadGltf(path);
  return 0;
}
