#pragma once
// What q3map2 reads from a shader script for lighting (q3map2's shaders.c, ParseShaderFile): the
// keywords below and nothing else. Scripts are scripts/*.shader in the game's archives; a shader
// defined twice keeps its first definition, as the renderer and q3map2 keep it.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/error.h"
#include "maplight/pak.h"

namespace dynbench::maplight {

struct ShaderSun {
  glm::dvec3 color{1.0};         // normalised to unit length (VectorNormalize)
  double intensity = 0.0;        // lightmap units on a surface facing it
  glm::dvec3 towardsSun{0, 0, 1};  // game axes, unit
};

struct ShaderLighting {
  std::string name;
  double surfaceLight = 0.0;                 // q3map_surfacelight
  std::optional<glm::dvec3> lightRgb;        // q3map_lightRGB (normalised: largest channel 1)
  std::string lightImage, editorImage, firstStageImage;  // q3map_lightImage, qer_editorimage, the first stage's map
  std::vector<ShaderSun> suns;               // q3map_sun, q3map_sunExt
  double skyLight = 0.0;                     // q3map_skylight value
  int skyLightIterations = 0;
  double backsplashFraction = 0.05, backsplashDistance = 23.0;  // q3map_backsplash (percent / 100, units)
  double lightSubdivide = 0.0;  // q3map_lightSubdivide, units (0: q3map2's default, kDefaultLightSubdivide)
  bool sky = false, translucent = false, noDraw = false;         // surfaceparm sky, trans, nodraw
  bool twoSided = false;  // cull none, disable or twosided: q3map2 makes its surface light emit from both sides
};

class ShaderScripts {
 public:
  // Every scripts/*.shader of the game's archives. An unbalanced script is an error naming it.
  static Expected<ShaderScripts> read(const GameFiles& files);
  // Parses one script's text (exposed for tests): `file` names it in errors.
  [[nodiscard]] Expected<void> add(const std::string& text, const std::string& file);
  const ShaderLighting* find(const std::string& name) const;  // without case; nullptr: no script
  std::size_t size() const { return shaders_.size(); }

 private:
  std::vector<ShaderLighting> shaders_;
  std::map<std::string, std::size_t> byName_;  // lower-case name -> index of its first definition
};

// The colour q3map2 gives a shader's surface light: q3map_lightRGB, else the mean colour of its
// light image (q3map_lightImage, else qer_editorimage, the shader's name as an image, the first
// stage's image), normalised so its largest channel is 1 (ColorNormalize). White when no image is
// found.
glm::dvec3 surfaceLightColor(const ShaderLighting& shader, const GameFiles& files);

}  // namespace dynbench::maplight
