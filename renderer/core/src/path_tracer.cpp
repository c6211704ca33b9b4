// The path tracer's cloud scene (volume_paths.hpp's Scene over the CPU
// core's medium) and the frame's sums: see sky/render/path_tracer.hpp.
#include "sky/render/path_tracer.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <mutex>
#include <thread>

#include "cpu_core.hpp"
#include "volume_paths.hpp"

namespace sky::render {

namespace {

namespace vp = volume_paths;
using cpu_core::CpuCore;
using glm::dvec3;

// Clouds are traced as far as the reference marches them: a layer's span
// starts within kMaxViewDistance_m of the camera and is at most kMaxSpan_m
// long (cloud_core.glsl), so the truth sees the clouds the model draws.
constexpr double kTracedDistance_m = CpuCore::kMaxViewDistance_m + CpuCore::kMaxSpan_m;

// [t0, t1] where the ray is within rho of the centre (false: never).
bool insideSphere(const dvec3& oc, const dvec3& d, double dist, double rho, double& t0, double& t1) {
  const double b = glm::dot(oc, d);
  const double c = (dist - rho) * (dist + rho);
  const double disc = b * b - c;
  if (disc < 0.0) return false;
  const double s = std::sqrt(disc);
  // The stable pair of roots (one by the product c).
  const double q = b > 0.0 ? -b - s : -b + s;
  if (q == 0.0) {
    t0 = t1 = 0.0;
    return true;
  }
  t0 = std::min(q, c / q);
  t1 = std::max(q, c / q);
  return true;
}

// A cloud type's scattering as the path tracer takes it: the phase, and
// the share of scattering events left out as the diffraction peak.
struct Scattering {
  vp::Phase phase;
  double peak = 0.0;
};

// The Mie fit's HG lobe of droplets (g 0.98-0.998, half its scattering) is
// the diffraction peak: its light leaves within about a degree of where it
// was going, under a pixel of the images the truth is drawn at (0.4-0.7
// degrees). Traced as scattering, it makes next-event estimation's sun
// term jump by 10^4 whenever a path heads near the sun (measured: a
// relative standard error of 37 % per pixel at 4 samples, single samples
// of 10^4 times a pixel's mean). Taken as unscattered instead (delta-M
// scaling of that lobe, Wiscombe 1977): the extinction loses albedo times
// its weight and the phase is the Draine lobe alone. Lobes wider than
// kPeakAsymmetry (ice's HG, 0.75) are traced as they are.
constexpr double kPeakAsymmetry = 0.95;

Scattering cloudScattering(CpuCore& core, const CpuCore::CloudType& t, bool truncatePeak) {
  if (t.dropletDiameter_um <= 0.0) return {vp::Phase{CpuCore::kIceAsymmetry, 0.0, 0.0, 0.0}, 0.0};
  const CpuCore::MieFit m = core.mieFit(t.dropletDiameter_um);
  if (!truncatePeak || m.gHG < kPeakAsymmetry) return {vp::Phase{m.gHG, m.gD, m.alpha, m.w}, 0.0};
  return {vp::Phase{m.gD, m.gD, m.alpha, 1.0}, 1.0 - m.w};
}

// Each layer's shell is bounded in this many slices of height: the
// density profiles rise from the base (cumulus: linearly), so a bound per
// slice saves the lookups a bound for the whole shell wastes low down.
constexpr int kSlices = 8;
constexpr int kSliceSamples = 32;
constexpr double kSliceMargin = 1.05;

struct Shell {
  int layer = 0;
  double inner = 0.0, outer = 0.0;  // radii from the Earth's centre, m
  double majorant = 0.0;            // 1/m
};

// The largest density a layer's weather map texels give (unorm8), 0..1.
double maxDensity(const WeatherField& field, std::uint32_t slice) {
  const std::size_t texelsPerSlice = std::size_t(field.size) * field.size;
  std::uint8_t best = 0;
  for (std::uint32_t ring = 0; ring < kWeatherRings; ++ring) {
    const std::size_t base = (std::size_t(ring) * field.sliceCount + slice) * texelsPerSlice * 4;
    if (base + texelsPerSlice * 4 > field.texels.size()) break;
    for (std::size_t i = 0; i < texelsPerSlice; ++i) best = std::max(best, field.texels[base + i * 4 + 1]);
  }
  return best / 255.0;
}

class CloudScene final : public vp::Scene {
 public:
  CloudScene(CpuCore& core, const CpuCore::CoreFrame& frame, const FrameSetup& setup, const WeatherField& field,
             bool truncatePeak, bool skyLight)
      : core_(core), f_(frame), truncatePeak_(truncatePeak), skyLight_(skyLight), r_(setup.r_m), groundRadius_(setup.r_m - setup.hGround_m), centre_(0.0, 0.0, -setup.r_m) {
    for (int i = 0; i < f_.layerCount; ++i) {
      const CpuCore::CoreLayer L = core_.layerAt(i);
      layers_[i] = L;
      if (L.absent) continue;
      // rho <= density profile x weather density (shape, erosion and
      // presence are each at most 1): per slice of the shell, the type's
      // extinction at the map's densest texel times the profile's largest
      // value in the slice (sampled finely, with a margin for the peaks
      // between samples) bounds the layer.
      const double density = maxDensity(field, std::uint32_t(i));
      if (density <= 0.0) continue;
      for (int k = 0; k < kSlices; ++k) {
        double bound = 0.0;
        for (int j = 0; j <= kSliceSamples; ++j) {
          const double ph = (k + double(j) / kSliceSamples) / kSlices;
          const double a = L.primary.extinction_perm * core_.densityProfile(L.primary, ph);
          const double b = L.blends ? L.secondary.extinction_perm * core_.densityProfile(L.secondary, ph) : 0.0;
          bound = std::max({bound, a, b});
        }
        if (bound <= 0.0) continue;
        // Bottom to top: the shell's heights above the camera's sphere
        // (base - band to top + band, as ph runs from 0 to 1).
        const double lo = r_ - L.hBase + L.thickness * k / kSlices;
        const double hi = r_ - L.hBase + L.thickness * (k + 1) / kSlices;
        shells_.push_back(Shell{i, lo, hi, bound * kSliceMargin * density});
        traced_[i] = true;
      }
    }
  }

