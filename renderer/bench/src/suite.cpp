// Scene suite TOML parsing and camera paths (see suite.hpp). Built into the
// fuzz target fuzz_bench_suite too, so it needs protocol/ only.
#include "sky/bench/suite.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include "sky/config/toml_fields.hpp"

namespace sky::bench {

namespace {

using config::number;
using config::numberIn;
using config::onlyKeys;
using config::required;
using config::Where;

template <class T>
tl::unexpected<Error> failWith(const Result<T>& r) {
  return tl::unexpected(r.error());
}

bool validName(std::string_view name) {
  return !name.empty() && name.size() <= 64 && std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_';
  });
}

Result<const toml::table*> subTable(const toml::node& node, const std::string& field, const Where& where) {
  if (const auto* t = node.as_table()) return t;
  return where.error(ErrorCode::Malformed, node.source(), field, "must be a table");
}

// A pose table: lat_deg, lon_deg, alt_m, yaw_deg, pitch_deg, roll_deg (+ t_s on a path).
Result<CameraKey> parseKey(const toml::table& t, bool onPath, const std::string& prefix, const Where& where) {
  if (auto r = onPath ? onlyKeys(t, {"t_s", "lat_deg", "lon_deg", "alt_m", "yaw_deg", "pitch_deg", "roll_deg"},
                                 prefix, where)
                      : onlyKeys(t, {"lat_deg", "lon_deg", "alt_m", "yaw_deg", "pitch_deg", "roll_deg"}, prefix,
                                 where);
      !r)
    return failWith(r);
  CameraKey key;
  struct Field {
    std::string_view name;
    double lo, hi;
    double* out;
  };
  // Altitude range as the renderer's FrameInputs accepts it; attitude any finite angle.
  const Field fields[] = {{"lat_deg", -90, 90, &key.pose.position.lat_deg},
                          {"lon_deg", -1e6, 1e6, &key.pose.position.lon_deg},
                          {"alt_m", -1000, 1e6, &key.pose.position.alt_m},
                          {"yaw_deg", -1e6, 1e6, &key.pose.yaw_deg},
                          {"pitch_deg", -90, 90, &key.pose.pitch_deg},
                          {"roll_deg", -1e6, 1e6, &key.pose.roll_deg}};
  for (const Field& f : fields) {
    auto v = numberIn(t, f.name, f.lo, f.hi, prefix, where);
    if (!v) return failWith(v);
    *f.out = *v;
  }
  if (onPath) {
    auto v = numberIn(t, "t_s", 0, 1e6, prefix, where);
    if (!v) return failWith(v);
    key.t_s = *v;
  }
  return key;
}

// A still's flash: { kind = "cloud-to-ground" | "in-cloud", lat_deg, lon_deg,
// bottom_m, top_m, energy_j (default 1e9), before_s (default 0.02), seed
// (default 1) }.
Result<weather::LightningFlash> parseFlash(const toml::node& node, const std::string& path, const Where& where) {
  auto ft = subTable(node, path, where);
  if (!ft) return failWith(ft);
  const std::string fp = path + ".";
  if (auto r = onlyKeys(**ft, {"kind", "lat_deg", "lon_deg", "bottom_m", "top_m", "energy_j", "before_s", "seed"}, fp,
                        where);
      !r)
    return failWith(r);
  weather::LightningFlash f;
  f.seed = 1;
  f.energy_j = weather::kTypicalFlashEnergy_j;
  f.time_s = 0.02;
  auto kind = config::string(**ft, "kind", fp, where);
  if (!kind) return failWith(kind);
  const auto k = weather::flashKindFromString(*kind);
  if (!k)
    return where.error(ErrorCode::InvalidArgument, (*ft)->get("kind")->source(), fp + "kind",
                       "'" + *kind + "' is not cloud-to-ground or in-cloud");
  f.kind = *k;
  const struct {
    const char* key;
    double lo, hi;
    double* out;
    bool required;
  } fields[] = {{"lat_deg", -90, 90, &f.lat_deg, true},        {"lon_deg", -180, 180, &f.lon_deg, true},
                {"bottom_m", -500, 20000, &f.bottom_m, true},  {"top_m", -500, 20000, &f.top_m, true},
                {"energy_j", 1, weather::kMaxFlashEnergy_j, &f.energy_j, false},
                {"before_s", 0, weather::kFlashLifetime_s, &f.time_s, false}};
  for (const auto& field : fields) {
    if (!field.required && !(*ft)->get(field.key)) continue;
    auto v = numberIn(**ft, field.key, field.lo, field.hi, fp, where);
    if (!v) return failWith(v);
    *field.out = *v;
  }
  if ((*ft)->get("seed")) {
    auto v = numberIn(**ft, "seed", 0, 9007199254740992.0, fp, where);
    if (!v) return failWith(v);
    f.seed = static_cast<std::uint64_t>(*v);
  }
  if (auto r = weather::validate(f); !r)
    return where.error(ErrorCode::InvalidArgument, node.source(), path, r.error().detail);
  return f;
}

