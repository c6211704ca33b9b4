// EXR output through tinyexr (Debian's libtinyexr-dev, compiled library; see
// exr_output.hpp): planar float channels in name order, ZIP compression.
#include "sky/render/exr_output.hpp"

#include <algorithm>
#include <array>
#include <cstring>
#include <memory>
#include <vector>

#include <tinyexr.h>

namespace sky::render {

namespace {

constexpr std::size_t kImageChannels = 5;

// The image's own channels, sorted by name as the OpenEXR file layout's
// "channels" attribute wants them.
constexpr std::array<const char*, kImageChannels> kNames = {kExrBlue, kExrGreen, kExrRed, kExrCloudDepth,
                                                            kExrCloudTransmittance};

// EXRChannelInfo::name's room, less its terminating zero.
constexpr std::size_t kMaxChannelName = 255;

struct Plane {
  std::string name;
  std::vector<float> values;
};

struct ErrorMessage {
  const char* text = nullptr;
  ~ErrorMessage() {
    if (text) FreeEXRErrorMessage(text);
  }
};

}  // namespace

Result<void> writeExr(const Image& image, const std::string& path, std::span<const ExrChannel> extra) {
  const std::size_t pixels = std::size_t(image.width) * image.height;
  if (pixels == 0 || image.rgba.size() != pixels * 4 ||
      !(image.cloudDepth_m.empty() || image.cloudDepth_m.size() == pixels))
    return fail(ErrorCode::InvalidArgument, "writeExr " + path + ": image size does not match its pixels");

  // Planar copies in the order of kNames: B, G, R, depth, transmittance;
  // then the extra channels.
  std::vector<Plane> planes(kImageChannels);
  for (std::size_t c = 0; c < kImageChannels; ++c) {
    planes[c].name = kNames[c];
    planes[c].values.resize(pixels);
  }
  for (std::size_t i = 0; i < pixels; ++i) {
    planes[0].values[i] = image.rgba[i * 4 + 2];
    planes[1].values[i] = image.rgba[i * 4 + 1];
    planes[2].values[i] = image.rgba[i * 4 + 0];
    planes[3].values[i] = image.cloudDepth_m.empty() ? 0.0f : image.cloudDepth_m[i];
    planes[4].values[i] = image.rgba[i * 4 + 3];
  }
  for (const ExrChannel& e : extra) {
    if (e.values.size() != pixels)
      return fail(ErrorCode::InvalidArgument, "writeExr " + path + ": channel " + e.name + " has " +
                                                  std::to_string(e.values.size()) + " values for " +
                                                  std::to_string(pixels) + " pixels");
    const bool taken = std::any_of(planes.begin(), planes.end(), [&](const Plane& p) { return p.name == e.name; });
    if (e.name.empty() || e.name.size() > kMaxChannelName || e.name.find('\0') != std::string::npos || taken)
      return fail(ErrorCode::InvalidArgument, "writeExr " + path + ": channel name '" + e.name + "' is empty, taken or too long");
    planes.push_back(Plane{e.name, std::vector<float>(e.values.begin(), e.values.end())});
  }
  std::stable_sort(planes.begin(), planes.end(), [](const Plane& a, const Plane& b) { return a.name < b.name; });
  const std::size_t channelCount = planes.size();
  std::vector<unsigned char*> pointers(channelCount);
  for (std::size_t c = 0; c < channelCount; ++c) pointers[c] = reinterpret_cast<unsigned char*>(planes[c].values.data());

  EXRImage exrImage;
  InitEXRImage(&exrImage);
  exrImage.images = pointers.data();
  exrImage.width = static_cast<int>(image.width);
  exrImage.height = static_cast<int>(image.height);
  exrImage.num_channels = static_cast<int>(channelCount);

  std::vector<EXRChannelInfo> channels(channelCount);
  std::vector<int> inputTypes(channelCount), storedTypes(channelCount);
  for (std::size_t c = 0; c < channelCount; ++c) {
    std::strncpy(channels[c].name, planes[c].name.c_str(), sizeof channels[c].name - 1);
    inputTypes[c] = TINYEXR_PIXELTYPE_FLOAT;
    storedTypes[c] = TINYEXR_PIXELTYPE_FLOAT;
  }
  EXRHeader header;
  InitEXRHeader(&header);
  header.num_channels = static_cast<int>(channelCount);
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
