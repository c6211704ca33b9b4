// Units the operator reads (feet, knots, oktas) against the API's (metres,
// m/s, fractions), and the checks a draft passes before it is sent: the same
// ranges the server enforces (protocol/weather/src/model.cpp, region.cpp), so
// a bad value is refused next to its field at once, and the server's own
// refusal (400 with "field") lands next to the same field.

export const M_PER_FT = 0.3048;        // international foot, exact
export const MPS_PER_KT = 1852 / 3600; // knot: one nautical mile (1852 m) per hour, exact
export const OKTAS = 8;                // eighths of the sky

export const CLOUD_TYPES = ["cumulus", "stratus", "stratocumulus", "cumulonimbus", "altocumulus", "altostratus",
  "nimbostratus", "cirrus", "cirrostratus", "cirrocumulus", "fog", "rain", "snow", "sleet", "hail", "none"];

// The server's ranges (model.cpp validate, region.cpp validate, change.hpp).
export const LIMITS = {
  base_m: [-500, 20000], thickness_m: [0, 20000], transition_band_m: [0, 5000], wind_speed_mps: [0, 150],
  wind_from_deg: [0, 360], wind_vertical_mps: [-50, 50], ramp_s: [0, 86400], region_size_m: [0, 2e6],
  clock_rate: [0, 3600],
};

export const ftFromM = (m) => m / M_PER_FT;
export const mFromFt = (ft) => ft * M_PER_FT;
export const ktFromMps = (v) => v / MPS_PER_KT;
export const mpsFromKt = (kt) => kt * MPS_PER_KT;

// Rounds for display without trailing zeros: fmt(1524.0000001, 1) = "1524".
export function fmt(v, digits = 0) {
  if (v === null || v === undefined || !Number.isFinite(v)) return "–";
  return String(Number(v.toFixed(digits)));
}

// Weather clock seconds as [d ]hh:mm:ss (the clock counts seconds; a value
// past a day shows the day).
export function clockText(s) {
  if (!Number.isFinite(s)) return "–";
  const sign = s < 0 ? "-" : "";
  let t = Math.floor(Math.abs(s));
  const d = Math.floor(t / 86400);
  t -= d * 86400;
  const hh = String(Math.floor(t / 3600)).padStart(2, "0");
  const mm = String(Math.floor((t % 3600) / 60)).padStart(2, "0");
  const ss = String(t % 60).padStart(2, "0");
  return `${sign}${d ? d + "d " : ""}${hh}:${mm}:${ss}`;
}

// "12:30", "12:30:15", "1d 02:00:00" or plain seconds to clock seconds; NaN
// when it is none of these.
export function parseClock(text) {
  const t = String(text).trim();
  if (/^-?\d+(\.\d+)?$/.test(t)) return Number(t);
  const m = /^(?:(\d+)d\s*)?(\d{1,2}):(\d{2})(?::(\d{2}))?$/.exec(t);
  if (!m) return NaN;
  const [, d, h, mi, s] = m;
  if (Number(mi) > 59 || (s && Number(s) > 59)) return NaN;
  return Number(d || 0) * 86400 + Number(h) * 3600 + Number(mi) * 60 + Number(s || 0);
}

// A number typed into a field: NaN for empty or not a number.
export function num(text) {
  const t = String(text).trim();
  return t === "" ? NaN : Number(t);
}

function range(errors, field, v, [lo, hi], what, unit, openLow = false) {
  if (!Number.isFinite(v)) errors[field] = `${what}: enter a number`;
  else if (openLow ? v <= lo : v < lo) errors[field] = `${what} ${fmt(v, 2)}${unit} is below ${lo}${unit}`;
  else if (v > hi) errors[field] = `${what} ${fmt(v, 2)}${unit} is above ${hi}${unit}`;
}

