// GRIB2 in: the messages of a file read with ecCodes into fields on their
// grids, and the grids' geometry (where a latitude/longitude falls on a
// grid, and a field's value there). The server turns such fields into cloud
// layers (forecast.hpp); this file knows nothing of clouds.
//
// Grids read: regular latitude/longitude (template 3.0, any resolution, both
// scanning directions in i and j, rows or columns consecutive, global grids
// periodic across the 0/360 seam, the pole rows) and Lambert conformal
// (template 3.30, secant or tangent, either hemisphere, on the spherical
// Earths GRIB names). Every packing ecCodes decodes is read; points a bitmap
// or the packing marks missing are NaN, never 0.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "sky/core/result.hpp"

namespace sky::server {

struct GribGrid {
  enum class Projection : std::uint8_t { LatLon, Lambert };
  Projection projection = Projection::LatLon;
  int ni = 0, nj = 0;          // points along a row (x, longitude) and rows (y, latitude)
  bool iNegative = false;      // i runs west (LatLon) or towards -x (Lambert)
  bool jPositive = false;      // j runs north / towards +y
  bool jConsecutive = false;   // values are stored column by column
  double lat1_deg = 0, lon1_deg = 0;  // the first grid point
  // LatLon: the last grid point.
  double lat2_deg = 0, lon2_deg = 0;
  // Lambert: the projection (GRIB2 template 3.30) and the sphere it is on.
  double lov_deg = 0, lad_deg = 0, latin1_deg = 0, latin2_deg = 0;
  double dx_m = 0, dy_m = 0;
  double radius_m = 6371229;
  // Winds (u, v) along the projection's x and y axes instead of east and
  // north (flag table 3.3, bit 5: ecCodes' uvRelativeToGrid). NAM's are.
  bool uvRelativeToGrid = false;
  bool operator==(const GribGrid&) const = default;
};

// A wind given by u and v of a message on this grid, as east and north
// components at a point: a Lambert grid's axes turn from east and north by
// n (lon - LoV) away from the central meridian (the cone's convergence), so
// grid-relative winds are rotated by that angle; earth-relative ones are
// returned as they are.
std::pair<double, double> eastNorthWind(const GribGrid& grid, double lat_deg, double lon_deg, double u, double v);

// Checks a grid's numbers (sizes, spacings, latitudes, a Lambert cone that
// exists); the error names the key ("Lambert: Latin1 -91").
Result<void> validate(const GribGrid& grid);

// A point on a grid in fractional indices (i along a row, j across rows,
// both from the first grid point, in the scanning order of the message).
struct GridPoint {
  double i = 0, j = 0;
};

// Where a point falls on the grid, or nullopt when it is outside (more than
// half a grid step beyond the edge rows or columns; a global LatLon grid has
// no edge in longitude). Never throws; for a valid grid only.
std::optional<GridPoint> locate(const GribGrid& grid, double lat_deg, double lon_deg);

// Latitude and longitude of grid point (i, j) (the inverse of locate).
struct LatLon {
  double lat_deg = 0, lon_deg = 0;
};
LatLon gridLatLon(const GribGrid& grid, double i, double j);

// Whether a LatLon grid closes round the Earth (its row spans 360 degrees).
bool isGlobalInLongitude(const GribGrid& grid);

// The index into a message's values of grid point (i, j), both in range.
std::size_t valueIndex(const GribGrid& grid, int i, int j);

// A field's value at a point: bilinear in the grid's indices between the
// four grid points round it. Missing points (NaN) leave the weight of the
// others; less than half the weight present, or outside the grid: NaN.
float sampleField(const GribGrid& grid, std::span<const float> values, double lat_deg, double lon_deg);

// What a field is, read before its values (GRIB2 sections 0, 1, 3, 4). A
// GRIB2 message may hold several fields (sections 2 to 7 repeated).
struct GribMeta {
  std::size_t message = 0;         // 1-based GRIB message in the file
  std::size_t field = 0;           // 1-based field in the file, as ecCodes' tools count (grib_get_data -w count=N)
  std::string shortName;           // ecCodes' name: "tcc", "u", "gh", "lcc"
  std::string typeOfLevel;         // ecCodes' name: "isobaricInhPa", "lowCloudLayer"
  std::string units;               // "%", "(0 - 1)", "m s**-1", "gpm", "Pa"
  long discipline = 0, category = 0, number = 0;  // the parameter, code table 4.2
  long levelType = 0;              // typeOfFirstFixedSurface, code table 4.5
  double level = 0;                // value of the first fixed surface (Pa, m), NaN when missing
  std::int64_t reference_unix = 0; // analysis time, s since 1970 (UTC)
  std::int64_t valid_unix = 0;     // the end of the forecast step, s since 1970 (UTC)
  GribGrid grid;
};

struct GribField {
  GribMeta meta;
  std::vector<float> values;  // ni × nj in the message's order (valueIndex), NaN: missing
};

// Bounds of one read: a file holding more is refused (or its messages
// skipped), never read into memory without end.
struct GribLimits {
  std::size_t maxMessages = 20000;
  std::size_t maxPointsPerMessage = 8u << 20;  // 8 Mi: a 0.1 degree global grid is 6.5 Mi
  std::size_t maxValuesKept = 64u << 20;       // floats over all kept fields (256 MiB)
};

// A message or field the reader passed over, and why ("message 3: GRIB
// edition 1").
struct GribSkip {
  std::size_t message = 0;
  std::size_t field = 0;  // 0: the whole message
  std::string reason;
};

struct GribFile {
  std::vector<GribField> fields;  // the wanted fields, in file order
  std::vector<GribSkip> skipped;  // not read (fields not wanted are not listed)
  std::size_t messages = 0;       // GRIB messages found
  std::size_t fieldCount = 0;     // fields in the messages that split
};

using GribWanted = std::function<bool(const GribMeta&)>;

// The GRIB2 messages of a file and the fields in them, found without
// ecCodes: each message by its section 0 ("GRIB", the edition, the total
// length) and closing "7777", each field by walking the sections (length,
// number) inside it. A GRIB2 message may repeat sections 2-7 for further
// fields; each field is the latest section 1, 2 and 3 with its own 4 to 7
// (a section 6 that says "the bitmap defined before" takes that one). A
// message whose sections do not add up, GRIB edition 1, or a length past the
// end of the file is skipped with its reason; bytes between messages are
// ignored. Pure: no ecCodes.
struct GribSection {
  std::size_t offset = 0, length = 0;  // in the file; length 0: absent (section 2)
};
struct GribFieldSpan {
  std::size_t message = 0, field = 0;  // 1-based; fields counted over the file as ecCodes' tools count
  std::array<GribSection, 7> sections;  // sections 1 to 7
};
struct GribSplit {
  std::vector<GribFieldSpan> fields;  // in file order
  std::vector<GribSkip> skipped;
  std::size_t messages = 0;  // every "GRIB" header, read or skipped
};
Result<GribSplit> splitGrib(std::span<const std::byte> bytes, std::string_view sourceName,
                            const GribLimits& limits = {});

// One field as a GRIB2 message of its own (section 0 with its length, the
// field's sections, "7777"): what ecCodes decodes, one field at a time.
std::vector<std::byte> fieldMessage(std::span<const std::byte> bytes, const GribFieldSpan& field);

// Decodes one field with ecCodes: nullopt when `wanted` says no, a skip
// (the error's detail) when it does not decode or is past the limits.
// ecCodes is not safe on hostile bytes (a damaged packing section can make
// it read out of bounds): outside tests, call this only in the decoder
// process (readGribIsolated). `kept` counts the values kept so far against
// limits.maxValuesKept (TooLarge past it).
Result<std::optional<GribField>> decodeGribField(std::span<const std::byte> bytes, const GribFieldSpan& field,
                                                 const GribWanted& wanted, const GribLimits& limits,
                                                 std::size_t& kept);

// splitGrib and decodeGribField over a whole file in this process: for
// files this program trusts (its tests, ecCodes' own samples). A file with no
// GRIB message, or past the limits, is an error naming `sourceName`.
Result<GribFile> readGrib(std::span<const std::byte> bytes, std::string_view sourceName, const GribWanted& wanted,
                          const GribLimits& limits = {});

}  // namespace sky::server
