#include "core/checksum.h"

#include <algorithm>
#include <array>
#include <fstream>
#include <memory>

#include <fmt/format.h>
#include <openssl/evp.h>

namespace dynbench {

struct Sha256Stream::State {
  std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)> context{EVP_MD_CTX_new(), EVP_MD_CTX_free};
  bool ok = false;
};

Sha256Stream::Sha256Stream() : state_(std::make_unique<State>()) {
  state_->ok = state_->context && EVP_DigestInit_ex(state_->context.get(), EVP_sha256(), nullptr) == 1;
}

Sha256Stream::~Sha256Stream() = default;

void Sha256Stream::update(const void* bytes, std::size_t size) {
  state_->ok = state_->ok && EVP_DigestUpdate(state_->context.get(), bytes, size) == 1;
}

std::string Sha256Stream::hex() {
  std::array<unsigned char, EVP_MAX_MD_SIZE> digest;
  unsigned int length = 0;
  if (!state_->ok || EVP_DigestFinal_ex(state_->context.get(), digest.data(), &length) != 1) return {};
  state_->ok = false;
  std::string out;
  for (unsigned int i = 0; i < length; ++i) out += fmt::format("{:02x}", digest[i]);
  return out;
}

Expected<std::string> sha256File(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail(ErrorCode::kIo, "{}: cannot read", path.string());
  Sha256Stream sha;
  std::array<char, 1 << 16> buffer;
  while (in) {
    in.read(buffer.data(), buffer.size());
    if (in.gcount() > 0) sha.update(buffer.data(), static_cast<std::size_t>(in.gcount()));
  }
  if (in.bad()) return fail(ErrorCode::kIo, "{}: read error", path.string());
  std::string hex = sha.hex();
  if (hex.empty()) return fail(ErrorCode::kInternal, "{}: OpenSSL's SHA-256 failed", path.string());
  return hex;
}

std::string sha256Text(std::string_view bytes) {
  Sha256Stream sha;
  sha.update(bytes.data(), bytes.size());
  return sha.hex();
}

Expected<std::string> sha256Listing(const std::filesystem::path& root, std::vector<std::string> relativePaths) {
  std::sort(relativePaths.begin(), relativePaths.end());  // std::string compares bytes, as LC_ALL=C sort
  std::string listing;
  for (const std::string& path : relativePaths) {
    auto sum = sha256File(root / path);
    if (!sum) return std::unexpected(sum.error());
    listing += *sum + "  " + path + "\n";
  }
  std::string digest = sha256Text(listing);
  if (digest.empty()) return fail(ErrorCode::kInternal, "{}: OpenSSL's SHA-256 of the files' listing failed", root.string());
  return digest;
}

}  // namespace dynbench
