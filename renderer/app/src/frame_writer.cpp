// Headless frame output (see frame_writer.hpp).
#include "sky/app/frame_writer.hpp"

#include <cstdio>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "sky/render/exposure.hpp"
#include "sky/render/exr_output.hpp"

namespace sky::app {

Result<FrameWriter> FrameWriter::open(const std::string& directory, const FrameOutputs& outputs,
                                      const RunSettings& run) {
  std::error_code ec;
  std::filesystem::create_directories(directory, ec);
  if (ec) return fail(ErrorCode::Io, directory + ": cannot create: " + ec.message());
  FrameWriter w;
  w.directory_ = directory;
  w.outputs_ = outputs;
  w.run_ = run;
  w.metadata_.open(directory + "/frames.jsonl", std::ios::trunc);
  if (!w.metadata_) return fail(ErrorCode::Io, directory + "/frames.jsonl: cannot open for writing");
  return w;
}

namespace {
// The march numbers as frames.jsonl names them (the run's, and a budget level's).
// The sun shadow's method, with its map's size and bytes where it has one.
nlohmann::json sunShadowJson(const render::SunMapSettings& s) {
  nlohmann::json j{{"method", render::sunShadowName(s.method)}};
  if (render::sunMapParts(s.method) > 0) {
    j["size"] = s.size;
    j["cascades"] = s.cascades;
    j["extent_m"] = s.extent_m;
    j["build_steps"] = s.buildSteps;
    j["build_frames"] = s.buildFrames;
    j["bytes"] = render::sunMapBytes(s);
    j["used_bytes"] = render::sunMapUsedBytes(s);
  }
  return j;
}

nlohmann::json marchJson(const render::MarchSettings& m) {
  return {{"primary_steps", m.primarySteps},
          {"light_steps", m.lightSteps},
          {"min_transmittance", m.minTransmittance},
          {"empty_stride", m.emptyStride},
          {"cloud_step_m", m.cloudStep_m},
          {"empty_step_m", m.emptyStep_m},
          {"step_growth", m.stepGrowth},
          {"coverage_step_min", m.coverageStepMin},
          {"density_step_min", m.densityStepMin},
          {"air_steps", m.airSteps},
          {"cloud_shadows", m.cloudShadows},
          {"near_precipitation", m.nearPrecipitation},
          {"showers_under_cells", m.showersUnderCells},
          {"air_table", m.airTable.enabled ? nlohmann::json{{"azimuths", m.airTable.azimuths},
                                                            {"zeniths", m.airTable.zeniths},
                                                            {"slices", m.airTable.slices}}
                                           : nlohmann::json(nullptr)},
          {"sun_shadow", sunShadowJson(m.sunShadow)},
          {"blue_noise", m.blueNoise}};
}

nlohmann::json areasJson(const std::vector<FrameRecord::Area>& areas) {
  nlohmann::json out = nlohmann::json::array();
  for (std::size_t i = 0; i < areas.size(); ++i)
    out.push_back({{"area", i}, {"tile_level", areas[i].tileLevel}, {"tiles", areas[i].tiles}});
  return out;
}
// The view's packets as applied and the camera they gave: enough to compute
// any pixel's ray (core_common.glsl, cameraRay) from the metadata alone.
nlohmann::json viewJson(const FrameRecord::View& v) {
  const ChannelView& c = v.view;
  const render::ViewFrustum& f = c.frustum;
  nlohmann::json view = {
      {"id", c.viewId},
      {"offset_m", {c.eyepoint.x_m, c.eyepoint.y_m, c.eyepoint.z_m}},
      {"rotation_deg", {{"yaw", c.eyepoint.yaw_deg}, {"pitch", c.eyepoint.pitch_deg}, {"roll", c.eyepoint.roll_deg}}},
      {"half_angles_deg", {{"left", f.left_deg}, {"right", f.right_deg}, {"top", f.up_deg}, {"bottom", f.down_deg}}},
      {"frustum_from_host", c.frustumFromHost},
      {"mirror", static_cast<int>(c.mirror)},
      {"definitions", c.definitions},
      {"controls", c.controls},
  };
  if (c.near_m) view["near_m"] = *c.near_m;
  if (c.far_m) view["far_m"] = *c.far_m;
  const geo::GeodeticPose& p = v.camera;
  return {{"view", view},
          {"camera",
           {{"lat_deg", p.position.lat_deg},
            {"lon_deg", p.position.lon_deg},
            {"alt_m", p.position.alt_m},
            {"yaw_deg", p.yaw_deg},
            {"pitch_deg", p.pitch_deg},
            {"roll_deg", p.roll_deg}}},
          {"fov_deg", {{"horizontal", f.right_deg - f.left_deg}, {"vertical", f.up_deg - f.down_deg}}}};
}

}  // namespace

Result<void> FrameWriter::write(const render::Image& image, const FrameRecord& r) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%06llu", static_cast<unsigned long long>(r.frame));
  const std::string base = directory_ + "/" + name;
  if (outputs_.png)
    if (auto ok = render::writePng(image, base + ".png", r.cameraExposure.exposure); !ok) return ok;
  if (outputs_.exr) {
    std::vector<render::ExrChannel> extra;
    if (r.truth) extra.push_back({kExrTruthStandardError, r.truth->standardError});
    if (auto ok = render::writeExr(image, base + ".exr", extra); !ok) return ok;
  }
  if (outputs_.pfm) {
    if (auto ok = writePfm(image, base + ".pfm", PfmChannels::Radiance); !ok) return ok;
    if (auto ok = writePfm(image, base + ".transmittance.pfm", PfmChannels::Transmittance); !ok) return ok;
  }
  const auto& p = r.host.pose;
  const auto& s = run_.render;
  nlohmann::json line = {
      {"frame", r.frame},
      {"source", r.source},
      {"host_frame", r.host.hostFrame},
      {"host_time_s", r.host.hostTime_s},
      {"lat_deg", p.position.lat_deg},
      {"lon_deg", p.position.lon_deg},
      {"alt_m", p.position.alt_m},
      {"yaw_deg", p.yaw_deg},
      {"pitch_deg", p.pitch_deg},
      {"roll_deg", p.roll_deg},
      {"weather_clock_s", r.weatherClock_s},
      {"weather_version", r.weatherVersion},
      {"weather_connected", r.weatherConnected},
      {"weather_source", r.weatherSource},
      {"layers", r.layerCount},
      {"weather_areas", areasJson(r.weatherAreas)},
      {"weather_map",
       {{"rebuilt", r.weatherMap.rebuilt},
        {"reason", r.weatherMap.reason},
        {"texels_rewritten", r.weatherMap.texelsRewritten},
        {"bytes_uploaded", r.weatherMap.bytesUploaded}}},
      {"sun_azimuth_deg", r.sunAzimuth_deg},
      {"sun_elevation_deg", r.sunElevation_deg},
      {"preset", run_.preset},
      {"march", marchJson(s.march)},
      {"interleave", s.temporal.interleave},
      {"accumulation", s.temporal.accumulation},
      {"pixel_jitter", s.temporal.pixelJitter && s.temporal.accumulation > 0},
      {"history_clip", s.temporal.interleave > 1 ? s.temporal.historyClip : 0.0},
      {"fresh_edges", s.temporal.interleave > 1 && s.temporal.freshEdges},
      {"sharp_history", s.temporal.interleave > 1 && s.temporal.sharpHistory},
      {"horizon_sides", s.temporal.interleave > 1 && s.temporal.horizonSides},
      {"resolution_divisor", s.resolution.divisor},
      {"resolution", {s.width, s.height}},
      {"vertical_fov_deg", s.verticalFov_deg},
      {"noise_seeds", {{"shape", s.noiseSeed}}},
      {"non_finite", r.stats.nonFinite},
      {"mean_luminance", r.stats.meanLuminance},
      {"render_ms", r.render_ms},
      {"cpu_ms", r.cpu_ms},
  };
  if (r.utc_s) line["utc_s"] = *r.utc_s;
  line["utc_source"] = toString(r.utcSource);
  line["moon_azimuth_deg"] = r.moonAzimuth_deg;
  line["moon_elevation_deg"] = r.moonElevation_deg;
  const HostAtmosphere& a = r.atmosphere;
  line["atmosphere"] = {{"source", toString(a.source)},
                        {"visibility_m", a.visibility_m},
                        {"humidity_pct", a.humidity_pct},
                        {"sea_level_temperature_c", a.seaLevelTemperature_c},
                        {"sea_level_pressure_hpa", a.seaLevelPressure_hpa},
                        {"haze_visibility_m", r.visibility_m ? nlohmann::json(*r.visibility_m) : nlohmann::json()}};
  if (r.serverClockAtArrival_s) {
    line["weather_clock_server_s"] = *r.serverClockAtArrival_s;
    line["weather_clock_lock"] = toString(r.weatherClockLock);
  }
  if (r.view) line.update(viewJson(*r.view));
  nlohmann::json gpu = nlohmann::json::object();
  for (const auto& t : r.gpu) gpu[t.pass] = gpu.value(t.pass, 0.0) + t.gpu_ms;
  line["gpu_ms"] = gpu;
  if (r.presented) line["presented"] = *r.presented;
  if (r.transportDelay_ms) line["transport_delay_ms"] = *r.transportDelay_ms;
  if (r.budget)
    line["budget"] = {{"target_ms", r.budget->target_ms},
                      {"level", r.budget->level},
                      {"name", r.budget->name},
                      {"predicted_ms", r.budget->predicted_ms},
                      {"expected_psnr_db", r.budget->expectedPsnr_db},
                      {"march", marchJson(r.budget->march)},
                      {"interleave", r.budget->interleave},
                      {"resolution_divisor", r.budget->divisor}};
  if (r.presentDelay_ms) line["present_delay_ms"] = *r.presentDelay_ms;
  if (s.temporal.interleave > 1 || (r.budget && r.budget->interleave > 1)) {
    const render::TemporalReport& t = r.temporal;
    line["temporal"] = {{"drawn_whole", t.drawnWhole}, {"reason", t.reason}, {"interleave", t.interleave},
                        {"drawn", t.drawn},           {"fresh_edge_pixels", t.freshEdgePixels},
                        {"reused", t.reused},          {"offscreen", t.offscreen}, {"disoccluded", t.disoccluded},
                        {"weather_changed_fraction", t.weatherChangedFraction}};
  }
  if (render::sunMapParts(s.march.sunShadow.method) > 0)
    line["sun_map"] = {{"rebuilt", r.sunMap.rebuilt},
                       {"reason", r.sunMap.reason},
                       {"rows", {r.sunMap.rowBegin, r.sunMap.rowEnd}},
                       {"cascades", {r.sunMap.firstCascade, r.sunMap.endCascade}},
                       {"completed", r.sunMap.completed}};
  if (r.nearPrecip.type != weather::CloudType::None)
    line["near_precipitation"] = {{"type", std::string(weather::toString(r.nearPrecip.type))},
                                  {"rate_mmph", r.nearPrecip.rate_mmph},
                                  {"drops", r.nearPrecip.drops},
                                  {"capped", r.nearPrecip.capped},
                                  {"streaks", r.nearPrecip.streaks},
                                  {"faint", r.nearPrecip.faint},
                                  {"drop_area_px2", r.nearPrecip.dropArea_px2},
                                  {"camera_speed_mps", r.nearPrecip.cameraSpeed_mps}};
  line["exposure_s"] = r.exposure_s;
  // The EXR's (and PFM's) linear rgb in physical units: one unit is this
  // radiance per channel, and this luminance (Rec. 709 Y of the rgb).
  line["units"] = {{"radiance_W_m2_sr", render::kRadianceUnit_Wpm2sr}, {"luminance_cd_m2", render::kLuminanceUnit_cdm2}};
  // The PNG's (and window's) camera: its EV100, the compensation, and the
  // multiplier of the linear rgb into the tonemap (exposure.hpp), and whose
  // setting it is.
  const render::FrameExposure& e = r.cameraExposure;
  line["camera_exposure"] = {{"source", r.exposureSource},
                             {"mode", e.automatic ? "auto" : "fixed"},
                             {"ev100", e.ev100},
                             {"compensation_ev", e.compensation_ev},
                             {"exposure", e.exposure},
                             {"metered_ev100", e.meteredEv100 ? nlohmann::json(*e.meteredEv100) : nlohmann::json()},
                             {"metered", e.meteredNow},
                             {"meter_ms", e.meter_ms}};
  if (r.truth) {
    const FrameRecord::Truth& t = *r.truth;
    line["truth"] = {{"mode", "path"},
                     {"samples_per_pixel", t.samplesPerPixel},
                     {"seed", t.seed},
                     {"threads", t.threads},
                     {"majorant_violations", t.majorantViolations},
                     {"density_lookups", t.densityLookups},
                     {"standard_error",
                      {{"of", "a pixel's rgb mean, radiance units"},
                       {"mean", t.meanStandardError},
                       {"max", t.maxStandardError},
                       {"image_mean", t.imageMeanStandardError},
                       {"mean_relative", t.meanRelativeStandardError}}},
                     {"exr_channel", outputs_.exr ? nlohmann::json(kExrTruthStandardError) : nlohmann::json()}};
  }
  if (!r.flashesLit.empty()) {
    nlohmann::json lit = nlohmann::json::array();
    for (const weather::LightningFlash& f : r.flashesLit)
      lit.push_back({{"seed", std::to_string(f.seed)}, {"time_s", f.time_s}, {"kind", std::string(weather::toString(f.kind))},
                     {"lat_deg", f.lat_deg}, {"lon_deg", f.lon_deg}});
    line["lightning"] = lit;
  }
  if (outputs_.png) line["file"] = std::string(name) + ".png";
  if (outputs_.exr) line["exr"] = std::string(name) + ".exr";
  metadata_ << line.dump() << '\n';
  metadata_.flush();
  if (!metadata_) return fail(ErrorCode::Io, directory_ + "/frames.jsonl: write failed");
  return {};
}

Result<void> writePfm(const render::Image& image, const std::string& path, PfmChannels channels) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return fail(ErrorCode::Io, path + ": cannot open for writing");
  // "PF" colour or "Pf" grey; "-1.0" scale: little-endian floats. Rows go
  // bottom to top in PFM.
  const bool rgb = channels == PfmChannels::Radiance;
  std::fprintf(f, "%s\n%u %u\n-1.0\n", rgb ? "PF" : "Pf", image.width, image.height);
  const std::size_t n = rgb ? 3 : 1;
  std::vector<float> row(static_cast<std::size_t>(image.width) * n);
  bool ok = true;
  for (std::uint32_t y = image.height; y-- > 0;) {
    for (std::uint32_t x = 0; x < image.width; ++x) {
      const float* px = &image.rgba[(static_cast<std::size_t>(y) * image.width + x) * 4];
      for (std::size_t c = 0; c < n; ++c) row[x * n + c] = rgb ? px[c] : px[3];
    }
    ok = ok && std::fwrite(row.data(), sizeof(float), row.size(), f) == row.size();
  }
  ok = (std::fclose(f) == 0) && ok;
  if (!ok) return fail(ErrorCode::Io, path + ": write failed");
  return {};
}

}  // namespace sky::app
