// Reading a result upload's body as it arrives: a small one into memory, a large one (an
// image-wide splat result, a big tile with AOVs) into a file under the data directory that is then
// mapped, so that many concurrent uploads do not each hold their whole body on the heap.
#pragma once

#include "tessera/server/coordinator.h"

#include <httplib.h>

#include <memory>
#include <string>

namespace tessera::server {

/// Bodies up to this size stay in memory.
constexpr size_t kUploadMemoryBytes = size_t(4) << 20;

/// The request's body, read through `reader`; spooled to a file in `spool_dir` (removed once mapped)
/// past `memory_bytes`. An Internal status when the spool file cannot be written.
[[nodiscard]] Result<std::shared_ptr<const UploadBytes>> read_upload(const httplib::ContentReader& reader,
                                                                     const std::string& spool_dir,
                                                                     size_t memory_bytes = kUploadMemoryBytes);

/// Removes spool files a crash left behind (at start, before any upload).
void clear_spool(const std::string& spool_dir);

}  // namespace tessera::server
