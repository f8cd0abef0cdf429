#include "convert/converter.h"

#include <optional>

#include "core/files.h"

namespace dynbench::convert::detail {

Expected<int> Converter::image(const std::string& texture) {
  if (texture.empty()) return -1;
  if (auto it = imageByTexture_.find(texture); it != imageByTexture_.end()) return it->second;
  int index = -1;
  const std::string ext = lowercaseExtension(texture);
  // glTF's images are PNG or JPEG, copied as they are; another format OpenImageIO reads (id Tech
  // 3's TGA) is rewritten as PNG beside them, its 8-bit values unchanged (read as float, written 8-bit).
  const bool copied = ext == ".png" || ext == ".jpg" || ext == ".jpeg";
  if (const fs::path source = textureSource(texture); !source.empty()) {
    fs::path relative = fs::path(texture).lexically_normal();
    std::optional<FloatImage> pixels;
    if (!copied) {
      auto read = readImage(source);
      if (!read) {
        report_.warnings.push_back(fmt::format("texture '{}': {}; left out", texture, read.error().message));
        imageByTexture_[texture] = -1;
        return -1;
      }
      pixels = std::move(*read);
      relative.replace_extension(".png");
    }
    const fs::path target = outDir_ / (stem_ + "_textures") / relative;
    std::error_code ec;
    fs::create_directories(target.parent_path(), ec);
    if (pixels) {
      if (auto ok = writeImage(target, *pixels); !ok) return std::unexpected(ok.error());
    } else {
      fs::copy_file(source, target, fs::copy_options::overwrite_existing, ec);
      if (ec) return fail(ErrorCode::kIo, "{}: cannot copy texture: {}", target.string(), ec.message());
    }
    report_.written.push_back(target);
    index = addTexture(relative.generic_string(), ext == ".jpg" || ext == ".jpeg" ? "image/jpeg" : "image/png");
  }
  imageByTexture_[texture] = index;
  return index;
}

// A texture's file under the data root, or empty (with a warning) when it cannot be used.
fs::path Converter::textureSource(const std::string& texture) {
  const fs::path relative = fs::path(texture).lexically_normal();
  fs::path root = options_.dataRoot ? *options_.dataRoot : fs::path(reader_->settings().dataRoot);
  if (root.is_relative()) root = options_.capture / root;
  std::error_code ec;
  if (relative.is_absolute() || relative.empty() || *relative.begin() == "..") {
    report_.warnings.push_back(fmt::format("texture '{}' is not a path inside the data root; left out", texture));
    return {};
  }
  if (!fs::is_regular_file(root / relative, ec)) {
    report_.warnings.push_back(fmt::format("texture '{}' not found at {}; left out", texture, (root / relative).string()));
    return {};
  }
  return root / relative;
}

int Converter::addTexture(const std::string& relativeUri, const std::string& mime) {
  doc_["images"].push_back({{"uri", uriPath(stem_ + "_textures/" + relativeUri)}, {"mimeType", mime}});
  doc_["textures"].push_back({{"source", doc_["images"].size() - 1}, {"sampler", 0}});
  ++report_.textures;
  return static_cast<int>(doc_["textures"].size()) - 1;
}

Expected<Converter::DerivedTexture> Converter::derivedTexture(const std::string& texture, const std::string& suffix, const FloatImage& image) {
  const std::string relative = (fs::path(texture).parent_path() / (fs::path(texture).stem().string() + suffix + ".png")).generic_string();
  const fs::path target = outDir_ / (stem_ + "_textures") / relative;
  std::error_code ec;
  fs::create_directories(target.parent_path(), ec);
  if (auto ok = writeImage(target, image); !ok) return std::unexpected(ok.error());
  report_.written.push_back(target);
  return DerivedTexture{addTexture(relative, "image/png"), target};
}

// The mask map turned into a glTF metallic-roughness texture (docs/dataset.md): Cube 2 masks hold
// specular intensity in R and the environment-map (chrome) mask in B, so roughness (G) = 1 - 0.8 R
// and metallic (B) = B. Returns -1 when the mask cannot be read.
Expected<int> Converter::metallicRoughnessFromMask(const std::string& mask) {
  if (mask.empty()) return -1;
  if (auto it = maskTextures_.find(mask); it != maskTextures_.end()) return it->second;
  int index = -1;
  if (const fs::path source = textureSource(mask); !source.empty()) {
    auto image = readImage(source);
    if (!image) {
      report_.warnings.push_back(fmt::format("mask map '{}': {}; left out", mask, image.error().message));
    } else {
      FloatImage mr{image->width, image->height, 3, {}, {}, {}, {}};
      mr.pixels.resize(static_cast<std::size_t>(image->width) * image->height * 3);
      for (std::size_t p = 0; p < mr.pixels.size() / 3; ++p) {
        const float* in = &image->pixels[p * static_cast<std::size_t>(image->channels)];
        const float specular = in[0];
        const float chrome = image->channels >= 3 ? in[2] : 0.0f;
        mr.pixels[p * 3 + 0] = 1.0f;                    // R: occlusion, unused
        mr.pixels[p * 3 + 1] = 1.0f - 0.8f * specular;  // G: roughness
        mr.pixels[p * 3 + 2] = chrome;                  // B: metallic
      }
      auto derived = derivedTexture(mask, "_metallic_roughness", mr);
      if (!derived) return std::unexpected(derived.error());
      index = derived->texture;
    }
  }
  maskTextures_[mask] = index;
  return index;
}

namespace {
// Whether a mesh lies over what is behind it with partial coverage (alpha below 1 in its base
// colour or its vertex colours: Cube 2's blend layers).
bool blended(const CapturedMesh& mesh) {
  if (mesh.baseColor.a < 1.0f) return true;
  return std::any_of(mesh.colors.begin(), mesh.colors.end(), [](const glm::vec4& c) { return c.a < 1.0f; });
}
}  // namespace

// Why a grey map: q3map2 gives a light-emitting shader one colour (its light image's mean, or
// q3map_lightRGB), often of another image than the one the game draws. Dividing the drawn map by its
// mean channel by channel kept the mean but not the hue: oa_ctf2's red flame, whose light image is
// orange, rendered magenta where its texels have a little green and blue. The level map keeps the
// map's pattern and the light's colour.
Expected<std::optional<Converter::EmissionLevelMap>> Converter::emissionLevelMap(const std::string& texture) {
  if (auto it = emissionLevelMaps_.find(texture); it != emissionLevelMaps_.end()) return it->second;
  std::optional<EmissionLevelMap> result;
  if (const fs::path source = textureSource(texture); !source.empty()) {
    auto pixels = readImage(source);
    if (pixels && pixels->channels >= 1 && !pixels->pixels.empty()) {
      const std::size_t n = static_cast<std::size_t>(pixels->width) * static_cast<std::size_t>(pixels->height);
      const auto channels = static_cast<std::size_t>(pixels->channels);
      FloatImage level{pixels->width, pixels->height, 3, {}, {}, {}, {}};
      level.pixels.resize(n * 3);
      for (std::size_t i = 0; i < n; ++i) {
        glm::dvec3 rgb;
        for (std::size_t c = 0; c < 3; ++c) rgb[static_cast<int>(c)] = srgbToLinear<double>(pixels->pixels[i * channels + std::min(c, channels - 1)]);
        const double y = std::clamp(luminance(rgb), 0.0, 1.0);
        const auto encoded = static_cast<float>(linearToSrgb(y));  // sRGB-encoded, as glTF stores emissive textures
        for (std::size_t c = 0; c < 3; ++c) level.pixels[i * 3 + c] = encoded;
      }
      auto derived = derivedTexture(texture, "_emission_level", level);
      if (!derived) return std::unexpected(derived.error());
      // the mean of the bytes written, decoded as the renderer decodes them
      auto written = readImage(derived->file);
      if (!written) return std::unexpected(written.error());
      double sum = 0.0;
      for (std::size_t i = 0; i < n; ++i) sum += srgbToLinear<double>(written->pixels[i * static_cast<std::size_t>(written->channels)]);
      result = EmissionLevelMap{derived->texture, sum / static_cast<double>(n)};
    }
  }
  if (!result) report_.warnings.push_back(fmt::format("emission map '{}' cannot be read; its surface gives off its mean emission evenly", texture));
  emissionLevelMaps_[texture] = result;
  return result;
}

// Material per distinct set of maps and factors (docs/dataset.md): base colour from the texture
// map times the captured factor; metallic and roughness from the captured values, else from the
// mask map, else dielectric with roughness 0.8; emission in cd/m2.
Expected<int> Converter::material(const CapturedMesh& mesh) {
  const bool blend = blended(mesh);
  const auto& c = mesh.baseColor;
  const std::string key = fmt::format("{}\n{}\n{}\n{} {} {} {}\n{}\n{} {} {}\n{}\n{}", mesh.texture, mesh.maskTexture, mesh.emissionTexture, c.r, c.g,
                                      c.b, c.a, mesh.metallicRoughness ? fmt::format("{} {}", mesh.metallicRoughness->x, mesh.metallicRoughness->y) : "",
                                      mesh.emission.r, mesh.emission.g, mesh.emission.b, blend, mesh.emissionTextureMeanOne);
  if (auto it = materialByMaps_.find(key); it != materialByMaps_.end()) return it->second;
  json m = {{"name", mesh.texture.empty() ? "untextured" : fs::path(mesh.texture).stem().string()},
            {"pbrMetallicRoughness", {{"metallicFactor", 0.0}, {"roughnessFactor", 0.8}}}};
  const auto baseColor = image(mesh.texture);
  if (!baseColor) return std::unexpected(baseColor.error());
  if (*baseColor >= 0) m["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", *baseColor}};
  if (c != glm::vec4(1.0f)) m["pbrMetallicRoughness"]["baseColorFactor"] = {c.r, c.g, c.b, c.a};
  if (mesh.metallicRoughness) {
    m["pbrMetallicRoughness"]["metallicFactor"] = mesh.metallicRoughness->x;
    m["pbrMetallicRoughness"]["roughnessFactor"] = mesh.metallicRoughness->y;
  } else {
    const auto fromMask = metallicRoughnessFromMask(mesh.maskTexture);
    if (!fromMask) return std::unexpected(fromMask.error());
    if (*fromMask >= 0) {
      m["pbrMetallicRoughness"]["metallicRoughnessTexture"] = {{"index", *fromMask}};
      m["pbrMetallicRoughness"]["metallicFactor"] = 1.0;
      m["pbrMetallicRoughness"]["roughnessFactor"] = 1.0;
      m["extras"] = {{"dynbench_mask_map", mesh.maskTexture}};
    }
  }
  // Emission e in the lights' units shows as bright as a white Lambertian surface under the
  // engine's full light, E_u lux: radiance E_u e / pi cd/m2. glTF keeps emissiveFactor within
  // [0, 1]; KHR_materials_emissive_strength carries the rest.
  glm::vec3 emission = mesh.emission;
  int emissionTexture = -1;
  if (mesh.emissionTextureMeanOne && !mesh.emissionTexture.empty() && glm::any(glm::greaterThan(emission, glm::vec3(0.0f)))) {
    // The capture's emission is the surface's mean (record m): in the light's colour, times the
    // map's level over its mean, the surface gives off the light the capture says. A map without
    // light (mean 0) leaves the surface dark.
    const auto level = emissionLevelMap(mesh.emissionTexture);
    if (!level) return std::unexpected(level.error());
    if (*level) {
      emission = (*level)->mean > 1e-6 ? emission / static_cast<float>((*level)->mean) : glm::vec3(0.0f);
      emissionTexture = (*level)->texture;
    }
  }
  if (const float peak = std::max({emission.r, emission.g, emission.b}); peak > 0) {
    if (!mesh.emissionTextureMeanOne) {
      const auto emissive = image(mesh.emissionTexture);
      if (!emissive) return std::unexpected(emissive.error());
      emissionTexture = *emissive;
    }
    const glm::vec3 factor = emission / peak;
    m["emissiveFactor"] = {factor.r, factor.g, factor.b};
    m["extensions"]["KHR_materials_emissive_strength"] = {{"emissiveStrength", luxPerUnit_ * peak / kPi}};
    usesEmissiveStrength_ = true;
    if (emissionTexture >= 0) m["emissiveTexture"] = {{"index", emissionTexture}};
  }
  if (blend) m["alphaMode"] = "BLEND";
  doc_["materials"].push_back(m);
  const int index = static_cast<int>(doc_["materials"].size()) - 1;
  materialByMaps_[key] = index;
  return index;
}

