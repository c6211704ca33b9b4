// A Monte Carlo volumetric path tracer over any scene that can say its
// extinction at a point and bound it along a ray: delta (Woodcock) tracking
// for free flights, ratio tracking for the sun's transmittance, the sun by
// next-event estimation, phase and Lambertian sampling, Russian roulette.
// Unbiased as long as the scene's majorant bounds its extinction (the
// points where it does not are counted, not hidden). Double precision
// throughout: the ground truth the renderer's model is measured against
// (path_tracer.cpp's clouds) and the closed forms it is itself tested
// against (tests/unit/renderer/volume_paths_test.cpp's slabs).
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include <glm/glm.hpp>

namespace sky::render::volume_paths {

using glm::dvec3;

inline constexpr double kInfinity = std::numeric_limits<double>::infinity();

// PCG32 (O'Neill 2014): one stream per pixel sample, so an image does not
// depend on how its pixels were split between threads.
class Rng {
 public:
  Rng(std::uint64_t seed, std::uint64_t stream);
  std::uint32_t next();
  double uniform();  // [0, 1)

 private:
  std::uint64_t state_ = 0;
  std::uint64_t inc_ = 1;
};

struct Ray {
  dvec3 origin{0.0};
  dvec3 dir{0.0, 0.0, 1.0};  // unit
};

// A phase function: (1 - w) HG(gHG) + w Draine(gD, alpha), 1/sr, which
// holds isotropic (all 0), Henyey-Greenstein (w = 0) and Jendersie &
// d'Eon's Mie fit of cloud droplets. cosTheta is between the light's
// direction of travel before and after the scattering.
struct Phase {
  double gHG = 0.0;
  double gD = 0.0;
  double alpha = 0.0;
  double w = 0.0;
};
double evalPhase(const Phase& p, double cosTheta);
// A direction of travel after scattering light travelling along `dir`:
// drawn from the mixture of HG(gHG) and HG(gD) by the weights (exact for
// the HG lobe); weight = phase / pdf (1 where the phase is a pure HG).
dvec3 samplePhase(const Phase& p, const dvec3& dir, Rng& rng, double& weight);
// A unit direction around n with pdf cos / pi.
dvec3 sampleCosine(const dvec3& n, Rng& rng);

// The scene's extinction bound on [t0, t1) of a ray, 1/m (0: no medium).
struct MajorantSegment {
  double t0 = 0.0;
  double t1 = 0.0;
  double sigma = 0.0;
};

struct MediumPoint {
  double sigmaT = 0.0;  // extinction, 1/m
  double albedo = 1.0;  // single-scattering albedo
  Phase phase;
};

struct Surface {
  dvec3 normal{0.0, 0.0, 1.0};
  double albedo = 0.0;  // Lambertian
};

// What the integrator asks of a scene. Radiance and irradiance are rgb in
// the scene's units; distances in metres.
class Scene {
 public:
  virtual ~Scene() = default;
  // Segments ordered along the ray covering where the medium is on
  // [0, tMax), each with a bound of its extinction (out is cleared first).
  virtual void majorants(const Ray& ray, double tMax, std::vector<MajorantSegment>& out) const = 0;
  // The medium at p; u in [0, 1) picks among overlapping components (the
  // phase is that of one chosen in proportion to its extinction).
  virtual MediumPoint medium(const dvec3& p, double u) const = 0;
  // Distance to the opaque surface along the ray, kInfinity when none.
  virtual double surfaceDistance(const Ray& ray) const = 0;
  virtual Surface surfaceAt(const dvec3& p) const = 0;
  // Towards the sun, unit.
  virtual dvec3 sunDirection() const = 0;
  // The sun's irradiance at p before the medium's shadow (on a plane
  // facing the sun; 0 where the sun is below p's horizon).
  virtual dvec3 sunIrradiance(const dvec3& p) const = 0;
  // Radiance arriving at ray.origin against ray.dir from beyond the medium
  // where the ray meets no surface (the sky, without the sun's disc, which
  // only next-event estimation sees).
  virtual dvec3 escapeRadiance(const Ray& ray) const = 0;
  // What the space without the medium adds between ray.origin and the
  // surface at distance t, as (in-scattered radiance, transmittance);
  // default: nothing, and clear.
  virtual void surfaceSegment(const Ray& ray, double t, dvec3& inscatter, dvec3& transmittance) const;
};

struct TraceOptions {
  // Scattering events (in the medium or at the surface) a counted path
  // may have; 0: any number. 1 is single scattering.
  int maxEvents = 0;
  // Events after which Russian roulette may end a path.
  int rouletteAfter = 8;
};

// Counters of one or many paths.
struct TraceStats {
  std::uint64_t densityLookups = 0;
  std::uint64_t majorantViolations = 0;  // points whose extinction exceeded the majorant
  std::uint64_t events = 0;
};

// The distance to the first collision along the ray before tMax (delta
// tracking), or kInfinity with none; `point` is the medium there.
double freeFlight(const Scene& scene, const Ray& ray, double tMax, Rng& rng, MediumPoint& point, TraceStats& stats,
                  std::vector<MajorantSegment>& scratch);

// Transmittance along the ray up to tMax by ratio tracking (an unbiased
// estimate).
double ratioTransmittance(const Scene& scene, const Ray& ray, double tMax, Rng& rng, TraceStats& stats,
                          std::vector<MajorantSegment>& scratch);

// Radiance arriving at the origin of a path that begins at a scattering
// event: the medium point `at` on a path that travelled along `incoming`
// (the view ray's direction), events already counted. Exposed for the
// camera-ray estimators, which trace the first segment themselves.
dvec3 radianceFromEvent(const Scene& scene, const dvec3& at, const dvec3& incoming, const MediumPoint& point,
                        int eventsBefore, const TraceOptions& options, Rng& rng, TraceStats& stats);
// The same for a surface point reached along `incoming`.
dvec3 radianceFromSurface(const Scene& scene, const dvec3& at, const dvec3& incoming, int eventsBefore,
                          const TraceOptions& options, Rng& rng, TraceStats& stats);

// Radiance arriving at ray.origin against ray.dir: one path's estimate.
dvec3 radiance(const Scene& scene, const Ray& ray, const TraceOptions& options, Rng& rng, TraceStats& stats);

}  // namespace sky::render::volume_paths