  void majorants(const vp::Ray& ray, double tMax, std::vector<vp::MajorantSegment>& out) const override {
    out.clear();
    struct Edge {
      double t;
      double dSigma;
    };
    Edge edges[4 * gpu::kMaxLayers * kSlices];
    int n = 0;
    const dvec3 oc = ray.origin - centre_;
    const double dist = glm::length(oc);
    const double tEnd = std::min(tMax, kTracedDistance_m);
    for (const Shell& s : shells_) {
      double o0, o1;
      if (!insideSphere(oc, ray.dir, dist, s.outer, o0, o1)) continue;
      double i0 = 0.0, i1 = 0.0;
      const bool inner = insideSphere(oc, ray.dir, dist, s.inner, i0, i1);
      const auto add = [&](double a, double b) {
        a = std::max(a, 0.0);
        b = std::min(b, tEnd);
        if (b <= a) return;
        edges[n++] = Edge{a, s.majorant};
        edges[n++] = Edge{b, -s.majorant};
      };
      if (!inner || i1 <= o0 || i0 >= o1) {
        add(o0, o1);
      } else {
        add(o0, i0);
        add(i1, o1);
      }
    }
    std::sort(edges, edges + n, [](const Edge& a, const Edge& b) { return a.t < b.t; });
    double sigma = 0.0;
    for (int k = 0; k < n; ++k) {
      sigma += edges[k].dSigma;
      if (k + 1 < n && edges[k + 1].t > edges[k].t && sigma > 1e-12) out.push_back({edges[k].t, edges[k + 1].t, sigma});
    }
  }

  vp::MediumPoint medium(const dvec3& p, double u) const override {
    const double h = core_.heightAboveCameraSphere(p, r_);
    double sigma[gpu::kMaxLayers];
    Scattering scattering[gpu::kMaxLayers];
    double total = 0.0;
    int count = 0;
    for (int li = 0; li < f_.layerCount; ++li) {
      if (!traced_[li]) continue;
      const CpuCore::CoreLayer& L = layers_[li];
      const double ph = (h + L.hBase) / L.thickness;
      if (ph <= 0.0 || ph >= 1.0) continue;
      const CpuCore::CloudSample cs = core_.layerSample(L, p, h, ph, false, r_);
      if (cs.rho <= 0.0) continue;
      scattering[count] = cloudScattering(core_, cs.ct, truncatePeak_);
      sigma[count] = cs.ct.extinction_perm * cs.rho * (1.0 - CpuCore::kAlbedo * scattering[count].peak);
      total += sigma[count];
      ++count;
    }
    vp::MediumPoint m;
    m.sigmaT = total;
    if (count == 0) return m;
    int pick = 0;
    for (double acc = sigma[0]; pick + 1 < count && u * total >= acc; acc += sigma[++pick]) {
    }
    const double peak = scattering[pick].peak;
    m.albedo = CpuCore::kAlbedo * (1.0 - peak) / (1.0 - CpuCore::kAlbedo * peak);
    m.phase = scattering[pick].phase;
    return m;
  }