Result<Scene> parseScene(const toml::table& t, std::size_t index, const Where& where) {
  const std::string prefix = "scene[" + std::to_string(index) + "].";
  if (auto r = onlyKeys(t, {"name", "description", "weather", "vfov_deg", "sun", "camera", "path", "frames", "change", "flash"}, prefix,
                        where);
      !r)
    return failWith(r);
  Scene scene;
  auto name = config::string(t, "name", prefix, where);
  if (!name) return failWith(name);
  if (!validName(*name))
    return where.error(ErrorCode::InvalidArgument, t.get("name")->source(), prefix + "name",
                       "'" + *name + "' must be 1-64 characters of A-Z a-z 0-9 - _");
  scene.name = *name;
  if (t.get("description")) {
    auto d = config::string(t, "description", prefix, where);
    if (!d) return failWith(d);
    scene.description = *d;
  }
  auto weather = config::string(t, "weather", prefix, where);
  if (!weather) return failWith(weather);
  if (weather->empty()) return where.error(ErrorCode::InvalidArgument, t.get("weather")->source(), prefix + "weather", "empty");
  scene.weatherFile = *weather;
  if (t.get("vfov_deg")) {
    auto v = number(t, "vfov_deg", prefix, where);
    if (!v) return failWith(v);
    if (!(*v > 0 && *v < 179))
      return where.error(ErrorCode::InvalidArgument, t.get("vfov_deg")->source(), prefix + "vfov_deg",
                         std::to_string(*v) + " outside (0, 179)");
    scene.verticalFov_deg = *v;
  }

  auto sunNode = required(t, "sun", prefix, where);
  if (!sunNode) return failWith(sunNode);
  auto sun = subTable(**sunNode, prefix + "sun", where);
  if (!sun) return failWith(sun);
  if (auto r = onlyKeys(**sun, {"azimuth_deg", "elevation_deg"}, prefix + "sun.", where); !r) return failWith(r);
  auto az = numberIn(**sun, "azimuth_deg", 0, 360, prefix + "sun.", where);
  if (!az) return failWith(az);
  auto el = numberIn(**sun, "elevation_deg", -90, 90, prefix + "sun.", where);
  if (!el) return failWith(el);
  scene.sunAzimuth_deg = *az;
  scene.sunElevation_deg = *el;

  const toml::node* camera = t.get("camera");
  const toml::node* path = t.get("path");
  if ((camera == nullptr) == (path == nullptr))
    return where.error(ErrorCode::Malformed, t.source(), prefix + "camera",
                       "a scene has either camera (a still) or path and frames (a camera path)");
  if (camera) {
    if (t.get("frames"))
      return where.error(ErrorCode::Malformed, t.get("frames")->source(), prefix + "frames", "only a path has frames");
    if (t.get("change"))
      return where.error(ErrorCode::Malformed, t.get("change")->source(), prefix + "change", "only a path has a change");
    auto ct = subTable(*camera, prefix + "camera", where);
    if (!ct) return failWith(ct);
    auto key = parseKey(**ct, false, prefix + "camera.", where);
    if (!key) return failWith(key);
    scene.keys.push_back(*key);
    if (const toml::node* flashNode = t.get("flash")) {
      auto flash = parseFlash(*flashNode, prefix + "flash", where);
      if (!flash) return failWith(flash);
      scene.flash = *flash;
    }
    return scene;
  }
  const toml::array* keys = path->as_array();
  if (!keys || !keys->is_array_of_tables() || keys->size() < 2 || keys->size() > kMaxPathFrames)
    return where.error(ErrorCode::Malformed, path->source(), prefix + "path",
                       "must be an array of 2 to " + std::to_string(kMaxPathFrames) + " pose tables");
  for (std::size_t i = 0; i < keys->size(); ++i) {
    const std::string keyPrefix = prefix + "path[" + std::to_string(i) + "].";
    auto key = parseKey(*(*keys)[i].as_table(), true, keyPrefix, where);
    if (!key) return failWith(key);
    if (!scene.keys.empty() && !(key->t_s > scene.keys.back().t_s))
      return where.error(ErrorCode::InvalidArgument, (*keys)[i].source(), keyPrefix + "t_s",
                         "times must increase along the path");
    scene.keys.push_back(*key);
  }
  auto frames = required(t, "frames", prefix, where);
  if (!frames) return failWith(frames);
  const auto* count = (*frames)->as_integer();
  if (!count || count->get() < 2 || count->get() > std::int64_t{kMaxPathFrames})
    return where.error(ErrorCode::InvalidArgument, (*frames)->source(), prefix + "frames",
                       "must be an integer in [2, " + std::to_string(kMaxPathFrames) + "]");
  scene.frames = std::uint32_t(count->get());
  if (t.get("flash"))
    return where.error(ErrorCode::Malformed, t.get("flash")->source(), prefix + "flash", "only a still has a flash");
  if (const toml::node* changeNode = t.get("change")) {
    auto ct = subTable(*changeNode, prefix + "change", where);
    if (!ct) return failWith(ct);
    const std::string cp = prefix + "change.";
    if (auto r = onlyKeys(**ct, {"t_s", "ramp_s", "layer", "lat_deg", "lon_deg", "radius_km", "coverage"}, cp, where); !r)
      return failWith(r);
    WeatherChange c;
    const struct {
      const char* key;
      double lo, hi;
      double* out;
    } fields[] = {{"t_s", 0, 1e6, &c.t_s},           {"lat_deg", -90, 90, &c.lat_deg},
                  {"lon_deg", -180, 180, &c.lon_deg}, {"radius_km", 1e-3, 100, &c.radius_m},
                  {"coverage", 0, 1, &c.coverage}};
    for (const auto& f : fields) {
      auto v = numberIn(**ct, f.key, f.lo, f.hi, cp, where);
      if (!v) return failWith(v);
      *f.out = *v;
    }
    if ((*ct)->get("ramp_s")) {
      auto v = numberIn(**ct, "ramp_s", 0, 1e6, cp, where);
      if (!v) return failWith(v);
      c.ramp_s = *v;
    }
    c.radius_m *= 1000.0;
    auto layer = numberIn(**ct, "layer", 0, 3, cp, where);
    if (!layer) return failWith(layer);
    if (*layer != std::floor(*layer))
      return where.error(ErrorCode::InvalidArgument, (*ct)->get("layer")->source(), cp + "layer", "not a whole number");
    c.layer = std::uint32_t(*layer);
    scene.change = c;
  }
  return scene;
}

}  // namespace

