// The flight category of a METAR report (VFR, MVFR, IFR, LIFR), read from
// its ceiling and prevailing visibility, for the station markers on the map
// (stations.js). Pure: tested by tests/console/coverage_test.mjs in Node.js.
//
// Categories as the US National Weather Service and FAA AIM 7-1-7 define
// them (the colours aviationweather.gov draws): the worse of the two decides.
//   LIFR  ceiling below 500 ft AGL, or visibility below 1 SM
//   IFR   ceiling 500 to below 1000 ft, or visibility 1 to below 3 SM
//   MVFR  ceiling 1000 to 3000 ft, or visibility 3 to 5 SM
//   VFR   ceiling above 3000 ft and visibility above 5 SM
// The ceiling is the lowest broken or overcast layer, or the vertical
// visibility into an obscured sky (VV).

// One statute mile (m).
const STATUTE_MILE_M = 1609.344;
// Upper bounds (exclusive) of each category but VFR: ceiling ft, visibility SM.
const LIMITS = [
  { category: "LIFR", ceiling_ft: 500, visibility_sm: 1 },
  { category: "IFR", ceiling_ft: 1000, visibility_sm: 3 },
  // MVFR includes 3000 ft and 5 SM themselves: "3000 or below", "5 or below".
  { category: "MVFR", ceiling_ft: 3000.5, visibility_sm: 5.0001 },
];
// Groups after which the report no longer describes the observation.
const END_OF_OBSERVATION = new Set(["RMK", "TEMPO", "BECMG", "NOSIG", "TREND"]);

// A statute-mile visibility: "10SM", "P6SM", "M1/4SM", "1/2SM", or "1 1/2SM"
// as two groups (the whole miles in `before`).
function statuteMiles(group, before) {
  const m = /^([PM])?(?:(\d+)\/(\d+)|(\d+))SM$/.exec(group);
  if (!m) return null;
  let sm = m[4] !== undefined ? Number(m[4]) : Number(m[2]) / Number(m[3]);
  if (m[2] !== undefined && /^\d$/.test(before || "")) sm += Number(before);
  // "M1/4SM" is less than a quarter mile: a hair below, so the bound holds.
  if (m[1] === "M") sm *= 0.999;
  return sm;
}

// {ceiling_ft, visibility_sm} of a report's observation (null when the
// report does not give one).
export function readReport(text) {
  const groups = String(text).trim().toUpperCase().split(/\s+/);
  let ceiling_ft = null, visibility_sm = null;
  const lower = (ft) => { ceiling_ft = ceiling_ft === null ? ft : Math.min(ceiling_ft, ft); };
  for (let i = 0; i < groups.length; ++i) {
    const g = groups[i];
    if (END_OF_OBSERVATION.has(g)) break;
    if (g === "CAVOK") { visibility_sm = Math.max(visibility_sm ?? 0, 10000 / STATUTE_MILE_M); continue; }
    // Metres: "9999" (10 km or more), "0800", with an optional direction
    // ("4000NE") or NDV. The first such group is the prevailing visibility.
    // A time group (DDHHMMZ) or wind group never matches: they have letters.
    const metres = /^(\d{4})(NDV|[NS]?[EW]?)?$/.exec(g);
    if (metres && visibility_sm === null && i > 1) {
      visibility_sm = (metres[1] === "9999" ? 10000 : Number(metres[1])) / STATUTE_MILE_M;
      continue;
    }
    const sm = statuteMiles(g, groups[i - 1]);
    if (sm !== null) { visibility_sm = sm; continue; }
    const cloud = /^(BKN|OVC)(\d{3})/.exec(g);
    if (cloud) { lower(Number(cloud[2]) * 100); continue; }
    const vv = /^VV(\d{3}|\/\/\/)$/.exec(g);
    // "VV///": obscured, height not measured: below the lowest category.
    if (vv) lower(vv[1] === "///" ? 0 : Number(vv[1]) * 100);
  }
  return { ceiling_ft, visibility_sm };
}

// The category of a ceiling (ft above the station) and a visibility (SM),
// either null when unknown; null when both are.
export function categoryOf(ceiling_ft, visibility_sm) {
  if (ceiling_ft === null && visibility_sm === null) return null;
  for (const l of LIMITS) {
    if ((ceiling_ft !== null && ceiling_ft < l.ceiling_ft) || (visibility_sm !== null && visibility_sm < l.visibility_sm))
      return l.category;
  }
  return "VFR";
}

// "VFR", "MVFR", "IFR", "LIFR", or null when the report gives neither a
// ceiling nor a visibility (nor says the sky is clear).
export function flightCategory(text) {
  const { ceiling_ft, visibility_sm } = readReport(text);
  return categoryOf(ceiling_ft, visibility_sm);
}

// Broken: 5 oktas, the least cover that makes a ceiling.
const CEILING_COVERAGE = 5 / 8;
const FT_PER_M = 1 / 0.3048;

// The weather model's fog: a density d stands for an extinction of 0.05 d
// per metre, whose Koschmieder range (3.912 / extinction) is the visibility
// (protocol/weather/include/sky/weather/query.hpp); precipitation's density
// for 0.01 d per metre (precipitation.hpp).
const FOG_EXTINCTION_PER_DENSITY = 0.05, PRECIPITATION_EXTINCTION_PER_DENSITY = 0.01, KOSCHMIEDER_DEPTH = 3.912;
const PRECIPITATION = ["rain", "snow", "sleet", "hail"];

// The category from a station region's layers alone (the server restarted
// and no longer has the report's text): the ceiling is the lowest cloud base
// with 5 oktas or more above the station; the visibility is that of its fog
// and precipitation together (the layers a report's obscuration and
// precipitation became), or unknown without.
export function categoryFromLayers(layers, elevation_m) {
  const obscures = (l) => l.type === "fog" || PRECIPITATION.includes(l.type);
  const cloud = layers.filter((l) => !obscures(l) && l.coverage >= CEILING_COVERAGE);
  const bases = cloud.map((l) => (l.base_m - elevation_m) * FT_PER_M);
  const seen = layers.filter((l) => obscures(l) && l.coverage > 0 && l.density > 0);
  const extinction = seen.reduce((sum, l) => sum + l.coverage * l.density *
    (l.type === "fog" ? FOG_EXTINCTION_PER_DENSITY : PRECIPITATION_EXTINCTION_PER_DENSITY), 0);
  const visibility_sm = seen.length ? KOSCHMIEDER_DEPTH / extinction / STATUTE_MILE_M : null;
  return categoryOf(bases.length ? Math.max(0, Math.min(...bases)) : Infinity, visibility_sm);
}
