#include "core/image_io.h"

#include <algorithm>
#include <cctype>

#include <OpenImageIO/imageio.h>

#include "core/files.h"

namespace dynbench {

Expected<void> writeImage(const std::filesystem::path& path, const FloatImage& image) {
  // The writer is chosen by the final name's extension, then opened on the temporary name.
  const auto tmp = temporarySibling(path);
  auto out = OIIO::ImageOutput::create(path.string());
  if (!out) return fail(ErrorCode::kIo, "{}: no image writer for this extension: {}", path.string(), OIIO::geterror());
  // 8-bit formats get 8-bit pixels (OpenImageIO quantises the floats); the rest keep floats.
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  const bool eightBit = ext == ".png" || ext == ".jpg" || ext == ".jpeg";
  const OIIO::ImageSpec spec(image.width, image.height, image.channels, eightBit ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::FLOAT);
  if (!out->open(tmp.string(), spec)) return fail(ErrorCode::kIo, "{}: cannot write: {}", path.string(), out->geterror());
  if (!out->write_image(OIIO::TypeDesc::FLOAT, image.pixels.data()) || !out->close()) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    return fail(ErrorCode::kIo, "{}: write failed: {}", path.string(), out->geterror());
  }
  return commitTemporary(tmp, path);
}

Expected<FloatImage> readImageHeader(const std::filesystem::path& path) {
  auto in = OIIO::ImageInput::open(path.string());
  if (!in) return fail(ErrorCode::kParse, "{}: not a readable image: {}", path.string(), OIIO::geterror());
  const auto& spec = in->spec();
  FloatImage image;
  image.width = spec.width;
  image.height = spec.height;
  image.channels = spec.nchannels;
  return image;
}

Expected<FloatImage> readImage(const std::filesystem::path& path) {
  auto in = OIIO::ImageInput::open(path.string());
  if (!in) return fail(ErrorCode::kParse, "{}: not a readable image: {}", path.string(), OIIO::geterror());
  const auto& spec = in->spec();
  FloatImage image{spec.width, spec.height, spec.nchannels, {}};
  image.pixels.resize(static_cast<std::size_t>(spec.width) * spec.height * spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, image.pixels.data()))
    return fail(ErrorCode::kParse, "{}: cannot read pixels: {}", path.string(), in->geterror());
  return image;
}

}  // namespace dynbench
