#include "render/textures.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include "core/image_io.h"
#include "core/math.h"
#include "render/prefetch.h"

namespace dynbench::render {
namespace {

// Texel i of `image` as RGBA: grey expands to RGB, a missing alpha is 1.
glm::vec4 rgba(const FloatImage& image, std::size_t i) {
  const int c = image.channels;
  const float* p = &image.pixels[i * static_cast<std::size_t>(c)];
  if (c == 1) return {p[0], p[0], p[0], 1.0f};
  if (c == 2) return {p[0], p[0], p[0], p[1]};  // grey + alpha
  return {p[0], p[1], p[2], c >= 4 ? p[3] : 1.0f};
}

// The texel values of `image` as floats, sRGB-decoded when `srgb` (alpha stays linear).
Texture floatTexture(const FloatImage& image, bool srgb) {
  Texture t;
  t.width = image.width;
  t.height = image.height;
  t.texels.resize(static_cast<std::size_t>(image.width) * image.height);
  for (std::size_t i = 0; i < t.texels.size(); ++i) {
    glm::vec4 v = rgba(image, i);
    if (srgb)
      for (int k = 0; k < 3; ++k) v[k] = srgbToLinear(v[k]);
    t.texels[i] = v;
  }
  return t;
}

// The same texture as 8-bit codes when every value of the image is one of 256 levels k / 255 (an
// 8-bit PNG or JPEG): each code decodes to exactly the float floatTexture would have stored.
// Otherwise (16-bit or HDR images) the float texture.
Texture toTexture(const FloatImage& image, bool srgb) {
  std::array<float, 256> level{};
  std::array<bool, 256> seen{};
  auto codeOf = [&](float v, std::uint8_t& code) {
    const float scaled = v * 255.0f;
    if (!(scaled >= -0.25f && scaled <= 255.25f)) return false;
    // Round to nearest by truncation (scaled + 0.5 > 0 here): a call to lround per channel was
    // 40 % of a one-frame job's instructions. Ties do not matter: a code within 1e-3 of `scaled`
    // is the nearest whichever way halves round.
    code = static_cast<std::uint8_t>(scaled + 0.5f);
    if (std::abs(scaled - code) > 1e-3f) return false;
    if (!seen[code]) {
      seen[code] = true;
      level[code] = v;
    }
    return level[code] == v;  // one float per code, or the decode would not be exact
  };
  Texture t;
  t.width = image.width;
  t.height = image.height;
  t.codes.resize(static_cast<std::size_t>(image.width) * image.height);
  for (std::size_t i = 0; i < t.codes.size(); ++i) {
    const glm::vec4 v = rgba(image, i);
    for (int k = 0; k < 4; ++k)
      if (!codeOf(v[k], t.codes[i][static_cast<std::size_t>(k)])) return floatTexture(image, srgb);
  }
  for (std::size_t k = 0; k < 256; ++k) {
    const float v = seen[k] ? level[k] : static_cast<float>(k) / 255.0f;
    t.decodeAlpha[k] = v;
    t.decodeColour[k] = srgb ? srgbToLinear(v) : v;
  }
  return t;
}

}  // namespace

// In float: texels are float, and a float uv resolves 1/1000 of a texel on a 16k-texel repeat.
Texture::Footprint Texture::footprint(glm::dvec2 uv) const {
  const float x = static_cast<float>(uv.x) * static_cast<float>(width) - 0.5f;
  const float y = static_cast<float>(uv.y) * static_cast<float>(height) - 0.5f;
  const float fx = std::floor(x), fy = std::floor(y);
  // Repeat: one remainder per axis (uv far outside [0, 1] stays exact as long as it fits a long),
  // and only when outside the image: a division is a large part of a lookup's arithmetic.
  auto wrap = [](float f, int n) {
    long i = static_cast<long>(f);
    if (i >= 0 && i < n) return static_cast<std::size_t>(i);
    i %= n;
    return static_cast<std::size_t>(i < 0 ? i + n : i);
  };
  const std::size_t x0 = wrap(fx, width), y0 = wrap(fy, height);
  const std::size_t x1 = x0 + 1 == static_cast<std::size_t>(width) ? 0 : x0 + 1;
  const std::size_t y1 = y0 + 1 == static_cast<std::size_t>(height) ? 0 : y0 + 1;
  const auto w = static_cast<std::size_t>(width);
  return {{y0 * w + x0, y0 * w + x1, y1 * w + x0, y1 * w + x1}, x - fx, y - fy};
}

glm::vec4 Texture::texel(std::size_t i) const {
  if (codes.empty()) return texels[i];
  const auto& k = codes[i];
  return glm::vec4(decodeColour[k[0]], decodeColour[k[1]], decodeColour[k[2]], decodeAlpha[k[3]]);
}

glm::dvec4 Texture::sample(glm::dvec2 uv) const {
  const Footprint f = footprint(uv);
  const glm::vec4 a = texel(f.index[0]), b = texel(f.index[1]), c = texel(f.index[2]), d = texel(f.index[3]);
  const float tx = f.tx, ty = f.ty;
  return glm::dvec4((1 - ty) * ((1 - tx) * a + tx * b) + ty * ((1 - tx) * c + tx * d));
}

namespace {

// Bilinear lookup in a float level, repeating at the edges (the same texel centres and wrap as
// level 0's Footprint).
glm::vec4 bilinear(const MipLevel& level, glm::dvec2 uv) {
  const double x = uv.x * level.width - 0.5, y = uv.y * level.height - 0.5;
  const double fx = std::floor(x), fy = std::floor(y);
  auto wrap = [](double f, int n) {
    long i = static_cast<long>(f) % n;
    return static_cast<std::size_t>(i < 0 ? i + n : i);
  };
  const std::size_t x0 = wrap(fx, level.width), y0 = wrap(fy, level.height);
  const std::size_t x1 = (x0 + 1) % static_cast<std::size_t>(level.width), y1 = (y0 + 1) % static_cast<std::size_t>(level.height);
  const auto w = static_cast<std::size_t>(level.width);
  const auto tx = static_cast<float>(x - fx), ty = static_cast<float>(y - fy);
  const auto& t = level.texels;
  return (1 - ty) * ((1 - tx) * t[y0 * w + x0] + tx * t[y0 * w + x1]) + ty * ((1 - tx) * t[y1 * w + x0] + tx * t[y1 * w + x1]);
}

}  // namespace

void Texture::buildMips() {
  mips.clear();
  // Level 0 in decoded values, as the levels above hold them.
  MipLevel below{width, height, {}};
  below.texels.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
  for (std::size_t i = 0; i < below.texels.size(); ++i) below.texels[i] = texel(i);
  while (below.width > 1 || below.height > 1) {
    MipLevel level{std::max(1, below.width / 2), std::max(1, below.height / 2), {}};
    level.texels.resize(static_cast<std::size_t>(level.width) * static_cast<std::size_t>(level.height));
    // The 2 x 2 box below each texel (an odd side's last row or column joins the box before it
    // only through the clamp: a box filter, as glGenerateMipmap's usual implementation).
    for (int y = 0; y < level.height; ++y)
      for (int x = 0; x < level.width; ++x) {
        glm::vec4 sum(0.0f);
        for (int dy = 0; dy < 2; ++dy)
          for (int dx = 0; dx < 2; ++dx) {
            const int sx = std::min(2 * x + dx, below.width - 1), sy = std::min(2 * y + dy, below.height - 1);
            sum += below.texels[static_cast<std::size_t>(sy) * static_cast<std::size_t>(below.width) + static_cast<std::size_t>(sx)];
          }
        level.texels[static_cast<std::size_t>(y) * static_cast<std::size_t>(level.width) + static_cast<std::size_t>(x)] = 0.25f * sum;
      }
    mips.push_back(level);
    below = std::move(level);
  }
}

glm::dvec4 Texture::sample(glm::dvec2 uv, double lod) const {
  const double level = lod + 0.5 * std::log2(static_cast<double>(width) * static_cast<double>(height));
  if (!(level > 0.0) || mips.empty()) return sample(uv);  // magnified, or no filtering (NaN, -inf)
  const double top = static_cast<double>(mips.size());
  if (level >= top) return glm::dvec4(bilinear(mips.back(), uv));
  const auto lower = static_cast<std::size_t>(level);
  const double t = level - static_cast<double>(lower);
  const glm::dvec4 a = lower == 0 ? sample(uv) : glm::dvec4(bilinear(mips[lower - 1], uv));
  const glm::dvec4 b(bilinear(mips[lower], uv));
  return a + t * (b - a);
}

double textureLod(double coneWidth, double cosine, double uvArea, double worldArea) {
  if (!(coneWidth > 0) || !(uvArea > 0) || !(worldArea > 0)) return -std::numeric_limits<double>::infinity();
  // A grazing cone's footprint grows as 1 / |cos|; capped, as the paper's implementations do, so
  // that a ray along a surface does not ask for a level beyond the texture.
  const double c = std::max(std::abs(cosine), 1e-3);
  return 0.5 * std::log2(uvArea / worldArea) + std::log2(coneWidth) - std::log2(c);
}

void Texture::prefetch(glm::dvec2 uv) const {
  const Footprint f = footprint(uv);
  // The two texels of a row share a cache line but at a line's end or the image's edge: one
  // prefetch per line, as each occupies one of the core's few slots for loads in flight (perf put
  // this function's stalls on its second prefetch of a row).
  auto address = [&](std::size_t i) {
    return reinterpret_cast<std::uintptr_t>(codes.empty() ? static_cast<const void*>(&texels[i]) : &codes[i]);
  };
  constexpr std::uintptr_t kLine = 64;
  for (const std::size_t row : {0, 2}) {
    const std::uintptr_t left = address(f.index[row]), right = address(f.index[row + 1]);
    prefetchLine(reinterpret_cast<const void*>(left));
    if (left / kLine != right / kLine) prefetchLine(reinterpret_cast<const void*>(right));
  }
}

Expected<TextureSet> TextureSet::load(const scene::Scene& scene, std::vector<std::string>& warnings) {
  TextureSet set;
  set.linear_.resize(scene.images.size());
  set.raw_.resize(scene.images.size());
  std::vector<char> wantLinear(scene.images.size(), 0), wantRaw(scene.images.size(), 0);
  for (const auto& m : scene.materials) {
    if (m.workflow != scene::MaterialWorkflow::kMetallicRoughness) continue;
    for (const auto* ref : {&m.baseColorTexture, &m.emissiveTexture})
      if (ref->image >= 0) wantLinear[static_cast<std::size_t>(ref->image)] = 1;
    for (const auto* ref : {&m.metallicRoughnessTexture, &m.normalTexture})
      if (ref->image >= 0) wantRaw[static_cast<std::size_t>(ref->image)] = 1;
  }
  // Decoded in parallel: a dataset's textures are the serial part of a render's start (0.7 s of
  // 0.8 s for one frame of the colos segment before this).
  std::vector<std::string> problems(scene.images.size());
  tbb::parallel_for(std::size_t{0}, scene.images.size(), [&](std::size_t i) {
    if (!wantLinear[i] && !wantRaw[i]) return;
    const auto& image = scene.images[i];
    if (image.embedded || image.file.empty()) {
      problems[i] = fmt::format("image {} ('{}') is embedded in the file; render reads only external image files, "
                                "so its material slots use their factors alone", i, image.name);
      return;
    }
    auto decoded = readImage(image.file);
    if (!decoded) {
      problems[i] = fmt::format("image {}: {}; its material slots use their factors alone", i, decoded.error().message);
      return;
    }
    if (decoded->width <= 0 || decoded->height <= 0 || decoded->channels <= 0) return;
    if (wantLinear[i]) {
      set.linear_[i] = toTexture(*decoded, true);
      set.linear_[i].buildMips();
    }
    if (wantRaw[i]) {
      set.raw_[i] = toTexture(*decoded, false);
      set.raw_[i].buildMips();
    }
  });
  for (auto& p : problems)
    if (!p.empty()) warnings.push_back(std::move(p));
  return set;
}

const Texture* TextureSet::find(int image, bool srgb) const {
  if (image < 0 || static_cast<std::size_t>(image) >= linear_.size()) return nullptr;
  const Texture& t = (srgb ? linear_ : raw_)[static_cast<std::size_t>(image)];
  return t.texels.empty() && t.codes.empty() ? nullptr : &t;
}

void TextureSet::prefetch(const scene::TextureRef& ref, bool srgb, glm::dvec2 uv) const {
  if (const Texture* t = find(ref.image, srgb)) t->prefetch(uv);
}

glm::dvec4 TextureSet::sample(const scene::TextureRef& ref, bool srgb, glm::dvec2 uv, glm::dvec4 fallback) const {
  const Texture* t = find(ref.image, srgb);
  return t ? t->sample(uv) : fallback;
}

glm::dvec4 TextureSet::sample(const scene::TextureRef& ref, bool srgb, glm::dvec2 uv, double lod, glm::dvec4 fallback) const {
  const Texture* t = find(ref.image, srgb);
  return t ? t->sample(uv, lod) : fallback;
}

}  // namespace dynbench::render
