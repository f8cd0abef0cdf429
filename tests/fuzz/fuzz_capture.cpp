// Fuzz target: the capture reader (capture/reader.cpp, through checkCapture, which streams every
// record). The first byte picks what the rest is: even, Capture.txt (beside the one ModelMesh
// file models/00000.txt of the seed capture, when the seed provided one); odd, a ModelMesh file.
// Seeds: tests/fuzz/make_seeds.sh cuts them from a real Cube 2 capture.
#include "capture/check.h"
#include "fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const auto dir = dynbench::fuzz::scratchDir() / "capture";
  std::filesystem::create_directories(dir / "models");
  if (data[0] % 2 == 0) {
    dynbench::fuzz::writeBytes(dir / "Capture.txt", data + 1, size - 1);
    (void)dynbench::capture::checkCapture(dir);
  } else {
    dynbench::fuzz::writeBytes(dir / "models" / "00000.txt", data + 1, size - 1);
    (void)dynbench::capture::readModelMesh(dir / "models" / "00000.txt");
  }
  return 0;
}
