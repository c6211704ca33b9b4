// The CPU core's hooks (cpu_core.hpp): texture lookups emulated on the
// CPU copies of what the GPU uploads, as shaders/clouds.comp reads them.
#include "cpu_core.hpp"

namespace sky::render::cpu_core {

std::shared_ptr<const CoreTables> makeCoreTables(std::uint32_t noiseSeed, const std::string& noiseCacheDir) {
  auto tables = std::make_shared<CoreTables>();
  tables->shape = shapeNoiseFor(noiseCacheDir, noiseSeed);
  tables->detail = detailNoiseFor(noiseCacheDir, noiseSeed);
  tables->atmosphere = sharedAtmosphereTables();
  tables->blueNoise = blueNoiseTile(noiseSeed);
  return tables;
}

CpuCore::CoreLayer CpuCore::layerAt(int li) { return layers_[li]; }
CpuCore::real4 CpuCore::flashAt(int k) { return setup_.flashes.lights[std::size_t(k)]; }
CpuCore::real4 CpuCore::boltStartAt(int k) { return setup_.flashes.boltStart[std::size_t(k)]; }
CpuCore::real3 CpuCore::boltEndAt(int k) { return setup_.flashes.boltEnd[std::size_t(k)]; }
CpuCore::real2 CpuCore::airCloudShadow(AirFrame a, real3 p, real h, real muSun) {
  return airSunShadow(a, p, h, muSun);
}
void CpuCore::storeSunMap(real4 part0, real4 part1) { sunMap_.store(part0, part1); }
CpuCore::real4 CpuCore::sampleSunMap(int layer, real2 uv) { return sunMap_.sample(layer, uv); }

void CpuCore::storeAirTable(int slice, real4 part0, real4 part1, real4 part2) {
  airTable_.store(slice, part0, part1, part2);
}
CpuCore::real4 CpuCore::sampleAirTable(int part, real3 uvw) { return airTable_.sample(part, uvw); }

// The hooks mirror those of shaders/clouds.comp.
bool CpuCore::weatherPlane(real3 p, real2& plane) {
  const real3 a = anchorPlane(setup_.camToAnchor, setup_.camInAnchor_m, setup_.anchorRadius_m, p);
  plane = real2(a.x, a.y);
  return a.z > 0.0;
}

CpuCore::real2 CpuCore::windInPlane(LayerSampling s, real2 plane) {
  ++lookups_;
  return windFromTexel(weather_.sampleLayer(kWindMapLayers + std::uint32_t(s.coverageShift.z), plane.x, plane.y));
}

CpuCore::real2 CpuCore::tilePlane(LayerSampling s, real2 plane) {
  if (s.flow.w > 0.5) return plane - windInPlane(s, plane) * s.windRef.w;  // (as cloud_pass.glsl's tilePlane)
  return plane - real2(s.coverageShift.x, s.coverageShift.y);
}

CpuCore::real3 CpuCore::sampleWeather(LayerSampling s, real3 p) {
  ++lookups_;
  real2 plane;
  if (!weatherPlane(p, plane)) return real3(0.0);
  plane = tilePlane(s, plane);
  return weather_.sample(std::uint32_t(s.coverageShift.z), plane.x, plane.y);
}

CpuCore::real3 CpuCore::sampleWindLocal(LayerSampling s, real3 p) {
  real2 plane;
  if (!weatherPlane(p, plane)) return real3(s.windRef);
  return real3(windInPlane(s, plane), 0.0) * setup_.camToAnchor;
}

CpuCore::real CpuCore::sampleMaxCoverage(LayerSampling s, real3 p) {
  ++lookups_;
  real2 plane;
  if (!weatherPlane(p, plane)) return 0.0;
  plane = tilePlane(s, plane);
  return sampleCoverageMip(coverageMip_, weather_, std::uint32_t(s.coverageShift.z), plane.x, plane.y);
}

CpuCore::real2 CpuCore::sampleShape(LayerSampling s, real3 p) {
  ++lookups_;
  real3 e = setup_.localToEcef * (p - s.flowShift);
  e.z *= s.shapeStretchZ;
  const real4 v = shape_.sample(real3(s.shapeOrigin) + e * s.shapeOrigin.w);
  return real2(v.x, v.y);
}

CpuCore::real CpuCore::sampleDetail(LayerSampling s, real3 p) {
  ++lookups_;
  return detail_.sample(real3(s.detailOrigin) + (setup_.localToEcef * (p - s.flowShift)) * s.detailOrigin.w).x;
}

// The cloud map: the shape texture's smooth and Worley channels at its own period.
CpuCore::real2 CpuCore::sampleCloudMap(LayerSampling s, real3 p) {
  ++lookups_;
  const real4 v = shape_.sample(real3(s.cloudMapOrigin) + (setup_.localToEcef * (p - s.flowShift)) * s.cloudMapOrigin.w);
  return real2(v.z, v.w);
}


}  // namespace sky::render::cpu_core
