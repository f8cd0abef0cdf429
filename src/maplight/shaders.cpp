#include "maplight/shaders.h"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <fstream>
#include <numbers>
#include <unistd.h>

#include "core/files.h"
#include "core/image_io.h"

namespace dynbench::maplight {

namespace {

// id Tech 3's script tokens: words, quoted strings, braces; // and /* */ comments; tokens keep
// their line so that a keyword's arguments end at the line's end.
struct Token {
  std::string text;
  int line = 0;
};

std::vector<Token> tokenize(const std::string& text) {
  std::vector<Token> tokens;
  int line = 1;
  for (std::size_t i = 0; i < text.size();) {
    const char c = text[i];
    if (c == '\n') {
      ++line;
      ++i;
    } else if (std::isspace(static_cast<unsigned char>(c))) {
      ++i;
    } else if (c == '/' && i + 1 < text.size() && text[i + 1] == '/') {
      while (i < text.size() && text[i] != '\n') ++i;
    } else if (c == '/' && i + 1 < text.size() && text[i + 1] == '*') {
      i += 2;
      while (i + 1 < text.size() && !(text[i] == '*' && text[i + 1] == '/')) line += text[i++] == '\n';
      i += 2;
    } else if (c == '{' || c == '}') {
      tokens.push_back({std::string(1, c), line});
      ++i;
    } else if (c == '"') {
      const std::size_t end = text.find('"', i + 1);
      const std::size_t stop = end == std::string::npos ? text.size() : end;
      tokens.push_back({text.substr(i + 1, stop - i - 1), line});
      i = stop + 1;
    } else {
      std::size_t end = i;
      while (end < text.size() && !std::isspace(static_cast<unsigned char>(text[end])) && text[end] != '{' && text[end] != '}') ++end;
      tokens.push_back({text.substr(i, end - i), line});
      i = end;
    }
  }
  return tokens;
}

double number(const std::string& s) { return std::atof(s.c_str()); }
}  // namespace

Expected<void> ShaderScripts::add(const std::string& text, const std::string& file) {
  const std::vector<Token> tokens = tokenize(text);
  std::size_t i = 0;
  while (i < tokens.size()) {
    ShaderLighting shader;
    shader.name = tokens[i].text;
    const int nameLine = tokens[i].line;
    if (shader.name == "{" || shader.name == "}")
      return fail(ErrorCode::kParse, "{}:{}: expected a shader name, found '{}'", file, tokens[i].line, shader.name);
    if (++i >= tokens.size() || tokens[i].text != "{")
      return fail(ErrorCode::kParse, "{}:{}: shader '{}': expected '{{' after its name", file, nameLine, shader.name);
    ++i;
    int depth = 1, stage = 0;
    while (i < tokens.size() && depth > 0) {
      const Token& t = tokens[i];
      if (t.text == "{") {
        ++depth;
        ++stage;
        ++i;
        continue;
      }
      if (t.text == "}") {
        --depth;
        ++i;
        continue;
      }
      // the keyword's arguments: the following tokens on its line
      std::vector<std::string> args;
      std::size_t j = i + 1;
      while (j < tokens.size() && tokens[j].line == t.line && tokens[j].text != "{" && tokens[j].text != "}") args.push_back(tokens[j++].text);
      const std::string key = asciiLowercase(t.text);
      if (depth == 1) {
        if (key == "q3map_surfacelight" && !args.empty()) shader.surfaceLight = number(args[0]);
        else if (key == "q3map_lightrgb" && args.size() >= 3) {
          glm::dvec3 c(number(args[0]), number(args[1]), number(args[2]));
          const double peak = std::max({c.r, c.g, c.b});
          if (peak > 0) shader.lightRgb = c / peak;
        } else if (key == "q3map_lightimage" && !args.empty()) shader.lightImage = args[0];
        else if (key == "qer_editorimage" && !args.empty()) shader.editorImage = args[0];
        else if ((key == "q3map_sun" || key == "q3map_sunext" || key == "sun") && args.size() >= 6) {
          ShaderSun sun;
          sun.color = glm::dvec3(number(args[0]), number(args[1]), number(args[2]));
          sun.color = glm::length(sun.color) > 0 ? glm::normalize(sun.color) : glm::dvec3(0.0);
          sun.intensity = number(args[3]);
          const double a = number(args[4]) * std::numbers::pi / 180.0, b = number(args[5]) * std::numbers::pi / 180.0;
          sun.towardsSun = {std::cos(a) * std::cos(b), std::sin(a) * std::cos(b), std::sin(b)};
          shader.suns.push_back(sun);
          shader.sky = true;  // q3map2 applies surfaceparm sky with a sun
        } else if (key == "q3map_skylight" && args.size() >= 2) {
          shader.skyLight = number(args[0]);
          shader.skyLightIterations = static_cast<int>(number(args[1]));
        } else if (key == "cull" && !args.empty()) {
          const std::string mode = asciiLowercase(args[0]);
          shader.twoSided = mode == "none" || mode == "disable" || mode == "twosided";
        } else if (key == "q3map_lightsubdivide" && !args.empty()) {
          shader.lightSubdivide = number(args[0]);
        } else if (key == "q3map_backsplash" && args.size() >= 2) {
          shader.backsplashFraction = number(args[0]) * 0.01;
          shader.backsplashDistance = number(args[1]);
        } else if (key == "surfaceparm" && !args.empty()) {
          const std::string parm = asciiLowercase(args[0]);
          shader.sky = shader.sky || parm == "sky";
          shader.translucent = shader.translucent || parm == "trans";
          shader.noDraw = shader.noDraw || parm == "nodraw";
        }
      } else if (stage == 1 && (key == "map" || key == "clampmap") && !args.empty() && shader.firstStageImage.empty()) {
        shader.firstStageImage = args[0];
      }
      i = j;
    }
    if (depth > 0) return fail(ErrorCode::kParse, "{}:{}: shader '{}' is not closed (expected '}}')", file, nameLine, shader.name);
    const std::string key = asciiLowercase(shader.name);
    if (byName_.emplace(key, shaders_.size()).second) shaders_.push_back(std::move(shader));
  }
  return {};
}

Expected<ShaderScripts> ShaderScripts::read(const GameFiles& files) {
  ShaderScripts scripts;
  for (const std::string& path : files.list("scripts/", ".shader")) {
    auto text = files.read(path);
    if (!text) return std::unexpected(text.error());
    if (auto added = scripts.add(*text, files.archiveOf(path) + ":" + path); !added) return std::unexpected(added.error());
  }
  return scripts;
}

const ShaderLighting* ShaderScripts::find(const std::string& name) const {
  const auto it = byName_.find(asciiLowercase(name));
  return it != byName_.end() ? &shaders_[it->second] : nullptr;
}

glm::dvec3 surfaceLightColor(const ShaderLighting& shader, const GameFiles& files) {
  if (shader.lightRgb) return *shader.lightRgb;
  std::vector<std::string> candidates;
  for (const std::string& image : {shader.lightImage, shader.editorImage, shader.name, shader.firstStageImage}) {
    if (image.empty()) continue;
    const auto dot = image.find_last_of('.');
    const std::string stem = dot == std::string::npos || image.find('/', dot) != std::string::npos ? image : image.substr(0, dot);
    candidates.push_back(stem + ".tga");
    candidates.push_back(stem + ".jpg");
  }
  for (const std::string& path : candidates) {
    if (!files.contains(path)) continue;
    auto bytes = files.read(path);
    if (!bytes) continue;
    // OpenImageIO reads files: the image goes through a private temporary file.
    static std::atomic<unsigned> serial{0};
    const auto temporary = std::filesystem::temp_directory_path() /
                           ("dynbench-light-image-" + std::to_string(::getpid()) + "-" + std::to_string(serial++) + path.substr(path.size() - 4));
    {
      std::ofstream out(temporary, std::ios::binary);
      out.write(bytes->data(), static_cast<std::streamsize>(bytes->size()));
    }
    auto image = readImage(temporary);
    std::error_code ec;
    std::filesystem::remove(temporary, ec);
    if (!image || image->channels < 3 || image->pixels.empty()) continue;
    glm::dvec3 sum(0.0);
    const std::size_t count = image->pixels.size() / static_cast<std::size_t>(image->channels);
    for (std::size_t p = 0; p < count; ++p)
      for (int c = 0; c < 3; ++c) sum[c] += image->pixels[p * static_cast<std::size_t>(image->channels) + static_cast<std::size_t>(c)];
    const double peak = std::max({sum.r, sum.g, sum.b});
    if (peak > 0) return sum / peak;
  }
  return glm::dvec3(1.0);
}

}  // namespace dynbench::maplight
