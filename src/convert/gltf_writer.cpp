#include "convert/gltf_writer.h"

#include <fcntl.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstring>
#include <fstream>

#include <fmt/format.h>

#include "core/files.h"

namespace dynbench::convert {

namespace fs = std::filesystem;
using json = nlohmann::json;

std::string uriPath(const std::string& path) {
  std::string out;
  for (unsigned char c : path) {
    if (std::isalnum(c) || c == '-' || c == '.' || c == '_' || c == '~' || c == '/') out += static_cast<char>(c);
    else out += fmt::format("%{:02X}", c);
  }
  return out;
}

BinaryBuffer::BinaryBuffer(const fs::path& path, Mode mode) : path_(path) {
  fd_ = ::open(path.c_str(), mode == Mode::kCreate ? (O_RDWR | O_CREAT | O_TRUNC) : O_RDWR, 0644);
  if (fd_ < 0) {
    keepFirstError("{}: cannot {}: {}", path.string(), mode == Mode::kCreate ? "create" : "open", std::strerror(errno));
    return;
  }
  if (mode == Mode::kAppend) {
    const off_t end = ::lseek(fd_, 0, SEEK_END);
    if (end < 0) keepFirstError("{}: cannot size: {}", path.string(), std::strerror(errno));
    else size_ = static_cast<std::uint64_t>(end);
  }
}

BinaryBuffer::~BinaryBuffer() {
  if (fd_ >= 0) ::close(fd_);
}

std::uint64_t BinaryBuffer::allocate(std::uint64_t bytes) {
  size_ = (size_ + 3) & ~std::uint64_t{3};  // every region 4-byte aligned (glTF §3.6.2.4)
  const std::uint64_t offset = size_;
  size_ += bytes;
  return offset;
}

void BinaryBuffer::write(std::uint64_t offset, const void* data, std::size_t bytes) {
  if (error_) return;
  const char* p = static_cast<const char*>(data);
  while (bytes > 0) {
    const ssize_t n = ::pwrite(fd_, p, bytes, static_cast<off_t>(offset));
    if (n < 0) {
      if (errno == EINTR) continue;
      keepFirstError("{}: write failed: {}", path_.string(), std::strerror(errno));
      return;
    }
    p += n;
    offset += static_cast<std::uint64_t>(n);
    bytes -= static_cast<std::size_t>(n);
  }
}

Expected<void> BinaryBuffer::finish() {
  size_ = (size_ + 3) & ~std::uint64_t{3};
  if (!error_ && ::ftruncate(fd_, static_cast<off_t>(size_)) != 0) keepFirstError("{}: cannot size: {}", path_.string(), std::strerror(errno));
  if (error_) return std::unexpected(*error_);
  return {};
}

void RegionWriter::flush() {
  if (pending_.empty() || !bin_) return;
  bin_->write(offset_ + written_, pending_.data(), pending_.size());
  written_ += pending_.size();
  pending_.clear();
}

std::size_t componentCount(std::string_view type) {
  return type == "SCALAR" ? 1 : type == "VEC2" ? 2 : type == "VEC3" ? 3 : type == "VEC4" ? 4 : 16;
}

int addBufferView(json& document, std::uint64_t offset, std::uint64_t length, int target) {
  json v = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", length}};
  if (target) v["target"] = target;
  document["bufferViews"].push_back(v);
  return static_cast<int>(document["bufferViews"].size()) - 1;
}

int addAccessor(json& document, int view, std::uint64_t byteOffset, int componentType, std::size_t count, const char* type, json min,
                json max) {
  json a = {{"componentType", componentType}, {"count", count}, {"type", type}};
  if (view >= 0) a["bufferView"] = view;  // none: zeros (glTF 2.0, 3.6.2.1)
  if (byteOffset) a["byteOffset"] = byteOffset;
  if (!min.is_null()) a["min"] = std::move(min);
  if (!max.is_null()) a["max"] = std::move(max);
  document["accessors"].push_back(a);
  return static_cast<int>(document["accessors"].size()) - 1;
}

namespace {

Expected<void> writeGlb(const json& document, const fs::path& binFile, std::uint64_t binBytes, const fs::path& output) {
  std::string text = document.dump();
  while (text.size() % 4) text.push_back(' ');
  const std::uint64_t binPadded = (binBytes + 3) & ~std::uint64_t{3};
  const std::uint64_t total = 12 + 8 + text.size() + 8 + binPadded;
  if (total > 0xFFFFFFFFull) return fail(ErrorCode::kUnsupported, "the dataset is larger than GLB's 4 GiB limit; write .gltf instead");
  const fs::path tmp = temporarySibling(output);
  std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
  auto u32 = [&](std::uint64_t v) {
    const auto x = static_cast<std::uint32_t>(v);
    out.write(reinterpret_cast<const char*>(&x), 4);
  };
  out.write("glTF", 4);
  u32(2);
  u32(total);
  u32(text.size());
  out.write("JSON", 4);
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  u32(binPadded);
  out.write("BIN\0", 4);
  {
    std::ifstream in(binFile, std::ios::binary);
    out << in.rdbuf();
  }
  for (std::uint64_t k = binBytes; k < binPadded; ++k) out.put('\0');
  out.close();
  std::error_code ec;
  fs::remove(binFile, ec);
  if (!out) {
    fs::remove(tmp, ec);
    return fail(ErrorCode::kIo, "{}: write failed", tmp.string());
  }
  return commitTemporary(tmp, output);
}

}  // namespace

Expected<std::vector<fs::path>> writeDataset(json document, const fs::path& binFile, std::uint64_t binBytes, const fs::path& output,
                                             bool glb) {
  if (glb) {
    if (auto ok = writeGlb(document, binFile, binBytes, output); !ok) return std::unexpected(ok.error());
    return std::vector<fs::path>{output};
  }
  const fs::path bin = output.parent_path() / (output.stem().string() + ".bin");
  document["buffers"][0]["uri"] = uriPath(bin.filename().string());
  document["buffers"][0]["byteLength"] = binBytes;
  if (auto ok = commitTemporary(binFile, bin); !ok) return std::unexpected(ok.error());
  if (auto ok = writeFileAtomic(output, document.dump()); !ok) return std::unexpected(ok.error());
  return std::vector<fs::path>{bin, output};
}

}  // namespace dynbench::convert