  double surfaceDistance(const vp::Ray& ray) const override {
    const dvec3 oc = ray.origin - centre_;
    double t0, t1;
    if (!insideSphere(oc, ray.dir, glm::length(oc), groundRadius_, t0, t1)) return vp::kInfinity;
    if (t0 > 0.0) return t0;
    return vp::kInfinity;  // from above the ground only (a point on it starts just above)
  }

  vp::Surface surfaceAt(const dvec3& p) const override {
    return vp::Surface{glm::normalize(p - centre_), CpuCore::kGroundAlbedo};
  }

  dvec3 sunDirection() const override { return f_.air.sunDir; }

  dvec3 sunIrradiance(const dvec3& p) const override {
    const double h = core_.heightAboveCameraSphere(p, r_) + f_.air.h;
    const double muSun = glm::dot(core_.upAt(p, r_), f_.air.sunDir);
    return f_.air.sunIrradiance * core_.sunTransmittance(h, muSun, groundRadius_);
  }

  dvec3 escapeRadiance(const vp::Ray& ray) const override {
    dvec3 inscatter, transmittance;
    clearAir(ray, CpuCore::kFarAway_m, inscatter, transmittance);
    return inscatter + transmittance * CpuCore::kNightSkyRadiance;
  }

  void surfaceSegment(const vp::Ray& ray, double t, dvec3& inscatter, dvec3& transmittance) const override {
    clearAir(ray, t, inscatter, transmittance);
  }

 private:
  // The clear air from ray.origin along ray.dir to distance t (or out of
  // the atmosphere): marchAir in the frame of a camera at the origin.
  void clearAir(const vp::Ray& ray, double t, dvec3& inscatter, dvec3& transmittance) const {
    inscatter = dvec3(0.0);
    transmittance = dvec3(1.0);
    if (!skyLight_) return;
    const dvec3 up = core_.upAt(ray.origin, r_);
    const double h = std::max(0.0, core_.heightAboveCameraSphere(ray.origin, r_) + f_.air.h);
    // Any frame with z up at the origin: the air depends on the ray's and
    // the sun's angles to the vertical and to each other.
    const dvec3 e1 = glm::normalize(std::abs(up.x) < 0.9 ? glm::cross(up, dvec3(1, 0, 0)) : glm::cross(up, dvec3(0, 1, 0)));
    const dvec3 e2 = glm::cross(up, e1);
    const auto local = [&](const dvec3& v) { return dvec3(glm::dot(v, e1), glm::dot(v, e2), glm::dot(v, up)); };
    CpuCore::AirFrame a = f_.air;
    a.h = h;
    a.r = groundRadius_ + h;
    a.cGround = h * (2.0 * a.r - h);
    const double above = h - CpuCore::kAtmosphereHeight_m;
    a.cTop = above * (2.0 * a.r - above);
    a.sunDir = local(f_.air.sunDir);
    a.shadowLayers = 0;
    a.aerosolExcess = 0.0;  // the haze of the view ray only (AirFrame::aerosolExcess)
    double q[CpuCore::kAirQueries];
    q[0] = t;
    const CpuCore::AirPath path = core_.marchAir(a, local(ray.dir), t, q, 1);
    inscatter = path.inscatter[0];
    transmittance = path.transmittance[0];
  }