// Checks a layer draft in API units. Returns {field: reason}; empty when the
// server would take it. Fields: id type coverage base top transition density
// windSpeed windFrom windVertical (the form's names).
export function checkLayer(l) {
  const e = {};
  if (!Number.isInteger(l.id) || l.id < 0 || l.id > 65535) e.id = "id: a whole number from 0 to 65535";
  if (!CLOUD_TYPES.includes(l.type)) e.type = `'${l.type}' is not a cloud type`;
  if (!Number.isFinite(l.coverage)) e.coverage = "coverage: enter a number";
  else if (l.coverage < 0 || l.coverage > 1)
    e.coverage = `coverage ${fmt(l.coverage * 100, 1)} % is outside 0–100 % (0–8 oktas)`;
  if (!Number.isFinite(l.base_m)) e.base = "base: enter a number";
  else if (l.base_m < LIMITS.base_m[0])
    e.base = `base ${fmt(l.base_m)} m is below the ground (lowest ${LIMITS.base_m[0]} m MSL)`;
  else if (l.base_m > LIMITS.base_m[1]) e.base = `base ${fmt(l.base_m)} m is above ${LIMITS.base_m[1]} m`;
  const top_m = l.base_m + l.thickness_m;
  if (!Number.isFinite(l.thickness_m)) e.top = "top: enter a number";
  else if (!e.base && l.thickness_m <= 0) e.top = `top ${fmt(top_m)} m must be above the base (${fmt(l.base_m)} m)`;
  else if (l.thickness_m > LIMITS.thickness_m[1]) e.top = `top is ${fmt(l.thickness_m)} m above the base, at most 20000 m`;
  range(e, "transition", l.transition_band_m, LIMITS.transition_band_m, "transition band", " m");
  if (!Number.isFinite(l.density)) e.density = "density: enter a number";
  else if (l.density < 0 || l.density > 1) e.density = `density ${fmt(l.density, 2)} is outside 0–1`;
  range(e, "windSpeed", l.wind.speed_mps, LIMITS.wind_speed_mps, "wind speed", " m/s");
  range(e, "windFrom", l.wind.from_deg, LIMITS.wind_from_deg, "wind direction", "°");
  range(e, "windVertical", l.wind.vertical_mps, LIMITS.wind_vertical_mps, "vertical wind", " m/s");
  return e;
}

// Checks ramp and start: ramp in [0, 86400] s; a start, when given, not
// before the clock now.
export function checkTiming(ramp_s, at_s, clockNow_s) {
  const e = {};
  range(e, "ramp", ramp_s, LIMITS.ramp_s, "ramp", " s");
  if (at_s !== null && at_s !== undefined) {
    if (!Number.isFinite(at_s)) e.at = "start: a clock time (12:30:00) or seconds";
    else if (at_s < clockNow_s - 1) e.at = `start ${clockText(at_s)} is in the past (clock ${clockText(clockNow_s)})`;
  }
  return e;
}

// Checks a region draft (API units). Fields: id lat lon sizeX sizeY corner
// rotation transition layers.
export function checkRegion(r) {
  const e = {};
  if (!Number.isInteger(r.id) || r.id < 1 || r.id > 65535) e.id = "region id: a whole number from 1 to 65535";
  range(e, "lat", r.center_lat_deg, [-90, 90], "latitude", "°");
  if (!Number.isFinite(r.center_lon_deg)) e.lon = "longitude: enter a number";
  range(e, "sizeX", r.size_x_m, LIMITS.region_size_m, "width", " m", true);
  range(e, "sizeY", r.size_y_m, LIMITS.region_size_m, "length", " m", true);
  const maxCorner = Math.min(r.size_x_m, r.size_y_m) / 2;
  if (!Number.isFinite(r.corner_radius_m)) e.corner = "corner radius: enter a number";
  else if (r.corner_radius_m < 0 || r.corner_radius_m > maxCorner)
    e.corner = `corner radius ${fmt(r.corner_radius_m)} m is outside 0–${fmt(maxCorner)} m (half the smaller side)`;
  range(e, "rotation", r.rotation_deg, [-180, 180], "rotation", "°");
  range(e, "transition", r.transition_m, LIMITS.region_size_m, "transition", " m");
  if (r.layers.length > 16) e.layers = `${r.layers.length} layers, at most 16`;
  const seen = new Set();
  r.layers.forEach((l, i) => {
    const le = checkLayer(l);
    const first = Object.values(le)[0];
    if (first && !e.layers) e.layers = `layer ${i + 1}: ${first}`;
    if (seen.has(l.id) && !e.layers) e.layers = `layer id ${l.id} given twice`;
    seen.add(l.id);
  });
  if (r.drifts_with_wind && r.layers.length === 0) e.drifts = "drifting needs a layer (it follows the first layer's wind)";
  return e;
}

// Which API key a server refusal concerns. The server names the JSON path
// in "field" ("changes[0].layer", "changes[0].layer.base_m") and, for a range
// check, the key in the text ("layer 2: coverage 1.4 outside [0, 1]"). The
// key in the text wins (it is the more precise); else the path's last part.
// Returns {key, layerIndex}: layerIndex when the text names a region's
// layers[i], else null.
export function keyOfServerError(body) {
  const text = (body && body.error) || "";
  const path = (body && body.field) || "";
  const layer = /layers\[(\d+)\]/.exec(text);
  const ranged = [...text.matchAll(/([a-z_]+(?:\.[a-z_]+)?) (?:\S+ outside|must be finite)/g)].pop();
  const last = path.split(".").pop().replace(/\[\d+\]$/, "");
  return { key: ranged ? ranged[1] : last, layerIndex: layer ? Number(layer[1]) : null };
}
