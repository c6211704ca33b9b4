#include "volume_paths.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace sky::render::volume_paths {

namespace {

constexpr double kPi = std::numbers::pi;
// Where ratio tracking's estimate falls below this, roulette ends half of
// the remaining walks (and doubles the others): a sun ray deep in a cloud
// otherwise reads density all the way out for a transmittance of 1e-9.
constexpr double kRatioRoulette = 0.05;
// A surface point's rays start this far off the surface, m: far above the
// double precision of points 6400 km from the Earth's centre (~1e-9 m).
constexpr double kSurfaceOffset_m = 1e-3;

double hg(double c, double g) {
  const double d = 1.0 + g * g - 2.0 * g * std::clamp(c, -1.0, 1.0);
  return (1.0 - g * g) / (4.0 * kPi * d * std::sqrt(d));
}

// cos(theta) drawn from HG(g) by inverting its distribution.
double sampleHgCosine(double g, double u) {
  if (std::abs(g) < 1e-4) return 1.0 - 2.0 * u;
  const double s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
  return std::clamp((1.0 + g * g - s * s) / (2.0 * g), -1.0, 1.0);
}

// A unit direction at cos c from axis (unit), azimuth phi (Duff et al.
// 2017's branchless orthonormal basis).
dvec3 around(const dvec3& axis, double c, double phi) {
  const double sign = std::copysign(1.0, axis.z);
  const double a = -1.0 / (sign + axis.z);
  const double b = axis.x * axis.y * a;
  const dvec3 t(1.0 + sign * axis.x * axis.x * a, sign * b, -sign * axis.x);
  const dvec3 bt(b, sign + axis.y * axis.y * a, -axis.y);
  const double s = std::sqrt(std::max(0.0, 1.0 - c * c));
  return glm::normalize(t * (s * std::cos(phi)) + bt * (s * std::sin(phi)) + axis * c);
}

bool isBlack(const dvec3& v) { return v.x <= 0.0 && v.y <= 0.0 && v.z <= 0.0; }

// The sun's light reaching p unshadowed by the surface, through the medium.
dvec3 sunThroughMedium(const Scene& scene, const dvec3& p, Rng& rng, TraceStats& stats,
                       std::vector<MajorantSegment>& scratch) {
  const dvec3 e = scene.sunIrradiance(p);
  if (isBlack(e)) return dvec3(0.0);
  const Ray toSun{p, scene.sunDirection()};
  if (scene.surfaceDistance(toSun) < kInfinity) return dvec3(0.0);
  const double t = ratioTransmittance(scene, toSun, kInfinity, rng, stats, scratch);
  return e * t;
}

}  // namespace

Rng::Rng(std::uint64_t seed, std::uint64_t stream) : inc_((stream << 1u) | 1u) {
  next();
  state_ += seed;
  next();
}

std::uint32_t Rng::next() {
  const std::uint64_t old = state_;
  state_ = old * 6364136223846793005ull + inc_;
  const auto xorshifted = std::uint32_t(((old >> 18u) ^ old) >> 27u);
  const auto rot = std::uint32_t(old >> 59u);
  return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
}

double Rng::uniform() { return double(next()) * 0x1p-32; }

double evalPhase(const Phase& p, double cosTheta) {
  const double c = std::clamp(cosTheta, -1.0, 1.0);
  const double draine =
      p.w > 0.0 ? hg(c, p.gD) * (1.0 + p.alpha * c * c) / (1.0 + p.alpha * (1.0 + 2.0 * p.gD * p.gD) / 3.0) : 0.0;
  return (1.0 - p.w) * hg(c, p.gHG) + p.w * draine;
}

dvec3 samplePhase(const Phase& p, const dvec3& dir, Rng& rng, double& weight) {
  const bool second = rng.uniform() < p.w;
  const double c = sampleHgCosine(second ? p.gD : p.gHG, rng.uniform());
  const dvec3 out = around(dir, c, 2.0 * kPi * rng.uniform());
  if (p.w <= 0.0) {
    weight = 1.0;
    return out;
  }
  const double pdf = (1.0 - p.w) * hg(c, p.gHG) + p.w * hg(c, p.gD);
  weight = evalPhase(p, c) / pdf;
  return out;
}

dvec3 sampleCosine(const dvec3& n, Rng& rng) {
  return around(n, std::sqrt(rng.uniform()), 2.0 * kPi * rng.uniform());
}

void Scene::surfaceSegment(const Ray&, double, dvec3& inscatter, dvec3& transmittance) const {
  inscatter = dvec3(0.0);
  transmittance = dvec3(1.0);
}

namespace {

// Tentative collisions along the ray before tMax, against the scene's
// majorants: visit(medium there, majorant) returns false to stop. Delta
// and ratio tracking differ only in what they do at each.
template <class Visit>
void trackCandidates(const Scene& scene, const Ray& ray, double tMax, Rng& rng, TraceStats& stats,
                     std::vector<MajorantSegment>& scratch, Visit&& visit, double& tStop) {
  scene.majorants(ray, tMax, scratch);
  for (const MajorantSegment& seg : scratch) {
    if (seg.sigma <= 0.0) continue;
    double t = seg.t0;
    for (;;) {
      t -= std::log1p(-rng.uniform()) / seg.sigma;
      if (t >= seg.t1) break;
      const MediumPoint m = scene.medium(ray.origin + ray.dir * t, rng.uniform());
      ++stats.densityLookups;
      if (m.sigmaT > seg.sigma) ++stats.majorantViolations;
      if (!visit(m, seg.sigma)) {
        tStop = t;
        return;
      }
    }
  }
}

}  // namespace

