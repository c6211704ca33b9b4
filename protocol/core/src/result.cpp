// Names for error codes, for logs and messages.
#include "sky/core/result.hpp"

namespace sky {

const char* toString(ErrorCode code) {
  switch (code) {
    case ErrorCode::InvalidArgument: return "InvalidArgument";
    case ErrorCode::Malformed: return "Malformed";
    case ErrorCode::Unsupported: return "Unsupported";
    case ErrorCode::TooLarge: return "TooLarge";
    case ErrorCode::Io: return "Io";
    case ErrorCode::Timeout: return "Timeout";
    case ErrorCode::Device: return "Device";
    case ErrorCode::NoDevice: return "NoDevice";
  }
  return "Unknown";
}

std::string describe(const Error& error) {
  return std::string(toString(error.code)) + ": " + error.detail;
}

}  // namespace sky