  CpuCore& core_;
  CpuCore::CoreFrame f_;
  bool truncatePeak_;
  bool skyLight_;
  CpuCore::CoreLayer layers_[gpu::kMaxLayers]{};
  bool traced_[gpu::kMaxLayers]{};  // layers with a shell (density somewhere)
  std::vector<Shell> shells_;
  double r_;
  double groundRadius_;
  dvec3 centre_;
};

// The view ray's air as the reference marches it (marchAir, with the
// clouds' shadow), kept at its steps' ends so the many samples of one
// pixel read it at their own distances without marching it again.
class ViewAir {
 public:
  ViewAir(CpuCore& core, const CpuCore::CoreFrame& f, const dvec3& dir, double tEnd) {
    const CpuCore::AirSegment seg = core.airSegment(f.air, dir, tEnd);
    tA_ = seg.t0;
    tB_ = seg.t1;
    if (tB_ <= tA_) return;
    const double nu = glm::dot(dir, f.air.sunDir);
    const double pR = core.phaseRayleigh(nu);
    const double pM = core.phaseCornetteShanks(nu, CpuCore::kMieG);
    const int steps = f.air.airSteps > 0 ? f.air.airSteps : CpuCore::kAirSteps;
    dvec3 inscatter(0.0), transmittance(1.0);
    for (int i = 0; i < steps; ++i) {
      const double u0 = double(i) / steps, u1 = double(i + 1) / steps;
      Step s;
      s.s0 = tA_ + (tB_ - tA_) * u0 * u0;
      s.s1 = tA_ + (tB_ - tA_) * u1 * u1;
      const CpuCore::AirSource src = core.airSourceAt(f.air, dir, 0.5 * (s.s0 + s.s1));
      s.sigma = src.extinction;
      s.source = src.rayleigh * pR + src.mie * pM + src.multiple;
      s.inscatter = inscatter;
      s.transmittance = transmittance;
      const double ds = s.s1 - s.s0;
      inscatter += transmittance * s.source * ds * core.scatterFraction3(s.sigma * ds);
      transmittance *= glm::exp(-s.sigma * ds);
      steps_.push_back(s);
    }
    endInscatter_ = inscatter;
    endTransmittance_ = transmittance;
  }

  // In-scattered radiance and transmittance from the camera to t.
  void at(CpuCore& core, double t, dvec3& inscatter, dvec3& transmittance) const {
    if (steps_.empty() || t <= tA_) {
      inscatter = dvec3(0.0);
      transmittance = dvec3(1.0);
      return;
    }
    const auto it = std::upper_bound(steps_.begin(), steps_.end(), t, [](double x, const Step& s) { return x < s.s1; });
    if (it == steps_.end()) {
      inscatter = endInscatter_;
      transmittance = endTransmittance_;
      return;
    }
    const double d = t - it->s0;
    inscatter = it->inscatter + it->transmittance * it->source * d * core.scatterFraction3(it->sigma * d);
    transmittance = it->transmittance * glm::exp(-it->sigma * d);
  }

 private:
  struct Step {
    double s0 = 0.0, s1 = 0.0;
    dvec3 sigma{0.0}, source{0.0}, inscatter{0.0}, transmittance{1.0};
  };
  double tA_ = 0.0, tB_ = 0.0;
  std::vector<Step> steps_;
  dvec3 endInscatter_{0.0}, endTransmittance_{1.0};
};

std::uint64_t splitMix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30u)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27u)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31u);
}

}  // namespace

PathTracer::PathTracer(RenderSettings settings, std::shared_ptr<const cpu_core::CoreTables> tables)
    : settings_(std::move(settings)), tables_(std::move(tables)) {}

Result<PathTracer> PathTracer::create(const RenderSettings& settings) {
  if (auto ok = validateSettings(settings); !ok) return tl::unexpected(ok.error());
  auto tables = cpu_core::makeCoreTables(settings.noiseSeed, settings.noiseCacheDir);
  RenderSettings full = settings;
  full.resolution = {};
  return PathTracer(full, std::move(tables));
}

