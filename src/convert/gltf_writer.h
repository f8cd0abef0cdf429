#pragma once
// Writing glTF 2.0 (the one place that does): the binary buffer, buffer views and accessors,
// URI encoding, and the finished dataset as .gltf + .bin or one .glb. Used by convert (a whole
// dataset from a capture) and merge-camera (keys appended to an existing dataset). Errors are
// returned: BinaryBuffer keeps its first one and returns it from finish(), as a stream does.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/error.h"

namespace dynbench::convert {

// glTF 2.0 §5.1.3 (accessor.componentType) and §5.11.4 (bufferView.target).
constexpr int kFloat = 5126, kUnsignedByte = 5121, kUnsignedShort = 5123, kUnsignedInt = 5125;
constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;

// A relative path as a glTF URI: RFC 3986 unreserved characters and '/' stay, everything else
// (spaces, '%', non-ASCII bytes) is percent-encoded, so readers that decode URIs find the file.
std::string uriPath(const std::string& path);

// The binary buffer on disk: regions are allocated first (4-byte aligned, glTF §3.6.2.4), then
// filled in any order with pwrite. kAppend keeps an existing file's bytes and allocates after them.
// Why a sticky error rather than one per write: the writes come from deep in a dataset's building
// (every accessor, every animated value's region), and a failed one (a full disk) spoils the whole
// file anyway. The first error is kept, later writes are skipped, and finish() returns it; nothing
// is taken as written until finish() succeeds.
class BinaryBuffer {
 public:
  enum class Mode { kCreate, kAppend };
  explicit BinaryBuffer(const std::filesystem::path& path, Mode mode = Mode::kCreate);
  ~BinaryBuffer();
  BinaryBuffer(const BinaryBuffer&) = delete;
  BinaryBuffer& operator=(const BinaryBuffer&) = delete;

  std::uint64_t allocate(std::uint64_t bytes);
  void write(std::uint64_t offset, const void* data, std::size_t bytes);
  // Pads the file to its allocated (4-byte aligned) size; the first error of the buffer's life
  // (opening, a write, sizing), if any.
  [[nodiscard]] Expected<void> finish();
  std::uint64_t size() const { return size_; }

 private:
  template <typename... Args>
  void keepFirstError(fmt::format_string<Args...> format, Args&&... args) {
    if (!error_) error_ = Error{ErrorCode::kIo, fmt::format(format, std::forward<Args>(args)...)};
  }
  std::filesystem::path path_;
  int fd_ = -1;
  std::uint64_t size_ = 0;
  std::optional<Error> error_;
};

// Fills one region front to back through a small buffer, so that a long capture costs a few
// kilobytes per animated value, not its whole history.
class RegionWriter {
 public:
  RegionWriter() = default;
  RegionWriter(BinaryBuffer* bin, std::uint64_t offset) : bin_(bin), offset_(offset) {}
  template <typename T>
  void put(const T& value) {
    const char* p = reinterpret_cast<const char*>(&value);
    pending_.insert(pending_.end(), p, p + sizeof(T));
    if (pending_.size() >= 4096) flush();
  }
  void flush();

 private:
  BinaryBuffer* bin_ = nullptr;
  std::uint64_t offset_ = 0, written_ = 0;
  std::vector<char> pending_;
};

// Components of an accessor type ("SCALAR" 1, "VEC2" 2, "VEC3" 3, "VEC4" 4, "MAT4" 16).
std::size_t componentCount(std::string_view type);

// Appends a buffer view of buffer 0 to `document`; returns its index.
int addBufferView(nlohmann::json& document, std::uint64_t offset, std::uint64_t length, int target = 0);
// Appends an accessor; min/max only when given. Returns its index.
int addAccessor(nlohmann::json& document, int view, std::uint64_t byteOffset, int componentType, std::size_t count,
                const char* type, nlohmann::json min = nullptr, nlohmann::json max = nullptr);
// Writes a whole array into `bin` now and returns the accessor over it (count: elements, by
// default data.size() / the type's components).
template <typename T>
int addDataAccessor(nlohmann::json& document, BinaryBuffer& bin, const std::vector<T>& data, int componentType, const char* type,
                    int target = 0, nlohmann::json min = nullptr, nlohmann::json max = nullptr, std::size_t count = 0) {
  const std::uint64_t bytes = data.size() * sizeof(T);
  const std::uint64_t offset = bin.allocate(bytes);
  bin.write(offset, data.data(), bytes);
  return addAccessor(document, addBufferView(document, offset, bytes, target), 0, componentType,
                     count ? count : data.size() / componentCount(type), type, std::move(min), std::move(max));
}

// The finished dataset at `output`: with glb, one .glb (glTF §4.4: header, JSON chunk, BIN chunk
// copied from `binFile`); else `output` and STEM.bin beside it (buffer 0's uri set to it). Every
// file through a temporary name; `binFile` is consumed. Returns the files written, .gltf/.glb last.
Expected<std::vector<std::filesystem::path>> writeDataset(nlohmann::json document, const std::filesystem::path& binFile,
                                                          std::uint64_t binBytes, const std::filesystem::path& output, bool glb);

}  // namespace dynbench::convert
