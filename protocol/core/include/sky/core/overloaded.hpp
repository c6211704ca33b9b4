// Overloaded{lambdas...}: one visitor out of several lambdas, for std::visit.
#pragma once

namespace sky {

template <class... Ts>
struct Overloaded : Ts... {
  using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;  // clang 14 lacks aggregate CTAD

}  // namespace sky