double freeFlight(const Scene& scene, const Ray& ray, double tMax, Rng& rng, MediumPoint& point, TraceStats& stats,
                  std::vector<MajorantSegment>& scratch) {
  double t = kInfinity;
  trackCandidates(scene, ray, tMax, rng, stats, scratch,
                  [&](const MediumPoint& m, double sigma) {
                    if (rng.uniform() * sigma >= m.sigmaT) return true;
                    point = m;
                    return false;
                  },
                  t);
  return t;
}

double ratioTransmittance(const Scene& scene, const Ray& ray, double tMax, Rng& rng, TraceStats& stats,
                          std::vector<MajorantSegment>& scratch) {
  double transmittance = 1.0, stopped = kInfinity;
  trackCandidates(scene, ray, tMax, rng, stats, scratch,
                  [&](const MediumPoint& m, double sigma) {
                    transmittance *= std::max(0.0, 1.0 - m.sigmaT / sigma);
                    if (transmittance < kRatioRoulette) {
                      if (rng.uniform() < 0.5) {
                        transmittance = 0.0;
                        return false;
                      }
                      transmittance *= 2.0;
                    }
                    return true;
                  },
                  stopped);
  return transmittance;
}

namespace {

// The path from a ray leaving a vertex: events so far, throughput beta.
dvec3 continuePath(const Scene& scene, Ray ray, dvec3 beta, int events, const TraceOptions& options, Rng& rng,
                   TraceStats& stats) {
  std::vector<MajorantSegment> scratch;
  dvec3 sum(0.0);
  for (;;) {
    const double tSurface = scene.surfaceDistance(ray);
    MediumPoint point;
    const double t = freeFlight(scene, ray, tSurface, rng, point, stats, scratch);
    const bool last = options.maxEvents > 0 && events >= options.maxEvents;
    if (t == kInfinity && tSurface == kInfinity) {
      sum += beta * scene.escapeRadiance(ray);
      break;
    }
    if (t == kInfinity) {
      dvec3 inscatter, transmittance;
      scene.surfaceSegment(ray, tSurface, inscatter, transmittance);
      sum += beta * inscatter;
      if (last) break;
      const dvec3 at = ray.origin + ray.dir * tSurface;
      const Surface s = scene.surfaceAt(at);
      beta *= transmittance;
      ++events;
      ++stats.events;
      const dvec3 from = at + s.normal * kSurfaceOffset_m;
      const dvec3 sun = sunThroughMedium(scene, from, rng, stats, scratch);
      sum += beta * sun * (s.albedo / kPi * std::max(0.0, glm::dot(s.normal, scene.sunDirection())));
      beta *= s.albedo;
      ray = Ray{from, sampleCosine(s.normal, rng)};
    } else {
      if (last) break;
      const dvec3 at = ray.origin + ray.dir * t;
      ++events;
      ++stats.events;
      beta *= point.albedo;
      const dvec3 sun = sunThroughMedium(scene, at, rng, stats, scratch);
      sum += beta * sun * evalPhase(point.phase, glm::dot(scene.sunDirection(), ray.dir));
      double weight = 1.0;
      const dvec3 next = samplePhase(point.phase, ray.dir, rng, weight);
      beta *= weight;
      ray = Ray{at, next};
    }
    if (events > options.rouletteAfter) {
      const double survive = std::min(1.0, std::max({beta.x, beta.y, beta.z}));
      if (survive <= 0.0 || rng.uniform() >= survive) break;
      beta /= survive;
    }
  }
  return sum;
}

}  // namespace

dvec3 radianceFromEvent(const Scene& scene, const dvec3& at, const dvec3& incoming, const MediumPoint& point,
                        int eventsBefore, const TraceOptions& options, Rng& rng, TraceStats& stats) {
  std::vector<MajorantSegment> scratch;
  ++stats.events;
  const dvec3 beta(point.albedo);
  const dvec3 sun = sunThroughMedium(scene, at, rng, stats, scratch);
  dvec3 sum = beta * sun * evalPhase(point.phase, glm::dot(scene.sunDirection(), incoming));
  double weight = 1.0;
  const dvec3 next = samplePhase(point.phase, incoming, rng, weight);
  return sum + continuePath(scene, Ray{at, next}, beta * weight, eventsBefore + 1, options, rng, stats);
}

dvec3 radianceFromSurface(const Scene& scene, const dvec3& at, const dvec3& incoming, int eventsBefore,
                          const TraceOptions& options, Rng& rng, TraceStats& stats) {
  (void)incoming;  // Lambertian: the way in does not matter
  std::vector<MajorantSegment> scratch;
  ++stats.events;
  const Surface s = scene.surfaceAt(at);
  const dvec3 from = at + s.normal * kSurfaceOffset_m;
  const dvec3 sun = sunThroughMedium(scene, from, rng, stats, scratch);
  dvec3 sum = sun * (s.albedo / kPi * std::max(0.0, glm::dot(s.normal, scene.sunDirection())));
  return sum + continuePath(scene, Ray{from, sampleCosine(s.normal, rng)}, dvec3(s.albedo), eventsBefore + 1,
                            options, rng, stats);
}

dvec3 radiance(const Scene& scene, const Ray& ray, const TraceOptions& options, Rng& rng, TraceStats& stats) {
  return continuePath(scene, ray, dvec3(1.0), 0, options, rng, stats);
}

}  // namespace sky::render::volume_paths
