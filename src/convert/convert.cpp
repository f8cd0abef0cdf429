#include "convert/convert.h"

#include "convert/converter.h"

namespace dynbench::convert {
namespace detail {

Expected<ConvertReport> Converter::run() {
  auto opened = CaptureReader::open(options_.capture);
  if (!opened) return std::unexpected(opened.error());
  reader_ = std::move(*opened);
  const fs::path out = options_.output;
  stem_ = out.stem().string();
  outDir_ = out.has_parent_path() ? out.parent_path() : fs::path(".");
  std::error_code ec;
  fs::create_directories(outDir_, ec);
  if (ec) return fail(ErrorCode::kIo, "{}: cannot create folder: {}", outDir_.string(), ec.message());

  if (auto ok = passOne(); !ok) return std::unexpected(ok.error());
  if (auto ok = calibrateLighting(); !ok) return std::unexpected(ok.error());
  if (times_.empty()) return fail(ErrorCode::kInvalidData, "{}: the capture has no complete frame", options_.capture.string());
  binPath_ = temporarySibling(outDir_ / (stem_ + ".bin"));
  auto written = writeBufferAndDocument();
  if (!written) {
    fs::remove(binPath_, ec);  // no half-written buffer left behind
    return std::unexpected(written.error());
  }
  report_.warnings.insert(report_.warnings.begin(), reader_->warnings().begin(), reader_->warnings().end());
  return report_;
}

Expected<void> Converter::writeBufferAndDocument() {
  {
    BinaryBuffer bin(binPath_);
    bin_ = &bin;
    auto built = buildDocument();
    if (built) built = passTwo();
    if (built) built = bin.finish();
    bin_ = nullptr;
    if (!built) return built;
    report_.binBytes = bin.size();
  }
  return writeOutputs();
}

}  // namespace detail

Expected<ConvertReport> convertCapture(const ConvertOptions& options) { return detail::Converter(options).run(); }

}  // namespace dynbench::convert
