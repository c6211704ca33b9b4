// Choosing the layers a channel draws (see drawable_weather.hpp).
#include "sky/app/drawable_weather.hpp"

#include <algorithm>
#include <map>
#include <set>

#include "sky/weather/precipitation.hpp"

namespace sky::app {

namespace {

// The snapshot with only the layers of these ids, and their tiles.
weather::WeatherSnapshot withLayers(const weather::WeatherSnapshot& s, const std::set<std::uint32_t>& keep) {
  weather::WeatherSnapshot out;
  out.weatherClock_s = s.weatherClock_s;
  out.tileLevel = s.tileLevel;
  out.areaIndex = s.areaIndex;
  for (const auto& l : s.layers)
    if (keep.count(l.id)) out.layers.push_back(l);
  for (const auto& t : s.tiles)
    if (keep.count(t.layerId)) out.tiles.push_back(t);
  return out;
}

}  // namespace

weather::WeatherSnapshot drawableWeather(const weather::WeatherSnapshot& s, std::size_t maxLayers,
                                         std::vector<std::uint32_t>* dropped) {
  if (dropped) dropped->clear();
  if (s.layers.size() <= maxLayers) return s;
  // How much cloud a layer has anywhere in the snapshot: its own value, or
  // more in some tile (a layer only a storm region has is 0 globally).
  std::map<std::uint32_t, double> most;
  for (const auto& l : s.layers) most[l.id] = l.coverage * l.density;
  for (const auto& t : s.tiles) {
    auto it = most.find(t.layerId);
    if (it != most.end()) it->second = std::max(it->second, double(t.coverage) * double(t.density));
  }
  std::vector<const weather::CloudLayer*> ranked;
  for (const auto& l : s.layers) ranked.push_back(&l);
  // Fog and precipitation that are there come first: they are thin by
  // density (a 4 km mist is 0.02, moderate rain 0.06) but seen along
  // kilometres of sight line at the ground, and the CIGI answer and the
  // conformance check count on them being drawn.
  const auto obscuresThere = [&](const weather::CloudLayer* l) {
    return (l->type == weather::CloudType::Fog || weather::isPrecipitation(l->type)) && most[l->id] > 0;
  };
  std::stable_sort(ranked.begin(), ranked.end(), [&](const weather::CloudLayer* a, const weather::CloudLayer* b) {
    if (obscuresThere(a) != obscuresThere(b)) return obscuresThere(a);
    const double ca = most[a->id], cb = most[b->id];
    return ca != cb ? ca > cb : a->id < b->id;
  });
  std::set<std::uint32_t> keep;
  for (std::size_t i = 0; i < ranked.size(); ++i) {
    if (i < maxLayers)
      keep.insert(ranked[i]->id);
    else if (dropped)
      dropped->push_back(ranked[i]->id);
  }
  if (dropped) std::sort(dropped->begin(), dropped->end());
  return withLayers(s, keep);
}

weather::WeatherSnapshot drawableCoarse(const weather::WeatherSnapshot& coarse,
                                        const weather::WeatherSnapshot& drawable) {
  std::set<std::uint32_t> keep;
  for (const auto& l : drawable.layers) keep.insert(l.id);
  return withLayers(coarse, keep);
}

}  // namespace sky::app