// A vertex-animated model's key frames as morph targets (docs/dataset.md): target k displaces the
// mesh's vertices to key frame k, so weights (1 - f) at key frame a and f at b (summing to 1) give
// (1 - f) x a + f x b, MD3's interpolation. glTF wants every primitive of a mesh to have the same
// targets: a mesh of the model without key frames gets targets of zeros (accessors without a
// buffer view, which glTF defines as zeros).
json Converter::morphTargets(const CapturedModel& model, const CapturedMesh& mesh) {
  json targets = json::array();
  const std::size_t n = mesh.positions.size();
  auto unit = [](glm::vec3 v) {
    const float len = glm::length(v);
    return len > 0 ? v / len : glm::vec3(0, 1, 0);
  };
  for (std::size_t k = 0; k < model.keyFrames; ++k) {
    if (mesh.keyPositions.empty()) {
      targets.push_back({{"POSITION", accessor(-1, 0, kFloat, n, "VEC3", std::vector<float>{0, 0, 0}, std::vector<float>{0, 0, 0})}});
      continue;
    }
    std::vector<float> displacement;
    glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    for (std::size_t v = 0; v < n; ++v) {
      const glm::vec3 d = mesh.keyPositions[k][v] - mesh.positions[v];
      lo = glm::min(lo, d), hi = glm::max(hi, d);
      displacement.insert(displacement.end(), {d.x, d.y, d.z});
    }
    json target = {{"POSITION", dataAccessor(displacement, kFloat, "VEC3", kArrayBuffer, std::vector<float>{lo.x, lo.y, lo.z},
                                             std::vector<float>{hi.x, hi.y, hi.z})}};
    if (!mesh.keyNormals.empty() && !mesh.normals.empty()) {
      std::vector<float> normals;
      for (std::size_t v = 0; v < n; ++v) {
        const glm::vec3 d = unit(mesh.keyNormals[k][v]) - unit(mesh.normals[v]);
        normals.insert(normals.end(), {d.x, d.y, d.z});
      }
      target["NORMAL"] = dataAccessor(normals, kFloat, "VEC3", kArrayBuffer);
    }
    targets.push_back(std::move(target));
  }
  return targets;
}

