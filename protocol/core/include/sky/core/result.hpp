// Result<T>: the return type of every operation that can fail for reasons
// outside the program (bytes from a socket, a file, a config, the GPU).
// Bugs are not Results: they are SKY_ASSERTs (sky/core/assert.hpp).
#pragma once

#include <string>
#include <utility>

#include <tl/expected.hpp>

namespace sky {

enum class ErrorCode {
  InvalidArgument,  // a value outside its documented range
  Malformed,        // bytes or text that do not parse
  Unsupported,      // a version or kind we do not speak
  TooLarge,         // a frame or file over its cap
  Io,               // the operating system said no
  Timeout,
  Device,           // the GPU (or its driver) failed
  NoDevice,         // no Vulkan driver or device at all: a missing dependency, not a fault
};

const char* toString(ErrorCode code);

struct Error {
  ErrorCode code;
  std::string detail;  // what and where: "flight.csv:12: field 'lat_deg': ..."
};

template <class T>
using Result = tl::expected<T, Error>;

inline tl::unexpected<Error> fail(ErrorCode code, std::string detail) {
  return tl::unexpected<Error>(Error{code, std::move(detail)});
}

// "Malformed: flight.csv:12: ..." for logs and exceptions at a main's edge.
std::string describe(const Error& error);

}  // namespace sky
