#pragma once
// The textures a scene's materials use, decoded once (through core/image_io, i.e. OpenImageIO)
// and shared by every frame and thread. Colour slots (base colour, emissive) are sRGB-decoded at
// load; data slots (metallic-roughness, normal) keep their values (glTF 2.0 §3.9).
#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "core/error.h"
#include "scene/scene.h"

namespace dynbench::render {

// One level of a texture's mip pyramid above the first: float RGBA, row-major, top row first.
struct MipLevel {
  int width = 0, height = 0;
  std::vector<glm::vec4> texels;
};

struct Texture {
  int width = 0, height = 0;
  // Row-major, top row first (glTF's uv (0, 0) is the top left); one of the two is filled. An
  // 8-bit image keeps its 8-bit codes, decoded through `decode` (the exact floats the 32-bit path
  // would hold): four bytes a texel instead of sixteen, which is what a texture lookup waits for
  // (the path tracer's largest cost in `perf` before this).
  std::vector<glm::vec4> texels;
  std::vector<std::array<std::uint8_t, 4>> codes;
  std::array<float, 256> decodeColour{}, decodeAlpha{};  // code -> value (sRGB-decoded for colour slots)
  // Levels 1, 2, ... of the mip pyramid, built once at load (buildMips): each the 2 x 2 box average
  // of the one below (in the slot's decoded values: linear colour for colour slots), halving each
  // side down to one texel.
  std::vector<MipLevel> mips;
  // Bilinear filtering between the four nearest texel centres, repeating at the edges (glTF's
  // default sampler; dynbench does not read sampler objects).
  glm::dvec4 sample(glm::dvec2 uv) const;
  // Trilinear filtering at level of detail lod + 0.5 log2(width x height) (lod: the footprint's
  // texture-independent part, TextureLod): bilinear within the two levels around it, blended;
  // level 0's bilinear where it is 0 or less (magnification); the top level beyond the pyramid.
  glm::dvec4 sample(glm::dvec2 uv, double lod) const;
  void buildMips();
  // Starts loading the texels sample(uv) reads, so that a later sample(uv) does not wait for
  // memory (the batched path tracer issues these for every path of a batch before shading any).
  void prefetch(glm::dvec2 uv) const;

 private:
  glm::vec4 texel(std::size_t i) const;  // texel i of level 0, decoded
  struct Footprint {
    std::size_t index[4];  // texels (x0, y0), (x1, y0), (x0, y1), (x1, y1)
    float tx, ty;          // bilinear weights of x1 and y1
  };
  Footprint footprint(glm::dvec2 uv) const;
};

// Texture level of detail by ray cones (Akenine-Möller et al., "Texture Level of Detail
// Strategies for Real-Time Ray Tracing", Ray Tracing Gems, 2019, ch. 20, ray cones: lambda = Delta_0 +
// log2 |W| - log2 |n . d|), without the texture's own size, which Texture::sample adds
// (0.5 log2(w h)): a cone of width W (world units) at the hit, meeting a triangle of world-space
// area worldArea and texture-coordinate area uvArea at |cos| = cosine between its normal and the
// ray. Delta_0 = 0.5 log2(uvArea / worldArea). No filtering (-infinity) for a degenerate triangle
// or a zero-width cone.
double textureLod(double coneWidth, double cosine, double uvArea, double worldArea);

class TextureSet {
 public:
  // Loads every image the scene's metallic-roughness materials use. Embedded images (GLB, data:
  // URIs) and images that cannot be decoded are skipped with a warning: their slot falls back to
  // white / the factor alone, so a dataset with one bad texture still renders.
  static Expected<TextureSet> load(const scene::Scene& scene, std::vector<std::string>& warnings);

  // The texture in `ref` sampled at uv (at level of detail `lod`, Texture::sample); `fallback`
  // when the slot is unused or was skipped.
  glm::dvec4 sample(const scene::TextureRef& ref, bool srgb, glm::dvec2 uv, glm::dvec4 fallback = glm::dvec4(1.0)) const;
  glm::dvec4 sample(const scene::TextureRef& ref, bool srgb, glm::dvec2 uv, double lod, glm::dvec4 fallback = glm::dvec4(1.0)) const;
  const Texture* find(int image, bool srgb) const;
  void prefetch(const scene::TextureRef& ref, bool srgb, glm::dvec2 uv) const;

 private:
  std::vector<Texture> linear_, raw_;  // per image: sRGB-decoded and as stored (empty when unused)
};

}  // namespace dynbench::render
