// CIGI's precipitation layer ids (Weather Control Layer ID 4-7: rain, snow,
// sleet, hail) and our precipitation types of the same kinds: one mapping
// for the server's weather input and the renderer's CIGI answers.
#pragma once

#include "sky/cigi/packets.hpp"
#include "sky/weather/model.hpp"

namespace sky::cigi {

// Our type for a precipitation layer id; CloudType::None for the others.
inline weather::CloudType precipitationTypeOf(LayerId id) {
  switch (id) {
    case LayerId::Rain: return weather::CloudType::Rain;
    case LayerId::Snow: return weather::CloudType::Snow;
    case LayerId::Sleet: return weather::CloudType::Sleet;
    case LayerId::Hail: return weather::CloudType::Hail;
    default: return weather::CloudType::None;
  }
}

inline constexpr LayerId kPrecipitationLayerIds[] = {LayerId::Rain, LayerId::Snow, LayerId::Sleet, LayerId::Hail};

}  // namespace sky::cigi
