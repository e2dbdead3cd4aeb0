// An uploaded result, decoded: a Tile unit's (tile_result.h) or a Paths unit's (splat_result.h),
// told apart by its first bytes; what the coordinator checks, commits and adds to its job.
#pragma once

#include "tessera/farm/sha256.h"
#include "tessera/farm/splat_result.h"
#include "tessera/farm/tile_result.h"
#include "tessera/server/status.h"

#include <memory>
#include <string>
#include <string_view>

namespace tessera::server {

struct UnitUpload {
  std::shared_ptr<TileResult> tile;     // a Tile unit's result, or
  std::shared_ptr<SplatResult> splats;  // a Paths unit's

  uint64_t job() const { return tile ? tile->job_id : splats->job_id; }
  uint32_t index() const { return tile ? tile->tile : splats->unit; }
  uint32_t pass() const { return tile ? tile->pass : splats->pass; }
  double seconds() const { return tile ? tile->seconds : splats->seconds; }
  /// Records for the artifact its unit feeds (a training unit's).
  const std::string& records() const { return tile ? tile->training : splats->records; }
  /// What two renders of its unit must agree on: its sums (not the worker's timing).
  Sha256Digest digest() const;
};

/// Decodes an upload of either kind; a 400's status on anything malformed.
Result<UnitUpload> decode_upload(std::string_view bytes, int64_t max_pixels);

}  // namespace tessera::server
