#include "scene/gltf_reader.h"

namespace dynbench::scene::gltf_detail {

void GltfReader::readBuffers() {
  const json& buffers = array(root_, "buffers", "");
  for (std::size_t i = 0; i < buffers.size(); ++i) {
    const auto p = child("/buffers", i);
    const json& b = objectAt(buffers, i, "/buffers");
    const std::size_t byteLength = unsignedInt(b, "byteLength", p, 0, true);
    std::string data;
    const json* uri = member(b, "uri");
    if (!uri) {
      if (i != 0 || !glbBin_)
        invalid(p, "has no uri and is not the GLB binary chunk (only buffer 0 of a .glb may omit it)");
      data.assign(glbBin_->data(), glbBin_->size());
    } else {
      if (!uri->is_string()) invalid(child(p, "uri"), "expected a string");
      const auto u = uri->get<std::string>();
      if (u.rfind("data:", 0) == 0) {
        const auto comma = u.find(',');
        if (comma == std::string::npos || u.substr(0, comma).find(";base64") == std::string::npos)
          invalid(child(p, "uri"), "data URI is not base64 encoded (expected data:...;base64,...)");
        bool ok = false;
        data = decodeBase64(std::string_view(u).substr(comma + 1), ok);
        if (!ok) invalid(child(p, "uri"), "data URI holds characters that are not base64");
      } else {
        const fs::path file = resolveUri(u, child(p, "uri"));
        auto bytes = readWholeFile(file);
        if (!bytes)
          fail(ErrorCode::kIo, child(p, "uri"),
               fmt::format("cannot read buffer '{}' ({})", u, bytes.error().message));
        data = std::move(*bytes);
        addSourceFile(file, data.size());
      }
    }
    if (data.size() < byteLength)
      invalid(p, fmt::format("byteLength is {} but the buffer data has only {} bytes", byteLength, data.size()));
    buffers_.push_back(std::move(data));
  }
}

void GltfReader::readBufferViews() {
  const json& views = array(root_, "bufferViews", "");
  for (std::size_t i = 0; i < views.size(); ++i) {
    const auto p = child("/bufferViews", i);
    const json& v = objectAt(views, i, "/bufferViews");
    BufferView view;
    view.buffer = index(v, "buffer", p, buffers_.size(), "buffer", true);
    view.offset = unsignedInt(v, "byteOffset", p, 0);
    view.length = unsignedInt(v, "byteLength", p, 0, true);
    view.stride = unsignedInt(v, "byteStride", p, 0);
    if (view.stride != 0 && (view.stride < 4 || view.stride > 252 || view.stride % 4 != 0))
      invalid(child(p, "byteStride"), fmt::format("byteStride {} must be a multiple of 4 in [4, 252]", view.stride));
    const auto bufferLength = buffers_[static_cast<std::size_t>(view.buffer)].size();
    if (view.offset + view.length > bufferLength)
      invalid(p, fmt::format("byteOffset {} + byteLength {} runs past the end of buffer {} ({} bytes)",
                             view.offset, view.length, view.buffer, bufferLength));
    bufferViews_.push_back(view);
  }
}

void GltfReader::readAccessors() {
  const json& accessors = array(root_, "accessors", "");
  for (std::size_t i = 0; i < accessors.size(); ++i) {
    const auto p = child("/accessors", i);
    const json& a = objectAt(accessors, i, "/accessors");
    AccessorInfo info;
    info.bufferView = index(a, "bufferView", p, bufferViews_.size(), "bufferView");
    info.byteOffset = unsignedInt(a, "byteOffset", p, 0);
    info.componentType = static_cast<int>(unsignedInt(a, "componentType", p, 0, true));
    if (componentBytes(info.componentType) == 0)
      invalid(child(p, "componentType"),
              fmt::format("{} is not a glTF component type (5120, 5121, 5122, 5123, 5125 or 5126)", info.componentType));
    info.normalized = boolean(a, "normalized", p, false);
    info.count = unsignedInt(a, "count", p, 0, true);
    if (info.count == 0) invalid(child(p, "count"), "must be at least 1");
    info.type = string(a, "type", p);
    info.components = typeComponents(info.type);
    if (info.components == 0)
      invalid(child(p, "type"), fmt::format("'{}' is not SCALAR, VEC2, VEC3, VEC4, MAT2, MAT3 or MAT4", info.type));
    if (info.bufferView >= 0) {
      const auto& view = bufferViews_[static_cast<std::size_t>(info.bufferView)];
      if (info.count > view.length)  // also keeps the byte arithmetic below from overflowing
        invalid(p, fmt::format("count {} is more elements than bufferView {} has bytes ({})", info.count,
                               info.bufferView, view.length));
      const std::size_t element = elementBytes(info);
      const std::size_t stride = view.stride ? view.stride : element;
      const std::size_t needed = info.byteOffset + stride * (info.count - 1) + element;
      if (needed > view.length)
        invalid(p, fmt::format("needs {} bytes (byteOffset {} + {} x stride {} + element {}) but bufferView {} "
                               "is only {} bytes long",
                               needed, info.byteOffset, info.count - 1, stride, element, info.bufferView,
                               view.length));
    }
    accessors_.push_back(info);
  }
}

std::size_t GltfReader::elementBytes(const AccessorInfo& a) {
  // Matrix columns are padded to 4-byte boundaries for 1- and 2-byte components (glTF §3.6.2.4).
  const int cb = componentBytes(a.componentType);
  if (a.type == "MAT2" && cb == 1) return 8;
  if (a.type == "MAT3" && cb == 1) return 12;
  if (a.type == "MAT3" && cb == 2) return 24;
  return static_cast<std::size_t>(cb * a.components);
}

double GltfReader::componentValue(const char* src, int componentType, bool normalized) {
  switch (componentType) {
    case 5120: { std::int8_t v; std::memcpy(&v, src, 1); return normalized ? std::max(v / 127.0, -1.0) : v; }
    case 5121: { std::uint8_t v; std::memcpy(&v, src, 1); return normalized ? v / 255.0 : v; }
    case 5122: { std::int16_t v; std::memcpy(&v, src, 2); return normalized ? std::max(v / 32767.0, -1.0) : v; }
    case 5123: { std::uint16_t v; std::memcpy(&v, src, 2); return normalized ? v / 65535.0 : v; }
    case 5125: { std::uint32_t v; std::memcpy(&v, src, 4); return v; }
    case 5126: { float v; std::memcpy(&v, src, 4); return v; }
  }
  return 0.0;
}

// All elements of an accessor as doubles, components flattened, sparse substitution applied.
std::vector<double> GltfReader::readAccessor(int accessorIndex) const {
  const auto& a = accessors_[static_cast<std::size_t>(accessorIndex)];
  const auto p = child("/accessors", static_cast<std::size_t>(accessorIndex));
  std::vector<double> out(a.count * static_cast<std::size_t>(a.components), 0.0);
  const int cb = componentBytes(a.componentType);
  if (a.bufferView >= 0) {
    const auto& view = bufferViews_[static_cast<std::size_t>(a.bufferView)];
    const char* base = buffers_[static_cast<std::size_t>(view.buffer)].data() + view.offset + a.byteOffset;
    const std::size_t stride = view.stride ? view.stride : elementBytes(a);
    const int columns = a.type.starts_with("MAT") ? (a.type == "MAT2" ? 2 : a.type == "MAT3" ? 3 : 4) : 1;
    const int rows = a.components / columns;
    const std::size_t columnStride = a.type.starts_with("MAT") ? ((static_cast<std::size_t>(rows * cb) + 3) & ~std::size_t{3}) : 0;
    for (std::size_t e = 0; e < a.count; ++e) {
      const char* element = base + e * stride;
      for (int c = 0; c < columns; ++c)
        for (int r = 0; r < rows; ++r)
          out[e * a.components + static_cast<std::size_t>(c * rows + r)] =
              componentValue(element + c * columnStride + r * cb, a.componentType, a.normalized);
    }
  }
  const json& accessorJson = root_["accessors"][static_cast<std::size_t>(accessorIndex)];
  if (const json* sparse = member(accessorJson, "sparse")) readSparse(*sparse, a, child(p, "sparse"), out);
  return out;
}

void GltfReader::readSparse(const json& sparse, const AccessorInfo& a, const std::string& p, std::vector<double>& out) const {
  if (!sparse.is_object()) invalid(p, "expected an object");
  const std::size_t count = unsignedInt(sparse, "count", p, 0, true);
  const json* indices = member(sparse, "indices");
  const json* values = member(sparse, "values");
  if (!indices || !indices->is_object()) invalid(child(p, "indices"), "missing");
  if (!values || !values->is_object()) invalid(child(p, "values"), "missing");
  const auto ip = child(p, "indices"), vp = child(p, "values");
  const int iView = index(*indices, "bufferView", ip, bufferViews_.size(), "bufferView", true);
  const int iType = static_cast<int>(unsignedInt(*indices, "componentType", ip, 0, true));
  if (iType != 5121 && iType != 5123 && iType != 5125)
    invalid(child(ip, "componentType"), "sparse indices must be 5121, 5123 or 5125");
  const int vView = index(*values, "bufferView", vp, bufferViews_.size(), "bufferView", true);
  const std::size_t iOffset = unsignedInt(*indices, "byteOffset", ip, 0);
  const std::size_t vOffset = unsignedInt(*values, "byteOffset", vp, 0);
  const auto& iv = bufferViews_[static_cast<std::size_t>(iView)];
  const auto& vv = bufferViews_[static_cast<std::size_t>(vView)];
  const int ib = componentBytes(iType), cb = componentBytes(a.componentType);
  if (count > a.count) invalid(child(p, "count"), fmt::format("{} sparse values for an accessor of {} elements", count, a.count));
  if (iOffset + count * static_cast<std::size_t>(ib) > iv.length)
    invalid(ip, fmt::format("{} indices do not fit in bufferView {} ({} bytes)", count, iView, iv.length));
  if (vOffset + count * static_cast<std::size_t>(cb * a.components) > vv.length)
    invalid(vp, fmt::format("{} values do not fit in bufferView {} ({} bytes)", count, vView, vv.length));
  const char* ibase = buffers_[static_cast<std::size_t>(iv.buffer)].data() + iv.offset + iOffset;
  const char* vbase = buffers_[static_cast<std::size_t>(vv.buffer)].data() + vv.offset + vOffset;
  for (std::size_t k = 0; k < count; ++k) {
    const auto target = static_cast<std::size_t>(componentValue(ibase + k * ib, iType, false));
    if (target >= a.count)
      invalid(ip, fmt::format("sparse index {} at position {} is out of range (count {})", target, k, a.count));
    for (int c = 0; c < a.components; ++c)
      out[target * a.components + c] =
          componentValue(vbase + (k * a.components + c) * cb, a.componentType, a.normalized);
  }
}
}  // namespace dynbench::scene::gltf_detail
