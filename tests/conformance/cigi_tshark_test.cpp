// CIGI conformance against a real peer: Wireshark's CIGI dissector. Datagrams
// with known values for every packet we encode, in both byte orders, go into
// a pcap; tshark decodes it (cigi.version left at "from packet", as the
// reference says) and every field must equal what we meant.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "pcap_writer.hpp"
#include "sky/cigi/codec.hpp"

namespace sky::cigi {
namespace {

struct Field {
  std::string name;  // tshark field
  double value;      // what we meant
};

std::string run(const std::string& cmd) {
  std::string out;
  std::FILE* p = popen(cmd.c_str(), "r");
  if (!p) return out;
  char buf[4096];
  while (std::size_t n = std::fread(buf, 1, sizeof buf, p)) out.append(buf, n);
  pclose(p);
  return out;
}

bool haveTshark() { return run("command -v tshark").find("tshark") != std::string::npos; }

// tshark prints booleans as True/False or 1/0 depending on the field type.
double parseValue(const std::string& s) {
  if (s == "True") return 1;
  if (s == "False") return 0;
  if (s.rfind("0x", 0) == 0) return static_cast<double>(std::stoul(s, nullptr, 16));
  return std::stod(s);
}

// The fields of one host datagram: every host packet with distinct values.
struct HostFrame {
  std::vector<Packet> packets;
  std::vector<Field> fields;
};

HostFrame hostFrame() {
  HostFrame f;
  IgControl ig{5, IgMode::Operate, true, true, 1234, 5000000, 1233};
  EntityControl e;
  e.entityId = 0;
  e.state = EntityState::Active;
  e.collisionDetection = true;
  e.groundClamp = 1;
  e.linearExtrapolation = true;
  e.alpha = 200;
  e.entityType = 1001;
  e.parentId = 3;
  e.roll_deg = 1.5f;
  e.pitch_deg = -2.25f;
  e.yaw_deg = 270;
  e.lat_deg = 47.4647;
  e.lon_deg = -179.9876;
  e.alt_m = 1234.5;
  CelestialSphereControl cel{14, 30, true, true, false, true, true, 6212025, 50};
  AtmosphereControl atm{true, 45, 15, 30000, 5, -1.5f, 250, 1013.25f};
  EnvironmentalRegionControl reg;
  reg.regionId = 7;
  reg.mergeWeather = true;
  reg.mergeTerrestrial = true;
  reg.lat_deg = -89.5;
  reg.lon_deg = 8.25;
  reg.sizeX_m = 50000;
  reg.sizeY_m = 40000;
  reg.cornerRadius_m = 5000;
  reg.rotation_deg = 30;
  reg.transitionPerimeter_m = 2000;
  WeatherControl w;
  w.entityOrRegionId = 7;
  w.layerId = LayerId::CloudLayer2;
  w.humidity_pct = 80;
  w.weatherEnable = true;
  w.randomWindsEnable = true;
  w.cloudType = weather::CloudType::Cumulonimbus;
  w.scope = WeatherScope::Regional;
  w.severity = 4;
  w.airTemperature_c = -5;
  w.visibility_m = 20000;
  w.scudFrequency_pct = 25;
  w.coverage_pct = 62.5f;
  w.baseElevation_m = 1500;
  w.thickness_m = 9000;
  w.transitionBand_m = 300;
  w.horizontalWind_mps = 12.5f;
  w.verticalWind_mps = 0.5f;
  w.windDirection_deg = 270;
  w.pressure_hpa = 1013.25f;
  w.aerosol_gpm3 = 0.35f;
  ViewDefinition vd;
  vd.viewId = 2;
  vd.groupId = 1;
  vd.nearEnable = vd.farEnable = vd.topEnable = true;
  vd.mirrorMode = 1;
  vd.pixelReplication = 3;
  vd.reorder = true;
  vd.viewType = 5;
  vd.near_m = 0.5f;
  vd.far_m = 100000;
  vd.left_deg = -40;
  vd.right_deg = 40;
  vd.top_deg = 25;
  vd.bottom_deg = -25;
  ViewControl vc;
  vc.viewId = 2;
  vc.groupId = 1;
  vc.zEnable = vc.pitchEnable = true;
  vc.entityId = 0;
  vc.x_m = 1.25f;
  vc.y_m = -0.5f;
  vc.z_m = -1.2f;
  vc.roll_deg = 2;
  vc.pitch_deg = -5;
  vc.yaw_deg = 45;
  EnvironmentalConditionsRequest ecr{kRequestWeather | kRequestAerosol, 42, 47.4647, 8.5492, 3000};
  CameraExposureControl exposure{2, ExposureMode::Fixed, 14.5f, -1.25f};
  f.packets = {ig, e, cel, atm, reg, w, vd, vc, ecr, exposure};
  f.fields = {
      {"cigi.ig_control.db_number", 5}, {"cigi.ig_control.ig_mode", 1},
      {"cigi.ig_control.timestamp_valid", 1}, {"cigi.ig_control.extrapolation_enable", 1},
      {"cigi.ig_control.minor_version", 3}, {"cigi.ig_control.host_frame_number", 1234},
      {"cigi.ig_control.timestamp", 5000000}, {"cigi.ig_control.last_ig_frame_number", 1233},
      {"cigi.entity_control.entity_id", 0}, {"cigi.entity_control.entity_state", 1},
      {"cigi.entity_control.attach_state", 0}, {"cigi.entity_control.coll_det_request", 1},
      {"cigi.entity_control.inherit_alpha", 0}, {"cigi.entity_control.ground_ocean_clamp", 1},
      {"cigi.entity_control.extrapolation_enable", 1}, {"cigi.entity_control.alpha", 200},
      {"cigi.entity_control.entity_type", 1001}, {"cigi.entity_control.parent_id", 3},
      {"cigi.entity_control.roll", 1.5}, {"cigi.entity_control.pitch", -2.25},
      {"cigi.entity_control.yaw", 270}, {"cigi.entity_control.lat_xoff", 47.4647},
      {"cigi.entity_control.lon_yoff", -179.9876}, {"cigi.entity_control.alt_zoff", 1234.5},
      {"cigi.celestial_sphere_control.hour", 14}, {"cigi.celestial_sphere_control.minute", 30},
      {"cigi.celestial_sphere_control.ephemeris_enable", 1}, {"cigi.celestial_sphere_control.sun_enable", 1},
      {"cigi.celestial_sphere_control.moon_enable", 0}, {"cigi.celestial_sphere_control.star_enable", 1},
      {"cigi.celestial_sphere_control.date_time_valid", 1}, {"cigi.celestial_sphere_control.date", 6212025},
      {"cigi.celestial_sphere_control.star_intensity", 50},
      {"cigi.atmosphere_control.atmospheric_model_enable", 1}, {"cigi.atmosphere_control.humidity", 45},
      {"cigi.atmosphere_control.air_temp", 15}, {"cigi.atmosphere_control.visibility_range", 30000},
      {"cigi.atmosphere_control.horiz_wind", 5}, {"cigi.atmosphere_control.vert_wind", -1.5},
      {"cigi.atmosphere_control.wind_direction", 250}, {"cigi.atmosphere_control.barometric_pressure", 1013.25},
      {"cigi.env_region_control.region_id", 7}, {"cigi.env_region_control.region_state", 1},
      {"cigi.env_region_control.merge_weather", 1}, {"cigi.env_region_control.merge_aerosol", 0},
      {"cigi.env_region_control.merge_maritime", 0}, {"cigi.env_region_control.merge_terrestrial", 1},
      {"cigi.env_region_control.lat", -89.5}, {"cigi.env_region_control.lon", 8.25},
      {"cigi.env_region_control.size_x", 50000}, {"cigi.env_region_control.size_y", 40000},
      {"cigi.env_region_control.corner_radius", 5000}, {"cigi.env_region_control.rotation", 30},
      {"cigi.env_region_control.transition_perimeter", 2000},
      {"cigi.weather_control.entity_region_id", 7}, {"cigi.weather_control.layer_id", 2},
      {"cigi.weather_control.humidity", 80}, {"cigi.weather_control.weather_enable", 1},
      {"cigi.weather_control.scud_enable", 0}, {"cigi.weather_control.random_winds_enable", 1},
      {"cigi.weather_control.random_lightning_enable", 0}, {"cigi.weather_control.cloud_type", 6},
      {"cigi.weather_control.scope", 1}, {"cigi.weather_control.severity", 4},
      {"cigi.weather_control.air_temp", -5}, {"cigi.weather_control.visibility_range", 20000},
      {"cigi.weather_control.scud_frequency", 25}, {"cigi.weather_control.coverage", 62.5},
      {"cigi.weather_control.base_elevation", 1500}, {"cigi.weather_control.thickness", 9000},
      {"cigi.weather_control.transition_band", 300}, {"cigi.weather_control.horiz_wind", 12.5},
      {"cigi.weather_control.vert_wind", 0.5}, {"cigi.weather_control.wind_direction", 270},
      {"cigi.weather_control.barometric_pressure", 1013.25}, {"cigi.weather_control.aerosol_concentration", 0.35},
      {"cigi.view_def.view_id", 2}, {"cigi.view_def.group_id", 1}, {"cigi.view_def.near_enable", 1},
      {"cigi.view_def.far_enable", 1}, {"cigi.view_def.left_enable", 0}, {"cigi.view_def.right_enable", 0},
      {"cigi.view_def.top_enable", 1}, {"cigi.view_def.bottom_enable", 0}, {"cigi.view_def.mirror_mode", 1},
      {"cigi.view_def.pixel_replication", 3}, {"cigi.view_def.projection_type", 0},
      {"cigi.view_def.reorder", 1}, {"cigi.view_def.view_type", 5}, {"cigi.view_def.near", 0.5},
      {"cigi.view_def.far", 100000}, {"cigi.view_def.left", -40}, {"cigi.view_def.right", 40},
      {"cigi.view_def.top", 25}, {"cigi.view_def.bottom", -25},
      {"cigi.view_control.view_id", 2}, {"cigi.view_control.group_id", 1},
      {"cigi.view_control.xoff_enable", 0}, {"cigi.view_control.zoff_enable", 1},
      {"cigi.view_control.pitch_enable", 1}, {"cigi.view_control.yaw_enable", 0},
      {"cigi.view_control.entity_id", 0}, {"cigi.view_control.xoff", 1.25}, {"cigi.view_control.yoff", -0.5},
      {"cigi.view_control.zoff", -1.2}, {"cigi.view_control.roll", 2}, {"cigi.view_control.pitch", -5},
      {"cigi.view_control.yaw", 45},
      {"cigi.env_cond_request.type", 12}, {"cigi.env_cond_request.id", 42},
      {"cigi.env_cond_request.lat", 47.4647}, {"cigi.env_cond_request.lon", 8.5492},
      {"cigi.env_cond_request.alt", 3000},
      // Skyshell's camera exposure component (its data words are bytes to
      // tshark, shown unswapped: checked by cigi_test.cpp's offsets).
      {"cigi.component_control.component_id", 100}, {"cigi.component_control.instance_id", 2},
      {"cigi.component_control.component_class", 1}, {"cigi.component_control.component_state", 1},
  };
  return f;
}

HostFrame igFrame() {
  HostFrame f;
  StartOfFrame sof;
  sof.databaseNumber = 5;
  sof.igStatus = 2;
  sof.mode = IgMode::Operate;
  sof.timestampValid = true;
  sof.igFrame = 777;
  sof.timestamp_10us = 5000100;
  sof.lastHostFrame = 1234;
  WeatherConditionsResponse wcr{42, 80, 5, 20000, 12.5f, 0.5f, 270, 1013.25f};
  AerosolConcentrationResponse acr{42, LayerId::CloudLayer1, 0.35f};
  f.packets = {sof, wcr, acr};
  f.fields = {
      {"cigi.sof.db_number", 5}, {"cigi.sof.ig_status", 2}, {"cigi.sof.ig_mode", 1},
      {"cigi.sof.timestamp_valid", 1}, {"cigi.sof.earth_reference_model", 0}, {"cigi.sof.minor_version", 3},
      {"cigi.sof.ig_frame_number", 777}, {"cigi.sof.timestamp", 5000100}, {"cigi.sof.last_host_frame_number", 1234},
      {"cigi.wea_cond_response.request_id", 42}, {"cigi.wea_cond_response.humidity", 80},
      {"cigi.wea_cond_response.air_temp", 5}, {"cigi.wea_cond_response.visibility_range", 20000},
      {"cigi.wea_cond_response.horiz_speed", 12.5}, {"cigi.wea_cond_response.vert_speed", 0.5},
      {"cigi.wea_cond_response.wind_direction", 270}, {"cigi.wea_cond_response.barometric_pressure", 1013.25},
      {"cigi.aerosol_concentration_response.request_id", 42}, {"cigi.aerosol_concentration_response.layer_id", 1},
      {"cigi.aerosol_concentration_response.aerosol_concentration", 0.35},
  };
  return f;
}

std::vector<std::string> split(const std::string& line, char sep) {
  std::vector<std::string> out;
  std::stringstream s(line);
  for (std::string item; std::getline(s, item, sep);) out.push_back(item);
  if (!line.empty() && line.back() == sep) out.emplace_back();
  return out;
}

void expectTsharkDecodes(const std::string& pcap, int frameNumber, const HostFrame& frame, ByteOrder order) {
  std::string cmd = "tshark -r " + pcap + " -d udp.port==8004,cigi -Y frame.number==" +
                    std::to_string(frameNumber) + " -T fields -E separator=/t -e cigi.byte_swap";
  for (const auto& f : frame.fields) cmd += " -e " + f.name;
  cmd += " 2>/dev/null";
  std::string out = run(cmd);
  while (!out.empty() && out.back() == '\n') out.pop_back();
  const auto values = split(out, '\t');
  ASSERT_EQ(values.size(), frame.fields.size() + 1) << "tshark said:\n" << out;
  EXPECT_EQ(parseValue(values[0]), order == ByteOrder::Big ? 0x8000 : 0x0080);
  for (std::size_t i = 0; i < frame.fields.size(); ++i) {
    const auto& f = frame.fields[i];
    ASSERT_FALSE(values[i + 1].empty()) << f.name << " missing in frame " << frameNumber;
    // Floats travel as binary32: allow their rounding, nothing more.
    const double tol = std::max(1e-9, std::abs(f.value) * 1e-7);
    EXPECT_NEAR(parseValue(values[i + 1]), f.value, tol) << f.name << " in frame " << frameNumber;
  }
}

TEST(CigiConformance, TsharkDecodesEveryFieldAsMeant) {
  if (!haveTshark()) GTEST_SKIP() << "tshark is not installed (deploy/setup installs it)";
  const std::string pcap = (std::filesystem::temp_directory_path() / "skyshell-cigi-conformance.pcap").string();
  const HostFrame host = hostFrame(), ig = igFrame();
  {
    sky::test::PcapWriter w(pcap);
    ASSERT_TRUE(w.ok());
    for (ByteOrder order : {ByteOrder::Big, ByteOrder::Little}) {
      DatagramWriter h(order), g(order);
      for (const auto& p : host.packets) h.add(p);
      for (const auto& p : ig.packets) g.add(p);
      // Our own decoder agrees first: tshark is the oracle for the bytes.
      ASSERT_TRUE(decodeDatagram(h.bytes()));
      ASSERT_TRUE(decodeDatagram(g.bytes()));
      w.add(h.bytes(), 8005, 8004);
      w.add(g.bytes(), 8004, 8005);
    }
  }
  expectTsharkDecodes(pcap, 1, host, ByteOrder::Big);
  expectTsharkDecodes(pcap, 2, ig, ByteOrder::Big);
  expectTsharkDecodes(pcap, 3, host, ByteOrder::Little);
  expectTsharkDecodes(pcap, 4, ig, ByteOrder::Little);
  // No frame is malformed in tshark's eyes.
  const std::string malformed = run("tshark -r " + pcap + " -d udp.port==8004,cigi -Y _ws.malformed 2>/dev/null");
  EXPECT_TRUE(malformed.empty()) << malformed;
}

}  // namespace
}  // namespace sky::cigi
