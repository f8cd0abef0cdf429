// The image module: OpenImageIO behind a small C interface, built as a separate shared object
// (dynbench_image) that dynbench loads on first use (src/core/image_io.cpp). OpenImageIO pulls in
// some 250 shared libraries; linking it into dynbench made every command, even `--version`, spend
// 0.7 s loading them.
#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <mutex>
#include <string>

#include <OpenImageIO/imageio.h>

namespace {

// OpenImageIO 2.4 (Debian bookworm's 2.4.7) is not thread-safe in ImageInput::open for files with
// an ICC profile: decoding it names fields and tags through static std::unordered_maps with
// operator[], which inserts unknown keys, so two threads corrupt the maps (OpenImageIO issue #3756;
// upstream now looks keys up with find). Cube 2's textures carry such profiles and textures
// load in parallel: `fidelity` crashed in about 1 run of 15. Opening (the header) is serialised;
// reading pixels is not.
std::mutex openMutex;

void setError(char* error, std::size_t size, const std::string& message) {
  if (!error || size == 0) return;
  std::strncpy(error, message.c_str(), size - 1);
  error[size - 1] = '\0';
}

}  // namespace

extern "C" {

// Writes `temporary` with the writer chosen by `path`'s extension; 8-bit formats get 8-bit pixels.
// `formats` (optional): one character per channel, 'h' half or 'f' float (EXR); `compression`
// (optional): the EXR compression name.
int dynbench_image_write_v2(const char* path, const char* temporary, int width, int height, int channels, const float* pixels,
                            const char* const* channelNames, const char* formats, const char* compression, char* error,
                            std::size_t errorSize) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  const bool eightBit = ext == ".png" || ext == ".jpg" || ext == ".jpeg";
  auto out = OIIO::ImageOutput::create(path);
  if (!out) {
    setError(error, errorSize, "no image writer for this extension: " + OIIO::geterror());
    return 1;
  }
  OIIO::ImageSpec spec(width, height, channels, eightBit ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::FLOAT);
  if (channelNames) {
    spec.channelnames.assign(channelNames, channelNames + channels);
    spec.alpha_channel = -1;  // feature buffers have no alpha; keep every channel as it is
  }
  if (formats && !eightBit) {
    for (int c = 0; c < channels; ++c) spec.channelformats.push_back(formats[c] == 'h' ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::FLOAT);
  }
  if (compression) spec.attribute("compression", compression);
  // No write time in the file (OpenImageIO stamps EXR's capDate with the clock unless DateTime is
  // set): the same frame rendered twice, here or as a Slurm task, is the same bytes.
  spec.attribute("DateTime", "");
  if (!out->open(temporary, spec) || !out->write_image(OIIO::TypeDesc::FLOAT, pixels) || !out->close()) {
    setError(error, errorSize, out->geterror());
    return 1;
  }
  return 0;
}

// Reads the header (pixels == NULL) or the whole image as floats (*pixels malloc'd; free with
// dynbench_image_free).
// `formats` receives one character per channel: 'h' for half, 'f' for any other type.
int dynbench_image_read_v2(const char* path, int* width, int* height, int* channels, float** pixels, char* names, std::size_t namesSize,
                           char* formats, std::size_t formatsSize, char* error, std::size_t errorSize) {
  std::unique_ptr<OIIO::ImageInput> in;
  {
    const std::lock_guard<std::mutex> lock(openMutex);
    in = OIIO::ImageInput::open(path);
  }
  if (!in) {
    setError(error, errorSize, "not a readable image: " + OIIO::geterror());
    return 1;
  }
  const auto& spec = in->spec();
  *width = spec.width;
  *height = spec.height;
  *channels = spec.nchannels;
  if (names && namesSize) {  // channel names joined by '\n'
    std::string joined;
    for (const auto& n : spec.channelnames) joined += n + "\n";
    setError(names, namesSize, joined);
  }
  if (formats && formatsSize) {
    std::string types;
    for (int c = 0; c < spec.nchannels; ++c) types += spec.channelformat(c) == OIIO::TypeDesc::HALF ? 'h' : 'f';
    setError(formats, formatsSize, types);
  }
  if (!pixels) return 0;
  const std::size_t count = static_cast<std::size_t>(spec.width) * spec.height * spec.nchannels;
  *pixels = static_cast<float*>(std::malloc(count * sizeof(float)));
  if (!*pixels || !in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, *pixels)) {
    setError(error, errorSize, "cannot read pixels: " + in->geterror());
    std::free(*pixels);
    *pixels = nullptr;
    return 1;
  }
  return 0;
}

void dynbench_image_free(float* pixels) { std::free(pixels); }

// OpenImageIO's pool and its OpenEXR compression pool (OpenImageIO's convention for the latter:
// 0 is every core, -1 none, so that the calling thread compresses).
void dynbench_image_set_threads(int threads) {
  OIIO::attribute("threads", threads);
  OIIO::attribute("exr_threads", threads == 1 ? -1 : threads);
}

}  // extern "C"
