// Internal to the bundle reader: one walk over an archive that validates every entry, shared by
// inspect_bundle (no sink) and unpack_bundle (a sink that writes files).
#pragma once

#include "tessera/farm/bundle.h"

#include <string>
#include <string_view>

namespace tessera::detail {

/// Receives the regular files of a bundle as they are read; every call returns an error or "".
class EntrySink {
 public:
  virtual ~EntrySink() = default;
  virtual std::string directory(const std::string& path) = 0;
  virtual std::string begin(const std::string& path) = 0;
  virtual std::string write(const char* data, size_t size) = 0;
  virtual std::string end() = 0;
};

/// Reads every entry of `bytes`, validating names, types and sizes; passes file data to `sink`
/// (may be null). The error names the entry; on error `sink` may have received part of the data.
BundleResult walk_bundle(std::string_view bytes, const BundleLimits& limits, EntrySink* sink);

}  // namespace tessera::detail
