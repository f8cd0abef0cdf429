#include "convert/convert.h"

#include "convert/converter.h"

namespace dynbench::convert {
namespace detail {

ConvertReport Converter::run() {
  auto opened = CaptureReader::open(options_.capture);
  if (!opened) throw Failure{Error{opened.error().code, opened.error().message}};
  reader_ = std::move(*opened);
  const fs::path out = options_.output;
  stem_ = out.stem().string();
  outDir_ = out.has_parent_path() ? out.parent_path() : fs::path(".");
  std::error_code ec;
  fs::create_directories(outDir_, ec);
  if (ec) throw Failure{Error{ErrorCode::kIo, fmt::format("{}: cannot create folder: {}", outDir_.string(), ec.message())}};

  passOne();
  calibrateLighting();
  if (times_.empty()) throw Failure{Error{ErrorCode::kInvalidData, fmt::format("{}: the capture has no complete frame", options_.capture.string())}};
  binPath_ = temporarySibling(outDir_ / (stem_ + ".bin"));
  try {
    {
      BinaryBuffer bin(binPath_);
      bin_ = &bin;
      buildDocument();
      passTwo();
      bin.finish();
      report_.binBytes = bin.size();
      bin_ = nullptr;
    }
    writeOutputs();
  } catch (...) {
    std::error_code ec;
    fs::remove(binPath_, ec);  // no half-written buffer left behind
    throw;
  }
  report_.warnings.insert(report_.warnings.begin(), reader_->warnings().begin(), reader_->warnings().end());
  return report_;
}

}  // namespace detail

Expected<ConvertReport> convertCapture(const ConvertOptions& options) {
  try {
    return detail::Converter(options).run();
  } catch (const Failure& f) {
    return std::unexpected(f.error);
  }
}

}  // namespace dynbench::convert
