#include "core/image_io.h"

#include <dlfcn.h>
#include <unistd.h>

#include <cstdlib>
#include <mutex>
#include <string_view>

#include "core/files.h"
#include "core/runtime_files.h"

namespace dynbench {
namespace {

namespace fs = std::filesystem;

using WriteFn = int (*)(const char*, const char*, int, int, int, const float*, const char* const*, const char*, const char*, char*,
                        std::size_t);
using ReadFn = int (*)(const char*, int*, int*, int*, float**, char*, std::size_t, char*, std::size_t, char*, std::size_t);
using FreeFn = void (*)(float*);
using SetThreadsFn = void (*)(int);

struct Module {
  WriteFn write = nullptr;
  ReadFn read = nullptr;
  FreeFn free = nullptr;
  SetThreadsFn setThreads = nullptr;
  std::string error;
};

// Finds the image module where core/runtime_files.h looks: $DYNBENCH_IMAGE_MODULE, the install
// (PREFIX/lib/dynbench), then where the build put it.
const Module& module() {
  static Module m;
  static std::once_flag once;
  std::call_once(once, [] {
    const auto candidates = runtimeFileCandidates({"the image module libdynbench_image.so", "DYNBENCH_IMAGE_MODULE",
                                                   "lib/dynbench/libdynbench_image.so", DYNBENCH_IMAGE_MODULE_BUILD_PATH});
    std::string tried;
    for (const auto& c : candidates) {
      void* handle = ::dlopen(c.c_str(), RTLD_NOW | RTLD_LOCAL);
      if (!handle) {
        tried += fmt::format("\n  {}: {}", c.string(), ::dlerror());
        continue;
      }
      m.write = reinterpret_cast<WriteFn>(::dlsym(handle, "dynbench_image_write_v2"));
      m.read = reinterpret_cast<ReadFn>(::dlsym(handle, "dynbench_image_read_v2"));
      m.free = reinterpret_cast<FreeFn>(::dlsym(handle, "dynbench_image_free"));
      m.setThreads = reinterpret_cast<SetThreadsFn>(::dlsym(handle, "dynbench_image_set_threads"));
      if (m.write && m.read && m.free && m.setThreads) return;
      tried += fmt::format("\n  {}: not a dynbench image module", c.string());
    }
    m.error = "cannot load the image module (libdynbench_image.so, OpenImageIO); tried:" + tried;
  });
  return m;
}

}  // namespace

Expected<void> writeImage(const fs::path& path, const FloatImage& image) {
  const Module& m = module();
  if (!m.write) return fail(ErrorCode::kExternalTool, "{}: {}", path.string(), m.error);
  std::error_code ec;
  if (path.has_parent_path()) fs::create_directories(path.parent_path(), ec);
  const fs::path tmp = temporarySibling(path);
  char error[1024] = "";
  if (!image.channelNames.empty() && image.channelNames.size() != static_cast<std::size_t>(image.channels))
    return fail(ErrorCode::kInvalidData, "{}: {} channel names for {} channels", path.string(), image.channelNames.size(), image.channels);
  if (!image.formats.empty() && image.formats.size() != static_cast<std::size_t>(image.channels))
    return fail(ErrorCode::kInvalidData, "{}: {} channel formats for {} channels", path.string(), image.formats.size(), image.channels);
  std::vector<const char*> names;
  for (const auto& n : image.channelNames) names.push_back(n.c_str());
  std::string formats;
  for (const SampleFormat f : image.formats) formats += static_cast<char>(f);
  if (m.write(path.c_str(), tmp.c_str(), image.width, image.height, image.channels, image.pixels.data(),
              names.empty() ? nullptr : names.data(), formats.empty() ? nullptr : formats.c_str(),
              image.compression.empty() ? nullptr : image.compression.c_str(), error, sizeof error) != 0) {
    fs::remove(tmp, ec);
    return fail(ErrorCode::kIo, "{}: cannot write: {}", path.string(), error);
  }
  return commitTemporary(tmp, path);
}

namespace {

Expected<FloatImage> read(const fs::path& path, bool pixelsToo) {
  const Module& m = module();
  if (!m.read) return fail(ErrorCode::kExternalTool, "{}: {}", path.string(), m.error);
  FloatImage image;
  float* pixels = nullptr;
  char error[1024] = "";
  std::string names(4096, '\0'), formats(1024, '\0');
  if (m.read(path.c_str(), &image.width, &image.height, &image.channels, pixelsToo ? &pixels : nullptr, names.data(), names.size(),
             formats.data(), formats.size(), error, sizeof error) != 0)
    return fail(ErrorCode::kParse, "{}: {}", path.string(), error);
  for (const char f : std::string_view(formats.c_str()))
    image.formats.push_back(f == 'h' ? SampleFormat::kFloat16 : SampleFormat::kFloat32);
  for (std::size_t start = 0, end; (end = names.find('\n', start)) != std::string::npos; start = end + 1)
    image.channelNames.push_back(names.substr(start, end - start));
  if (pixels) {
    image.pixels.assign(pixels, pixels + static_cast<std::size_t>(image.width) * image.height * image.channels);
    m.free(pixels);
  }
  return image;
}

}  // namespace

void setImageThreads(int threads) {
  // Without the module nothing reads or writes images, and the first read or write says why.
  if (const Module& m = module(); m.setThreads) m.setThreads(threads);
}

Expected<FloatImage> readImageHeader(const fs::path& path) { return read(path, false); }
Expected<FloatImage> readImage(const fs::path& path) { return read(path, true); }

}  // namespace dynbench