Expected<void> Converter::buildMeshes() {
  for (const auto& model : reader_->models()) {
    json primitives = json::array();
    for (const auto& mesh : model.meshes) {
      if (mesh.indices.empty()) continue;
      glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
      std::vector<float> positions;
      for (const auto& p : mesh.positions) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
        positions.insert(positions.end(), {p.x, p.y, p.z});
      }
      json attributes = {{"POSITION", dataAccessor(positions, kFloat, "VEC3", kArrayBuffer, std::vector<float>{lo.x, lo.y, lo.z},
                                                   std::vector<float>{hi.x, hi.y, hi.z})}};
      if (!mesh.normals.empty()) {
        std::vector<float> normals;
        for (auto n : mesh.normals) {
          const float len = glm::length(n);
          n = len > 0 ? n / len : glm::vec3(0, 1, 0);  // glTF requires unit normals
          normals.insert(normals.end(), {n.x, n.y, n.z});
        }
        attributes["NORMAL"] = dataAccessor(normals, kFloat, "VEC3", kArrayBuffer);
      }
      if (!mesh.colors.empty()) {
        std::vector<float> colors;
        for (const auto& c : mesh.colors) colors.insert(colors.end(), {c.r, c.g, c.b, c.a});
        attributes["COLOR_0"] = dataAccessor(colors, kFloat, "VEC4", kArrayBuffer);
      }
      if (!mesh.uvs.empty()) {
        std::vector<float> uvs;
        for (const auto& t : mesh.uvs) uvs.insert(uvs.end(), {t.x, t.y});
        attributes["TEXCOORD_0"] = dataAccessor(uvs, kFloat, "VEC2", kArrayBuffer);
      }
      if (!model.joints.empty() && !mesh.joints.empty()) {
        std::vector<std::uint16_t> joints;
        std::vector<float> weights;
        for (std::size_t v = 0; v < mesh.joints.size(); ++v) {
          const glm::vec4 w = mesh.weights[v];
          const float sum = w.x + w.y + w.z + w.w;
          for (int k = 0; k < 4; ++k) {
            joints.push_back(w[k] > 0 ? mesh.joints[v][k] : 0);
            weights.push_back(sum > 0 ? w[k] / sum : (k == 0 ? 1.0f : 0.0f));  // glTF: weights sum to 1
          }
        }
        attributes["JOINTS_0"] = dataAccessor(joints, kUnsignedShort, "VEC4", kArrayBuffer);
        attributes["WEIGHTS_0"] = dataAccessor(weights, kFloat, "VEC4", kArrayBuffer);
      }
      const auto materialIndex = material(mesh);
      if (!materialIndex) return std::unexpected(materialIndex.error());
      json primitive = {{"attributes", attributes},
                        {"indices", dataAccessor(mesh.indices, kUnsignedInt, "SCALAR", kElementArrayBuffer)},
                        {"material", *materialIndex}};
      if (model.keyFrames > 0) primitive["targets"] = morphTargets(model, mesh);
      primitives.push_back(std::move(primitive));
    }
    if (primitives.empty()) {
      meshOfModel_.push_back(-1);
      continue;
    }
    json gltfMesh = {{"name", model.path}, {"primitives", primitives}};
    if (model.keyFrames > 0) {
      // Without an animation (a static instance) the mesh shows key frame 0.
      std::vector<float> weights(model.keyFrames, 0.0f);
      weights[0] = 1.0f;
      gltfMesh["weights"] = weights;
      report_.morphTargets += model.keyFrames;
    }
    doc_["meshes"].push_back(std::move(gltfMesh));
    meshOfModel_.push_back(static_cast<int>(doc_["meshes"].size()) - 1);
    ++report_.meshes;
    // Inverse bind matrices, shared by every instance of the model.
    if (!model.joints.empty()) {
      std::vector<float> matrices;
      for (const auto& j : model.joints) {
        const glm::dmat4 m = matrixOf(j.inverseBindPose);
        for (int c = 0; c < 4; ++c)
          for (int r = 0; r < 4; ++r) matrices.push_back(static_cast<float>(m[c][r]));
      }
      ibmOfModel_[static_cast<int>(meshOfModel_.size()) - 1] = dataAccessor(matrices, kFloat, "MAT4", 0);
    }
  }
  return {};
}
}  // namespace dynbench::convert::detail