Result<void> PathTracer::render(const FrameInputs& inputs, const PathTraceOptions& options,
                                PathTraceState& state) const {
  if (auto ok = validateInputs(inputs); !ok) return tl::unexpected(ok.error());
  if (options.samplesPerPixel == 0) return fail(ErrorCode::InvalidArgument, "PathTracer::render: no samples asked");
  const std::uint32_t w = settings_.width, h = settings_.height;
  const std::size_t n = std::size_t(w) * h;
  if (state.samples == 0 && state.sum.empty()) {
    state.width = w;
    state.height = h;
    state.sum.assign(n * 4, 0.0);
    state.sumSquares.assign(n * 3, 0.0);
    state.depthSum.assign(n, 0.0);
    state.depthCount.assign(n, 0);
  } else if (state.width != w || state.height != h || state.sum.size() != n * 4) {
    return fail(ErrorCode::InvalidArgument, "PathTracer::render: the state is " + std::to_string(state.width) + "x" +
                                                std::to_string(state.height) + ", the image " + std::to_string(w) +
                                                "x" + std::to_string(h));
  }
  const WeatherField field =
      buildWeatherField(inputs.weather, inputs.coarseWeather, weatherAnchorFor(inputs.camera.position));
  const FrameSetup setup = prepareFrame(settings_, inputs, field, tables_->atmosphere);
  const unsigned threads = options.threads > 0 ? options.threads : std::max(1u, std::thread::hardware_concurrency());
  std::atomic<std::uint32_t> nextRow{0};
  std::atomic<std::uint64_t> violations{0}, lookups{0};
  std::mutex progressMutex;
  std::uint32_t rowsDone = 0;
  vp::TraceOptions trace;
  trace.maxEvents = int(options.maxEvents);
  const std::uint64_t first = state.samples;
  const auto work = [&] {
    CpuCore core(setup, *tables_, field);
    const CpuCore::CoreFrame frame = core.coreFrame();
    core.buildSunMap(frame);
    CloudScene scene(core, frame, setup, field, !options.exactPeak, options.skyLight);
    vp::TraceStats stats;
    std::vector<vp::MajorantSegment> scratch;
    for (std::uint32_t y = nextRow++; y < h; y = nextRow++) {
      for (std::uint32_t x = 0; x < w; ++x) {
        const std::size_t i = std::size_t(y) * w + x;
        const auto rayAt = [&](double px, double py) {
          return core.cameraRay(setup.camForward, setup.camRight, setup.camDown, setup.frustum, px, py,
                                setup.rasterWidth, setup.rasterHeight);
        };
        const dvec3 centre = rayAt(double(x), double(y));
        std::unique_ptr<ViewAir> centreAir;
        if (!options.pixelArea) centreAir = std::make_unique<ViewAir>(core, frame, centre, core.airRayEnd(frame.air, centre.z));
        for (std::uint32_t s = 0; s < options.samplesPerPixel; ++s) {
          vp::Rng rng(splitMix(options.seed ^ splitMix(first + s)), i);
          // cameraRay takes the pixel's corner coordinate to its centre (+0.5).
          const dvec3 dir = options.pixelArea ? rayAt(x + rng.uniform() - 0.5, y + rng.uniform() - 0.5) : centre;
          const double tEnd = core.airRayEnd(frame.air, dir.z);
          const bool ground = tEnd < CpuCore::kFarAway_m;
          vp::MediumPoint point;
          const double t = vp::freeFlight(scene, vp::Ray{dvec3(0.0), dir}, ground ? tEnd : vp::kInfinity, rng, point,
                                          stats, scratch);
          const bool met = t < vp::kInfinity;
          dvec3 inscatter, transmittance;
          std::unique_ptr<ViewAir> ownAir;
          const ViewAir* air = centreAir.get();
          if (air == nullptr) air = (ownAir = std::make_unique<ViewAir>(core, frame, dir, tEnd)).get();
          air->at(core, met ? t : tEnd, inscatter, transmittance);
          dvec3 behind(CpuCore::kNightSkyRadiance);
          if (met) {
            behind = vp::radianceFromEvent(scene, dir * t, dir, point, 0, trace, rng, stats);
          } else if (ground) {
            behind = vp::radianceFromSurface(scene, dir * tEnd, dir, 0, trace, rng, stats);
          }
          const dvec3 l = inscatter + transmittance * behind;
          for (int c = 0; c < 3; ++c) {
            state.sum[i * 4 + c] += l[c];
            state.sumSquares[i * 3 + c] += l[c] * l[c];
          }
          state.sum[i * 4 + 3] += met ? 0.0 : 1.0;
          if (met) {
            state.depthSum[i] += t;
            ++state.depthCount[i];
          }
        }
      }
      if (options.progress) {
        const std::lock_guard lock(progressMutex);
        options.progress(++rowsDone, h);
      }
    }
    violations += stats.majorantViolations;
    lookups += stats.densityLookups;
  };
  std::vector<std::thread> pool;
  for (unsigned k = 1; k < threads; ++k) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
  state.samples += options.samplesPerPixel;
  state.violations += violations;
  state.lookups += lookups;
  return {};
}

}  // namespace sky::render
