// A forecast in the live weather (see live_weather.hpp).
#include <cmath>
#include <set>

#include "ramp_math.hpp"
#include "sky/server/api_json.hpp"
#include "sky/server/live_weather.hpp"
#include "sky/server/weather_store.hpp"

namespace sky::server {

namespace {

std::string utc(std::int64_t unix_s) {
  const std::time_t t = static_cast<std::time_t>(unix_s);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%MZ", &tm);
  return buf;
}

bool isForecastSlot(std::uint32_t id) { return id >= kForecastBoundarySlot && id <= kForecastConvectiveSlot; }

}  // namespace

nlohmann::json forecastJson(const LoadedForecast* f) {
  if (!f || !f->forecast) return nullptr;
  nlohmann::json files = nlohmann::json::array();
  for (const auto& file : f->files) files.push_back({{"key", file.key}, {"name", file.name}});
  nlohmann::json layers = nlohmann::json::array();
  for (const ForecastLayer& l : f->forecast->layers())
    layers.push_back({{"id", l.layer.id},
                      {"type", std::string(weather::toString(l.layer.type))},
                      {"base_m", l.layer.base_m},
                      {"thickness_m", l.layer.thickness_m},
                      {"steps", l.steps.size()},
                      {"source", l.steps.front().cover->source},
                      {"height_from", l.heightFrom}});
  const Forecast& fc = *f->forecast;
  return {{"name", fc.name()},
          {"files", files},
          {"anchor_clock_s", f->placement.anchorClock_s},
          {"anchor_valid_unix", f->placement.anchorValid_unix},
          {"reference", utc(fc.reference_unix())},
          {"first_valid", utc(fc.firstValid_unix())},
          {"last_valid", utc(fc.lastValid_unix())},
          {"steps", fc.stepCount()},
          {"layers", layers},
          {"notes", fc.notes()}};
}

Result<std::vector<LoadedForecast::File>> forecastFilesFromJson(const nlohmann::json& j) {
  try {
    std::vector<LoadedForecast::File> files;
    for (const auto& f : j.at("files")) files.push_back({f.at("key").get<std::string>(), f.at("name").get<std::string>()});
    if (files.empty()) return fail(ErrorCode::Malformed, "forecast: no files");
    return files;
  } catch (const nlohmann::json::exception& e) {
    return fail(ErrorCode::Malformed, std::string("forecast: ") + e.what());
  }
}

Result<ForecastPlacement> forecastPlacementFromJson(const nlohmann::json& j) {
  try {
    ForecastPlacement p;
    p.anchorClock_s = j.at("anchor_clock_s").get<double>();
    p.anchorValid_unix = j.at("anchor_valid_unix").get<std::int64_t>();
    if (!std::isfinite(p.anchorClock_s)) return fail(ErrorCode::Malformed, "forecast: anchor_clock_s not finite");
    return p;
  } catch (const nlohmann::json::exception& e) {
    return fail(ErrorCode::Malformed, std::string("forecast: ") + e.what());
  }
}

nlohmann::json apiStateJson(const LiveWeather& weather) {
  nlohmann::json state = toJson(weather.view());
  state["forecast"] = forecastJson(weather.forecast().get());
  return state;
}

std::shared_ptr<const ForecastField> LiveWeather::fieldAt(double clock_s) const {
  if (!forecast_ || !forecast_->forecast) return nullptr;
  return std::make_shared<const ForecastField>(forecast_->forecast, forecast_->serial,
                                               forecast_->placement.validAt(clock_s));
}

Result<AppliedChange> LiveWeather::loadForecast(LoadedForecast loaded, const std::string& author,
                                                const std::string& source) {
  if (!loaded.forecast || loaded.forecast->layers().empty()) {
    ++rejected_;
    return fail(ErrorCode::InvalidArgument, "forecast: no layers");
  }
  const double now_s = clockNow();
  settle(now_s);
  State next = state();
  // The forecast's layers replace what stood in their slots (a forecast
  // loaded before included); ramps of those ids end with it.
  for (auto it = next.layers.begin(); it != next.layers.end();)
    it = isForecastSlot(it->first) ? next.layers.erase(it) : std::next(it);
  std::erase_if(next.ramps, [](const Ramp& r) { return isForecastSlot(r.layerId); });
  for (const ForecastLayer& l : loaded.forecast->layers()) {
    if (auto ok = weather::validate(l.layer); !ok) {
      ++rejected_;
      return fail(ErrorCode::InvalidArgument, "forecast layer " + std::to_string(l.layer.id) + ": " + ok.error().detail);
    }
    next.layers[l.layer.id] = l.layer;
  }
  std::vector<weather::CloudLayer> all;
  for (const auto& [id, l] : next.layers) all.push_back(l);
  if (const std::size_t ids = distinctLayerIds(all, evaluateRegions(next, now_s)); ids > kMaxScenarioLayers) {
    ++rejected_;
    return fail(ErrorCode::InvalidArgument, "forecast: " + std::to_string(ids) + " layers with the forecast's, at most " +
                                                std::to_string(kMaxScenarioLayers));
  }
  loaded.serial = ++forecastSerial_;
  const Forecast& fc = *loaded.forecast;
  const std::string summary = "forecast " + fc.name() + " loaded: " + std::to_string(fc.layers().size()) +
                              " layer(s), " + std::to_string(fc.stepCount()) + " step(s) valid " +
                              utc(fc.firstValid_unix()) +
                              (fc.stepCount() > 1 ? " to " + utc(fc.lastValid_unix()) : "") + ", " +
                              utc(loaded.placement.anchorValid_unix) + " at clock " +
                              std::to_string(static_cast<long long>(std::llround(loaded.placement.anchorClock_s))) + " s";
  next.forecast = std::make_shared<const LoadedForecast>(std::move(loaded));
  auto applied = commit(std::move(next), timeline_, author, source, summary, now_s);
  if (applied && store_) {
    std::set<std::string> keep;
    for (const auto& f : forecast_->files) keep.insert(f.key);
    (void)store_->keepFiles(keep);  // a failure only leaves unused bytes behind
  }
  return applied;
}

Result<AppliedChange> LiveWeather::removeForecast(const std::string& author, const std::string& source) {
  if (!forecast_) {
    ++rejected_;
    return fail(ErrorCode::InvalidArgument, "forecast: none is loaded");
  }
  const double now_s = clockNow();
  settle(now_s);
  State next = state();
  for (const ForecastLayer& l : forecast_->forecast->layers()) next.layers.erase(l.layer.id);
  std::erase_if(next.ramps, [](const Ramp& r) { return isForecastSlot(r.layerId); });
  const std::string summary = "forecast " + forecast_->forecast->name() + " removed with its layers";
  next.forecast = nullptr;
  auto applied = commit(std::move(next), timeline_, author, source, summary, now_s);
  if (applied && store_) (void)store_->keepFiles({});
  return applied;
}

}  // namespace sky::server
