// The look-ahead pass of scene loading that decodes every bitmap file of a scene in the
// background while the build loads meshes, instead of one by one as the build meets the textures.
#pragma once

#include "tessera/scene/load_context.h"
#include "tessera/texture/bitmap_decode.h"

#include <tbb/task_group.h>

#include <atomic>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace tessera {

/// One file and decoding to read ahead.
struct BitmapDecodeJob {
  std::string key, path;
  BitmapDecodeSettings settings;
};

/// Bitmaps being decoded by TBB tasks. A bitmap the build asks for before a task has started on
/// it is decoded by the asking thread; one being decoded is waited for. Each result depends only
/// on its file and settings, never on which thread made it or when.
class BitmapPrefetch {
 public:
  /// Starts decoding `jobs`, in their order.
  explicit BitmapPrefetch(std::vector<BitmapDecodeJob> jobs);
  /// Cancels the decodings not yet started (the load no longer needs them) and waits for the rest.
  ~BitmapPrefetch();
  BitmapPrefetch(const BitmapPrefetch&) = delete;
  BitmapPrefetch& operator=(const BitmapPrefetch&) = delete;

  /// The bitmap decoded for `key`; null when `key` was not among the jobs or its decoding failed
  /// (the caller decodes it again and reports the error where the scene names the file).
  std::shared_ptr<const DecodedBitmap> get(const std::string& key) const;
  /// Waits until every job has been decoded; returns how many succeeded.
  size_t wait_all() const;

 private:
  enum State : int { kPending, kRunning, kDone };
  struct Slot {
    BitmapDecodeJob job;
    std::atomic<int> state{kPending};
    std::shared_ptr<const DecodedBitmap> result;
  };
  /// Decodes the slot unless another thread has claimed it, else waits until that thread is done.
  const std::shared_ptr<const DecodedBitmap>& run(Slot& slot) const;

  std::vector<std::unique_ptr<Slot>> slots_;
  std::map<std::string, Slot*> by_key_;
  tbb::task_group tasks_;
};

/// Starts decoding, in the background, every bitmap texture file the scene description names
/// (each distinct file and decoding once), largest file first, and keeps the work in `ctx`. Reads
/// parameters without marking them used or logging them; a bitmap whose parameters or file are
/// wrong is left out, for the factory to report with its location. Never throws.
void prefetch_bitmaps(LoadContext& ctx);
/// The background work prefetch_bitmaps started for `ctx`, or null.
const BitmapPrefetch* bitmap_prefetch(const LoadContext& ctx);

}  // namespace tessera
