// A full disk is an operating condition, not a bug: every write of the coordinator (bundles,
// unpacked scenes, SQLite commits, job images) turns ENOSPC/EDQUOT/SQLITE_FULL into DiskFullError,
// answered 507 with the data directory named, and leaves nothing half-written behind. Once space
// is freed the same requests succeed (workers retry 5xx answers).
#pragma once

#include "tessera/image/image.h"
#include "tessera/server/status.h"
#include "tessera/server/store.h"

#include <cstdint>
#include <exception>
#include <string>

namespace tessera::server {

bool is_disk_full_errno(int err);
/// True when `e` says a write failed for lack of space: DiskFullError, a StoreError flagged so,
/// a system_error with ENOSPC/EDQUOT, or a library's message carrying that errno's text (OpenEXR
/// and the bundle unpacker report errors as text).
bool is_disk_full(const std::exception& e);

/// A failed write of `what` with `err` (an errno): DiskFullError when the disk is full, else
/// StoreError.
[[noreturn]] void throw_write_error(const std::string& what, int err, const std::string& data_dir);
/// For writers that report errors as text (the bundle unpacker): throws DiskFullError when
/// `error` is a full disk's message, or when a write failed and `data_dir` has no space left.
void throw_if_disk_full(const std::string& error, const std::string& data_dir);

/// 507 with "the coordinator's disk is full: ... (data dir X)"; counted for /metrics.
Status disk_full_status(const std::exception& e);
/// 507 answers given since start (all coordinators of the process).
uint64_t disk_full_errors();

/// Writes a job's EXR durably: to a temporary name, read back and compared bit for bit (OpenEXR
/// and the C++ streams drop errors that happen when the file is closed, so a full disk can
/// truncate a file whose writer reported success), fsync'd, renamed. On failure nothing is left
/// and a full disk throws DiskFullError. `layers` (AOVs) are written beside the image.
void write_image_durably(const std::string& path, const Image& image, const ImageAttributes& attributes,
                         const std::string& data_dir, const std::vector<ImageLayer>& layers = {});
/// Checks a freshly written image file (`format` exr, pfm or png) decodes to `image`'s size (exr:
/// to its exact bits); throws DiskFullError when it does not and the disk is full, else
/// std::runtime_error.
void verify_image_file(const std::string& path, const std::string& format, const Image& image,
                       const std::string& data_dir);

}  // namespace tessera::server
