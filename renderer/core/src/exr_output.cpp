// EXR output through tinyexr (Debian's libtinyexr-dev, compiled library; see
// exr_output.hpp): planar float channels in name order, ZIP compression.
#include "sky/render/exr_output.hpp"

#include <array>
#include <cstring>
#include <memory>
#include <vector>

#include <tinyexr.h>

namespace sky::render {

namespace {

constexpr std::size_t kChannels = 5;

// The channel list must be sorted by name (OpenEXR file layout, "channels"
// attribute): these are.
constexpr std::array<const char*, kChannels> kNames = {kExrBlue, kExrGreen, kExrRed, kExrCloudDepth,
                                                       kExrCloudTransmittance};

struct ErrorMessage {
  const char* text = nullptr;
  ~ErrorMessage() {
    if (text) FreeEXRErrorMessage(text);
  }
};

}  // namespace

Result<void> writeExr(const Image& image, const std::string& path) {
  const std::size_t pixels = std::size_t(image.width) * image.height;
  if (pixels == 0 || image.rgba.size() != pixels * 4 ||
      !(image.cloudDepth_m.empty() || image.cloudDepth_m.size() == pixels))
    return fail(ErrorCode::InvalidArgument, "writeExr " + path + ": image size does not match its pixels");

  // Planar copies in the order of kNames: B, G, R, depth, transmittance.
  std::array<std::vector<float>, kChannels> planes;
  for (auto& p : planes) p.resize(pixels);
  for (std::size_t i = 0; i < pixels; ++i) {
    planes[0][i] = image.rgba[i * 4 + 2];
    planes[1][i] = image.rgba[i * 4 + 1];
    planes[2][i] = image.rgba[i * 4 + 0];
    planes[3][i] = image.cloudDepth_m.empty() ? 0.0f : image.cloudDepth_m[i];
    planes[4][i] = image.rgba[i * 4 + 3];
  }
  std::array<unsigned char*, kChannels> pointers{};
  for (std::size_t c = 0; c < kChannels; ++c) pointers[c] = reinterpret_cast<unsigned char*>(planes[c].data());

  EXRImage exrImage;
  InitEXRImage(&exrImage);
  exrImage.images = pointers.data();
  exrImage.width = static_cast<int>(image.width);
  exrImage.height = static_cast<int>(image.height);
  exrImage.num_channels = static_cast<int>(kChannels);

  std::array<EXRChannelInfo, kChannels> channels{};
  std::array<int, kChannels> inputTypes{}, storedTypes{};
  for (std::size_t c = 0; c < kChannels; ++c) {
    std::strncpy(channels[c].name, kNames[c], sizeof channels[c].name - 1);
    inputTypes[c] = TINYEXR_PIXELTYPE_FLOAT;
    storedTypes[c] = TINYEXR_PIXELTYPE_FLOAT;
  }
  EXRHeader header;
  InitEXRHeader(&header);
  header.num_channels = static_cast<int>(kChannels);
  header.channels = channels.data();
  header.pixel_types = inputTypes.data();
  header.requested_pixel_types = storedTypes.data();
  header.compression_type = TINYEXR_COMPRESSIONTYPE_ZIP;

  ErrorMessage err;
  if (SaveEXRImageToFile(&exrImage, &header, path.c_str(), &err.text) != TINYEXR_SUCCESS)
    return fail(ErrorCode::Io, "writeExr " + path + ": " + (err.text ? err.text : "tinyexr failed"));
  return {};
}

}  // namespace sky::render
