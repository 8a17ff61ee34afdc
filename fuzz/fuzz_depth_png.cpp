// libFuzzer target: the depth PNG decoder (libpng) and the back-projection
// on arbitrary bytes.
#include <obsgroup/io/depth_sequence.h>
#include <obsgroup/io/errors.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string_view>

using namespace obsgroup::io;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  try {
    const DepthImage image = decodeDepthPng(bytes, "fuzz.png");
    if (image.width <= 0 || image.height <= 0 ||
        image.values.size() != std::size_t(image.width) * std::size_t(image.height))
      std::abort();
    const auto cloud = backProject(image, PinholeIntrinsics{}, 5000.0, 10.0, 1 + int(size % 3));
    if (cloud->size() > image.values.size()) std::abort();
    for (const auto& p : *cloud)
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !(p.z > 0.0f) || p.z > 10.0f) std::abort();
  } catch (const InputError&) {
  }
  return 0;
}