Result<Suite> parseSuite(std::string_view text, std::string_view sourceName) {
  const Where where(sourceName);
  auto parsed = config::parseText(text, where);
  if (!parsed) return failWith(parsed);
  const toml::table& root = *parsed;
  if (auto r = onlyKeys(root, {"scene"}, "", where); !r) return failWith(r);
  auto scenesNode = required(root, "scene", "", where);
  if (!scenesNode) return failWith(scenesNode);
  const toml::array* scenes = (*scenesNode)->as_array();
  if (!scenes || !scenes->is_array_of_tables() || scenes->empty())
    return where.error(ErrorCode::Malformed, (*scenesNode)->source(), "scene", "must be an array of tables ([[scene]])");
  if (scenes->size() > kMaxScenes)
    return where.error(ErrorCode::InvalidArgument, (*scenesNode)->source(), "scene",
                       std::to_string(scenes->size()) + " scenes, at most " + std::to_string(kMaxScenes));
  Suite suite;
  std::set<std::string> names;
  for (std::size_t i = 0; i < scenes->size(); ++i) {
    const toml::table& t = *(*scenes)[i].as_table();
    auto scene = parseScene(t, i, where);
    if (!scene) return failWith(scene);
    if (!names.insert(scene->name).second)
      return where.error(ErrorCode::InvalidArgument, t.get("name")->source(), "scene[" + std::to_string(i) + "].name",
                         "'" + scene->name + "' used by an earlier scene");
    suite.scenes.push_back(std::move(*scene));
  }
  return suite;
}

double frameTime_s(const Scene& scene, std::uint32_t frame) {
  if (!scene.isPath() || scene.frames < 2) return 0;
  const double t0 = scene.keys.front().t_s, t1 = scene.keys.back().t_s;
  return t0 + (t1 - t0) * double(std::min(frame, scene.frames - 1)) / double(scene.frames - 1);
}

geo::GeodeticPose poseAt(const Scene& scene, double t_s) {
  const auto& keys = scene.keys;
  if (keys.size() == 1 || t_s <= keys.front().t_s) return keys.front().pose;
  if (t_s >= keys.back().t_s) return keys.back().pose;
  std::size_t i = 1;
  while (keys[i].t_s < t_s) ++i;
  const CameraKey& a = keys[i - 1];
  const CameraKey& b = keys[i];
  const double f = (t_s - a.t_s) / (b.t_s - a.t_s);
  auto angle = [f](double from, double to) { return from + f * geo::angleDiff_deg(from, to); };
  geo::GeodeticPose p;
  p.position.lat_deg = a.pose.position.lat_deg + f * (b.pose.position.lat_deg - a.pose.position.lat_deg);
  p.position.lon_deg = angle(a.pose.position.lon_deg, b.pose.position.lon_deg);
  p.position.alt_m = a.pose.position.alt_m + f * (b.pose.position.alt_m - a.pose.position.alt_m);
  p.yaw_deg = angle(a.pose.yaw_deg, b.pose.yaw_deg);
  p.pitch_deg = a.pose.pitch_deg + f * (b.pose.pitch_deg - a.pose.pitch_deg);
  p.roll_deg = angle(a.pose.roll_deg, b.pose.roll_deg);
  return p;
}

}  // namespace sky::bench
